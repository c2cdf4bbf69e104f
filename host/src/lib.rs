//! The host of a snapgen board.
//!
//! * [`protocol`]: the protocol's codecs (commands to frames, frames to replies, the stream
//!   decoder) over the tables of `snapgen_spec`.
//! * [`axis`]: the PLCopen host axis (MC_MoveAbsolute with its buffer modes, MC_MoveVelocity,
//!   MC_Halt, the override) and the driver that plays it on a board through program swaps.

pub mod axis;
pub mod protocol;
