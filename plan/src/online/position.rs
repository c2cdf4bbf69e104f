//! To a position from any state, in tick units and continuous time: seed 002's motion
//! planner ("determine if an increased speed can be reached in the time and distance
//! available; if not, set a speed that can be attained"). Mirrored so that the axis moves in
//! `+` toward the target (or in the direction of a non-zero end speed), let `v_i` be the speed
//! at which the entry acceleration reaches zero at full jerk
//! ([`super::transition::intermediate_speed`]), `v_e ≥ 0` the end speed, and `D(v_c)` the
//! distance of a transition from the entry state to a speed `v_c` followed by one from `v_c` to
//! `v_e` (no cruise). The branches, by the distance `X` to go:
//!
//! 1. [`Branch::Cruise`] — `D(v_max) ≤ X`: transition to the limit, cruise for
//!    `(X − D(v_max))/v_max`, transition to `v_e`.
//! 2. [`Branch::Peak`] — `D(max(v_i, v_e)) ≤ X < D(v_max)`: `D` grows with `v_c` there and the
//!    `v_c` with `D(v_c) = X` is found by Brent's method; the speed peaks there (the seed's
//!    "incrementally optimal" speed when the set speed cannot be reached in the remaining
//!    distance).
//! 3. [`Branch::Partial`] — the entry already brakes (`a₀ < 0`) and `X` lies between the
//!    distance of braking on at once (`D(v_e)`) and `D(v_i)` (releasing the brake fully, then
//!    braking again): the brake is released only partly — jerk `+J` for a time `t` that the
//!    distance decides (found by Brent's method), then the fall to `v_e` from where that leaves
//!    the acceleration. This is seed 002's *partial* transition (PARTIAL_CONCAVE_FALL: the
//!    acceleration never reaches zero before the end).
//! 4. [`Branch::Descend`] — an entry whose speed is or will be beyond the limit (`v_i > v_max`,
//!    limits lowered mid-move) with `D(v_e) ≤ X < D(v_max)`: fall to the `v_c ≤ v_max` with
//!    `D(v_c) = X`, then to `v_e`. (Such a start is only promised to come back within its
//!    limits without undershoot or reversal.)
//!
//! Below `D(v_e)` no profile in this direction reaches `v_e` by the target: with `v_e = 0` the
//! target lies behind the point where braking at once stops the axis, and the plan is the same
//! problem mirrored — the direction is chosen first ([`direction`]), so the axis reverses
//! exactly when it must; with `v_e ≠ 0` the blend point is refused
//! ([`super::OnlineError::BlendUnreachable`]).

use serde::Serialize;

use super::transition::{intermediate_speed, velocity, Piece, TickLimits, Transition};

/// Which branch decided the cruise speed (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Branch {
    /// Cruise at the velocity limit.
    Cruise,
    /// Peak speed below the limit, no cruise.
    Peak,
    /// A brake released in part, then the fall to the end speed.
    Partial,
    /// From beyond the limits, fall to a speed within them, then to the end speed.
    Descend,
    /// A retry ([`ease`]): brake to the end speed at once, cruise at it, and leave the end
    /// a short transition from the end speed back to it.
    Ease,
    /// The fallback: brake to rest, then move on from rest (`super::fallback`).
    Stop,
}

/// A planned position profile (continuous, tick units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PositionProfile {
    /// Transition to `vc`, cruise, transition to the end speed ([`Branch::Cruise`],
    /// [`Branch::Peak`], [`Branch::Descend`]).
    Through {
        /// Branch.
        branch: Branch,
        /// Cruise speed (raw per tick).
        vc: f64,
        /// Transition from the entry state to `vc`.
        first: Transition,
        /// Cruise duration (ticks, real, ≥ 0).
        cruise: f64,
        /// Transition from `vc` to the end speed.
        second: Transition,
    },
    /// [`Branch::Partial`]: the brake released in part (`release`: jerk held for its
    /// duration), then the fall to the end speed.
    Partial {
        /// The release.
        release: Piece,
        /// The fall, from the state the release leaves.
        fall: Transition,
    },
}

