//! One move on a board, and a stop from the host (`snapgen send`, `snapgen stop`), over any
//! [`Link`]: plan the move from the board's exact registers with its Ts and format, write the
//! stop limits ([`crate::limits`]), the watchdog and the telemetry period (each read back),
//! power the axis, upload, start, follow, and check where it ended bit for bit: a move that ran
//! to its end must stand exactly on the planned register at rest; a move cut by a stop must end
//! where the controlled stop taken on one of its ticks ends
//! ([`snapgen_model::stop::explain`]).
//!
//! `START` is only sent after every segment and the commit were acknowledged. Time is the
//! link's: a virtual board's own clocks, or the wall clock.

use snapgen_model::io::servo::ServoConfig;
use snapgen_model::stop::{StopFound, StopLimits};
use snapgen_model::ChainState;
use snapgen_plan::{plan_from, MoveRequest, Plan};
use snapgen_spec::Settable;

use crate::limits::{stop_limits, LimitSource};
use crate::link::Link;
use crate::protocol::{flag, AxisState, Command, Param, StateReply, Status};
use crate::session::{Failure, HostError, InputError, Session};

/// How often the host reads the status while a move runs (s; well inside the watchdog's
/// default second).
pub const POLL: f64 = 0.1;
/// No progress for this long ends the run, or the wait for a stop (s).
pub const STALL: f64 = 5.0;

/// Follows a move's progress (the CLI's progress bar; nothing in tests).
pub trait Progress {
    /// The move has `ticks` ticks.
    fn start(&mut self, ticks: u64);
    /// It has played `tick` of them.
    fn at(&mut self, tick: u64);
    /// It is over.
    fn finish(&mut self);
}

/// No progress shown.
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&mut self, _: u64) {}
    fn at(&mut self, _: u64) {}
    fn finish(&mut self) {}
}

/// The controller's configuration for the motor the axis drives (gains derived by the
/// caller) and the PWM period it needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoSetup {
    /// The controller's registers.
    pub config: ServoConfig,
    /// PWM_PERIOD (clocks).
    pub pwm_period: u16,
}

/// What a move is run with.
#[derive(Clone, Debug, Default)]
pub struct SendOptions {
    /// The Ts the user asked for (refused unless it is the board's).
    pub ts: Option<f64>,
    /// The stop's deceleration limit (units/s²) [default: the move's peak acceleration].
    pub stop_decel: Option<f64>,
    /// The stop's jerk limit (units/s³) [default: the move's peak jerk].
    pub stop_jerk: Option<f64>,
    /// Reset an axis found in ErrorStop before the move.
    pub reset: bool,
    /// The board's host watchdog (ms; 0: off).
    pub watchdog_ms: u32,
    /// The axis drives a motor: the controller is configured for it.
    pub servo: Option<ServoSetup>,
    /// Settled: |position − encoder| within this many LSBs.
    pub settle_lsb: u32,
    /// Send a controlled stop this long after the start (s).
    pub stop_after: Option<f64>,
}

/// How the motor followed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Following {
    /// The largest |following error| at a controller sample during the move (LSBs).
    pub peak_lsb: f64,
    /// Position − encoder when the reference came to rest (LSBs).
    pub at_end_lsb: i64,
    /// Seconds from then until |position − encoder| stayed within the band (to the poll);
    /// `None` if not within the wait.
    pub settle_s: Option<f64>,
    /// The band (LSBs).
    pub band_lsb: u32,
}

/// The outcome of a move.
#[derive(Clone, Debug)]
pub struct SendReport {
    /// The plan that was run.
    pub plan: Plan,
    /// The stop limits used (raw).
    pub stop_limits: StopLimits,
    /// Warnings about them.
    pub warnings: Vec<String>,
    /// Final status.
    pub status: Status,
    /// Final registers.
    pub state: StateReply,
    /// The controlled stop that cut the move, if one did.
    pub stop: Option<StopFound>,
    /// With a motor: how it followed.
    pub following: Option<Following>,
}

/// The peaks of a plan (raw |a| and |j|), from the independent integration of its program.
fn plan_peaks(plan: &Plan) -> (i128, i128) {
    let st = plan.start;
    let run = snapgen_verify::integrate(
        snapgen_verify::State::new(st.x, st.v, st.a, st.j),
        plan.program
            .segments
            .iter()
            .map(|g| (u64::from(g.ticks), g.snap)),
    );
    let peak = |r: usize| run.range(r).max_abs().as_i128();
    (peak(2), peak(3))
}

/// Refuses a Ts the user asked for that is not the board's (the host plans with the board's).
pub fn check_ts<L: Link>(s: &Session<L>, asked: Option<f64>) -> Result<(), InputError> {
    let Some(asked) = asked else {
        return Ok(());
    };
    if !(asked.is_finite() && asked > 0.0) {
        return Err(InputError::BadTs(asked));
    }
    let board = s.format.ts;
    if (asked - board).abs() > 1e-9 * board {
        return Err(InputError::Ts {
            asked,
            board,
            div: s.identity.tick_divider,
            clock: s.identity.clock_hz,
        });
    }
    Ok(())
}

