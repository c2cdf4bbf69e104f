//! The host of a snapgen board: everything that plans, talks and checks on the host's side.
//!
//! * [`protocol`]: the protocol's codecs (commands to frames, frames to replies, the stream
//!   decoder) over the tables of `snapgen_spec`.
//! * [`link`]: the one [`link::Link`] every host talks through, its one retry policy, and
//!   [`link::FramedLink`] over any byte [`link::Transport`]; [`serial`] is the serial port,
//!   [`uio`] the station's AXI4-Lite registers (a `/dev/uioN` mapping on the board's ARM).
//! * [`session`]: a session with a board (PING, its format, typed requests) and the errors a
//!   host reports.
//! * [`limits`]: the one rule for the board's controlled-stop limits.
//! * [`send`]: one move (`snapgen send`) and a stop from the host (`snapgen stop`);
//!   [`identify`]: an excitation through the board's loop, recorded (`snapgen identify`).
//! * [`axis`]: the PLCopen host axis (MC_MoveAbsolute with its buffer modes, MC_MoveVelocity,
//!   MC_Halt, the override), pure; [`driver`] plays it on a board through program swaps;
//!   [`online`] sets a board up for a script and plays it.

pub mod axis;
pub mod driver;
pub mod gcode;
pub mod identify;
pub mod limits;
pub mod link;
pub mod online;
pub mod path;
pub mod protocol;
pub mod send;
pub mod serial;
pub mod session;
pub mod uio;
