//! The limits an element allows its path length `s`, so that no axis exceeds its own (the
//! motion planner's part of seed 002, derived here for what the seed leaves open: geometry).
//!
//! Along an element each axis is a function of `s`; its velocity, acceleration and jerk follow
//! from the path's `v`, `a`, `j` by the chain rule:
//!
//! * **Line**, `xᵢ = fromᵢ + uᵢ·s` (`uᵢ` the axis's share of the length): `vᵢ = uᵢ·v`,
//!   `aᵢ = uᵢ·a`, `jᵢ = uᵢ·j`; the path's limits are the smallest `limitᵢ / |uᵢ|`.
//! * **Arc** of radius `R`, in-plane share `c` of the length (1 when flat; a helix climbs
//!   the rest): with `φ = c·s/R`, a plane axis `x = R·cos φ` has
//!   `|ẋ| ≤ c·v`, `|ẍ| ≤ c·a + c²v²/R`, `|x⃛| ≤ c·j + 3c²·v·a/R + c³v³/R²` (the centripetal
//!   terms); a climbing axis is a line's. Half of each plane axis's acceleration and jerk is
//!   given to the centripetal terms, half to the path's own, and `v` lowered until the
//!   centripetal terms fit their half.
//!
//! These are the limits along an element; where two meet at speed, the curvature jump and any
//! kink are the junction's ([`super::junction`]). The tick adds to what the derivatives say (a
//! third difference of sampled positions is not exactly `x⃛·Ts³`): the limits given are kept
//! [`MARGIN`] below.

/// The share of each limit the derivation uses (the rest absorbs the tick's discretisation).
pub const MARGIN: f64 = 0.98;

/// An axis's or the path's limits (units/s, /s², /s³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
    /// Jerk.
    pub jerk: f64,
}

/// An element's geometry as the derivation needs it.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A line: each axis's share of the length (`Δxᵢ / length`).
    Line {
        /// Shares.
        shares: Vec<f64>,
    },
    /// An arc or helix.
    Arc {
        /// Its plane's axes.
        plane: [usize; 2],
        /// Radius (units).
        radius: f64,
        /// The climbing axes' shares of the length (the plane's axes: 0).
        shares: Vec<f64>,
    },
}

impl Geometry {
    /// The same with its radius in units of `unit` (output LSBs to the limits' units: the
    /// LSB's size).
    pub fn scaled(&self, unit: f64) -> Geometry {
        match self {
            Geometry::Arc {
                plane,
                radius,
                shares,
            } => Geometry::Arc {
                plane: *plane,
                radius: radius * unit,
                shares: shares.clone(),
            },
            g => g.clone(),
        }
    }
}

/// The limits of `s` along an element of `geometry`, for axes limited by `axes` and a
/// programmed feed `feed` (units/s). None when an axis allows no motion (a limit of 0).
pub fn element_limits(geometry: &Geometry, axes: &[Limits], feed: f64) -> Option<Limits> {
    let mut out = Limits {
        velocity: feed,
        acceleration: f64::INFINITY,
        jerk: f64::INFINITY,
    };
    let linear = |out: &mut Limits, shares: &[f64]| {
        for (u, l) in shares.iter().zip(axes) {
            let u = u.abs();
            if u > 0.0 {
                out.velocity = out.velocity.min(MARGIN * l.velocity / u);
                out.acceleration = out.acceleration.min(MARGIN * l.acceleration / u);
                out.jerk = out.jerk.min(MARGIN * l.jerk / u);
            }
        }
    };
    match geometry {
        Geometry::Line { shares } => linear(&mut out, shares),
        Geometry::Arc {
            plane,
            radius,
            shares,
        } => {
            linear(&mut out, shares);
            let c = (1.0 - shares.iter().map(|u| u * u).sum::<f64>())
                .max(0.0)
                .sqrt();
            let r = *radius;
            for &i in plane {
                let l = axes[i];
                let (a_half, j_half) = (MARGIN * l.acceleration / 2.0, MARGIN * l.jerk / 2.0);
                out.velocity = out
                    .velocity
                    .min(MARGIN * l.velocity / c)
                    .min((a_half * r).sqrt() / c);
                out.acceleration = out.acceleration.min(a_half / c);
                out.jerk = out.jerk.min(j_half / c);
            }
            // The centripetal jerk, 3c²·v·a/R + c³v³/R², within each plane axis's half: lower
            // v (it grows with v) by halving the excess until it fits.
            let centripetal =
                |v: f64| 3.0 * c * c * v * out.acceleration / r + (c * v).powi(3) / (r * r);
            let j_half = plane
                .iter()
                .map(|&i| MARGIN * axes[i].jerk / 2.0)
                .fold(f64::INFINITY, f64::min);
            if centripetal(out.velocity) > j_half {
                let (mut lo, mut hi) = (0.0, out.velocity);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if centripetal(mid) <= j_half {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                out.velocity = lo;
            }
        }
    }
    let ok = |x: f64| x.is_finite() && x > 0.0;
    (ok(out.velocity) && ok(out.acceleration) && ok(out.jerk)).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const AXIS: Limits = Limits {
        velocity: 100.0,
        acceleration: 1000.0,
        jerk: 100_000.0,
    };

    #[test]
    fn a_diagonal_line_is_limited_by_its_faster_axis() {
        let g = Geometry::Line {
            shares: vec![0.6, 0.8, 0.0],
        };
        let l = element_limits(&g, &[AXIS; 3], 1e9).unwrap();
        assert!((l.velocity - MARGIN * 100.0 / 0.8).abs() < 1e-9);
        assert!((l.jerk - MARGIN * 100_000.0 / 0.8).abs() < 1e-6);
        // The feed, when lower.
        assert_eq!(element_limits(&g, &[AXIS; 3], 10.0).unwrap().velocity, 10.0);
    }

    #[test]
    fn a_small_arc_is_slower_than_a_large_one() {
        let arc = |radius| Geometry::Arc {
            plane: [0, 1],
            radius,
            shares: vec![0.0, 0.0],
        };
        let small = element_limits(&arc(1.0), &[AXIS; 2], 1e9).unwrap();
        let large = element_limits(&arc(1000.0), &[AXIS; 2], 1e9).unwrap();
        assert!(small.velocity < large.velocity);
        // v²/R within half the acceleration.
        assert!(small.velocity.powi(2) / 1.0 <= MARGIN * 500.0 * (1.0 + 1e-12));
        assert_eq!(large.velocity, MARGIN * 100.0);
    }

    #[test]
    fn an_axis_that_cannot_move_refuses_the_element() {
        let still = Limits {
            velocity: 0.0,
            ..AXIS
        };
        let g = Geometry::Line {
            shares: vec![1.0, 0.0],
        };
        assert!(element_limits(&g, &[still, AXIS], 1e9).is_none());
        assert!(element_limits(&g, &[AXIS, still], 1e9).is_some());
    }
}
