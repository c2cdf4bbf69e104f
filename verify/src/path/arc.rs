//! A circular arc in the plane of two axes, or a helix (the other axes move in proportion to
//! the angle swept), and whether a point lies on it within a bound.
//!
//! The arc is the circle around `centre` through `from` (radius `R = |from − centre|` in the
//! plane), swept in `direction` from `from`'s angle to `to`'s angle (`to` projected along its
//! radius; the same angle is a full turn). Counter-clockwise turns from the plane's first axis
//! toward its second (`plane = [X, Y]` is G-code's G17 with G3; `[Z, X]` is G18, `[Y, Z]` G19).
//! A point `p` lies on the arc within `b` when
//!
//! * **radially**, its distance `d` from the centre in the plane has `|d − R| ≤ b`. With
//!   `D = d²` and `Q = R²` integers, `d ≤ R + b` is `D − Q − b² ≤ 2b·√Q`, which holds when the
//!   left side is negative and otherwise squares to `(D − Q − b²)² ≤ 4b²Q`; `d ≥ R − b` is the
//!   same with `D` and `Q` exchanged. Exact.
//! * **angularly**, its angle lies in the swept range: ordered by the counter-clockwise angle
//!   from `from` (clockwise arcs mirrored), by the half-plane each vector lies in and then the
//!   sign of their cross product. Exact. A point within `b` of `from` or `to` on every axis
//!   counts as on the arc (it may lie a hair outside the swept range).
//! * **axially**: an axis off the plane that does not climb lies within `b` of where it
//!   stands (exact). On a helix, some one point of it lies within `b` of `p` in the plane and
//!   on every climbing axis: its point at the share `t` of the sweep `Θ` has axis `i` at
//!   `fromᵢ + t·(toᵢ − fromᵢ)`; the angles whose circle point lies within `b` of `p` in the
//!   plane are `θₚ ± δ`, `sin²(δ/2) = (b² − (d − R)²)/(4dR)` (`d` the point's distance from
//!   the centre, `d − R` from the exact `d² − R²`); so the shares allowed by the plane and by
//!   every climbing axis must meet. A steep helix needs the window: a point's in-plane
//!   rounding moves its own angle enough to move the helix's height there by many LSBs.
//!   Computed in `f64` (the angles by `atan2` of exact cross and dot products), `δ` and the
//!   axial windows shrunk by `ε = 10⁻¹³` of the values and the window of angles by atan2's
//!   own rounding, far above the rounding of these few well-conditioned operations (2⁻⁵³
//!   each): it may refuse a point within `b` by a hair, and is not meant to accept one beyond.
//!
//! An arc sweeps at most one turn.

use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};

use super::big;

/// Which way an arc turns in its plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// From the plane's first axis toward its second (G-code G3 in G17).
    CounterClockwise,
    /// The other way (G2).
    Clockwise,
}

/// An arc or helix (module documentation).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Arc {
    /// The two axes of its plane, in the order that sets its sense of rotation.
    pub plane: [usize; 2],
    /// Its centre in the plane.
    pub centre: [i128; 2],
    /// Which way it turns.
    pub direction: Direction,
    /// Start point (every axis).
    pub from: Vec<i128>,
    /// End point (every axis).
    pub to: Vec<i128>,
}

/// Relative rounding allowance of the helix's axial test (module documentation).
const EPSILON: f64 = 1e-13;

/// A vector in the arc's plane, mirrored for a clockwise arc so that every arc turns
/// counter-clockwise.
#[derive(Clone, Debug)]
struct V2 {
    x: BigInt,
    y: BigInt,
}

impl V2 {
    fn cross(&self, o: &V2) -> BigInt {
        &self.x * &o.y - &self.y * &o.x
    }

    fn dot(&self, o: &V2) -> BigInt {
        &self.x * &o.x + &self.y * &o.y
    }

    fn norm2(&self) -> BigInt {
        self.dot(self)
    }
}

impl Arc {
    /// Why the arc cannot be followed, if it cannot: its plane's axes must be two different
    /// axes of the path's `axes`, and `from` must not be its centre.
    pub fn check(&self, axes: usize) -> Result<(), String> {
        let [p, q] = self.plane;
        if p == q || p >= axes || q >= axes {
            return Err(format!(
                "the plane's axes {p} and {q} must be two different axes of the {axes}"
            ));
        }
        if self.rel(&self.from).norm2().is_zero() || self.rel(&self.to).norm2().is_zero() {
            return Err("the arc starts or ends on its centre (radius 0)".into());
        }
        Ok(())
    }

    /// `p − centre` in the plane, mirrored for a clockwise arc.
    fn rel(&self, p: &[i128]) -> V2 {
        let [a, b] = self.plane;
        let y = big(p[b]) - big(self.centre[1]);
        V2 {
            x: big(p[a]) - big(self.centre[0]),
            y: match self.direction {
                Direction::CounterClockwise => y,
                Direction::Clockwise => -y,
            },
        }
    }

