//! Where two elements meet: the speed the path may pass the junction at, and the look-ahead
//! that keeps every junction's speed one the path can brake from (seed 002's motion planner,
//! which "accumulates the lengths of the tangent moves" so the speed carries across them).
//!
//! Passed at speed `v`, a junction changes each axis's direction share `uᵢ` by `Δuᵢ` (a kink;
//! 0 where the elements are tangent) and its curvature term `κᵢ` (`c²/R` toward an arc's
//! centre; 0 on a line) by `Δκᵢ`, within a tick. On the positions sampled every `Ts` that is,
//! for each axis (a velocity step `v·Δuᵢ` and an acceleration step `v²·Δκᵢ` in one tick):
//!
//! * acceleration `v·Δuᵢ/Ts + v²·max(|κ₁ᵢ|, |κ₂ᵢ|) ≤ ½·M·Aᵢ`,
//! * jerk `v·Δuᵢ/Ts² + v²·Δκᵢ/Ts ≤ ½·M·Jᵢ`,
//!
//! the other half of each limit left to the path's own acceleration and jerk, as
//! [`super::speed`] splits an arc's ([`MARGIN`] `M`). The acceleration step's jerk is spread
//! over two ticks on the samples (`v²Δκ/(2Ts)` each), so the bound holds with room. A junction
//! whose directions differ by more than [`TANGENT`] is a **corner**: no speed is allowed there
//! (the path stops exactly, PLCopen Buffered).
//!
//! [`lookahead`] then lowers each element's entry speed so that it can still brake to the next
//! one's (to rest at the end of what is known) within its own length, and raises none beyond
//! what the element before can reach: the motion on the path length plans blends that exist.

use super::speed::{Geometry, Limits, MARGIN};
use super::Element;

/// Largest change of the unit direction (`|u₂ − u₁|`, ≈ the angle in radians) a junction may
/// have and still be passed at speed; beyond, it is a corner.
pub const TANGENT: f64 = 0.01;

/// Share of an element's length the look-ahead counts on for a speed change (the rest absorbs
/// the realisation on whole ticks).
pub const FILL: f64 = 0.75;

/// The path's direction and curvature at an element's end (per axis).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The unit direction of motion.
    pub direction: Vec<f64>,
    /// The curvature vector (1/LSB): `c²/R` toward an arc's centre, 0 on a line.
    pub curvature: Vec<f64>,
}

impl Frame {
    /// The frame of the element's rule when its length is stretched by `f` on the path
    /// length (the axes move `1/f` times as far per unit of `s`): direction `/f`, curvature
    /// `/f²`.
    pub fn stretched(&self, f: f64) -> Frame {
        Frame {
            direction: self.direction.iter().map(|u| u / f).collect(),
            curvature: self.curvature.iter().map(|k| k / (f * f)).collect(),
        }
    }
}

/// An element's frames at its start and at its end, from `from` (LSB), its `geometry` and
/// its `length` (LSB) as [`super::prepare`] measured them. An arc whose end point is off its
/// circle by a fraction of an LSB is a spiral (its radius changes along it,
/// `snapgen_model::path::interp`): its direction has that radial share too, and its speed
/// along the circle grows with the radius (the rule turns at one rate), so the end's
/// direction is longer or shorter than a unit by the radii's ratio: a junction sees both.
pub fn frames(from: &[i64], element: &Element, geometry: &Geometry, length: f64) -> (Frame, Frame) {
    match (element, geometry) {
        (Element::Line { to }, _) => {
            let d: Vec<f64> = from.iter().zip(to).map(|(a, b)| (b - a) as f64).collect();
            let n = d
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
                .sqrt()
                .max(f64::MIN_POSITIVE);
            let f = Frame {
                direction: d.iter().map(|x| x / n).collect(),
                curvature: vec![0.0; d.len()],
            };
            (f.clone(), f)
        }
        (
            Element::Arc {
                plane,
                centre,
                ccw,
                to,
                ..
            },
            Geometry::Arc { shares, .. },
        ) => {
            let c2 = (1.0 - shares.iter().map(|u| u * u).sum::<f64>()).max(0.0);
            let radius = |p: &[i64]| {
                ((p[plane[0]] - centre[0]) as f64).hypot((p[plane[1]] - centre[1]) as f64)
            };
            let growth = (radius(to) - radius(from)) / length.max(f64::MIN_POSITIVE);
            let at = |p: &[i64]| {
                let (x, y) = (
                    (p[plane[0]] - centre[0]) as f64,
                    (p[plane[1]] - centre[1]) as f64,
                );
                let r = x.hypot(y).max(f64::MIN_POSITIVE);
                let (rx, ry) = (x / r, y / r);
                // Counter-clockwise turns the radius a quarter forward.
                let (tx, ty) = if *ccw { (-ry, rx) } else { (ry, -rx) };
                // The rule turns at one rate along the arc, so its speed along the circle is
                // the radius's share of the start's (the length is measured at the start's).
                let along = c2.sqrt() * r / radius(from).max(f64::MIN_POSITIVE);
                let mut direction = shares.clone();
                direction[plane[0]] = along * tx + growth * rx;
                direction[plane[1]] = along * ty + growth * ry;
                let mut curvature = vec![0.0; shares.len()];
                curvature[plane[0]] = -c2 / r * rx;
                curvature[plane[1]] = -c2 / r * ry;
                Frame {
                    direction,
                    curvature,
                }
            };
            (at(from), at(to))
        }
        (Element::Arc { .. }, Geometry::Line { .. }) => {
            unreachable!("an arc is measured as an arc")
        }
    }
}

