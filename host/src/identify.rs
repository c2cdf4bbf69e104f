//! The board's side of identification (issue 24, item 1; `snapgen identify`): a bounded
//! excitation played through the fabric's own position loop, recorded from its TELEMETRY
//! frames. The fit is `snapgen_plant::identify`'s.
//!
//! The board is configured with the given controller (a low-bandwidth one derived from the
//! data sheet's plant: the excitation is the loop's own duty, whatever the motor really is),
//! its following-error limit armed and its duty bounded by its OUTPUT_LIMIT, and TELEMETRY_PERIOD
//! set to SERVO_PERIOD, so each frame carries one controller sample: the encoder's count and the
//! duty then. Each move of the excitation is uploaded, started and recorded to its end; the
//! watchdog covers each move (it is set to the longest move and a second). A following-error
//! trip ends the recording with the board's error. However it ends, the axis is brought to
//! rest and its amplifier switched off ([`record`]).

use snapgen_model::io::servo::ServoConfig;
use snapgen_model::stop::StopLimits;
use snapgen_model::Program;
use snapgen_plant::identify::{Electrical, Record, Segment};
use snapgen_plant::Physical;

use crate::link::Link;
use crate::protocol::{AxisState, Command, Param, Status};
use crate::session::{HostError, Session};

/// What to play.
#[derive(Clone, Debug, PartialEq)]
pub struct Excitation {
    /// PWM period (clocks).
    pub pwm_period: u16,
    /// The controller during the excitation (its SERVO_PERIOD is the record's period).
    pub servo: ServoConfig,
    /// The stop's limits.
    pub stop: StopLimits,
    /// The moves, each from where the last ended.
    pub moves: Vec<Program>,
    /// Seconds recorded after each move's last tick (its frames stop with the chain, the
    /// board's status is read then).
    pub settle_s: f64,
}

/// One move's frames, in the order they came.
pub type MoveFrames = Vec<Status>;

/// Plays `e` on the board of `s` and returns each move's TELEMETRY frames. Whatever ends it —
/// the last move, a following-error trip, a refusal or a lost link — the axis is stopped (STOP,
/// waited for) and its amplifier switched off before this returns; the host watchdog is set
/// back as it was.
pub fn record<L: Link>(s: &mut Session<L>, e: &Excitation) -> Result<Vec<MoveFrames>, HostError> {
    let watchdog = s.read_config(Param::WatchdogMs)?;
    let out = play(s, e);
    let off = shut_down(s);
    // The host watchdog as it was, whatever happened.
    let restored = s.configure(Param::WatchdogMs, watchdog);
    let frames = out?;
    off?;
    restored?;
    Ok(frames)
}

/// STOP if the axis moves, wait for it to rest (two seconds at most), POWER 0.
fn shut_down<L: Link>(s: &mut Session<L>) -> Result<(), HostError> {
    let mut st = s.status()?;
    if matches!(
        st.axis(),
        Some(AxisState::DiscreteMotion | AxisState::Stopping)
    ) {
        let _ = s.expect_ack(&Command::Stop);
        for _ in 0..40 {
            s.link.wait(0.05);
            st = s.status()?;
            if !matches!(
                st.axis(),
                Some(AxisState::DiscreteMotion | AxisState::Stopping)
            ) {
                break;
            }
        }
    }
    match st.axis() {
        // Already off (Disabled), or off by the trip (ErrorStop: the amplifier is off).
        Some(AxisState::Disabled | AxisState::ErrorStop) => Ok(()),
        _ => s.expect_ack(&Command::Power { on: false }),
    }
}