impl PositionProfile {
    /// Total duration (ticks, real).
    pub fn duration(&self) -> f64 {
        match self {
            PositionProfile::Through {
                first,
                cruise,
                second,
                ..
            } => first.duration() + cruise + second.duration(),
            PositionProfile::Partial { release, fall } => release.t + fall.duration(),
        }
    }

    /// The branch.
    pub fn branch(&self) -> Branch {
        match self {
            PositionProfile::Through { branch, .. } => *branch,
            PositionProfile::Partial { .. } => Branch::Partial,
        }
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

    /// The partial release (order 3, `a₀ < 0`): jerk `+J` for `t`, then the fall to the end
    /// speed; the distance it covers, the release and the fall.
    fn partial(&self, t: f64) -> (f64, Piece, Transition) {
        let j = self.lim.j;
        let (v0, a0) = (self.v0, self.a0);
        let a1 = a0 + j * t;
        let v1 = v0 + a0 * t + j * t * t / 2.0;
        let x1 = v0 * t + a0 * t * t / 2.0 + j * t * t * t / 6.0;
        let fall = velocity(3, v1, a1, self.v_end, self.lim);
        (x1 + fall.distance(3, v1, a1), Piece { t, level: j }, fall)
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
            1e-9 * x.abs(),
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

/// The direction (`±1`) a move over distance `x` from `(v0, a0)` to end speed `v_end` goes:
/// that of a non-zero end speed, else where the target lies from the point where braking at
/// once stops the axis.
pub fn direction(order: u8, v0: f64, a0: f64, x: f64, v_end: f64, lim: &TickLimits) -> f64 {
    if v_end != 0.0 {
        return v_end.signum();
    }
    let a0 = if order == 2 { 0.0 } else { a0 };
    let stop = velocity(order, v0, a0, 0.0, lim).distance(order, v0, a0);
    if x >= stop {
        1.0
    } else {
        -1.0
    }
}

/// The profile a plan retries when the time-optimal one cannot be realised near the distance
/// of braking at once ([`Branch::Ease`]): the transition to the end speed `v_end` at once, a
/// cruise at it for what distance is left (none at rest), and a transition from `v_end` to
/// itself. Its last, short pieces carry the ticks' rounding: from a state on the planner's own
/// trajectory in its final brake they take up the half tick of travel that rounding the brake
/// adds, which a release at the start cannot. `None` when the end speed cannot be reached by
/// the target in direction `dir`.
pub fn ease(
    order: u8,
    v0: f64,
    a0: f64,
    x: f64,
    v_end: f64,
    dir: f64,
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
    let (d_end, first, second) = ahead.through(v_end);
    let rest = dir * (x - d_end);
    let cruise = if v_end != 0.0 {
        if rest < 0.0 {
            return None;
        }
        rest / v_end.abs()
    } else {
        0.0
    };
    Some(PositionProfile::Through {
        branch: Branch::Ease,
        vc: v_end,
        first,
        cruise,
        second,
    })
}

/// Plans the move over distance `x` (from the current position) from `(v0, a0)` to end speed
/// `v_end`, in direction `dir` ([`direction`]); `None` when no profile in that direction
/// reaches `v_end` by the target.
pub fn plan(
    order: u8,
    v0: f64,
    a0: f64,
    x: f64,
    v_end: f64,
    dir: f64,
    lim: &TickLimits,
) -> Option<PositionProfile> {
    let a0 = if order == 2 { 0.0 } else { a0 };
    let s = dir;
    let c = Ctx {
        order,
        v0: s * v0,
        a0: s * a0,
        v_end: s * v_end,
        lim,
    };
    if c.v_end < 0.0 {
        return None;
    }
    let x = s * x;
    let vmax = lim.v;
    let vi = if order == 2 {
        c.v0
    } else {
        intermediate_speed(c.v0, c.a0, lim.j)
    };
    // Transitions planned from the true (unmirrored) state.
    let ahead = Ctx {
        order,
        v0,
        a0,
        v_end,
        lim,
    };
    let through = |branch, vc: f64, cruise: f64| {
        let (_, first, second) = ahead.through(s * vc);
        PositionProfile::Through {
            branch,
            vc: s * vc,
            first,
            cruise,
            second,
        }
    };
    let d_max = c.d(vmax);
    if d_max <= x {
        return Some(through(Branch::Cruise, vmax, (x - d_max) / vmax));
    }
    let tol = 1e-9 * x.abs();
    let lo = c.v_end.max(vi.min(vmax));
    let d_lo = c.d(lo);
    if d_lo <= x {
        return Some(through(
            Branch::Peak,
            c.solve(x, (lo, d_lo), (vmax, d_max)),
            0.0,
        ));
    }
    let d_end = c.d(c.v_end);
    if vi > vmax {
        // From beyond the limits: fall to a speed within them.
        if d_end > x {
            return None;
        }
        let u = root(
            |u| c.d(c.v_end + u * u) - x,
            0.0,
            d_end - x,
            (vmax - c.v_end).max(0.0).sqrt(),
            d_max - x,
            tol,
        );
        let vc = (c.v_end + u * u).min(vmax);
        return Some(through(Branch::Descend, vc, 0.0));
    }
    if order == 3 && c.a0 < 0.0 && vi > c.v_end {
        // A brake released in part: t from 0 (brake on: D(v_e)) to |a₀|/J (released: D(v_i)).
        if d_end > x {
            return None;
        }
        let t_full = -c.a0 / lim.j;
        let t = root(
            |t| c.partial(t).0 - x,
            0.0,
            d_end - x,
            t_full,
            d_lo - x,
            tol,
        );
        let (_, release, _) = c.partial(t);
        // The fall from the state the release leaves, unmirrored.
        let (v1, a1) = (v0 + a0 * t + s * lim.j * t * t / 2.0, a0 + s * lim.j * t);
        let fall = velocity(3, v1, a1, v_end, lim);
        return Some(PositionProfile::Partial {
            release: Piece {
                t: release.t,
                level: s * release.level,
            },
            fall,
        });
    }
    // Otherwise D(max(v_i, v_e)) is the distance of braking at once: only the rounding of
    // the distances brings a target here, and the peak is at its lower end.
    if x >= d_lo - 1e-9 * d_lo.abs() {
        return Some(through(Branch::Peak, lo, 0.0));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: TickLimits = TickLimits {
        v: 10.0,
        acc: 4.0,
        dec: 3.0,
        j: 1.0,
    };

    /// Integrates `(level, duration)` pieces of jerk independently, in small exact steps;
    /// returns the final (x, v, a) and the largest |a| and |v| on the way.
    fn integrate(v0: f64, a0: f64, pieces: &[(f64, f64)]) -> ((f64, f64, f64), f64, f64) {
        let (mut x, mut v, mut a) = (0.0, v0, a0);
        let (mut peak_a, mut peak_v) = (a0.abs(), v0.abs());
        for &(level, t) in pieces {
            let n = 4000;
            let dt = t / n as f64;
            for _ in 0..n {
                x += v * dt + a * dt * dt / 2.0 + level * dt * dt * dt / 6.0;
                v += a * dt + level * dt * dt / 2.0;
                a += level * dt;
                peak_a = peak_a.max(a.abs());
                peak_v = peak_v.max(v.abs());
            }
        }
        ((x, v, a), peak_a, peak_v)
    }

    fn pieces(p: &PositionProfile) -> Vec<(f64, f64)> {
        let of = |t: &Transition| {
            t.pieces()
                .iter()
                .map(|p| (p.level, p.t))
                .collect::<Vec<_>>()
        };
        match p {
            PositionProfile::Through {
                first,
                cruise,
                second,
                ..
            } => [of(first), vec![(0.0, *cruise)], of(second)].concat(),
            PositionProfile::Partial { release, fall } => {
                [vec![(release.level, release.t)], of(fall)].concat()
            }
        }
    }

    /// Every branch, planned and then integrated here: it ends at the end speed with zero
    /// acceleration, having covered the distance, within the acceleration limit.
    #[test]
    fn every_branch_ends_on_its_distance_at_its_speed() {
        // (v0, a0, x, v_end, branch)
        let cases = [
            (0.0, 0.0, 500.0, 0.0, Branch::Cruise),
            (0.0, 0.0, 30.0, 0.0, Branch::Peak),
            (2.0, 1.0, 30.0, 1.0, Branch::Peak),
            // Braking at 2 from 6: a brake released in part covers from its own distance
            // (8.x) up to releasing fully and braking again.
            (6.0, -2.0, 9.6, 0.0, Branch::Partial),
            (6.0, -2.0, 11.0, 2.0, Branch::Partial),
            // Beyond the speed limit (lowered to 10 while at 14).
            (14.0, 0.0, 60.0, 0.0, Branch::Descend),
            // Moving away from the target: reverses.
            (-3.0, 0.0, 20.0, 0.0, Branch::Peak),
        ];
        for (v0, a0, x, v_end, branch) in cases {
            let dir = direction(3, v0, a0, x, v_end, &LIM);
            let p = plan(3, v0, a0, x, v_end, dir, &LIM)
                .unwrap_or_else(|| panic!("{v0} {a0} {x} {v_end}: no profile"));
            assert_eq!(p.branch(), branch, "{v0} {a0} {x} {v_end}");
            let ((xe, ve, ae), peak_a, peak_v) = integrate(v0, a0, &pieces(&p));
            let what = format!("{v0} {a0} {x} {v_end}: ended at {xe} {ve} {ae}");
            assert!((xe - x).abs() < 1e-6 * x.abs().max(1.0), "{what}");
            assert!((ve - v_end).abs() < 1e-6, "{what}");
            assert!(ae.abs() < 1e-6, "{what}");
            assert!(
                peak_a <= LIM.acc.max(a0.abs()) + 1e-9,
                "{what}: |a| {peak_a}"
            );
            if branch != Branch::Descend {
                assert!(peak_v <= LIM.v + 1e-9, "{what}: |v| {peak_v}");
            }
        }
    }

    /// The partial release is faster than releasing the brake fully and braking again (what a
    /// peak at the intermediate speed would do), and no slower than braking at once.
    #[test]
    fn a_partial_release_beats_releasing_fully() {
        let (v0, a0, v_end) = (6.0, -2.0, 0.0);
        let c = Ctx {
            order: 3,
            v0,
            a0,
            v_end,
            lim: &LIM,
        };
        let vi = intermediate_speed(v0, a0, LIM.j);
        let (d_brake, d_release) = (c.d(v_end), c.d(vi));
        let x = 0.5 * (d_brake + d_release);
        let p = plan(3, v0, a0, x, v_end, 1.0, &LIM).expect("plans");
        assert_eq!(p.branch(), Branch::Partial);
        let released = c.through(vi);
        let full = released.1.duration() + released.2.duration();
        let brake = velocity(3, v0, a0, v_end, &LIM).duration();
        assert!(p.duration() < full, "{} ≥ {full}", p.duration());
        assert!(p.duration() >= brake, "{} < {brake}", p.duration());
    }

    /// The ease profile brakes to the end speed at once and cruises the rest.
    #[test]
    fn the_ease_profile_brakes_at_once_and_cruises_the_rest() {
        let p = ease(3, 6.0, -1.0, 40.0, 2.0, 1.0, &LIM).expect("plans");
        assert_eq!(p.branch(), Branch::Ease);
        let ((xe, ve, ae), _, _) = integrate(6.0, -1.0, &pieces(&p));
        assert!((xe - 40.0).abs() < 1e-6 && (ve - 2.0).abs() < 1e-9 && ae.abs() < 1e-9);
        // A blend point before the end speed can be reached.
        assert!(ease(3, 6.0, -1.0, 1.0, 2.0, 1.0, &LIM).is_none());
    }

    #[test]
    fn brents_method_finds_roots_to_the_tolerance() {
        let r = root(|x| x * x * x - 2.0, 0.0, -2.0, 2.0, 6.0, 1e-12);
        assert!((r - 2f64.powf(1.0 / 3.0)).abs() < 1e-11, "{r}");
        // A root at an end, and a function flat near its root.
        assert_eq!(root(|x| x, 0.0, 0.0, 1.0, 1.0, 0.0), 0.0);
        let r = root(
            |x| (x - 0.3).powi(5),
            0.0,
            -(0.3f64.powi(5)),
            1.0,
            0.7f64.powi(5),
            0.0,
        );
        assert!((r - 0.3).abs() < 1e-3, "{r}");
    }
}
