//! Why a move cannot be planned, with what to change.

use snapgen_model::error::{FormatError, ProgramError};
use thiserror::Error;

/// A move that cannot be planned, with what to change.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlanError {
    /// Bad format.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// A NaN or infinite input.
    #[error("{name} = {value} is not a finite number: give a finite value")]
    NotFinite {
        /// Input name (as the CLI flag).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A limit, duration or period that must be > 0.
    #[error("{name} = {value} must be greater than 0")]
    NotPositive {
        /// Input name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A ratio outside its range.
    #[error("{name} = {value} is outside its range ({min}, {max}]: choose a value in that range")]
    OutOfRange {
        /// Input name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Exclusive lower bound.
        min: f64,
        /// Inclusive upper bound.
        max: f64,
    },
    /// The target does not fit the position register.
    #[error("distance {distance} is outside the format's position range ±{max:.6}: shorten the move or use a coarser position LSB")]
    DistanceOutOfRange {
        /// Requested distance.
        distance: f64,
        /// Largest distance.
        max: f64,
    },
    /// A limit below one raw LSB of its register.
    #[error("{quantity} limit {limit:e} {unit} is below the format's resolution ({lsb:e} {unit} per LSB): raise the limit, lengthen Ts or use a finer position LSB")]
    LimitBelowResolution {
        /// Quantity name.
        quantity: &'static str,
        /// Requested limit.
        limit: f64,
        /// Physical value of one raw LSB.
        lsb: f64,
        /// Unit.
        unit: &'static str,
    },
    /// The move lasts more ticks than the format's counters express.
    #[error("the move needs {ticks} ticks ({seconds:.3} s), more than the format allows ({max_ticks} ticks): raise the limits, shorten the move or lengthen Ts")]
    TooLong {
        /// Ticks needed.
        ticks: u128,
        /// Duration in seconds.
        seconds: f64,
        /// Largest tick count.
        max_ticks: u64,
    },
    /// The closed-form position gain is too large for an exact endpoint.
    #[error("the move is too long for an exact endpoint in this format (position gain 2^{log2_gain:.1} ≥ 2^{frac}): shorten the move, raise the limits or lengthen Ts")]
    GainTooLarge {
        /// log2 of the gain.
        log2_gain: f64,
        /// Fractional bits available.
        frac: u32,
    },
    /// A register would overflow on this move.
    #[error("the {quantity} register would overflow on this move (needs {needed:.1} bits of {bits}): lower the limits, shorten the move or widen the register")]
    Overflow {
        /// Quantity name.
        quantity: &'static str,
        /// Bits needed.
        needed: f64,
        /// Width available.
        bits: u32,
    },
    /// The duration-based method needs at least a few ticks per phase.
    #[error("duration {duration} s with gamma {gamma} and phi {phi} leaves {jerk_ticks} tick(s) of jerk at Ts = {ts} s: lengthen the duration or shorten Ts")]
    DurationTooShort {
        /// Requested duration.
        duration: f64,
        /// Gamma.
        gamma: f64,
        /// Phi.
        phi: f64,
        /// Ticks of the jerk phase after rounding.
        jerk_ticks: u64,
        /// Tick period.
        ts: f64,
    },
    /// The program does not fit the program memory.
    #[error(transparent)]
    Program(#[from] ProgramError),
}
