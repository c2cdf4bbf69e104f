//! Bit-accurate reference model of the snapgen motion core, and the host-side planners.
//!
//! * [`format`]: the fixed-point format, the single source of truth for widths, `Ts` and units.
//! * [`program`]: the segment program the fabric plays.
//! * [`chain`]: the sequencer and the snap integrator chain, per tick and in closed form.
//! * [`peaks`]: exact register peaks over a program.
//! * [`timing`]: the clock, UART and tick dividers the fabric is generated for.
//! * [`stop`]: the fabric's controlled stop from any state (the law, exact).
//! * [`online`]: planning from any exact state (seed 002's adaptive S-curve, PLCopen moves).
//! * [`planner`]: seed 000 (order 4), orders 3 and 2, seed 001 (duration-based), and the
//!   quantizer that makes the endpoint exact.
//!
//! This crate does no I/O.

pub mod axis;
pub mod chain;
pub mod core;
pub mod device;
pub mod error;
pub mod format;
pub mod io;
pub mod online;
pub mod peaks;
pub mod peer;
pub mod planner;
pub mod program;
pub mod protocol;
pub mod stop;
pub mod timing;

pub use chain::{ChainState, Sequencer, TickSample, Trace};
pub use core::{CoreInputs, CoreModel, CoreOutputs};
pub use error::{FormatError, PlanError, ProgramError};
pub use format::{Format, PositionFix, Quantity, RegisterRange, Widths, DEFAULT_FORMAT, FRAC_BITS};
pub use planner::{plan, plan_from, plan_into, Method, MoveRequest, PhaseTicks, Plan};
pub use program::{Program, Segment, SnapTimeline};
