//! `snapgen send`: a move planned with the board's own Ts and format and run on it over a
//! serial port: the controller's gains for the motor (from the plant, docs/PLANT.md), a
//! progress bar, and the report. The move itself, its checks and the stop are the host's
//! (`snapgen_host::send`).

use std::io::IsTerminal;
use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use snapgen_host::send::{check_ts, send_move, Progress, SendOptions, SendReport, ServoSetup};
use snapgen_host::session::{InputError as HostInput, Session};
use snapgen_model::DEFAULT_FORMAT;

use crate::args::{optional_motor, LinkArgs, PlanArgs, ServoArgs};
use crate::error::{failure, InputError};

/// Plan a move and run it on a board over a serial port.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    link: LinkArgs,
    /// Test hook: corrupt one bit of segment K's frame on every attempt.
    #[arg(long, hide = true)]
    corrupt_segment: Option<u8>,
    /// Controlled stop (STOP) this many milliseconds after the start: the board brings the
    /// axis to rest within the stop limits; the end is checked against the model's stop.
    #[arg(long)]
    stop_after_ms: Option<u64>,
    /// The stop's deceleration limit, units/s² [default: the move's peak acceleration].
    #[arg(long)]
    stop_decel: Option<f64>,
    /// The stop's jerk limit, units/s³ [default: the move's peak jerk].
    #[arg(long)]
    stop_jerk: Option<f64>,
    /// Reset an axis found in ErrorStop (after its cause is removed) before the move.
    #[arg(long)]
    reset: bool,
    /// The board's host watchdog, in milliseconds (written and read back): a moving axis
    /// that hears nothing from the host for this long stops by itself. 0 turns it off.
    #[arg(long, default_value_t = snapgen_spec::Param::WatchdogMs.spec().reset_value(0) as u32)]
    watchdog_ms: u32,
    /// The axis drives a motor: configure the board's controller for it (gains derived
    /// from the plant, docs/PLANT.md) and report the following error and the settling.
    /// `--motor` (or `--motor default`) for the default motor, `--motor FILE` for a plant
    /// file.
    #[arg(long, num_args = 0..=1, default_missing_value = "default")]
    motor: Option<PathBuf>,
    /// The settling band: the move has settled when |position − encoder| stays within this
    /// many output LSBs (encoder counts).
    #[arg(long, default_value_t = 2)]
    settle_lsb: u32,
    #[command(flatten)]
    servo: ServoArgs,
    #[command(flatten)]
    plan: PlanArgs,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let request = a.plan.request().map_err(InputError::from)?;
    let motor = optional_motor(a.motor.as_deref())?;
    let lsb = a.plan.lsb.unwrap_or_else(|| {
        motor.as_ref().map_or(DEFAULT_FORMAT.position_lsb, |m| {
            m.physical().rad_per_count()
        })
    });
    let mut session = a.link.open(lsb).map_err(failure)?;
    session.link.corrupt_segment(a.corrupt_segment);
    check_ts(&session, a.plan.ts).map_err(InputError::Host)?;
    let servo = match motor {
        Some(plant) => Some(
            servo_setup(
                &session,
                &MotorOptions {
                    plant,
                    design: a.servo.design(),
                    loop_hz: a.servo.loop_hz,
                    pwm_hz: a.servo.pwm_hz,
                },
            )
            .map_err(InputError::Host)?,
        ),
        None => None,
    };
    let opts = SendOptions {
        ts: a.plan.ts,
        stop_decel: a.stop_decel,
        stop_jerk: a.stop_jerk,
        reset: a.reset,
        watchdog_ms: a.watchdog_ms,
        servo,
        settle_lsb: a.settle_lsb,
        stop_after: a.stop_after_ms.map(|ms| ms as f64 / 1e3),
    };
    let r = send_move(&mut session, &request, &opts, &mut Bar::new()).map_err(failure)?;
    print!("{}", describe(&r, &session.identity));
    Ok(())
}

/// The motor the axis drives, and how to control it.
#[derive(Clone, Debug)]
pub struct MotorOptions {
    /// The plant.
    pub plant: snapgen_plant::PlantParams,
    /// Bandwidth, damping, feed-forward, following limit.
    pub design: snapgen_plant::gains::LoopDesign,
    /// Sample rate (Hz).
    pub loop_hz: f64,
    /// PWM frequency (Hz).
    pub pwm_hz: f64,
}

