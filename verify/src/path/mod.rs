//! An independent check of a multi-axis path: does a per-tick trace of N axes stay on the
//! programmed path, and within each axis's limits?
//!
//! For the coordinated motion of several axes along lines, arcs and helices (seed 002's
//! Cartesian path following). Like the rest of this crate it uses nothing a planner or an
//! interpolator computes: it takes the path as the user programmed it (end points, centres,
//! directions on the integer grid) and the integer positions the axes took, tick by tick.
//!
//! * **Geometry** ([`follow`]): the trace starts exactly on the path's start, every point of
//!   it lies on the path within a bound, the elements visited in their order (a point may lie
//!   on an element after the current one, never before it; an element is left only once the
//!   trace has come within a step of its end, following its progress a step at a time, and
//!   every junction a step passes must lie within that step's box widened by the bound: an
//!   element passed over within one tick, never a detour skipped nor a full turn cut short; a
//!   point within the bound of two elements near their junction is read both ways until the
//!   trace decides), and the trace ends exactly on the last element's end point, followed onto
//!   the last element (a path that passes its end point earlier is not done there). A
//!   line's bound is per axis ([`line`]: a point of the exact segment exists from which every
//!   axis is within `b`), an arc's is radial in its plane and per axis
//!   off it ([`arc`]). Lines and the radial and angular tests of arcs are exact (integer
//!   arithmetic of any size); only a helix's axial test uses floating point, with margins for
//!   its rounding counted against the trace (it may refuse a point within the bound by a
//!   hair).
//! * **Limits** ([`limits`]): each axis's velocity, acceleration and jerk, as the first, second
//!   and third differences of its positions from tick to tick, and the path's speed (the
//!   Euclidean length of a tick's step), never above their limits.
//!
//! Units are the caller's integers: positions and bounds on one grid shared by all the axes
//! (a group's axes interpolate in one frame), limits in that grid's units per tick, tick², tick³.

pub mod arc;
pub mod limits;
pub mod line;

use num_bigint::BigInt;

pub use arc::{Arc, Direction};
pub use limits::{AxisLimits, Exceeded, Peaks};
pub use line::Line;

/// One element of a path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Element {
    /// A straight line.
    Line(Line),
    /// A circular arc in a plane of two axes, or a helix (the other axes move linearly with
    /// the angle).
    Arc(Arc),
}

impl Element {
    /// Its start point.
    pub fn from(&self) -> &[i128] {
        match self {
            Element::Line(l) => &l.from,
            Element::Arc(a) => &a.from,
        }
    }

    /// Its end point.
    pub fn to(&self) -> &[i128] {
        match self {
            Element::Line(l) => &l.to,
            Element::Arc(a) => &a.to,
        }
    }

    /// How far along the element `p` is (0 to 1) and the element's length (`f64`).
    fn progress(&self, p: &[i128]) -> (f64, f64) {
        match self {
            Element::Line(l) => l.progress(p),
            Element::Arc(a) => a.progress(p),
        }
    }

    /// How far `p` (in LSBs, `f64`) is from the element: from the nearest point of a line;
    /// radially in an arc's plane from its circle (through its start), a helix's climb not
    /// counted. For reports and pictures (the check is [`Element::holds`], exact).
    pub fn distance(&self, p: &[f64]) -> f64 {
        let f = |v: &[i128]| v.iter().map(|&x| x as f64).collect::<Vec<f64>>();
        match self {
            Element::Line(l) => {
                let (a, b) = (f(&l.from), f(&l.to));
                let d: Vec<f64> = a.iter().zip(&b).map(|(a, b)| b - a).collect();
                let dd: f64 = d.iter().map(|x| x * x).sum();
                let t = if dd > 0.0 {
                    let dot: f64 = p
                        .iter()
                        .zip(&a)
                        .zip(&d)
                        .map(|((p, a), d)| (p - a) * d)
                        .sum();
                    (dot / dd).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                p.iter()
                    .zip(&a)
                    .zip(&d)
                    .map(|((p, a), d)| (p - a - t * d).powi(2))
                    .sum::<f64>()
                    .sqrt()
            }
            Element::Arc(arc) => {
                let [i, j] = arc.plane;
                let (cx, cy) = (arc.centre[0] as f64, arc.centre[1] as f64);
                let radius = (arc.from[i] as f64 - cx).hypot(arc.from[j] as f64 - cy);
                ((p[i] - cx).hypot(p[j] - cy) - radius).abs()
            }
        }
    }

    /// True when `p` lies on the element within its kind's bound.
    pub fn holds(&self, p: &[i128], bounds: Bounds) -> bool {
        match self {
            Element::Line(l) => l.holds(p, bounds.line),
            Element::Arc(a) => a.holds(p, bounds.arc),
        }
    }
}

/// How far a point may lie from each kind of element (issue 22 asks 1 LSB of a line on
/// every axis, 2 of an arc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bounds {
    /// From a line, on every axis.
    pub line: i128,
    /// From an arc: radially in its plane, and on each other axis.
    pub arc: i128,
}

