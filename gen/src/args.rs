//! The plan arguments shared by `plan`, `trace` and `plot`, and their translation into a
//! [`MoveRequest`] and a [`Format`].

use clap::Args;
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plan::{Method, MoveRequest};

/// A command-line mistake that clap cannot see: a flag that the chosen method does not use,
/// or one that it needs. Exit code 2, like clap's own usage errors.
#[derive(Debug, thiserror::Error)]
pub enum ArgError {
    /// A needed flag is missing.
    #[error("{method} needs --{flag}")]
    Missing {
        /// The method.
        method: &'static str,
        /// The flag.
        flag: &'static str,
    },
    /// A flag the method does not use.
    #[error("--{flag} is not used by {method}: remove it")]
    Unused {
        /// The method.
        method: &'static str,
        /// The flag.
        flag: &'static str,
    },
}

/// How to plan a move. Units: positions in user units (m, rad, …), times in seconds.
#[derive(Args, Debug, Clone)]
pub struct PlanArgs {
    /// Profile order: 4 (snap-limited, seed 000), 3 (jerk-limited S-curve) or 2 (trapezoid).
    #[arg(long, value_parser = clap::value_parser!(u8).range(2..=4))]
    pub order: Option<u8>,
    /// Signed distance to move (units).
    #[arg(long, allow_hyphen_values = true)]
    pub distance: f64,
    /// Velocity limit (units/s).
    #[arg(long, allow_hyphen_values = true)]
    pub vmax: Option<f64>,
    /// Acceleration limit (units/s²).
    #[arg(long, allow_hyphen_values = true)]
    pub amax: Option<f64>,
    /// Jerk limit (units/s³); orders 4 and 3.
    #[arg(long, allow_hyphen_values = true)]
    pub jmax: Option<f64>,
    /// Snap limit (units/s⁴); order 4.
    #[arg(long, allow_hyphen_values = true)]
    pub dmax: Option<f64>,
    /// Seed 001 duration-based S-curve: the move's duration T (s). Needs --gamma and --phi.
    #[arg(long, allow_hyphen_values = true)]
    pub duration: Option<f64>,
    /// Seed 001 acceleration-time factor γ ∈ (0, 0.5]: T_acc = γ·T.
    #[arg(long, allow_hyphen_values = true)]
    pub gamma: Option<f64>,
    /// Seed 001 jerk-time factor φ ∈ (0, 0.5]: T_jerk = φ·T_acc.
    #[arg(long, allow_hyphen_values = true)]
    pub phi: Option<f64>,
    /// Tick (sampling) period Ts (s) [default: 1e-5; `send`: the board's, and a different
    /// one is refused].
    #[arg(long, allow_hyphen_values = true)]
    pub ts: Option<f64>,
    /// Physical size of one output position LSB (units) [default: 1e-6; `send --motor`: one
    /// count of the motor's encoder, in rad].
    #[arg(long, allow_hyphen_values = true)]
    pub lsb: Option<f64>,
}

fn need(method: &'static str, flag: &'static str, v: Option<f64>) -> Result<f64, ArgError> {
    v.ok_or(ArgError::Missing { method, flag })
}

fn unused(method: &'static str, flag: &'static str, v: Option<f64>) -> Result<(), ArgError> {
    match v {
        Some(_) => Err(ArgError::Unused { method, flag }),
        None => Ok(()),
    }
}

impl PlanArgs {
    /// The format these arguments select.
    pub fn format(&self) -> Format {
        Format {
            ts: self.ts.unwrap_or(DEFAULT_FORMAT.ts),
            position_lsb: self.lsb.unwrap_or(DEFAULT_FORMAT.position_lsb),
            ..DEFAULT_FORMAT
        }
    }

    /// The move these arguments describe.
    pub fn request(&self) -> Result<MoveRequest, ArgError> {
        let method = if self.duration.is_some() {
            const M: &str = "the duration-based method (--duration)";
            if let Some(order) = self.order {
                if order != 3 {
                    return Err(ArgError::Unused {
                        method: M,
                        flag: "order",
                    });
                }
            }
            unused(M, "vmax", self.vmax)?;
            unused(M, "amax", self.amax)?;
            unused(M, "jmax", self.jmax)?;
            unused(M, "dmax", self.dmax)?;
            Method::Duration {
                duration: need(M, "duration", self.duration)?,
                gamma: need(M, "gamma", self.gamma)?,
                phi: need(M, "phi", self.phi)?,
            }
        } else {
            let order = self.order.unwrap_or(4);
            let m: &'static str = match order {
                4 => "order 4",
                3 => "order 3",
                _ => "order 2",
            };
            unused(m, "gamma", self.gamma)?;
            unused(m, "phi", self.phi)?;
            let vmax = need(m, "vmax", self.vmax)?;
            let amax = need(m, "amax", self.amax)?;
            match order {
                4 => Method::Order4 {
                    vmax,
                    amax,
                    jmax: need(m, "jmax", self.jmax)?,
                    dmax: need(m, "dmax", self.dmax)?,
                },
                3 => {
                    unused(m, "dmax", self.dmax)?;
                    Method::Order3 {
                        vmax,
                        amax,
                        jmax: need(m, "jmax", self.jmax)?,
                    }
                }
                _ => {
                    unused(m, "dmax", self.dmax)?;
                    unused(m, "jmax", self.jmax)?;
                    Method::Order2 { vmax, amax }
                }
            }
        };
        Ok(MoveRequest {
            distance: self.distance,
            method,
        })
    }
}
