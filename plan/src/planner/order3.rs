//! Order 3: the seven-segment jerk-limited time-optimal rest-to-rest S-curve with sampling-time
//! rounding — seed 000's procedure one order lower, as its summary says.
//!
//! Tick units as in [`super::order4`]. With `s` the jerk magnitude and `tj`, `ta`, `tv` the
//! jerk, constant-acceleration and cruise phases (ticks):
//!
//! ```text
//! a_peak = s·tj      v_peak = s·tj·(tj+ta)      x = v_peak·(2tj+ta+tv)
//! ```
//!
//! `tj` from the distance, then the velocity and acceleration checks; `ta` from the quadratic,
//! then the velocity check; `tv` last; the jerk is recomputed after every rounding.

use super::{ceil_ticks_f, ceil_ticks_min1_f, fmath, ContinuousProfile, PhaseTicks};

/// Limits and distance in tick units.
#[derive(Clone, Copy, Debug)]
pub struct TickLimits3 {
    /// |distance| in user units.
    pub x: f64,
    /// v̄·Ts.
    pub v: f64,
    /// ā·Ts².
    pub a: f64,
    /// j̄·Ts³.
    pub j: f64,
}

/// Plans `tj`, `ta`, `tv` (ticks) and the jerk magnitude (tick units).
pub fn plan(l: &TickLimits3) -> ContinuousProfile {
    // tj from the distance alone: x = 2·s·tj³.
    let mut tj = ceil_ticks_min1_f(fmath::cbrt(l.x / (2.0 * l.j)));
    let mut s = l.x / (2.0 * tj * tj * tj);
    // Velocity check: v_peak = s·tj².
    if s * tj * tj > l.v {
        tj = ceil_ticks_min1_f((l.v / l.j).sqrt());
        s = l.v / (tj * tj);
    }
    // Acceleration check: a_peak = s·tj.
    if s * tj > l.a {
        tj = ceil_ticks_min1_f(l.a / l.j);
        s = l.a / tj;
    }
    // 1/(s·tj) with the jerk of the t_j step, used by both t_a candidates below.
    let inv_s1_tj = 1.0 / (s * tj);
    // ta from x = s·tj·(tj+ta)·(2tj+ta): ta² + 3tj·ta + 2tj² − x/(s·tj) = 0.
    let ta_x = (-3.0 * tj + (tj * tj + 4.0 * l.x * inv_s1_tj).max(0.0).sqrt()) / 2.0;
    let mut ta = ceil_ticks_f(ta_x);
    s = l.x / (tj * (tj + ta) * (2.0 * tj + ta));
    // Velocity check: v_peak = s·tj·(tj+ta).
    if s * tj * (tj + ta) > l.v {
        ta = ceil_ticks_f(l.v * inv_s1_tj - tj);
        s = l.v / (tj * (tj + ta));
    }
    // Cruise for the distance left at the velocity limit.
    let moved = s * tj * (tj + ta) * (2.0 * tj + ta);
    let tv = ceil_ticks_f((l.x - moved) / l.v);
    s = l.x / (tj * (tj + ta) * (2.0 * tj + ta + tv));
    ContinuousProfile {
        phases: PhaseTicks {
            d: 0,
            j: tj as u64,
            a: ta as u64,
            v: tv as u64,
        },
        amplitude: s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reaches_distance_within_limits() {
        let ts: f64 = 1e-3;
        let l = TickLimits3 {
            x: 2.0,
            v: 1.0 * ts,
            a: 5.0 * ts * ts,
            j: 100.0 * ts.powi(3),
        };
        let p = plan(&l);
        let (tj, ta, tv) = (p.phases.j as f64, p.phases.a as f64, p.phases.v as f64);
        let s = p.amplitude;
        assert!((s * tj * (tj + ta) * (2.0 * tj + ta + tv) - l.x).abs() < 1e-9);
        assert!(s <= l.j * (1.0 + 1e-9));
        assert!(s * tj <= l.a * (1.0 + 1e-9));
        assert!(s * tj * (tj + ta) <= l.v * (1.0 + 1e-9));
        assert!(tv > 0.0 && ta > 0.0);
    }
}