impl Bounds {
    /// The same bound for every kind.
    pub const fn all(b: i128) -> Self {
        Bounds { line: b, arc: b }
    }
}

/// What is wrong with a path or a trace.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PathError {
    /// The path has no element.
    #[error("the path has no element")]
    Empty,
    /// An element with another number of axes than the path's first.
    #[error("element {element} has {found} axes, the path {axes}")]
    Axes {
        /// The element.
        element: usize,
        /// The path's axes.
        axes: usize,
        /// Found.
        found: usize,
    },
    /// A trace point with another number of axes than the path.
    #[error("the trace's tick {tick} has {found} axes, the path {axes}")]
    TraceAxes {
        /// The tick.
        tick: usize,
        /// The path's axes.
        axes: usize,
        /// Found.
        found: usize,
    },
    /// An element that does not begin where the one before it ends.
    #[error("element {element} begins at {from:?}, not where element {} ends ({prev_to:?})", element - 1)]
    Gap {
        /// The element.
        element: usize,
        /// Where it begins.
        from: Vec<i128>,
        /// Where the one before ends.
        prev_to: Vec<i128>,
    },
    /// An element that cannot be followed as given (see the message).
    #[error("element {element}: {why}")]
    Element {
        /// The element.
        element: usize,
        /// Why.
        why: String,
    },
}

/// Where a trace left its path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Deviation {
    /// The trace does not start on the path's start.
    Start {
        /// Its first point.
        point: Vec<i128>,
        /// The path's start.
        start: Vec<i128>,
    },
    /// The point of `tick` lies on no element from the current one on.
    OffPath {
        /// The tick.
        tick: usize,
        /// The element it was on before.
        element: usize,
        /// Its point.
        point: Vec<i128>,
    },
    /// The trace does not end on the path's end point.
    End {
        /// Its last point.
        point: Vec<i128>,
        /// The path's end point.
        end: Vec<i128>,
    },
}

/// What [`follow`] found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Followed {
    /// For each element, the first tick whose point lay on it (None: passed over within one
    /// tick's step).
    pub entered: Vec<Option<usize>>,
}

/// Checks a path before a trace is held against it: at least one element, one number of axes,
/// each element beginning where the one before it ends, each element well formed.
pub fn check_path(path: &[Element]) -> Result<usize, PathError> {
    let first = path.first().ok_or(PathError::Empty)?;
    let axes = first.from().len();
    for (k, e) in path.iter().enumerate() {
        for found in [e.from().len(), e.to().len()] {
            if found != axes {
                return Err(PathError::Axes {
                    element: k,
                    axes,
                    found,
                });
            }
        }
        if k > 0 && path[k - 1].to() != e.from() {
            return Err(PathError::Gap {
                element: k,
                from: e.from().to_vec(),
                prev_to: path[k - 1].to().to_vec(),
            });
        }
        if let Element::Arc(a) = e {
            a.check(axes)
                .map_err(|why| PathError::Element { element: k, why })?;
        }
    }
    Ok(axes)
}

