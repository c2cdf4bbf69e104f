//! The CLI's errors: the user's to fix ([`InputError`], exit 2) and the co-simulations'
//! disagreement ([`Mismatched`], exit 1); the `--inject-fault` test hooks' parsers.

use snapgen_plan::PlanError;

use crate::args::ArgError;

/// Errors that are the user's to fix (exit 2).
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// A flag the chosen method does not use, or one it needs.
    #[error(transparent)]
    Args(#[from] ArgError),
    /// A move that cannot be planned.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// A malformed `--inject-fault`.
    #[error("--inject-fault {0:?}: use CLOCK:NAME:BIT, e.g. 1000:x:3 (cosim) or 1000:status.flags:3 (cosim-io)")]
    Fault(String),
    /// A board, timing, motor or controller setting.
    #[error("{0}")]
    Board(String),
    /// The host's refusal of an input (stop limits, Ts, the controller).
    #[error(transparent)]
    Host(snapgen_host::session::InputError),
    /// An online script.
    #[error("{0:#}")]
    Script(anyhow::Error),
}

/// A host failure: the user's input (exit 2) or the link and the board (exit 1).
pub fn failure(f: snapgen_host::session::Failure) -> anyhow::Error {
    match f {
        snapgen_host::session::Failure::Input(e) => InputError::Host(e).into(),
        snapgen_host::session::Failure::Host(e) => e.into(),
    }
}

/// A closed loop's error: the host's as [`failure`] sorts it (the user's to fix: exit 2),
/// the simulation's as it is.
pub fn loop_failure(e: snapgen_sim::closed_loop::LoopError) -> anyhow::Error {
    match e {
        snapgen_sim::closed_loop::LoopError::Host(f) => failure(f),
        e => e.into(),
    }
}

/// The co-simulation found a difference (exit 1; the report is already printed).
#[derive(Debug, thiserror::Error)]
#[error("the fabric and the model disagree")]
pub struct Mismatched;

/// `CLOCK:NAME:BIT`, the form of both co-simulations' `--inject-fault`.
pub fn split_fault<T: std::str::FromStr>(s: &str) -> Result<(u64, T, u32), InputError> {
    let bad = || InputError::Fault(s.to_string());
    let mut it = s.split(':');
    let (Some(c), Some(name), Some(b), None) = (it.next(), it.next(), it.next(), it.next()) else {
        return Err(bad());
    };
    Ok((
        c.parse().map_err(|_| bad())?,
        name.parse().map_err(|_| bad())?,
        b.parse().map_err(|_| bad())?,
    ))
}
