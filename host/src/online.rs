//! A timed script of PLCopen commands on a board, as every host sets it up: a [`Session`]
//! (PING, the board's format), the stop limits from the script by the one rule
//! ([`crate::limits`]: the given ones, or the script's largest deceleration and jerk), the
//! axis powered, then the [`crate::driver`] run. `snapgen online` plays scripts with it on a
//! serial port or a virtual board; the co-simulation plays random ones on the Verilated core.

use snapgen_model::format::{Format, Quantity};
use snapgen_model::stop::StopLimits;
use snapgen_plan::online::OnlineOrder;

use crate::axis::{AxisSettings, MotionCommand};
use crate::driver::{run, Action, Event, RunError, RunOptions, RunReport};
use crate::limits::{stop_limits, LimitSource};
use crate::link::Link;
use crate::session::{Failure, Session};

/// How a script is played.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlayOptions {
    /// Profile order.
    pub order: OnlineOrder,
    /// The board's controlled stop: deceleration (unit/s²) [default: the script's largest].
    pub stop_deceleration: Option<f64>,
    /// Its jerk (unit/s³) [default: the script's largest].
    pub stop_jerk: Option<f64>,
    /// The driver's poll and settle times.
    pub run: RunOptions,
}

/// Why a play stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlayError {
    /// The set-up (the board, the stop limits, the amplifier).
    #[error(transparent)]
    Setup(#[from] Failure),
    /// The run.
    #[error(transparent)]
    Run(#[from] RunError),
}

/// The largest deceleration and jerk of the script's commands (unit/s², unit/s³).
pub fn script_peaks(events: &[Event]) -> (f64, f64) {
    let (mut d, mut j) = (0.0f64, 0.0f64);
    for e in events {
        if let Action::Command(c) = e.action {
            let (dc, jc) = match c {
                MotionCommand::MoveAbsolute {
                    deceleration, jerk, ..
                }
                | MotionCommand::MoveVelocity {
                    deceleration, jerk, ..
                }
                | MotionCommand::Halt { deceleration, jerk } => (deceleration, jerk),
            };
            d = d.max(dc);
            j = j.max(jc);
        }
    }
    (d, j)
}

/// The stop limits a script is played with, in `format`, and the rule's warnings.
pub fn script_stop_limits(
    events: &[Event],
    opts: &PlayOptions,
    format: &Format,
) -> Result<(StopLimits, Vec<String>), Failure> {
    let (d, j) = script_peaks(events);
    let raw = |v: f64, q| (v * format.scale(q)).floor().min(i128::MAX as f64) as i128;
    Ok(stop_limits(
        LimitSource {
            flag: "stop_deceleration",
            given: opts.stop_deceleration,
            peak: raw(d, Quantity::Acceleration),
        },
        LimitSource {
            flag: "stop_jerk",
            given: opts.stop_jerk,
            peak: raw(j, Quantity::Jerk),
        },
        format,
    )?)
}

/// Plays `events` on the board of `session`: the stop limits written, the axis powered,
/// the script run. The warnings of the stop-limit rule come back with the report.
pub fn play<L: Link>(
    session: &mut Session<L>,
    events: &[Event],
    opts: &PlayOptions,
) -> Result<(RunReport, StopLimits, Vec<String>), PlayError> {
    let (limits, warnings) = script_stop_limits(events, opts, &session.format)?;
    session.power_up(limits).map_err(Failure::from)?;
    let settings = AxisSettings {
        format: session.format,
        order: opts.order,
    };
    let report = run(&mut session.link, settings, events, &opts.run)?;
    Ok((report, limits, warnings))
}
