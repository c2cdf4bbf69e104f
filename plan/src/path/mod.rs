//! A path of lines, arcs and helices on the output grid, prepared for the interpolator
//! (`snapgen_model::path::interp`): each element's length in `s` and the integers its rule
//! reads, so that the chain can be planned on the path length alone (seed 002: the trajectory
//! generator "is not concerned with the type of curve").
//!
//! * Points are whole output LSBs, one grid for all the axes; a point at rest sits at the
//!   centre of its cell, as the chain's position does (`x·2^FRAC_BITS + half an LSB`).
//! * Lengths: a line's is `|Δ|`, exact to the raw unit (an integer square root); an arc's is
//!   `√((R·sweep)² + |Δ of the other axes|²)` (a helix), in `f64`. [`prepare`] gives the
//!   path's length; the chain is planned for it, and [`Prepared::fit`] stretches the path onto
//!   the chain's exact displacement (the planner's quantized move, within a fraction of an
//!   LSB of the length), so the chain's end is the path's end.
//! * Each element starts where the rule leaves the one before it, so the axes never jump; a
//!   line ends on its end point (within 2⁻³⁰ LSB); so does an arc, its radius going from the
//!   start's to the end point's along it (the two may differ by at most 1 LSB: an end point
//!   rounded to the grid is rarely exactly on the circle).
//! * [`speed`]: the limits each element allows `s` so that no axis exceeds its own.
//! * [`junction`]: the speed a junction of two tangent elements may be passed at, and the
//!   look-ahead; corners stop exactly.
//! * Not built yet: blends at corners, the sequencer in the fabric (issue 22).

pub mod junction;
pub mod speed;

use ethnum::I256;
use snapgen_model::path::cordic::{isqrt, Turn, ONE_BITS};
use snapgen_model::path::interp::{Path, Segment, Shape, RATE_SHIFT};
use snapgen_model::FRAC_BITS;
use speed::Geometry;

/// One element, from where the one before it ends.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Element {
    /// A straight line to `to` (every axis, whole LSBs).
    Line {
        /// End point.
        to: Vec<i64>,
    },
    /// An arc (or a helix) to `to`, around `centre` in the plane of two axes.
    Arc {
        /// The plane's axes: counter-clockwise turns from the first toward the second.
        plane: [usize; 2],
        /// Centre in the plane (whole LSBs).
        centre: [i64; 2],
        /// Counter-clockwise (true) or clockwise.
        ccw: bool,
        /// End point (every axis; the same angle as the start is a full turn).
        to: Vec<i64>,
    },
}

impl Element {
    /// Its end point.
    pub fn to(&self) -> &[i64] {
        match self {
            Element::Line { to } | Element::Arc { to, .. } => to,
        }
    }
}

/// Why a path cannot be prepared.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// No element.
    #[error("the path has no element")]
    Empty,
    /// A point or centre too far out for the interpolator's registers.
    #[error("element {element}: a coordinate of {value} LSB is beyond ±2^40 LSB")]
    Range {
        /// The element.
        element: usize,
        /// The coordinate.
        value: i64,
    },
    /// A point with another number of axes than the start.
    #[error("element {element} has {found} axes, the start {axes}: give every axis of each point")]
    Axes {
        /// The element.
        element: usize,
        /// The start's axes.
        axes: usize,
        /// Found.
        found: usize,
    },
    /// An arc's plane that is not two different axes.
    #[error("element {element}: the arc's plane needs two different axes of the {axes}")]
    Plane {
        /// The element.
        element: usize,
        /// The path's axes.
        axes: usize,
    },
    /// An arc whose start or end is its centre, or whose end is off its circle.
    #[error("element {element}: the arc's start is {start} LSB from its centre, its end {end}: they must be equal within 1 LSB and not 0")]
    Radius {
        /// The element.
        element: usize,
        /// The start's distance from the centre (LSB).
        start: f64,
        /// The end's.
        end: f64,
    },
}

/// A path measured, ready to be fitted onto a chain's move.
#[derive(Clone)]
pub struct Prepared {
    start: Vec<i64>,
    drafts: Vec<Draft>,
    lengths: Vec<i128>,
    geometries: Vec<Geometry>,
}

