//! To a position from any state: a velocity transition to a cruise speed `v_c`, a cruise, and a
//! transition from `v_c` to the end speed (zero for MC_MoveAbsolute, the blend speed when the
//! move hands over to a tangent next move). In tick units, continuous time.
//!
//! The distance covered without cruise, `D(v_c)`, is what decides `v_c` (seed 002's motion
//! planner: "determine if an increased speed can be reached in the time and distance
//! available; if not, set a speed that can be attained"). Let `v_i` be the speed at which the
//! entry acceleration reaches zero at full jerk ([`super::transition::intermediate_speed`]) and
//! `S = D(clamp(v_i))` the distance of braking at once. Mirrored so that the target lies ahead
//! of the point where an immediate stop would end (or in the direction of a non-zero end
//! speed):
//!
//! 1. [`Branch::Cruise`] — `D(v_max) ≤ X`: cruise at the limit for `(X − D(v_max))/v_max`.
//! 2. [`Branch::Peak`] — `D` grows with `v_c` above `max(v_i, v_end)`: the `v_c` with
//!    `D(v_c) = X` is found by bisection; the speed peaks there (the seed's "incrementally
//!    optimal" speed when the set speed cannot be reached in the remaining distance).
//! 3. [`Branch::Ease`] — `D(v_end) ≤ X` but the peak branch does not fit (an entry above the
//!    limits, or one already braking): brake to the end speed and cruise at it to the point.
//!
//! A target behind the stopping point (end speed zero) is the same problem mirrored: the
//! direction is chosen first, so the axis reverses exactly when it must.
//!
//! A non-zero end speed whose blend point lies behind the point where that speed can be
//! reached is refused ([`super::OnlineError::BlendUnreachable`]).

use serde::Serialize;

use super::transition::{intermediate_speed, velocity, TickLimits, Transition};

/// Which branch decided the cruise speed (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Branch {
    /// Cruise at the velocity limit.
    Cruise,
    /// Peak speed below the limit, no cruise.
    Peak,
    /// Brake to the end speed, cruise at it.
    Ease,
}

/// A planned position profile (continuous, tick units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionProfile {
    /// Branch.
    pub branch: Branch,
    /// Cruise speed (raw per tick).
    pub vc: f64,
    /// Transition from the entry state to `vc`.
    pub first: Transition,
    /// Cruise duration (ticks, real, ≥ 0).
    pub cruise: f64,
    /// Transition from `vc` to the end speed.
    pub second: Transition,
}

impl PositionProfile {
    /// Total duration (ticks, real).
    pub fn duration(&self) -> f64 {
        self.first.duration() + self.cruise + self.second.duration()
    }
}

/// The entry state, end speed and limits of one plan, mirrored into its direction.
struct Ctx<'l> {
    order: u8,
    v0: f64,
    a0: f64,
    v_end: f64,
    lim: &'l TickLimits,
}

impl Ctx<'_> {
    /// The two transitions through `vc` (no cruise) and the distance they cover.
    fn through(&self, vc: f64) -> (f64, Transition, Transition) {
        let first = velocity(self.order, self.v0, self.a0, vc, self.lim);
        let second = velocity(self.order, vc, 0.0, self.v_end, self.lim);
        let d = first.distance(self.order, self.v0, self.a0) + second.distance(self.order, vc, 0.0);
        (d, first, second)
    }

    /// `D(vc)`.
    fn d(&self, vc: f64) -> f64 {
        self.through(vc).0
    }

    /// The `v` in `[lo, hi]` with `D(v) = x`, given `d_lo = D(lo) ≤ x ≤ D(hi) = d_hi`.
    fn solve(&self, x: f64, (lo, d_lo): (f64, f64), (hi, d_hi): (f64, f64)) -> f64 {
        // D(lo + u²) is nearly polynomial in u near lo, where the first transition's duration
        // grows with √(v − v_i): the interpolations converge fast on it.
        let u = root(
            |u| self.d(lo + u * u) - x,
            0.0,
            d_lo - x,
            (hi - lo).sqrt(),
            d_hi - x,
            1e-12 * x.abs(),
        );
        (lo + u * u).min(hi)
    }
}