    /// True when `p` lies on the arc within `bound` (module documentation).
    pub fn holds(&self, p: &[i128], bound: i128) -> bool {
        let near = |e: &[i128]| e.iter().zip(p).all(|(&e, &q)| (q - e).abs() <= bound);
        if near(&self.from) || near(&self.to) {
            return true;
        }
        let (s, e, u) = (self.rel(&self.from), self.rel(&self.to), self.rel(p));
        let b = big(bound);
        if !within_radius(&u.norm2(), &s.norm2(), &b) || !within_radius(&s.norm2(), &u.norm2(), &b)
        {
            return false;
        }
        if u.norm2().is_zero() {
            return false;
        }
        let full = e.cross(&s).is_zero() && e.dot(&s).is_positive();
        if !full && !angle_le(&s, &u, &e) {
            return false;
        }
        let [a, c] = self.plane;
        let axial: Vec<usize> = (0..p.len()).filter(|&i| i != a && i != c).collect();
        // Axes that do not climb: exactly within the bound of where they stand.
        let (still, climbing): (Vec<usize>, Vec<usize>) =
            axial.iter().partition(|&&i| self.from[i] == self.to[i]);
        if still.iter().any(|&i| (p[i] - self.from[i]).abs() > bound) {
            return false;
        }
        if climbing.is_empty() {
            return true;
        }
        let theta = sweep(&s, &u);
        let total = if full {
            std::f64::consts::TAU
        } else {
            sweep(&s, &e)
        };
        // The angles whose circle point lies within the bound of p in the plane: θₚ ± δ with
        // sin²(δ/2) = (b² − (d − R)²) / (4dR), d − R = (D − Q)/(d + R) from the exact D − Q
        // (well conditioned where acos of a cosine near 1 is not).
        let dq = (u.norm2() - s.norm2()).to_f64().unwrap_or(f64::INFINITY);
        let (d, r, b) = (
            u.norm2().to_f64().unwrap_or(f64::INFINITY).sqrt(),
            s.norm2().to_f64().unwrap_or(f64::INFINITY).sqrt(),
            bound as f64,
        );
        let gap = dq / (d + r);
        let half = ((b * b - gap * gap) / (4.0 * d * r))
            .max(0.0)
            .sqrt()
            .min(1.0);
        let delta = 2.0 * half.asin() * (1.0 - EPSILON);
        // The share of the sweep the helix may be at: within those angles, on the arc, and for
        // every climbing axis where its height is within the bound (one share for all: one
        // point of the helix).
        // atan2's rounding, a few units of 2⁻⁵³ of the angles, taken off the window too.
        let angle_error = 4.0 * f64::EPSILON * (1.0 + theta + total);
        let mut lo = ((theta - delta + angle_error) / total).max(0.0);
        let mut hi = ((theta + delta - angle_error) / total).min(1.0);
        for &i in &climbing {
            let moved = (big(p[i]) - big(self.from[i]))
                .to_f64()
                .unwrap_or(f64::INFINITY);
            let climb = (big(self.to[i]) - big(self.from[i]))
                .to_f64()
                .unwrap_or(f64::INFINITY);
            let slack = EPSILON * (moved.abs() + climb.abs());
            let (x, y) = ((moved - b + slack) / climb, (moved + b - slack) / climb);
            lo = lo.max(x.min(y));
            hi = hi.min(x.max(y));
        }
        lo <= hi
    }
}

impl Arc {
    /// The share of the sweep `p`'s angle has reached (0 at the start, 1 at the end), and the
    /// arc's length, in `f64`: for following its progress, not for the bound.
    pub(crate) fn progress(&self, p: &[i128]) -> (f64, f64) {
        let (s, e, u) = (self.rel(&self.from), self.rel(&self.to), self.rel(p));
        let full = e.cross(&s).is_zero() && e.dot(&s).is_positive();
        let total = if full {
            std::f64::consts::TAU
        } else {
            sweep(&s, &e)
        };
        let r = s.norm2().to_f64().unwrap_or(f64::INFINITY).sqrt();
        let [a, c] = self.plane;
        let climb2: f64 = (0..p.len())
            .filter(|&i| i != a && i != c)
            .map(|i| ((self.to[i] - self.from[i]) as f64).powi(2))
            .sum();
        let length = ((r * total).powi(2) + climb2).sqrt();
        if u.norm2().is_zero() {
            return (0.0, length);
        }
        ((sweep(&s, &u) / total).clamp(0.0, 1.0), length)
    }
}

/// `√D ≤ √Q + b`, exactly (module documentation).
fn within_radius(d: &BigInt, q: &BigInt, b: &BigInt) -> bool {
    let left = d - q - b * b;
    !left.is_positive() || &left * &left <= BigInt::from(4) * b * b * q
}

/// True when the counter-clockwise angle from `s` to `a` is at most the one from `s` to `b`
/// (angles in `[0, 2π)`; `a`, `b`, `s` not zero).
fn angle_le(s: &V2, a: &V2, b: &V2) -> bool {
    let half = |v: &V2| {
        let c = s.cross(v);
        !(c.is_positive() || (c.is_zero() && s.dot(v).is_positive()))
    };
    match (half(a), half(b)) {
        (false, true) => true,
        (true, false) => false,
        _ => !a.cross(b).is_negative(),
    }
}

