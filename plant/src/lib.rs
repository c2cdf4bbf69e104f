//! The world around a board's motor, simulated: a brushed DC motor with its load, the H-bridge
//! that the fabric's PWM drives, and the quadrature encoder the fabric reads — pure and
//! deterministic (docs/PLANT.md). Also the controller's gains derived from the plant
//! ([`gains`]) and a fast closed loop around the bit-exact controller model ([`fast`]).
//!
//! * [`params`]: the plant as data (TOML; the default is a maxon RE 40 with seed 001's load).
//! * [`motor`]: the motor's equations and their fixed-step integrator.
//! * [`plant`]: the plant clock by clock (bridge, motor, encoder), what a co-simulation drives.
//! * [`gains`]: the controller's gains by pole placement on the plant's model.
//! * [`fast`]: a fast event-driven closed loop around the controller's bit-exact law.
//! * [`metrics`]: a closed-loop move's figures; [`seed001`]: seed 001's experiment as moves.
//! * [`mismatch`]: a plant that differs from the one the gains were derived from.

pub mod fast;
pub mod gains;
pub mod identify;
pub mod metrics;
pub mod mismatch;
pub mod motor;
pub mod params;
pub mod plant;
pub mod seed001;

pub use motor::MotorState;
pub use params::{Physical, PlantError, PlantParams};
pub use plant::{BridgePins, Plant};