/// A root of `f` between `a` and `b`, whose values `fa`, `fb` have opposite signs (or one is
/// zero): a point where `|f| ≤ tol`, or the bracket at the resolution of an f64. Brent's
/// method (inverse quadratic interpolation, secant, bisection when they would not shrink the
/// bracket fast enough): superlinear on a smooth `f`, never slower than about twice a
/// bisection. Pure IEEE-754 arithmetic: every platform finds the same root.
pub fn root(f: impl Fn(f64) -> f64, a: f64, fa: f64, b: f64, fb: f64, tol: f64) -> f64 {
    let (mut a, mut fa, mut b, mut fb) = (a, fa, b, fb);
    if fa.abs() <= tol {
        return a;
    }
    if fb.abs() <= tol {
        return b;
    }
    if fa.abs() < fb.abs() {
        std::mem::swap(&mut a, &mut b);
        std::mem::swap(&mut fa, &mut fb);
    }
    // `b` the best estimate, `a` the other end of the bracket, `c` the previous `b`.
    let (mut c, mut fc) = (a, fa);
    let mut d = c;
    let mut bisected = true;
    for _ in 0..200 {
        let close = 2.0 * f64::EPSILON * b.abs().max(a.abs());
        if (b - a).abs() <= close {
            break;
        }
        let mut s = if fa != fc && fb != fc {
            // Inverse quadratic interpolation.
            a * fb * fc / ((fa - fb) * (fa - fc))
                + b * fa * fc / ((fb - fa) * (fb - fc))
                + c * fa * fb / ((fc - fa) * (fc - fb))
        } else {
            // Secant.
            b - fb * (b - a) / (fb - fa)
        };
        let q = (3.0 * a + b) / 4.0;
        let between = if q < b {
            s > q && s < b
        } else {
            s > b && s < q
        };
        let slow = if bisected {
            (s - b).abs() >= (b - c).abs() / 2.0 || (b - c).abs() < close
        } else {
            (s - b).abs() >= (c - d).abs() / 2.0 || (c - d).abs() < close
        };
        bisected = !between || slow || !s.is_finite();
        if bisected {
            s = 0.5 * (a + b);
        }
        let fs = f(s);
        if fs.abs() <= tol {
            return s;
        }
        d = c;
        c = b;
        fc = fb;
        if (fa < 0.0) == (fs < 0.0) {
            a = s;
            fa = fs;
        } else {
            b = s;
            fb = fs;
        }
        if fa.abs() < fb.abs() {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut fa, &mut fb);
        }
    }
    b
}

/// Plans the move over distance `x` (from the current position) from `(v0, a0)` to end speed
/// `v_end`; `None` when a non-zero end speed cannot be reached before the blend point.
pub fn plan(
    order: u8,
    v0: f64,
    a0: f64,
    x: f64,
    v_end: f64,
    lim: &TickLimits,
) -> Option<PositionProfile> {
    let a0 = if order == 2 { 0.0 } else { a0 };
    let ahead = Ctx {
        order,
        v0,
        a0,
        v_end,
        lim,
    };
    // Direction: that of a non-zero end speed, else where the target lies from the stop point.
    let s = if v_end != 0.0 {
        v_end.signum()
    } else if x >= ahead.d(0.0) {
        1.0
    } else {
        -1.0
    };
    let c = Ctx {
        order,
        v0: s * v0,
        a0: s * a0,
        v_end: s * v_end,
        lim,
    };
    let x = s * x;
    let vmax = lim.v;
    let vi = if order == 2 {
        c.v0
    } else {
        intermediate_speed(c.v0, c.a0, lim.j)
    };
    let profile = |branch, vc: f64, cruise: f64| {
        let (_, first, second) = ahead.through(s * vc);
        PositionProfile {
            branch,
            vc: s * vc,
            first,
            cruise,
            second,
        }
    };
    let d_max = c.d(vmax);
    if d_max <= x {
        return Some(profile(Branch::Cruise, vmax, (x - d_max) / vmax));
    }
    let lo = c.v_end.max(vi.min(vmax));
    let d_lo = c.d(lo);
    if d_lo <= x {
        return Some(profile(
            Branch::Peak,
            c.solve(x, (lo, d_lo), (vmax, d_max)),
            0.0,
        ));
    }
    // Between the straight brake to the end speed and the peak branch: brake to the end speed
    // and cruise at it. (A profile that eases between two brakes would be faster, but where
    // D(v) is flat in v its levels cannot absorb the rounding of its pieces to ticks; the
    // cruise can.) With an end speed of zero the direction choice puts x at or beyond D(0);
    // only rounding of the distances brings it here.
    let d_end = c.d(c.v_end);
    if d_end <= x || c.v_end == 0.0 {
        let cruise = if c.v_end > 0.0 {
            ((x - d_end) / c.v_end).max(0.0)
        } else {
            0.0
        };
        return Some(profile(Branch::Ease, c.v_end, cruise));
    }
    None
}