/// The highest speed (units/s) the path may pass from an element ending in `end` into one
/// starting in `start`, for `axes` limited by their limits (units), a tick of `ts` s and an
/// output LSB of `lsb` units: 0 at a corner (module documentation).
pub fn junction_speed(end: &Frame, start: &Frame, axes: &[Limits], ts: f64, lsb: f64) -> f64 {
    let du: Vec<f64> = end
        .direction
        .iter()
        .zip(&start.direction)
        .map(|(a, b)| (b - a).abs())
        .collect();
    if du.iter().map(|d| d * d).sum::<f64>().sqrt() > TANGENT {
        return 0.0;
    }
    let mut v = f64::INFINITY;
    for (i, l) in axes.iter().enumerate() {
        let (k1, k2) = (end.curvature[i] / lsb, start.curvature[i] / lsb);
        let dk = (k2 - k1).abs();
        let k = k1.abs().max(k2.abs());
        v = v
            .min(quadratic(k, du[i] / ts, 0.5 * MARGIN * l.acceleration))
            .min(quadratic(dk / ts, du[i] / (ts * ts), 0.5 * MARGIN * l.jerk));
    }
    v
}

/// The largest `v ≥ 0` with `a·v² + b·v ≤ c` (`a, b, c ≥ 0`).
fn quadratic(a: f64, b: f64, c: f64) -> f64 {
    if a > 0.0 {
        (-b + (b * b + 4.0 * a * c).sqrt()) / (2.0 * a)
    } else if b > 0.0 {
        c / b
    } else {
        f64::INFINITY
    }
}

/// The distance a jerk-limited change of speed between `v` and `w` (acceleration 0 at both
/// ends) takes with acceleration `acc` and jerk `jerk`: its mean speed `(v + w)/2` times its
/// duration (an S-curve is point-symmetric about its middle).
pub fn change_distance(v: f64, w: f64, acc: f64, jerk: f64) -> f64 {
    let dv = (v - w).abs();
    let t = if dv >= acc * acc / jerk {
        dv / acc + acc / jerk
    } else {
        2.0 * (dv / jerk).sqrt()
    };
    0.5 * (v + w) * t
}

