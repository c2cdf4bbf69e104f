//! Seed 001 (duration-based S-curve), section 2.2: the seven-segment profile given the
//! displacement `θd`, the duration `T`, the acceleration-time factor `γ` (`T_acc = γ·T`) and the
//! jerk-time factor `φ` (`T_jerk = φ·T_acc`):
//!
//! ```text
//! ω_d = θd / ((1−γ)·T)                      (eq 11)
//! α_d = θd / (γ·(1−γ)·(1−φ)·T²)             (eq 12)
//! J_d = α_d / T_jerk = α_d / (φ·γ·T)        (eq 13)
//! ```
//!
//! A negative `θd` gives the inverse S-curve of Table 3 (all three values negative).
//!
//! The profile is the order-3 shape with `tj = T_jerk`, a constant-acceleration plateau of
//! `T_acc − 2·T_jerk` and a cruise of `T − 2·T_acc`; each is rounded to the nearest tick
//! (`T_acc` and `T_jerk` first, the plateau and cruise by difference, so the phases add up to
//! `round(T/Ts)` ticks), and the jerk is recomputed from the rounded times.

use serde::{Deserialize, Serialize};

use super::{fmath, ContinuousProfile, PhaseTicks};
use crate::error::PlanError;

/// The seed 001 values of a duration-based move (physical units, signed by direction).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DurationValues {
    /// ω_d, cruise velocity (eq 11).
    pub velocity: f64,
    /// α_d, acceleration plateau (eq 12).
    pub acceleration: f64,
    /// J_d, jerk (eq 13).
    pub jerk: f64,
    /// T_acc = γ·T (s).
    pub t_acc: f64,
    /// T_jerk = φ·T_acc (s).
    pub t_jerk: f64,
}

/// Inputs of the seed 001 method.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DurationInput {
    /// Displacement θd (signed, units).
    pub distance: f64,
    /// Duration T (s).
    pub duration: f64,
    /// γ ∈ (0, 0.5].
    pub gamma: f64,
    /// φ ∈ (0, 0.5].
    pub phi: f64,
}

/// Eqs 11–13 and the phase times, unrounded.
pub fn values(i: &DurationInput) -> DurationValues {
    let (th, t, g, p) = (i.distance, i.duration, i.gamma, i.phi);
    let acceleration = th / (g * (1.0 - g) * (1.0 - p) * t * t);
    DurationValues {
        velocity: th / ((1.0 - g) * t),
        acceleration,
        jerk: acceleration / (p * g * t),
        t_acc: g * t,
        t_jerk: p * g * t,
    }
}

/// Rounds the phases to ticks and recomputes the jerk (tick units) for `|θd|`.
pub fn plan(i: &DurationInput, ts: f64) -> Result<ContinuousProfile, PlanError> {
    let v = values(i);
    let total = fmath::round(i.duration / ts) as u64;
    let t_acc = (fmath::round(v.t_acc / ts) as u64).min(total / 2);
    let tj = (fmath::round(v.t_jerk / ts) as u64).min(t_acc / 2);
    if tj == 0 {
        return Err(PlanError::DurationTooShort {
            duration: i.duration,
            gamma: i.gamma,
            phi: i.phi,
            jerk_ticks: tj,
            ts,
        });
    }
    let ta = t_acc - 2 * tj;
    let tv = total - 2 * t_acc;
    let (fj, fa, fv) = (tj as f64, ta as f64, tv as f64);
    Ok(ContinuousProfile {
        phases: PhaseTicks {
            d: 0,
            j: tj,
            a: ta,
            v: tv,
        },
        amplitude: i.distance.abs() / (fj * (fj + fa) * (2.0 * fj + fa + fv)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trunc4(x: f64) -> f64 {
        (x * 1e4).trunc() / 1e4
    }

    #[test]
    fn table_1_values() {
        let i = DurationInput {
            distance: 12.0 * std::f64::consts::PI,
            duration: 1.8,
            gamma: 0.4,
            phi: 0.25,
        };
        let v = values(&i);
        // The paper prints its values truncated to four decimals.
        assert_eq!(trunc4(v.velocity), 34.9065, "{v:?}");
        assert_eq!(trunc4(v.acceleration), 64.6418, "{v:?}");
        assert_eq!(trunc4(v.jerk), 359.1212, "{v:?}");
        assert!((v.t_acc - 0.72).abs() < 1e-12 && (v.t_jerk - 0.18).abs() < 1e-12);
        let p = plan(&i, 1e-5).unwrap();
        assert_eq!(
            (p.phases.j, p.phases.a, p.phases.v),
            (18_000, 36_000, 36_000)
        );
        // With exact ticks the recomputed jerk is J_d itself.
        assert!((p.amplitude / 1e-15 - 359.1212).abs() < 5e-5);
    }

    #[test]
    fn table_3_negative_move() {
        let i = DurationInput {
            distance: -12.0 * std::f64::consts::PI,
            duration: 1.8,
            gamma: 0.4,
            phi: 0.25,
        };
        let v = values(&i);
        assert_eq!(trunc4(v.velocity), -34.9065);
        assert_eq!(trunc4(v.acceleration), -64.6418);
        assert_eq!(trunc4(v.jerk), -359.1212);
    }
}