/// Holds `trace` (one point per tick, from the first tick of the path) against `path`: every
/// point within `bounds` of an element, the elements in their order, the last point exactly
/// the path's end (see the module documentation). `Err(PathError)` for a path or trace that
/// cannot be checked; `Ok(Err(Deviation))` for a trace that leaves the path.
#[allow(clippy::type_complexity)]
pub fn follow(
    path: &[Element],
    trace: &[Vec<i128>],
    bounds: Bounds,
) -> Result<Result<Followed, Deviation>, PathError> {
    let axes = check_path(path)?;
    if let Some((tick, p)) = trace.iter().enumerate().find(|(_, p)| p.len() != axes) {
        return Err(PathError::TraceAxes {
            tick,
            axes,
            found: p.len(),
        });
    }
    let mut entered = vec![None; path.len()];
    let start = path[0].from();
    if let Some(p) = trace.first().filter(|p| p.as_slice() != start) {
        return Ok(Err(Deviation::Start {
            point: p.clone(),
            start: start.to_vec(),
        }));
    }
    let reach = bounds.line.max(bounds.arc);
    // Every way of following the path so far: the element the trace is on and how far it
    // has come along it (0 to 1). Near a junction a point may lie within the bound of both
    // elements (at a sharp corner approached a cell at a time, still on the first; just past
    // a tangent one, already on the second): both readings are kept until the trace decides.
    let mut ways: Vec<(usize, f64)> = vec![(0, 0.0)];
    for (tick, p) in trace.iter().enumerate() {
        let prev = &trace[tick.saturating_sub(1)];
        // This step's length.
        let step = prev
            .iter()
            .zip(p)
            .map(|(&a, &b)| ((b - a) as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        let within = |q: &[i128]| {
            q.iter()
                .zip(prev.iter().zip(p))
                .all(|(&x, (&a, &b))| a.min(b) - reach <= x && x <= a.max(b) + reach)
        };
        let mut next: Vec<(usize, f64)> = Vec::new();
        let mut keep = |at: usize, reached: f64| match next.iter_mut().find(|w| w.0 == at) {
            Some(w) => w.1 = w.1.max(reached),
            None => next.push((at, reached)),
        };
        for &(at, reached) in &ways {
            let (progress, length) = path[at].progress(p);
            // The share of the element the step and the bound cover. (Twice the step: a chord
            // of an arc is shorter than the arc, at most by π/2.)
            let slack = (2.0 * step + 2.0 * reach as f64 + 1.0) / length.max(1.0);
            // Leave the element only from its end (within a step), for the first later
            // element that holds the point, every junction on the way within the step's box.
            if reached >= 1.0 - slack {
                let onto = (at + 1..path.len())
                    .take_while(|&k| within(path[k].from()))
                    .find(|&k| path[k].holds(p, bounds));
                if let Some(k) = onto {
                    entered[k].get_or_insert(tick);
                    keep(k, path[k].progress(p).0);
                }
            }
            if path[at].holds(p, bounds) {
                entered[at].get_or_insert(tick);
                // Progress counts only as far as a step can go (a point just behind a full
                // turn's start is not its end).
                keep(
                    at,
                    if progress <= reached + slack {
                        reached.max(progress)
                    } else {
                        reached
                    },
                );
            }
        }
        if next.is_empty() {
            return Ok(Err(Deviation::OffPath {
                tick,
                element: ways.iter().map(|w| w.0).max().unwrap_or(0),
                point: p.clone(),
            }));
        }
        ways = next;
    }
    let last = path.len() - 1;
    let end = path[last].to();
    // The trace ends on a reading of the last element (a path that passes its end point
    // earlier is not done there).
    let done = ways.iter().any(|&(at, _)| at == last);
    match trace.last() {
        Some(p) if p.as_slice() == end && done => Ok(Ok(Followed { entered })),
        last => Ok(Err(Deviation::End {
            point: last.cloned().unwrap_or_default(),
            end: end.to_vec(),
        })),
    }
}

/// `x` as an exact integer.
pub(crate) fn big(x: i128) -> BigInt {
    BigInt::from(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn distance_is_from_a_lines_nearest_point_and_an_arcs_circle() {
        let line = Element::Line(Line {
            from: vec![0, 0],
            to: vec![1000, 0],
        });
        assert_eq!(line.distance(&[500.0, 3.0]), 3.0);
        assert_eq!(
            line.distance(&[1004.0, 3.0]),
            5.0,
            "past the end: from the end"
        );
        let arc = Element::Arc(Arc {
            plane: [0, 1],
            centre: [0, 0],
            direction: Direction::CounterClockwise,
            from: vec![100, 0],
            to: vec![0, 100],
        });
        assert!((arc.distance(&[0.0, 98.5]) - 1.5).abs() < 1e-12);
        assert!((arc.distance(&[60.0, 80.0])).abs() < 1e-12);
    }

    /// A slot: a line from (0, 0) to (1000, 0), a half turn counter-clockwise around
    /// (1000, 500) to (1000, 1000), a line back to (0, 1000); with z climbing 300 on the arc.
    fn slot() -> Vec<Element> {
        vec![
            Element::Line(Line {
                from: vec![0, 0, 0],
                to: vec![1000, 0, 0],
            }),
            Element::Arc(Arc {
                plane: [0, 1],
                centre: [1000, 500],
                direction: Direction::CounterClockwise,
                from: vec![1000, 0, 0],
                to: vec![1000, 1000, 300],
            }),
            Element::Line(Line {
                from: vec![1000, 1000, 300],
                to: vec![0, 1000, 300],
            }),
        ]
    }

    /// The slot sampled in `n` steps per element, rounded to the grid (a generator of its own:
    /// floating point, not this module's arithmetic).
    fn sampled(n: usize) -> Vec<Vec<i128>> {
        let mut out = Vec::new();
        for k in 0..=n {
            let t = k as f64 / n as f64;
            out.push(vec![(1000.0 * t).round() as i128, 0, 0]);
        }
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let th = -std::f64::consts::FRAC_PI_2 + t * std::f64::consts::PI;
            out.push(vec![
                (1000.0 + 500.0 * th.cos()).round() as i128,
                (500.0 + 500.0 * th.sin()).round() as i128,
                (300.0 * t).round() as i128,
            ]);
        }
        for k in 1..=n {
            let t = k as f64 / n as f64;
            out.push(vec![(1000.0 * (1.0 - t)).round() as i128, 1000, 300]);
        }
        out
    }

    #[test]
    fn a_rounded_slot_is_followed_and_each_change_of_it_is_caught() {
        let path = slot();
        let trace = sampled(97);
        let f = follow(&path, &trace, Bounds::all(1)).unwrap().unwrap();
        // Each element entered on the point that ends the one before (it holds on both).
        assert_eq!(f.entered, vec![Some(0), Some(97), Some(194)]);
        // One point moved off the path by 2 or more across it (along a line it would stay on
        // the path): off the path there. On the arc: 3 out or in along its radius, or 2 up.
        let across = |p: &[i128], k: usize| -> Vec<i128> {
            let (dx, dy) = ((p[0] - 1000) as f64, (p[1] - 500) as f64);
            let n = dx.hypot(dy);
            let s = if k == 0 { 3.0 } else { -3.0 };
            vec![
                p[0] + (s * dx / n).round() as i128,
                p[1] + (s * dy / n).round() as i128,
                p[2],
            ]
        };
        for tick in [5, 120, 150, 250] {
            let on_arc = (98..195).contains(&tick);
            for k in 0..3 {
                let mut bad = trace.clone();
                match (on_arc, k) {
                    (true, 2) | (false, 0) => bad[tick][2] += 2,
                    (true, _) => bad[tick] = across(&trace[tick], k),
                    (false, _) => bad[tick][1] += if k == 1 { 2 } else { -2 },
                }
                match follow(&path, &bad, Bounds::all(1)).unwrap() {
                    Err(Deviation::OffPath { tick: t, .. }) => assert_eq!(t, tick),
                    r => panic!("tick {tick} change {k}: {r:?}"),
                }
            }
        }
        // Back onto an element already left.
        let mut back = trace.clone();
        back[200] = trace[50].clone();
        assert!(matches!(
            follow(&path, &back, Bounds::all(1)).unwrap(),
            Err(Deviation::OffPath { tick: 200, .. })
        ));
        // Ending a count short of the end point.
        let mut short = trace.clone();
        short.last_mut().unwrap()[0] = 1;
        assert!(matches!(
            follow(&path, &short, Bounds::all(1)).unwrap(),
            Err(Deviation::End { .. })
        ));
        // A trace that skips the arc's first half within one tick is still on the path.
        let mut skip = trace.clone();
        skip.drain(99..140);
        assert!(follow(&path, &skip, Bounds::all(1)).unwrap().is_ok());
    }

    /// A line in the plane.
    fn line(from: [i128; 2], to: [i128; 2]) -> Element {
        Element::Line(Line {
            from: from.to_vec(),
            to: to.to_vec(),
        })
    }

    #[test]
    fn a_trace_ends_only_on_the_last_elements_end() {
        // Out along x, up and back down to (10, 0): the path ends where its first line does.
        let path = [
            line([0, 0], [10, 0]),
            line([10, 0], [10, 10]),
            line([10, 10], [10, 0]),
        ];
        let short: Vec<Vec<i128>> = (0..=10).map(|x| vec![x, 0]).collect();
        assert!(matches!(
            follow(&path, &short, Bounds::all(1)).unwrap(),
            Err(Deviation::End { .. })
        ));
        let mut whole = short.clone();
        whole.extend((1..=10).map(|y| vec![10, y]));
        whole.extend((0..10).rev().map(|y| vec![10, y]));
        assert!(follow(&path, &whole, Bounds::all(1)).unwrap().is_ok());
    }

    #[test]
    fn a_detour_or_a_turn_cannot_be_skipped_and_the_start_is_the_path_s() {
        // Out along x, up 10 in y and back down (a retract), then on along x: a trace
        // straight along x passes the retract's ends but not the retract itself.
        let path = [
            line([0, 0], [10, 0]),
            line([10, 0], [10, 10]),
            line([10, 10], [10, 0]),
            line([10, 0], [20, 0]),
        ];
        let straight: Vec<Vec<i128>> = (0..=20).map(|x| vec![x, 0]).collect();
        assert!(matches!(
            follow(&path, &straight, Bounds::all(1)).unwrap(),
            Err(Deviation::OffPath { .. })
        ));
        let mut with_retract: Vec<Vec<i128>> = (0..=10).map(|x| vec![x, 0]).collect();
        with_retract.extend((1..=10).map(|y| vec![10, y]));
        with_retract.extend((0..10).rev().map(|y| vec![10, y]));
        with_retract.extend((11..=20).map(|x| vec![x, 0]));
        let f = follow(&path, &with_retract, Bounds::all(0))
            .unwrap()
            .unwrap();
        assert!(f.entered.iter().all(Option::is_some), "{f:?}");
        // A full turn then a line from its end (its start): leaving onto the line at once,
        // the turn cut short, is off the path.
        let turn = [
            Element::Arc(Arc {
                plane: [0, 1],
                centre: [0, 100],
                direction: Direction::CounterClockwise,
                from: vec![0, 0],
                to: vec![0, 0],
            }),
            line([0, 0], [50, 0]),
        ];
        let cut: Vec<Vec<i128>> = (0..=50).map(|x| vec![x, 0]).collect();
        assert!(matches!(
            follow(&turn, &cut, Bounds::all(1)).unwrap(),
            Err(Deviation::OffPath { .. })
        ));
        // A trace that does not begin on the start.
        assert!(matches!(
            follow(&path, &with_retract[1..], Bounds::all(1)).unwrap(),
            Err(Deviation::Start { .. })
        ));
    }

    #[test]
    fn paths_that_cannot_be_checked_say_why() {
        assert_eq!(follow(&[], &[], Bounds::all(1)), Err(PathError::Empty));
        let mut gap = slot();
        if let Element::Line(l) = &mut gap[2] {
            l.from = vec![1000, 1001, 300];
        }
        assert!(matches!(
            check_path(&gap),
            Err(PathError::Gap { element: 2, .. })
        ));
        let mut flat = slot();
        if let Element::Arc(a) = &mut flat[1] {
            a.plane = [0, 3];
        }
        let e = check_path(&flat).unwrap_err();
        assert!(
            e.to_string().starts_with("element 1: the plane's axes"),
            "{e}"
        );
        let two_axes = vec![vec![0, 0]];
        assert_eq!(
            follow(&slot(), &two_axes, Bounds::all(1)),
            Err(PathError::TraceAxes {
                tick: 0,
                axes: 3,
                found: 2
            })
        );
    }

    proptest! {
        /// Any point of a random line, rounded to the grid, lies within 1 of it on every axis
        /// (rounding moves each by at most ½); any point of a random arc within 2 of it (the
        /// arc's own rounded start sets its radius). The arcs here are flat: a helix's axial
        /// test is checked on exact cases above.
        #[test]
        fn rounded_points_lie_within_one(
            a in prop::array::uniform3(-1_000_000i64..1_000_000),
            b in prop::array::uniform3(-1_000_000i64..1_000_000),
            r in 50i64..1_000_000,
            start in 0.0f64..std::f64::consts::TAU,
            sweep in 0.01f64..std::f64::consts::TAU,
            ccw in any::<bool>(),
            t in 0.0f64..=1.0,
        ) {
            let line = Line {
                from: a.map(i128::from).to_vec(),
                to: b.map(i128::from).to_vec(),
            };
            let p: Vec<i128> = (0..3)
                .map(|i| (a[i] as f64 + t * (b[i] - a[i]) as f64).round() as i128)
                .collect();
            prop_assert!(line.holds(&p, 1), "{:?} {:?}", line, p);
            let sign = if ccw { 1.0 } else { -1.0 };
            let at = |u: f64| {
                let th = start + sign * u * sweep;
                let x = a[0] as f64 + r as f64 * th.cos();
                let y = a[1] as f64 + r as f64 * th.sin();
                vec![x.round() as i128, y.round() as i128, i128::from(a[2])]
            };
            let arc = Arc {
                plane: [0, 1],
                centre: [i128::from(a[0]), i128::from(a[1])],
                direction: if ccw { Direction::CounterClockwise } else { Direction::Clockwise },
                from: at(0.0),
                to: at(1.0),
            };
            // The rounded start sets the radius: the exact circle lies within √½ of the
            // float one, the rounded point within √½ of that: within 2.
            prop_assume!(arc.check(3).is_ok());
            prop_assert!(arc.holds(&at(t), 2), "{:?} {:?}", arc, at(t));
        }
    }
}
