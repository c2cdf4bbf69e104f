//! snapgen's planning math, on the host: what program the fabric should play.
//!
//! * [`planner`]: rest-to-rest moves: seed 000 (order 4), orders 3 and 2, seed 001's
//!   duration-based S-curve, and the quantizer that makes every endpoint exact.
//! * [`online`]: planning from any exact chain state to a position at rest, a set velocity or
//!   a blend point (seed 002's adaptive S-curve, PLCopen moves), exact on the integer chain.
//! * [`error`]: why a move cannot be planned.
//!
//! Every plan is a [`snapgen_model::Program`] checked on the integer chain; this crate does no
//! I/O.

pub mod error;
pub mod online;
pub mod path;
pub mod planner;

pub use error::PlanError;
pub use planner::{plan, plan_from, plan_into, Method, MoveRequest, PhaseTicks, Plan};
