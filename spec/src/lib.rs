//! The contract between snapgen's parts, written once.
//!
//! Everything that crosses a boundary between the model, the fabric, the host, the
//! co-simulation harness, the board files and the docs lives here, and everything else is
//! generated from it:
//!
//! * [`widths`]: the registers' widths and the byte sizes they give on the wire;
//! * [`wire`]: the frame (start byte, CRC, limits);
//! * [`codes`]: command and reply codes, NAK reasons, axis states, error identifiers, flags;
//! * [`refusals`]: why each command is refused, in the order the device checks;
//! * [`params`]: the configuration parameters (code, register, width, reset, when settable);
//! * [`fields`]: every payload's byte layout, with a plain struct and its codec each;
//! * [`rules`]: the protocol's numbers (swap lead and reach, reply queue, host retries);
//! * [`ports`]: the ports of the motion core and the I/O top and the board's pins;
//! * [`text`]: constants named in the tables' prose;
//! * [`emit`]: the docs' tables, a C header, a JSON description, Verilog `localparam`s.
//!
//! This crate depends on no other snapgen crate, does no I/O and panics on no input.

pub mod axi;
pub mod codes;
pub mod emit;
pub mod fields;
pub mod params;
pub mod ports;
pub mod refusals;
pub mod rules;
pub mod text;
pub mod widths;
pub mod wire;

pub use codes::{
    code, flag, AxisState, CommandSpec, ErrorId, Reason, ReplySpec, COMMANDS, FLAGS, REPLIES,
};
pub use fields::{ConfigValue, Field, Identity, StateReply, Status, STATUS_BITS};
pub use params::{Param, ParamSpec, Reset, Settable, PARAMS};