/// Plans, uploads, starts and follows one move; checks its end.
pub fn send_move<L: Link>(
    s: &mut Session<L>,
    request: &MoveRequest,
    opts: &SendOptions,
    progress: &mut dyn Progress,
) -> Result<SendReport, Failure> {
    let format = s.format;
    check_ts(s, opts.ts)?;
    // Where it stands.
    let mut status = s.status()?;
    if status.axis() == Some(AxisState::ErrorStop) {
        if !opts.reset {
            return Err(HostError::AxisError {
                error: status.error_id().unwrap_or_default(),
            }
            .into());
        }
        s.expect_ack(&Command::Reset)?;
        status = s.status()?;
    }
    let state = s.state()?;
    let axis = status.axis().unwrap_or(AxisState::ErrorStop);
    let at_rest = (state.v, state.a, state.j) == (0, 0, 0);
    if !matches!(axis, AxisState::Standstill | AxisState::Disabled) || !at_rest {
        return Err(HostError::NotIdle {
            state: axis,
            v: state.v,
            a: state.a,
            j: state.j,
        }
        .into());
    }
    if let Some(servo) = &opts.servo {
        configure_servo(s, servo, axis)?;
    }
    // (POWER 0 for the controller's rate leaves the axis Disabled.)
    let axis = s.axis()?;
    let start = ChainState::at_rest(s.state()?.x);
    let plan = plan_from(request, &format, start)?;
    let (peak_a, peak_j) = plan_peaks(&plan);
    let (limits, warnings) = stop_limits(
        LimitSource {
            flag: "--stop-decel",
            given: opts.stop_decel,
            peak: peak_a,
        },
        LimitSource {
            flag: "--stop-jerk",
            given: opts.stop_jerk,
            peak: peak_j,
        },
        &format,
    )?;
    let ticks = plan.ticks_total();
    // Configuration, each write read back; then the amplifier.
    s.set_stop_limits(limits)?;
    s.configure(Param::WatchdogMs, i128::from(opts.watchdog_ms))?;
    s.configure(
        Param::TelemetryPeriod,
        i128::from((ticks / 50).clamp(1, u64::from(u32::MAX))),
    )?;
    if axis == AxisState::Disabled {
        s.expect_ack(&Command::Power { on: true })?;
    }
    for (k, seg) in plan.program.segments.iter().enumerate() {
        s.expect_ack(&Command::LoadSegment {
            index: k as u8,
            segment: *seg,
        })?;
    }
    s.expect_ack(&Command::Commit {
        count: plan.program.segments.len() as u8,
    })?;
    progress.start(ticks);
    s.expect_ack(&Command::Start)?;
    let started = s.link.now();
    // The tick count last seen before the stop went out: the stop was taken on a later tick.
    let mut stop_from: Option<u32> = None;
    let mut seen_ticks = 0u32;
    let mut last_progress = (started, u32::MAX);
    let end_status = loop {
        s.link.wait(POLL);
        if let Some(t) = s.link.take_telemetry() {
            seen_ticks = seen_ticks.max(t.tick_count);
        }
        if let Some(after) = opts.stop_after {
            if stop_from.is_none() && s.link.now() - started >= after {
                stop_from = Some(seen_ticks);
                s.expect_ack(&Command::Stop)?;
            }
        }
        let st = s.status()?;
        seen_ticks = seen_ticks.max(st.tick_count);
        progress.at(u64::from(st.tick_count));
        let axis = st.axis().unwrap_or(AxisState::ErrorStop);
        if axis == AxisState::ErrorStop {
            progress.finish();
            return Err(HostError::Stopped {
                error: st.error_id().unwrap_or_default(),
                state: axis,
                tick: st.tick_count,
            }
            .into());
        }
        if axis == AxisState::Standstill {
            break st;
        }
        if st.tick_count != last_progress.1 {
            last_progress = (s.link.now(), st.tick_count);
        } else if s.link.now() - last_progress.0 > STALL {
            progress.finish();
            return Err(HostError::Stalled(STALL).into());
        }
    };
    progress.finish();
    s.configure(Param::TelemetryPeriod, 0)?;
    let end = s.state()?;
    let end_chain = ChainState {
        x: end.x,
        v: end.v,
        a: end.a,
        j: end.j,
    };
    let stop = match stop_from {
        None => {
            if end_chain != plan.final_state {
                return Err(HostError::WrongEnd {
                    got: end.x,
                    want: plan.final_state.x,
                    v: end.v,
                    a: end.a,
                    j: end.j,
                }
                .into());
            }
            None
        }
        Some(from) => {
            let found = snapgen_model::stop::explain(
                start,
                &plan.program,
                &format.widths,
                limits,
                end_chain,
                u64::from(end_status.tick_count),
                u64::from(from),
            );
            match found {
                Some(f) => Some(f),
                // The stop came after the move's end: it must then stand on the target.
                None if end_chain == plan.final_state => None,
                None => {
                    return Err(HostError::StopUnexplained {
                        x: end.x,
                        ticks: end_status.tick_count,
                        from,
                    }
                    .into())
                }
            }
        }
    };
    let (last, following) = settle(s, opts, &end_status)?;
    Ok(SendReport {
        plan,
        stop_limits: limits,
        warnings,
        status: Status {
            tick_count: end_status.tick_count,
            ..last
        },
        state: end,
        stop,
        following,
    })
}