fn play<L: Link>(s: &mut Session<L>, e: &Excitation) -> Result<Vec<MoveFrames>, HostError> {
    let ts = s.format.ts;
    let longest = e
        .moves
        .iter()
        .map(|p| p.total_ticks() as f64 * ts)
        .fold(0.0, f64::max);
    let watchdog_ms = ((longest + e.settle_s + 1.0) * 1e3).ceil();
    s.expect_ack(&Command::Configure {
        param: Param::PwmPeriod,
        value: i128::from(e.pwm_period),
    })?;
    for (param, value) in e.servo.writes() {
        s.configure(param, value)?;
    }
    s.set_stop_limits(e.stop)?;
    s.configure(Param::TelemetryPeriod, i128::from(e.servo.servo_period))?;
    s.configure(Param::WatchdogMs, watchdog_ms as i128)?;
    s.expect_ack(&Command::Power { on: true })?;
    let mut out = Vec::new();
    for p in &e.moves {
        for (k, seg) in p.segments.iter().enumerate() {
            s.expect_ack(&Command::LoadSegment {
                index: k as u8,
                segment: *seg,
            })?;
        }
        s.expect_ack(&Command::Commit {
            count: p.segments.len() as u8,
        })?;
        s.link.drain_telemetry();
        s.expect_ack(&Command::Start)?;
        s.link.wait(p.total_ticks() as f64 * ts + e.settle_s);
        let mut frames = s.link.drain_telemetry();
        // Still moving (the start came late): wait for its end, a second at most.
        let mut st = s.status()?;
        let mut polls = 0;
        while st.axis() == Some(AxisState::DiscreteMotion) && polls < 20 {
            s.link.wait(0.05);
            frames.extend(s.link.drain_telemetry());
            st = s.status()?;
            polls += 1;
        }
        let axis = st.axis().unwrap_or(AxisState::ErrorStop);
        if axis != AxisState::Standstill {
            return Err(HostError::Stopped {
                error: st.error_id().unwrap_or_default(),
                state: axis,
                tick: st.tick_count,
            });
        }
        out.push(frames);
    }
    Ok(out)
}

/// One move's samples without a gap: the encoder's count and the duty of each frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Run {
    /// Encoder counts.
    pub encoder: Vec<i32>,
    /// Duties (PWM clocks, signed).
    pub duty: Vec<i16>,
}

/// A move's frames as runs of consecutive samples: a frame lost on the wire (its tick count
/// more than `period` ticks after the one before) or one out of order starts a new run.
pub fn runs(frames: &[Status], period: u16) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::new();
    let mut last: Option<u32> = None;
    for f in frames {
        let next = last.is_some_and(|t| f.tick_count == t.wrapping_add(u32::from(period)));
        if !next || out.is_empty() {
            out.push(Run::default());
        }
        let r = out.last_mut().expect("a run was pushed");
        r.encoder.push(f.encoder);
        r.duty.push(f.duty);
        last = Some(f.tick_count);
    }
    out
}

/// The recording as the fit takes it (`snapgen_plant::identify::Record`): each run's counts in
/// radians and duties in volts, by the data sheet's plant `p` (its encoder, supply, and the
/// armature's R and L for the current's ripple), at the board's Ts `ts` and clock `clock_hz`.
pub fn to_record(
    frames: &[MoveFrames],
    e: &Excitation,
    p: &Physical,
    ts: f64,
    clock_hz: u32,
) -> Record {
    let volts_per_duty = p.vs / f64::from(e.pwm_period);
    Record {
        period: f64::from(e.servo.servo_period) * ts,
        count_rad: p.rad_per_count(),
        electrical: Some(Electrical {
            r: p.r,
            l: p.l,
            vs: p.vs,
            pwm_hz: f64::from(clock_hz) / f64::from(e.pwm_period),
        }),
        segments: frames
            .iter()
            .flat_map(|m| runs(m, e.servo.servo_period))
            .map(|r| Segment {
                angle: r
                    .encoder
                    .iter()
                    .map(|&n| f64::from(n) * p.rad_per_count())
                    .collect(),
                volts: r
                    .duty
                    .iter()
                    .map(|&d| f64::from(d) * volts_per_duty)
                    .collect(),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_frame_splits_the_run() {
        let frame = |tick_count, encoder| Status {
            tick_count,
            encoder,
            duty: encoder as i16,
            ..Default::default()
        };
        let frames = [frame(400, 1), frame(800, 2), frame(1600, 4), frame(2000, 5)];
        let r = runs(&frames, 400);
        assert_eq!(r.len(), 2);
        assert_eq!(
            (r[0].encoder.clone(), r[1].duty.clone()),
            (vec![1, 2], vec![4, 5])
        );
    }
}