/// The counter-clockwise angle from `s` to `v` in `[0, 2π)`, in `f64`.
fn sweep(s: &V2, v: &V2) -> f64 {
    let y = s.cross(v).to_f64().unwrap_or(0.0);
    let x = s.dot(v).to_f64().unwrap_or(0.0);
    let t = y.atan2(x);
    if t < 0.0 {
        t + std::f64::consts::TAU
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(direction: Direction, from: &[i128], to: &[i128]) -> Arc {
        Arc {
            plane: [0, 1],
            centre: [0, 0],
            direction,
            from: from.to_vec(),
            to: to.to_vec(),
        }
    }

    /// The points of a quarter circle of radius 1000 rounded to the grid: all within 1 of it.
    #[test]
    fn a_rounded_quarter_circle_lies_within_one() {
        let a = arc(Direction::CounterClockwise, &[1000, 0], &[0, 1000]);
        for k in 0..=900 {
            let t = f64::from(k) / 900.0 * std::f64::consts::FRAC_PI_2;
            let p = [
                (1000.0 * t.cos()).round() as i128,
                (1000.0 * t.sin()).round() as i128,
            ];
            assert!(a.holds(&p, 1), "{p:?}");
        }
        // The other three quarters are not on it, though on the circle.
        for p in [
            [-1000, 0],
            [0, -1000],
            [-707, -707],
            [707, -707],
            [-707, 707],
        ] {
            assert!(!a.holds(&p, 1), "{p:?}");
        }
        // The same end points clockwise: the other three quarters.
        let cw = arc(Direction::Clockwise, &[1000, 0], &[0, 1000]);
        assert!(cw.holds(&[-1000, 0], 0) && cw.holds(&[0, -1000], 0));
        assert!(!cw.holds(&[707, 707], 1));
    }

    #[test]
    fn radial_bounds_are_exact() {
        // R = 5: (3, 4) is on the circle; (6, 8) is 5 out; (0, 7) is 2 out; (0, 3) is 2 in.
        let a = arc(Direction::CounterClockwise, &[5, 0], &[5, 0]);
        assert!(a.holds(&[3, 4], 0));
        assert!(a.holds(&[0, 7], 2) && !a.holds(&[0, 7], 1));
        assert!(a.holds(&[0, -3], 2) && !a.holds(&[0, -3], 1));
        assert!(!a.holds(&[6, 8], 4) && a.holds(&[6, 8], 5));
        // Irrational distances: (1, 7) is √50 ≈ 7.071 from the centre, 2.071 out.
        assert!(!a.holds(&[1, 7], 2) && a.holds(&[1, 7], 3));
    }

    #[test]
    fn a_full_turn_holds_every_angle() {
        let a = arc(Direction::Clockwise, &[0, 100], &[0, 100]);
        for p in [[100, 0], [0, -100], [-100, 0], [-71, 71], [71, 71]] {
            assert!(a.holds(&p, 1), "{p:?}");
        }
    }

    #[test]
    fn a_helix_climbs_with_the_angle() {
        // Half a turn, z from 0 to 600: at a quarter z is 300.
        let h = Arc {
            plane: [0, 1],
            centre: [0, 0],
            direction: Direction::CounterClockwise,
            from: vec![1000, 0, 0],
            to: vec![-1000, 0, 600],
        };
        assert!(h.check(3).is_ok());
        // The axial test is conservative by its rounding allowance: a point exactly at the
        // bound is refused, one inside it taken.
        assert!(h.holds(&[0, 1000, 300], 1) && !h.holds(&[0, 1000, 300], 0));
        assert!(h.holds(&[0, 1000, 301], 2) && !h.holds(&[0, 1000, 302], 1));
        assert!(h.holds(&[707, 707, 150], 1));
        assert!(!h.holds(&[707, 707, 300], 1));
        // A full-turn helix: the start's angle is the end's.
        let turn = Arc {
            to: vec![1000, 0, 600],
            ..h.clone()
        };
        assert!(turn.holds(&[1000, 0, 600], 0) && turn.holds(&[1000, 0, 0], 0));
        assert!(turn.holds(&[-1000, 0, 300], 1));
        assert!(!turn.holds(&[1000, 0, 300], 1));
    }

    #[test]
    fn malformed_arcs_are_refused() {
        let mut a = arc(Direction::CounterClockwise, &[0, 0], &[1, 0]);
        assert!(a.check(2).unwrap_err().contains("radius 0"));
        a.from = vec![1, 0];
        a.to = vec![0, 0];
        assert!(a.check(2).unwrap_err().contains("radius 0"));
        a.to = vec![1, 0];
        a.from = vec![1, 0];
        a.plane = [1, 1];
        assert!(a.check(2).is_err());
        a.plane = [0, 2];
        assert!(a.check(2).is_err());
    }
}
