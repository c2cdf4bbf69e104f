//! Typed errors. Every message names the offending value and says what to change.

use thiserror::Error;

/// A [`crate::Format`] that cannot be used.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FormatError {
    /// Tick period not finite and positive.
    #[error("tick period Ts = {0} s is invalid: give a finite value > 0 (e.g. --ts 1e-5)")]
    Ts(f64),
    /// Output LSB not finite and positive.
    #[error("position LSB = {0} is invalid: give a finite value > 0")]
    PositionLsb(f64),
    /// A register width outside 8..=127 bits.
    #[error("register {register} has {bits} bits: widths must lie in 8..=127")]
    Width {
        /// Register name.
        register: &'static str,
        /// Its width.
        bits: u32,
    },
    /// Position register too narrow for the fractional bits.
    #[error("position register has {bits} bits but {frac} are fractional: it needs more than {} bits", frac + 1)]
    PositionWidth {
        /// Width.
        bits: u32,
        /// Fractional bits.
        frac: u32,
    },
    /// Tick count width outside 1..=32.
    #[error("segment tick counts of {0} bits are not supported: use 1..=32")]
    TickBits(u32),
    /// Zero program depth.
    #[error("a program must be allowed at least one segment")]
    MaxSegments,
    /// A scale factor overflowed f64.
    #[error("the {0} scale Ts^n/LSB is not a finite number: choose a Ts and LSB of sane size")]
    Scale(&'static str),
}

/// A program that the fabric could not run.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ProgramError {
    /// More segments than the program memory holds.
    #[error("program has {count} segments but the format holds at most {max}")]
    TooManySegments {
        /// Segments in the program.
        count: usize,
        /// Memory depth.
        max: usize,
    },
    /// A segment with zero ticks.
    #[error("segment {index} has 0 ticks: every segment must last at least one tick")]
    ZeroTicks {
        /// Segment index.
        index: usize,
    },
    /// A segment whose tick count does not fit the tick counter.
    #[error("segment {index} lasts {ticks} ticks, more than the {bits}-bit tick counter holds")]
    TicksTooLarge {
        /// Segment index.
        index: usize,
        /// Tick count.
        ticks: u64,
        /// Counter width.
        bits: u32,
    },
    /// A snap value that does not fit the snap register.
    #[error("segment {index} snap {snap} does not fit the {bits}-bit snap register")]
    SnapTooLarge {
        /// Segment index.
        index: usize,
        /// Raw snap.
        snap: i128,
        /// Register width.
        bits: u32,
    },
    /// Bytes that do not decode to a program.
    #[error("program bytes are malformed: {0}")]
    Malformed(&'static str),
}
