//! Order 2: the acceleration-limited trapezoid with sampling-time rounding (seed 000's procedure
//! two orders lower).
//!
//! Tick units as in [`super::order4`]. With `s` the acceleration magnitude, `ta` the
//! acceleration phase and `tv` the cruise (ticks): `v_peak = s·ta`, `x = v_peak·(ta+tv)`.

use super::{ceil_ticks_f, ceil_ticks_min1_f, ContinuousProfile, PhaseTicks};

/// Limits and distance in tick units.
#[derive(Clone, Copy, Debug)]
pub struct TickLimits2 {
    /// |distance| in user units.
    pub x: f64,
    /// v̄·Ts.
    pub v: f64,
    /// ā·Ts².
    pub a: f64,
}

/// Plans `ta`, `tv` (ticks) and the acceleration magnitude (tick units).
pub fn plan(l: &TickLimits2) -> ContinuousProfile {
    // ta from the distance alone: x = s·ta².
    let mut ta = ceil_ticks_min1_f((l.x / l.a).sqrt());
    let mut s = l.x / (ta * ta);
    // Velocity check: v_peak = s·ta.
    if s * ta > l.v {
        ta = ceil_ticks_min1_f(l.v / l.a);
        s = l.v / ta;
    }
    let tv = ceil_ticks_f((l.x - s * ta * ta) / l.v);
    s = l.x / (ta * (ta + tv));
    ContinuousProfile {
        phases: PhaseTicks {
            d: 0,
            j: 0,
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
    fn velocity_limited_trapezoid() {
        let ts: f64 = 1e-3;
        let l = TickLimits2 {
            x: 3.0,
            v: 1.0 * ts,
            a: 4.0 * ts * ts,
        };
        let p = plan(&l);
        // ta = v/a = 0.25 s, tv = (3 − 0.25)/1 = 2.75 s.
        assert_eq!((p.phases.a, p.phases.v), (250, 2750));
        assert!((p.amplitude - l.a).abs() < 1e-12 * l.a);
    }
}
