//! Seed 000 (Pietrusewicz et al., MC_MoveAbsolute 4th order), section 3: the time-optimal
//! symmetric snap-limited rest-to-rest profile with sampling-time rounding.
//!
//! Everything here is in *tick units*: times in ticks, limits pre-multiplied by `Ts^n`
//! (`v·Ts`, `a·Ts²`, `j·Ts³`, `d·Ts⁴`), so "round up to a multiple of Ts" (eq 3) is a plain
//! `ceil`. The paper's equations are garbled in the extracted text; the relations used here were
//! re-derived and checked (see `docs/MODEL.md`):
//!
//! ```text
//! j_peak = s·td                         a_peak = s·td·(td+tj)
//! v_peak = a_peak·(2td+tj+ta)           x      = v_peak·(4td+2tj+ta+tv)
//! ```
//!
//! with `s` the snap magnitude. Each phase time is rounded up and the snap recomputed from the
//! rounded times, in the paper's order: 3.1 `t_d` (distance, then velocity, acceleration, jerk
//! checks), 3.2 `t_j` (Cardano cubic, then velocity, acceleration), 3.3 `t_a` (quadratic, then
//! velocity), 3.4 `t_v`.

use super::{ceil_ticks_f, ceil_ticks_min1_f, fmath, ContinuousProfile, PhaseTicks};

/// Limits and distance in tick units (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct TickLimits4 {
    /// |distance| in user units.
    pub x: f64,
    /// v̄·Ts.
    pub v: f64,
    /// ā·Ts².
    pub a: f64,
    /// j̄·Ts³.
    pub j: f64,
    /// d̄·Ts⁴.
    pub d: f64,
}

/// Section 3.1: `t_d` and the snap after its last rounding (eqs 4–22).
fn phase_d(l: &TickLimits4) -> (f64, f64) {
    // eqs 4–6: td from distance alone, x = 8·s·td⁴.
    let mut td = ceil_ticks_min1_f((l.x / (8.0 * l.d)).sqrt().sqrt());
    let mut s = l.x / (8.0 * td * td * td * td);
    // eqs 7–11: velocity check, v_peak = 2·s·td³.
    if 2.0 * s * td * td * td > l.v {
        td = ceil_ticks_min1_f(fmath::cbrt(l.v / (2.0 * l.d)));
        s = l.v / (2.0 * td * td * td);
    }
    // eqs 12–16: acceleration check, a_peak = s·td².
    if s * td * td > l.a {
        td = ceil_ticks_min1_f((l.a / l.d).sqrt());
        s = l.a / (td * td);
    }
    // eqs 17–21: jerk check, j_peak = s·td.
    if s * td > l.j {
        td = ceil_ticks_min1_f(l.j / l.d);
        s = l.j / td;
    }
    (td, s)
}

/// Section 3.2: `t_j` and the snap after its last rounding (eqs 23–36). `s3` is the snap of 3.1.
fn phase_j(l: &TickLimits4, td: f64, s3: f64) -> (f64, f64) {
    // eq 23: x = 2·s·td·(td+tj)·(2td+tj)², a cubic in tj. With tj = u − 5td/3 it is depressed
    // to u³ + 3P·u + 2Q = 0, P = −td²/9, Q = −td³/27 − x/(4·s·td), solved by Cardano.
    let p = -td * td / 9.0;
    let q = -td * td * td / 27.0 - l.x / (4.0 * s3 * td);
    let disc = (p * p * p + q * q).sqrt();
    let r = fmath::cbrt(-q + disc);
    let tj_x = r - p / r - 5.0 / 3.0 * td;
    let mut tj = ceil_ticks_f(tj_x);
    // eq 25: snap from the rounded times.
    let mut s = l.x / (2.0 * td * (td + tj) * (2.0 * td + tj) * (2.0 * td + tj));
    // eqs 26–30: velocity check, v_peak = s·td·(td+tj)·(2td+tj).
    if s * td * (td + tj) * (2.0 * td + tj) > l.v {
        tj = ceil_ticks_f((td * td / 4.0 + l.v / (s3 * td)).sqrt() - 1.5 * td);
        s = l.v / (td * (td + tj) * (2.0 * td + tj));
    }
    // eqs 31–35: acceleration check, a_peak = s·td·(td+tj).
    if s * td * (td + tj) > l.a {
        tj = ceil_ticks_f(l.a / (s3 * td) - td);
        s = l.a / (td * (td + tj));
    }
    (tj, s)
}