/// The controller's registers for the motor in `m` at the board's Ts and clock.
pub fn servo_setup<L: snapgen_host::link::Link>(
    s: &Session<L>,
    m: &MotorOptions,
) -> Result<ServoSetup, HostInput> {
    let bad = HostInput::Servo;
    let ts = s.format.ts;
    let ticks = (1.0 / (m.loop_hz * ts)).round();
    if !(m.loop_hz.is_finite() && m.loop_hz > 0.0 && (1.0..=65535.0).contains(&ticks)) {
        return Err(bad(format!(
            "--loop-hz {} is {ticks} ticks of the board's Ts {ts} s: give a rate of 1 to 65 535 ticks",
            m.loop_hz
        )));
    }
    let clock = s.identity.clock_hz;
    let clocks = (f64::from(clock) / m.pwm_hz).round();
    if !(m.pwm_hz.is_finite() && m.pwm_hz > 0.0 && (2.0..=32767.0).contains(&clocks)) {
        return Err(bad(format!(
            "--pwm-hz {} is {clocks} clocks of the board's {clock} Hz: give a rate with 2 to 32 767",
            m.pwm_hz
        )));
    }
    let timing = snapgen_plant::gains::LoopTiming {
        ts,
        servo_period: ticks as u16,
        pwm_period: clocks as u16,
    };
    let g = snapgen_plant::gains::derive(&m.plant.physical(), &m.design, &timing)
        .map_err(|e| bad(e.to_string()))?;
    Ok(ServoSetup {
        config: g.config,
        pwm_period: timing.pwm_period,
    })
}

/// The move's progress on the terminal (hidden when stderr is not one).
pub struct Bar(Option<ProgressBar>);

impl Bar {
    /// A bar, on a terminal.
    pub fn new() -> Self {
        Bar(None)
    }
}

impl Progress for Bar {
    fn start(&mut self, ticks: u64) {
        if std::io::stderr().is_terminal() {
            let b = ProgressBar::new(ticks);
            b.set_style(
                ProgressStyle::with_template("{bar:40} {pos}/{len} ticks {elapsed_precise}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            self.0 = Some(b);
        }
    }

    fn at(&mut self, tick: u64) {
        if let Some(b) = &self.0 {
            b.set_position(tick);
        }
    }

    fn finish(&mut self) {
        if let Some(b) = self.0.take() {
            b.finish_and_clear();
        }
    }
}

/// The report `snapgen send` prints.
pub fn describe(r: &SendReport, id: &snapgen_host::protocol::Identity) -> String {
    let f = &r.plan.format;
    let digits = (-f.position_lsb.log10()).ceil().max(0.0) as usize;
    let mut s = String::new();
    for w in &r.warnings {
        s.push_str(&format!("warning: {w}\n"));
    }
    s.push_str(&format!(
        "board: protocol {}, design {:#010x}, {} Hz, {} baud, Ts {} s (tick divider {}), stop limits {} (jerk) / {} (accel) raw\n",
        id.protocol,
        id.design_hash,
        id.clock_hz,
        id.baud,
        f.ts,
        id.tick_divider,
        r.stop_limits.jerk,
        r.stop_limits.accel
    ));
    let pos = |x: i128| f.output_lsb(x);
    match r.stop {
        None => s.push_str(&format!(
            "moved {} units in {} ticks: at {} LSB = {:.*} units, encoder {} counts; the registers match the plan bit for bit (x {:#x}, v = a = j = 0)\n",
            r.plan.request.distance,
            r.status.tick_count,
            pos(r.state.x),
            digits,
            f.position_physical(r.state.x),
            r.status.encoder,
            r.state.x
        )),
        Some(st) => s.push_str(&format!(
            "stopped: the controlled stop was taken on tick {} of {} and ran {} ticks to rest{}; at {} LSB = {:.*} units, encoder {} counts; the registers match the model's stop bit for bit (x {:#x}, v = a = j = 0)\n",
            st.taken,
            r.plan.ticks_total(),
            st.ticks,
            if st.over_limits { " (it began outside the stop limits and landed regardless)" } else { " within the stop limits" },
            pos(r.state.x),
            digits,
            f.position_physical(r.state.x),
            r.status.encoder,
            r.state.x
        )),
    }
    if let Some(fo) = r.following {
        let lsb = f.position_lsb;
        s.push_str(&format!(
            "following error: peak {:.2} LSB = {:.3e} units during the move, {} LSB when the reference came to rest; {}\n",
            fo.peak_lsb,
            fo.peak_lsb * lsb,
            fo.at_end_lsb,
            match fo.settle_s {
                Some(t) => format!("within ±{} LSB {:.2} s later (host-measured, 10 ms polls)", fo.band_lsb, t),
                None => format!("not within ±{} LSB after 2 s", fo.band_lsb),
            }
        ));
    }
    s
}