/// Lets the encoder settle on the final position (a real axis follows the reference with a
/// lag): until |position − encoder| stays within the band for 0.2 s, for up to 2 s.
fn settle<L: Link>(
    s: &mut Session<L>,
    opts: &SendOptions,
    end_status: &Status,
) -> Result<(Status, Option<Following>), HostError> {
    let band = if opts.servo.is_some() {
        i64::from(opts.settle_lsb)
    } else {
        0
    };
    let t0 = s.link.now();
    let mut last = s.status()?;
    let at_end = i64::from(last.position) - i64::from(last.encoder);
    let mut settled: Option<f64> = None;
    while s.link.now() - t0 < 2.0 {
        let e = (i64::from(last.position) - i64::from(last.encoder)).abs();
        let now = s.link.now();
        match (e <= band, settled) {
            (true, None) => settled = Some(now),
            (false, Some(_)) => settled = None,
            (true, Some(t)) if now - t >= 0.2 => break,
            _ => {}
        }
        s.link.wait(0.01);
        last = s.status()?;
    }
    let following = opts.servo.as_ref().map(|_| Following {
        peak_lsb: end_status.following_peak_counts(),
        at_end_lsb: at_end,
        settle_s: settled.map(|t| t - t0),
        band_lsb: opts.settle_lsb,
    });
    Ok((last, following))
}

/// Configures the board's controller (each write read back): the parameters set only while
/// Disabled (the rate, the following limit) only when they change (an enabled axis at rest is
/// powered off first), the gains at any time.
fn configure_servo<L: Link>(
    s: &mut Session<L>,
    servo: &ServoSetup,
    axis: AxisState,
) -> Result<(), HostError> {
    let writes = servo.config.writes();
    let disabled_only = writes
        .iter()
        .take_while(|(p, _)| p.settable() == Settable::Disabled)
        .count();
    let (fixed, rest) = writes.split_at(disabled_only);
    if axis != AxisState::Disabled {
        let mut same = true;
        for &(p, v) in fixed {
            same &= s.read_config(p)? == v;
        }
        if !same {
            s.expect_ack(&Command::Power { on: false })?;
        }
    }
    let pwm = [(Param::PwmPeriod, i128::from(servo.pwm_period))];
    for &(p, v) in fixed.iter().chain(&pwm).chain(rest) {
        if s.read_config(p)? != v {
            s.configure(p, v)?;
        }
    }
    Ok(())
}

/// What a stop from the host saw.
#[derive(Clone, Debug)]
pub struct StopReport {
    /// The axis state before the stop.
    pub before: AxisState,
    /// The status once the stop was over.
    pub status: Status,
    /// The registers then.
    pub state: StateReply,
}

/// MC_Stop (`halt` false: STOP, the axis goes through Stopping) or MC_Halt (`halt`: HALT, the
/// axis stays in its motion state until at rest) from the host: the board brings the axis to
/// rest by itself, within its stop limits; this waits for it and reads the registers. It fails
/// only when nothing changes for [`STALL`].
pub fn stop_axis<L: Link>(s: &mut Session<L>, halt: bool) -> Result<StopReport, Failure> {
    let before = s.axis()?;
    let c = if halt { Command::Halt } else { Command::Stop };
    s.expect_ack(&c)?;
    let mut last_change = (s.link.now(), None);
    let status = loop {
        s.link.wait(0.02);
        let st = s.status()?;
        let axis = st.axis().unwrap_or(AxisState::ErrorStop);
        if !st.has(flag::STOPPING) && matches!(axis, AxisState::Standstill | AxisState::ErrorStop) {
            break st;
        }
        let seen = Some((st.tick_count, st.position, st.velocity));
        if seen != last_change.1 {
            last_change = (s.link.now(), seen);
        } else if s.link.now() - last_change.0 > STALL {
            return Err(HostError::Stalled(STALL).into());
        }
    };
    let state = s.state()?;
    if (state.v, state.a, state.j) != (0, 0, 0) {
        return Err(HostError::NotIdle {
            state: status.axis().unwrap_or(AxisState::ErrorStop),
            v: state.v,
            a: state.a,
            j: state.j,
        }
        .into());
    }
    Ok(StopReport {
        before,
        status,
        state,
    })
}