impl Prepared {
    /// The path's length in raw units of `s`.
    pub fn length(&self) -> i128 {
        self.lengths.iter().sum()
    }

    /// Each element's geometry for [`speed::element_limits`], lengths in output LSBs.
    pub fn geometries(&self) -> &[Geometry] {
        &self.geometries
    }

    /// The path's length in the chain's physical units (`format`'s LSB).
    pub fn length_physical(&self, position_lsb: f64) -> f64 {
        self.length() as f64 / 2f64.powi(FRAC_BITS as i32) * position_lsb
    }
}

/// A point in raw units: the centre of its cell.
pub fn raw(x: i64) -> i128 {
    (i128::from(x) << FRAC_BITS) + (1i128 << (FRAC_BITS - 1))
}

/// `round(a · 2^shift / b)`, `b > 0`.
fn ratio(a: i128, shift: u32, b: i128) -> i128 {
    let n = I256::from(a) << shift;
    let b = I256::from(b);
    let q = (n + if n < 0 { -b / 2 } else { b / 2 }) / b;
    q.as_i128()
}

/// An element's geometry before the lengths are stretched.
#[derive(Clone)]
enum Draft {
    Line {
        to: Vec<i128>,
    },
    Arc {
        plane: [usize; 2],
        centre: [i128; 2],
        ccw: bool,
        /// Sweep in turns·2⁶⁴ (a full turn is 2⁶⁴).
        sweep: i128,
        to: Vec<i128>,
    },
}

/// Measures `elements` from `start` and checks them (module documentation).
pub fn prepare(start: &[i64], elements: &[Element]) -> Result<Prepared, PathError> {
    if elements.is_empty() {
        return Err(PathError::Empty);
    }
    let axes = start.len();
    // The geometry on the grid and each element's length (raw).
    let mut drafts = Vec::new();
    let mut lengths = Vec::new();
    let mut geometries = Vec::new();
    let mut at: Vec<i64> = start.to_vec();
    for (k, e) in elements.iter().enumerate() {
        let to = e.to();
        if to.len() != axes {
            return Err(PathError::Axes {
                element: k,
                axes,
                found: to.len(),
            });
        }
        let centre: &[i64] = match e {
            Element::Arc { centre, .. } => centre,
            Element::Line { .. } => &[],
        };
        let far = at
            .iter()
            .chain(to)
            .chain(centre)
            .find(|x| x.unsigned_abs() >= 1 << 40);
        if let Some(&value) = far {
            return Err(PathError::Range { element: k, value });
        }
        let to_raw: Vec<i128> = to.iter().map(|&x| raw(x)).collect();
        match e {
            Element::Line { .. } => {
                let d2: I256 = at
                    .iter()
                    .zip(to)
                    .map(|(&a, &b)| {
                        let d = I256::from(i128::from(b) - i128::from(a));
                        d * d
                    })
                    .sum();
                let length = isqrt((d2 << (2 * FRAC_BITS)).as_u256()).as_i128();
                let len = length as f64 / 2f64.powi(FRAC_BITS as i32);
                geometries.push(Geometry::Line {
                    shares: at
                        .iter()
                        .zip(to)
                        .map(|(&a, &b)| if len > 0.0 { (b - a) as f64 / len } else { 0.0 })
                        .collect(),
                });
                lengths.push(length);
                drafts.push(Draft::Line { to: to_raw });
            }
            Element::Arc {
                plane, centre, ccw, ..
            } => {
                let [p, q] = *plane;
                if p == q || p >= axes || q >= axes {
                    return Err(PathError::Plane { element: k, axes });
                }
                let rel = |pt: &[i64]| ((pt[p] - centre[0]) as f64, (pt[q] - centre[1]) as f64);
                let (s, e2) = (rel(&at), rel(to));
                let (rs, re) = (s.0.hypot(s.1), e2.0.hypot(e2.1));
                if rs == 0.0 || re == 0.0 || (rs - re).abs() > 1.0 {
                    return Err(PathError::Radius {
                        element: k,
                        start: rs,
                        end: re,
                    });
                }
                let angle = |v: (f64, f64)| v.1.atan2(v.0) / std::f64::consts::TAU;
                let mut sweep = angle(e2) - angle(s);
                if !*ccw {
                    sweep = -sweep;
                }
                sweep = sweep.rem_euclid(1.0);
                let same = (s.0 * e2.1 - s.1 * e2.0) == 0.0 && s.0 * e2.0 + s.1 * e2.1 > 0.0;
                if same || sweep == 0.0 {
                    sweep = 1.0;
                }
                let climb2: f64 = (0..axes)
                    .filter(|&i| i != p && i != q)
                    .map(|i| ((to[i] - at[i]) as f64).powi(2))
                    .sum();
                let len = ((rs * sweep * std::f64::consts::TAU).powi(2) + climb2).sqrt();
                lengths.push((len * 2f64.powi(FRAC_BITS as i32)) as i128);
                geometries.push(Geometry::Arc {
                    plane: *plane,
                    radius: rs,
                    shares: (0..axes)
                        .map(|i| {
                            if i == p || i == q {
                                0.0
                            } else {
                                (to[i] - at[i]) as f64 / len
                            }
                        })
                        .collect(),
                });
                drafts.push(Draft::Arc {
                    plane: *plane,
                    centre: [raw(centre[0]), raw(centre[1])],
                    ccw: *ccw,
                    sweep: (sweep * 2f64.powi(64)) as i128,
                    to: to_raw,
                });
            }
        }
        at = to.to_vec();
    }
    Ok(Prepared {
        start: start.to_vec(),
        drafts,
        lengths,
        geometries,
    })
}

