//! What a move request is — a signed distance and a method with its limits (seed 000's order
//! 4, orders 3 and 2, seed 001's duration-based S-curve) — and its validation, before any
//! planning: every input finite, every limit positive, seed 001's ratios in (0, 0.5].

use serde::{Deserialize, Serialize};

use crate::error::PlanError;
use snapgen_model::format::{Format, Quantity};

use super::quantize::Shape;

/// How a move is planned.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Method {
    /// Seed 000: snap-limited, order 4.
    Order4 {
        /// Velocity limit (unit/s).
        vmax: f64,
        /// Acceleration limit (unit/s²).
        amax: f64,
        /// Jerk limit (unit/s³).
        jmax: f64,
        /// Snap limit (unit/s⁴).
        dmax: f64,
    },
    /// Jerk-limited seven-segment S-curve, order 3.
    Order3 {
        /// Velocity limit.
        vmax: f64,
        /// Acceleration limit.
        amax: f64,
        /// Jerk limit.
        jmax: f64,
    },
    /// Acceleration-limited trapezoid, order 2.
    Order2 {
        /// Velocity limit.
        vmax: f64,
        /// Acceleration limit.
        amax: f64,
    },
    /// Seed 001: duration-based S-curve.
    Duration {
        /// Duration T (s).
        duration: f64,
        /// γ ∈ (0, 0.5].
        gamma: f64,
        /// φ ∈ (0, 0.5].
        phi: f64,
    },
}

impl Method {
    /// The profile order (highest limited derivative).
    pub fn order(&self) -> u8 {
        match self {
            Method::Order4 { .. } => 4,
            Method::Order3 { .. } | Method::Duration { .. } => 3,
            Method::Order2 { .. } => 2,
        }
    }

    /// The requested limits as `(quantity, flag name, value)`.
    pub(super) fn limits(&self) -> Limits {
        let mut l = Limits::default();
        match *self {
            Method::Order4 {
                vmax,
                amax,
                jmax,
                dmax,
            } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
                l.push(Quantity::Jerk, "jmax", jmax);
                l.push(Quantity::Snap, "dmax", dmax);
            }
            Method::Order3 { vmax, amax, jmax } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
                l.push(Quantity::Jerk, "jmax", jmax);
            }
            Method::Order2 { vmax, amax } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
            }
            Method::Duration { .. } => {}
        }
        l
    }

    pub(super) fn shape(&self) -> Shape {
        match self.order() {
            4 => Shape::Snap4,
            3 => Shape::Jerk3,
            _ => Shape::Accel2,
        }
    }
}

/// Up to four requested limits, on the stack.
#[derive(Clone, Copy, Default)]
pub(super) struct Limits {
    items: [(Quantity, &'static str, f64); 4],
    len: usize,
}

impl Limits {
    pub(super) fn push(&mut self, q: Quantity, name: &'static str, value: f64) {
        self.items[self.len] = (q, name, value);
        self.len += 1;
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = (Quantity, &'static str, f64)> + '_ {
        self.items[..self.len].iter().copied()
    }
}

/// A point-to-point move: a signed distance and how to plan it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MoveRequest {
    /// Signed distance (units).
    pub distance: f64,
    /// Planning method and its limits.
    pub method: Method,
}

fn finite(name: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PlanError::NotFinite { name, value })
    }
}

fn positive(name: &'static str, value: f64) -> Result<f64, PlanError> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::NotPositive { name, value })
    }
}

fn ratio(name: &'static str, value: f64) -> Result<f64, PlanError> {
    finite(name, value)?;
    if value > 0.0 && value <= 0.5 {
        Ok(value)
    } else {
        Err(PlanError::OutOfRange {
            name,
            value,
            min: 0.0,
            max: 0.5,
        })
    }
}

/// Checks every input of a request; returns it unchanged.
pub fn validate(request: &MoveRequest, format: &Format) -> Result<(), PlanError> {
    format.validate()?;
    finite("distance", request.distance)?;
    match request.method {
        Method::Duration {
            duration,
            gamma,
            phi,
        } => {
            positive("duration", duration)?;
            ratio("gamma", gamma)?;
            ratio("phi", phi)?;
        }
        m => {
            for (_, name, value) in m.limits().iter() {
                positive(name, value)?;
            }
        }
    }
    Ok(())
}
