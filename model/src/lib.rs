//! The bit-accurate twin of the snapgen fabric: what the hardware does on every clock, in
//! Rust, so that the fabric can be compared with it bit for bit.
//!
//! * [`format`]: the fixed-point format, the single source of truth for widths, `Ts` and units.
//! * [`program`]: the segment program the fabric plays.
//! * [`chain`]: the sequencer and the snap integrator chain, per tick and in closed form.
//! * [`peaks`]: exact register peaks over a program.
//! * [`timing`]: the clock, UART and tick dividers the fabric is generated for.
//! * [`stop`]: the fabric's controlled stop from any state (the law, exact).
//! * [`core`]: the motion core clock by clock (tick divider, program banks, sequencer, stop
//!   unit, chain, swap timer).
//! * [`io`]: the I/O blocks clock by clock (UART, FIFOs, frame receiver, executor, reply
//!   transmitter, encoder, PWM, position controller).
//! * [`station`]: everything of the I/O top but its transport, clock by clock.
//! * [`device`]: the I/O top clock by clock (the station behind a UART): the board as the
//!   host sees it.
//! * [`peer`]: the other end of the board's UART (a byte stream as line levels and back).
//!
//! This crate does no I/O.

pub mod chain;
pub mod core;
pub mod device;
pub mod error;
pub mod format;
pub mod io;
pub mod path;
pub mod peaks;
pub mod peer;
pub mod ports;
pub mod program;
pub mod station;
pub mod stop;
pub mod timing;

pub use chain::{ChainState, Sequencer, TickSample, Trace};
pub use core::CoreModel;
pub use error::{FormatError, ProgramError};
pub use format::{Format, PositionFix, Quantity, RegisterRange, Widths, DEFAULT_FORMAT, FRAC_BITS};
pub use ports::{
    CoreCommand, CoreInputs, CoreOutputs, CoreStatus, InterpInputs, InterpOutputs, IoInputs,
    IoOutputs, PathCoreInputs, PathCoreOutputs, PathSeqInputs, PathSeqOutputs, PathSteppersInputs,
    PathSteppersOutputs, StepDirInputs, StepDirOutputs,
};
pub use program::{Program, Segment, SnapTimeline};

/// Facts of the design that the contract's prose names and the spec does not know: the
/// position controller's latency (`{SERVO_LATENCY}`, clocks from a sample to its duty).
pub fn spec_facts() -> Vec<(&'static str, String)> {
    vec![("SERVO_LATENCY", io::servo::LATENCY.to_string())]
}
