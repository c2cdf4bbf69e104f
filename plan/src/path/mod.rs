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
//!   line ends on its end point (within 2⁻³⁰ LSB); an arc ends on its circle at its end
//!   point's angle: the next element starts from there. An arc that ends the path must end on
//!   its end point's cell (its end on the circle), or it is refused.
//! * Not built yet: the speed each element allows (curvature, per-axis limits), tangent
//!   extension online, corners, the sequencer in the fabric (issue 22).

use ethnum::{I256, U256};
use snapgen_model::path::cordic::{Turn, ONE_BITS};
use snapgen_model::path::interp::{Path, Segment, Shape, RATE_SHIFT};
use snapgen_model::FRAC_BITS;

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

/// Why a path cannot be prepared.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// No element.
    #[error("the path has no element")]
    Empty,
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
    /// The last element, an arc, whose end on its circle is not its end point's cell.
    #[error("the last element, an arc, ends at {reached:?}, not on its end point {to:?}: put the end point on the circle")]
    ArcEnd {
        /// Where its rule ends (whole LSBs).
        reached: Vec<i128>,
        /// Its end point.
        to: Vec<i64>,
    },
}

/// A path measured, ready to be fitted onto a chain's move.
pub struct Prepared {
    start: Vec<i64>,
    elements: Vec<Element>,
    drafts: Vec<Draft>,
    lengths: Vec<i128>,
}

impl Prepared {
    /// The path's length in raw units of `s`.
    pub fn length(&self) -> i128 {
        self.lengths.iter().sum()
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

/// `⌊√n⌋`.
fn isqrt(n: U256) -> U256 {
    if n < 2 {
        return n;
    }
    let mut x = U256::ONE << (256 - n.leading_zeros()).div_ceil(2);
    loop {
        let y = (x + n / x) >> 1;
        if y >= x {
            return x;
        }
        x = y;
    }
}

/// `round(a · 2^shift / b)`, `b > 0`.
fn ratio(a: i128, shift: u32, b: i128) -> i128 {
    let n = I256::from(a) << shift;
    let b = I256::from(b);
    let q = (n + if n < 0 { -b / 2 } else { b / 2 }) / b;
    q.as_i128()
}

/// An element's geometry before the lengths are stretched.
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
    let mut at: Vec<i64> = start.to_vec();
    for (k, e) in elements.iter().enumerate() {
        let to = match e {
            Element::Line { to } | Element::Arc { to, .. } => to,
        };
        if to.len() != axes {
            return Err(PathError::Axes {
                element: k,
                axes,
                found: to.len(),
            });
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
                lengths.push(isqrt((d2 << (2 * FRAC_BITS)).as_u256()).as_i128());
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
                drafts.push(Draft::Arc {
                    plane: *plane,
                    centre: [raw(centre[0]), raw(centre[1])],
                    ccw: *ccw,
                    sweep: (sweep * 2f64.powi(64)) as i128,
                    to: to_raw,
                });
            }
        }
        at = to.clone();
    }
    Ok(Prepared {
        start: start.to_vec(),
        elements: elements.to_vec(),
        drafts,
        lengths,
    })
}

impl Prepared {
    /// The interpolator's path over `s` from 0 to `total` (raw, > 0: the chain's exact
    /// displacement for the path's length), each element's share of it in proportion to its
    /// length.
    pub fn fit(&self, total: i128) -> Result<Path, PathError> {
        let (start, elements, drafts, lengths) =
            (&self.start, &self.elements, &self.drafts, &self.lengths);
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
        fit_rules(start, elements, drafts, &bounds, axes)
    }
}

/// The rules, each from where the one before leaves the axes.
fn fit_rules(
    start: &[i64],
    elements: &[Element],
    drafts: &[Draft],
    bounds: &[i128],
    axes: usize,
) -> Result<Path, PathError> {
    let mut from: Vec<i128> = start.iter().map(|&x| raw(x)).collect();
    let mut segments = Vec::new();
    for (k, d) in drafts.iter().enumerate() {
        let length = (bounds[k + 1] - bounds[k]).max(1);
        let shape = match d {
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
                Shape::Arc {
                    plane: *plane,
                    centre: *centre,
                    radius: isqrt(r2.as_u256()).as_i128(),
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
    if let (Some(Element::Arc { to, .. }), Some(end)) = (elements.last(), segments.last()) {
        let reached: Vec<i128> = end.at(end.length).iter().map(|x| x >> FRAC_BITS).collect();
        if reached.iter().zip(to).any(|(&r, &t)| r != i128::from(t)) {
            return Err(PathError::ArcEnd {
                reached,
                to: to.clone(),
            });
        }
    }
    Ok(Path { segments })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prepared and fitted onto its own length.
    fn made(start: &[i64], elements: &[Element]) -> Result<Path, PathError> {
        let p = prepare(start, elements)?;
        p.fit(p.length())
    }

    #[test]
    fn a_line_ends_on_its_cell() {
        let p = prepare(&[0, 0], &[Element::Line { to: vec![3, 4] }]).unwrap();
        assert_eq!(p.length(), 5 << FRAC_BITS, "|(3, 4)| = 5 exactly");
        // Fitted onto a move a little longer: the end is still the end point's cell.
        let path = p.fit((5 << FRAC_BITS) + 12345).unwrap();
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
        // (0, 10) is on the circle of radius 10: fine; (0, 11) is 11 from the centre: within
        // 1 LSB, but its cell is not the circle's point at that angle, and it ends the path.
        assert!(made(&[10, 0], &[arc([0, 0], vec![0, 10])]).is_ok());
        let e = made(&[10, 0], &[arc([0, 0], vec![0, 11])]).unwrap_err();
        assert!(
            e.to_string().contains("put the end point on the circle"),
            "{e}"
        );
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