impl Prepared {
    /// The interpolator's path over `s` from 0 to `total` (raw, > 0: the chain's exact
    /// displacement for the path's length), each element's share of it in proportion to its
    /// length.
    pub fn fit(&self, total: i128) -> Path {
        let (start, drafts, lengths) = (&self.start, &self.drafts, &self.lengths);
        let axes = start.len();
        let whole = self.length().max(1);
        let total = total.max(1);
        // Element k spans [b_k, b_k+1) of s.
        let mut bounds = vec![0i128];
        let mut sum = 0i128;
        for &l in lengths {
            sum += l;
            bounds.push(((I256::from(sum) * I256::from(total)) / I256::from(whole)).as_i128());
        }
        *bounds.last_mut().expect("one element at least") = total;
        fit_rules(start, drafts, &bounds, axes)
    }
}

/// The rules, each from where the one before leaves the axes.
fn fit_rules(start: &[i64], drafts: &[Draft], bounds: &[i128], axes: usize) -> Path {
    let mut from: Vec<i128> = start.iter().map(|&x| raw(x)).collect();
    let mut segments = Vec::new();
    for (k, d) in drafts.iter().enumerate() {
        let length = (bounds[k + 1] - bounds[k]).max(1);
        let shape = match d {
            // A repeated point (an element of length 0): the axes are already in its cell
            // (where the element before ended); they hold. (Else the rounding of that end
            // over one unit of s would be a share of 2^90 and more: beyond the fabric's port.)
            Draft::Line { .. } if bounds[k + 1] == bounds[k] => Shape::Line {
                dir: vec![0; axes],
                from: from.clone(),
            },
            Draft::Line { to } => Shape::Line {
                dir: from
                    .iter()
                    .zip(to)
                    .map(|(&a, &b)| ratio(b - a, ONE_BITS, length))
                    .collect(),
                from: from.clone(),
            },
            Draft::Arc {
                plane,
                centre,
                ccw,
                sweep,
                to,
            } => {
                let [p, q] = *plane;
                let (dx, dy) = (from[p] - centre[0], from[q] - centre[1]);
                let r2 = I256::from(dx) * I256::from(dx) + I256::from(dy) * I256::from(dy);
                let start = (dy as f64).atan2(dx as f64) / std::f64::consts::TAU;
                let radius = isqrt(r2.as_u256()).as_i128();
                let (ex, ey) = (to[p] - centre[0], to[q] - centre[1]);
                let e2 = I256::from(ex) * I256::from(ex) + I256::from(ey) * I256::from(ey);
                let end_radius = isqrt(e2.as_u256()).as_i128();
                Shape::Arc {
                    plane: *plane,
                    centre: *centre,
                    radius,
                    growth: ratio(end_radius - radius, ONE_BITS, length),
                    start: Turn((start.rem_euclid(1.0) * 2f64.powi(64)) as u64),
                    rate: ratio(*sweep, RATE_SHIFT, length),
                    ccw: *ccw,
                    dir: (0..axes)
                        .map(|i| {
                            if i == p || i == q {
                                0
                            } else {
                                ratio(to[i] - from[i], ONE_BITS, length)
                            }
                        })
                        .collect(),
                    from: from.clone(),
                }
            }
        };
        let segment = Segment { length, shape };
        from = segment.at(length);
        segments.push(segment);
    }
    Path { segments }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prepared and fitted onto its own length.
    fn made(start: &[i64], elements: &[Element]) -> Result<Path, PathError> {
        let p = prepare(start, elements)?;
        Ok(p.fit(p.length()))
    }

    #[test]
    fn a_line_ends_on_its_cell() {
        let p = prepare(&[0, 0], &[Element::Line { to: vec![3, 4] }]).unwrap();
        assert_eq!(p.length(), 5 << FRAC_BITS, "|(3, 4)| = 5 exactly");
        // Fitted onto a move a little longer: the end is still the end point's cell.
        let path = p.fit((5 << FRAC_BITS) + 12345);
        let end = path.at(path.length()).unwrap();
        assert_eq!(
            end.iter().map(|x| x >> FRAC_BITS).collect::<Vec<_>>(),
            vec![3, 4]
        );
        // |(1, 1)| = √2 LSB.
        let p = prepare(&[0, 0], &[Element::Line { to: vec![1, 1] }]).unwrap();
        let root2 = p.length() as f64 / 2f64.powi(FRAC_BITS as i32);
        assert!((root2 - std::f64::consts::SQRT_2).abs() < 1e-15, "{root2}");
    }

    #[test]
    fn a_repeated_point_holds_the_axes_in_its_cell() {
        let path = made(
            &[0],
            &[
                Element::Line { to: vec![7] },
                Element::Line { to: vec![7] },
                Element::Line { to: vec![4] },
            ],
        )
        .unwrap();
        let one = 1i128 << ONE_BITS;
        for g in &path.segments {
            let Shape::Line { dir, .. } = &g.shape else {
                panic!("lines")
            };
            assert!(dir.iter().all(|d| d.abs() <= one), "{g:?}");
        }
        let held = &path.segments[1];
        assert_eq!(held.at(0)[0] >> FRAC_BITS, 7);
        assert_eq!(path.at(path.length()).unwrap()[0] >> FRAC_BITS, 4);
    }

    #[test]
    fn bad_paths_say_what_to_change() {
        assert!(matches!(made(&[0], &[]), Err(PathError::Empty)));
        let e = made(&[0, 0], &[Element::Line { to: vec![1] }]).unwrap_err();
        assert!(e.to_string().contains("give every axis"), "{e}");
        let arc = |centre, to| Element::Arc {
            plane: [0, 1],
            centre,
            ccw: true,
            to,
        };
        let e = made(&[0, 0], &[arc([0, 0], vec![1, 0])]).unwrap_err();
        assert!(matches!(e, PathError::Radius { .. }), "{e}");
        let e = made(&[10, 0], &[arc([0, 0], vec![0, 13])]).unwrap_err();
        assert!(matches!(e, PathError::Radius { .. }), "{e}");
        // (0, 10) is on the circle of radius 10; (0, 11) is 1 LSB off it: a spiral of 1 LSB
        // ends on it exactly.
        for end in [10i64, 11] {
            let path = made(&[10, 0], &[arc([0, 0], vec![0, end])]).unwrap();
            let last = path.at(path.length()).unwrap();
            assert_eq!(
                last.iter().map(|x| x >> FRAC_BITS).collect::<Vec<_>>(),
                vec![0, i128::from(end)]
            );
        }
        assert!(matches!(
            made(
                &[0, 0],
                &[Element::Line {
                    to: vec![1 << 41, 0]
                }]
            ),
            Err(PathError::Range { .. })
        ));
        let flat = Element::Arc {
            plane: [0, 0],
            centre: [0, 0],
            ccw: true,
            to: vec![0, 10],
        };
        assert!(matches!(
            made(&[10, 0], &[flat]),
            Err(PathError::Plane { .. })
        ));
    }
}