/// The coefficients of eq 37: `x/s = c1·ta² + c2·ta + c3` when `tv = 0`.
fn coefficients(td: f64, tj: f64) -> (f64, f64, f64) {
    let c1 = td * (td + tj);
    let c2 = 3.0 * td * (td + tj) * (2.0 * td + tj);
    let c3 = 2.0 * td * (td + tj) * (2.0 * td + tj) * (2.0 * td + tj);
    (c1, c2, c3)
}

/// Section 3.3: `t_a` and the snap after its last rounding (eqs 37–46). `s6` is the snap of 3.2.
fn phase_a(l: &TickLimits4, td: f64, tj: f64, s6: f64) -> (f64, f64) {
    let (c1, c2, c3) = coefficients(td, tj);
    // eq 38: the positive root of c1·ta² + c2·ta + c3 − x/s = 0.
    let ta_x = (-c2 + (c2 * c2 - 4.0 * c1 * (c3 - l.x / s6)).max(0.0).sqrt()) / (2.0 * c1);
    let mut ta = ceil_ticks_f(ta_x);
    // eq 40.
    let mut s = l.x / (ta * (c1 * ta + c2) + c3);
    // eqs 41–45: velocity check, v_peak = s·td·(td+tj)·(2td+tj+ta).
    if s * c1 * (2.0 * td + tj + ta) > l.v {
        ta = ceil_ticks_f((l.v / s6 - c1 * (2.0 * td + tj)) / c1);
        s = l.v / (c1 * (2.0 * td + tj + ta));
    }
    (ta, s)
}

/// Section 3.4: `t_v` and the final snap (eqs 47–49). `s8` is the snap of 3.3.
fn phase_v(l: &TickLimits4, td: f64, tj: f64, ta: f64, s8: f64) -> (f64, f64) {
    let (c1, c2, c3) = coefficients(td, tj);
    let moved = ta * (c1 * ta + c2) + c3;
    // eq 47: cruise time at the velocity limit for the distance left.
    let tv = ceil_ticks_f((l.x - s8 * moved) / l.v);
    // eq 49: snap from all four rounded times.
    let s = l.x / (moved + tv * c1 * (2.0 * td + tj + ta));
    (tv, s)
}

/// Plans the four phase times (ticks) and the snap magnitude (tick units) of seed 000.
/// `l.x` must be > 0 and all limits > 0.
pub fn plan(l: &TickLimits4) -> ContinuousProfile {
    let (td, s3) = phase_d(l);
    let (tj, s6) = phase_j(l, td, s3);
    let (ta, s8) = phase_a(l, td, tj, s6);
    let (tv, s) = phase_v(l, td, tj, ta, s8);
    ContinuousProfile {
        phases: PhaseTicks {
            d: td as u64,
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

    fn limits() -> TickLimits4 {
        // Ts = 1 ms: v = 1, a = 10, j = 100, d = 1000 (SI) → tick units.
        let ts: f64 = 1e-3;
        TickLimits4 {
            x: 1.0,
            v: 1.0 * ts,
            a: 10.0 * ts.powi(2),
            j: 100.0 * ts.powi(3),
            d: 1000.0 * ts.powi(4),
        }
    }

    /// Distance of a profile, from the re-derived relations.
    fn distance(p: &ContinuousProfile) -> f64 {
        let (td, tj, ta, tv) = (
            p.phases.d as f64,
            p.phases.j as f64,
            p.phases.a as f64,
            p.phases.v as f64,
        );
        p.amplitude * td * (td + tj) * (2.0 * td + tj + ta) * (4.0 * td + 2.0 * tj + ta + tv)
    }

    #[test]
    fn every_limit_active_profile_reaches_distance_within_limits() {
        let l = limits();
        let p = plan(&l);
        // td = j/d = 0.1 s, tj = a/j − td = 0, ta = v/a − … all phases present for 1 m.
        assert!(p.phases.d > 0 && p.phases.v > 0, "{p:?}");
        assert!((distance(&p) - l.x).abs() < 1e-9 * l.x);
        let (td, tj, ta) = (p.phases.d as f64, p.phases.j as f64, p.phases.a as f64);
        assert!(p.amplitude <= l.d * (1.0 + 1e-9));
        assert!(p.amplitude * td <= l.j * (1.0 + 1e-9));
        assert!(p.amplitude * td * (td + tj) <= l.a * (1.0 + 1e-9));
        assert!(p.amplitude * td * (td + tj) * (2.0 * td + tj + ta) <= l.v * (1.0 + 1e-9));
    }

    #[test]
    fn short_move_is_snap_limited_only() {
        let mut l = limits();
        l.x = 1e-6;
        let p = plan(&l);
        assert_eq!((p.phases.j, p.phases.a, p.phases.v), (0, 0, 0), "{p:?}");
        assert!((distance(&p) - l.x).abs() < 1e-9 * l.x);
    }
}