/// The highest speed from which a change to `w` fits in `length` with `limits` (the same
/// both ways: braking to `w`, or reached from `w`).
fn reach(w: f64, length: f64, limits: &Limits) -> f64 {
    let fits = |v: f64| change_distance(v, w, limits.acceleration, limits.jerk) <= length;
    let (mut lo, mut hi) = (w, w.max(1e-9) * 2.0);
    while fits(hi) {
        lo = hi;
        hi *= 2.0;
        if !hi.is_finite() {
            return f64::INFINITY;
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// One element as the look-ahead sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ahead {
    /// Its length (units).
    pub length: f64,
    /// The limits of its path length.
    pub limits: Limits,
    /// The highest speed its start may be passed at (its junction's; 0 for the first element
    /// and after a corner).
    pub entry: f64,
}

/// Every element's entry speed (units/s): its junction's and the elements' speed limits,
/// lowered so that each element can change to the next entry (0 after the last) within
/// [`FILL`] of its length, backward then forward (module documentation).
pub fn lookahead(elements: &[Ahead]) -> Vec<f64> {
    let n = elements.len();
    let mut entry: Vec<f64> = elements
        .iter()
        .enumerate()
        .map(|(k, e)| {
            // The first element's entry is given (0 from rest, or a move already running).
            let before = k
                .checked_sub(1)
                .map_or(e.entry, |p| elements[p].limits.velocity);
            e.entry.min(e.limits.velocity).min(before)
        })
        .collect();
    entry.push(0.0);
    for k in (0..n).rev() {
        let e = &elements[k];
        entry[k] = entry[k].min(reach(entry[k + 1], FILL * e.length, &e.limits));
    }
    for k in 0..n {
        let e = &elements[k];
        entry[k + 1] = entry[k + 1].min(reach(entry[k], FILL * e.length, &e.limits));
    }
    entry.truncate(n);
    entry
}

#[cfg(test)]
mod tests {
    use super::*;

    const AXIS: Limits = Limits {
        velocity: 250.0,
        acceleration: 5000.0,
        jerk: 2e6,
    };

    fn line(to: &[i64]) -> Element {
        Element::Line { to: to.to_vec() }
    }

    #[test]
    fn a_line_into_a_tangent_arc_is_limited_by_the_curvature_jump() {
        // Along X to (400, 0) mm, then counter-clockwise around (400, 200) mm: tangent.
        let lsb = 1e-3;
        let l = line(&[400_000, 0]);
        let arc = Element::Arc {
            plane: [0, 1],
            centre: [400_000, 200_000],
            ccw: true,
            to: vec![600_000, 200_000],
        };
        let g_arc = Geometry::Arc {
            plane: [0, 1],
            radius: 200_000.0,
            shares: vec![0.0, 0.0],
        };
        let g_line = Geometry::Line {
            shares: vec![1.0, 0.0],
        };
        let (_, end) = frames(&[0, 0], &l, &g_line, 400_000.0);
        let (start, _) = frames(
            &[400_000, 0],
            &arc,
            &g_arc,
            200_000.0 * std::f64::consts::FRAC_PI_2,
        );
        assert!((start.direction[0] - 1.0).abs() < 1e-12 && start.direction[1].abs() < 1e-12);
        let v = junction_speed(&end, &start, &[AXIS; 2], 1e-4, lsb);
        // v²/(R·Ts) = ½·M·J on Y: v = √(0.49·2e6·1e-4·200) = 140 mm/s.
        let want = (0.5 * MARGIN * 2e6 * 1e-4 * 200.0f64).sqrt();
        assert!((v - want).abs() < 1e-9 * want, "{v} vs {want}");
        // A quarter turn is a corner; a straight continuation is free.
        let (up, _) = frames(&[400_000, 0], &line(&[400_000, 9]), &g_line, 9.0);
        assert_eq!(junction_speed(&end, &up, &[AXIS; 2], 1e-4, lsb), 0.0);
        let (on, _) = frames(&[400_000, 0], &line(&[500_000, 0]), &g_line, 100_000.0);
        assert_eq!(
            junction_speed(&end, &on, &[AXIS; 2], 1e-4, lsb),
            f64::INFINITY
        );
    }

    #[test]
    fn the_lookahead_lets_every_element_brake_to_the_next() {
        let lim = Limits {
            velocity: 100.0,
            acceleration: 1000.0,
            jerk: 1e5,
        };
        let e = |length, entry| Ahead {
            length,
            limits: lim,
            entry,
        };
        // Two long elements, then a very short one to the end.
        let v = lookahead(&[e(100.0, 0.0), e(100.0, 1e9), e(0.5, 1e9)]);
        assert_eq!(v[0], 0.0);
        assert_eq!(v[1], 100.0);
        assert!(v[2] > 0.0 && v[2] < 100.0);
        // From v[2] to rest within the short element, and (forward) v[2] reached from v[1].
        let d = |a, b| change_distance(a, b, lim.acceleration, lim.jerk);
        assert!(d(v[2], 0.0) <= FILL * 0.5 * (1.0 + 1e-9));
        assert!(
            d(v[2], 0.0) >= FILL * 0.5 * (1.0 - 1e-9),
            "no lower than it must"
        );
        // From rest, the first element's end is limited by what 100 mm can reach.
        let w = lookahead(&[e(1.0, 0.0), e(100.0, 1e9)]);
        assert!(d(w[1], 0.0) <= FILL * 1.0 * (1.0 + 1e-9) && w[1] < 100.0);
        // A speed step of 100 mm/s at 1000 mm/s², 1e5 mm/s³: 0.1 s + 0.01 s at 50 mm/s.
        assert!((d(100.0, 0.0) - 5.5).abs() < 1e-12);
    }
}
