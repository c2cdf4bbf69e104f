//! A G-code program played along its path on the bit-accurate model, and checked.
//!
//! Each block is an element planned from rest to rest on its length (an exact stop at every
//! block end, PLCopen Buffered: tangent blocks joined at speed are not built yet) with the
//! limits the element allows (`snapgen_plan::path::speed`: the block's feed, or for a rapid
//! the axes' own limits, and whatever the geometry takes from each axis). The chain plays the
//! plan tick by tick and the interpolator's rules map it onto the axes. The whole trace is
//! then held, from the positions alone, against the path as programmed and each axis's limits
//! (`snapgen_verify::path`): lines within 1 LSB on every axis, arcs within 2.

use snapgen_model::chain::Trace;
use snapgen_model::{Format, Quantity, FRAC_BITS};
use snapgen_plan::path::speed::{element_limits, Limits};
use snapgen_plan::path::{prepare, Element, PathError};
use snapgen_plan::{plan, Method, MoveRequest, PlanError};
use snapgen_verify::path as check;

use crate::gcode::Block;

/// What went wrong with a block.
#[derive(Debug, thiserror::Error)]
pub enum PlayError {
    /// The element cannot be prepared (see the message).
    #[error("line {line}: {source}")]
    Path {
        /// Its line.
        line: usize,
        /// Why.
        source: PathError,
    },
    /// An axis's limit of 0 lets the element not move.
    #[error("line {line}: an axis this block moves has a limit of 0")]
    Still {
        /// Its line.
        line: usize,
    },
    /// The planner refused the block.
    #[error("line {line}: {source}")]
    Plan {
        /// Its line.
        line: usize,
        /// Why.
        source: PlanError,
    },
}

/// One block as played.
#[derive(Clone, Debug, PartialEq)]
pub struct Played {
    /// Its line.
    pub line: usize,
    /// "line", "arc" or "rapid".
    pub kind: &'static str,
    /// Its length (mm).
    pub length: f64,
    /// The limits its path length was planned with.
    pub limits: Limits,
    /// Ticks it took.
    pub ticks: u64,
}

/// A program played: each block, and every axis's raw position on every tick (from the
/// start, at rest).
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The blocks.
    pub blocks: Vec<Played>,
    /// Every axis on every tick (raw, the chain's format).
    pub trace: Vec<Vec<i128>>,
}

/// What the independent check found.
#[derive(Clone, Debug, PartialEq)]
pub struct Checked {
    /// The first tick off the path, if any.
    pub deviation: Option<check::Deviation>,
    /// The first axis limit exceeded, if any.
    pub exceeded: Option<check::Exceeded>,
    /// Each axis's peak velocity, acceleration and jerk (mm/s, /s², /s³).
    pub peaks: Vec<[f64; 3]>,
}

/// Plays `blocks` from the origin with `axes` (X, Y, Z) limits in `format` (mm, its LSB and
/// Ts).
pub fn play(blocks: &[Block], axes: &[Limits; 3], format: &Format) -> Result<Run, PlayError> {
    // Every block prepared first: a block that cannot be is refused before anything moves.
    let mut at = vec![0i64; 3];
    let mut prepared_all = Vec::new();
    for b in blocks {
        let prepared =
            prepare(&at, std::slice::from_ref(&b.element)).map_err(|source| PlayError::Path {
                line: b.line,
                source,
            })?;
        prepared_all.push(prepared);
        at = match &b.element {
            Element::Line { to } | Element::Arc { to, .. } => to.clone(),
        };
    }
    let mut trace: Vec<Vec<i128>> = vec![vec![snapgen_plan::path::raw(0); 3]];
    let mut played = Vec::new();
    for (b, prepared) in blocks.iter().zip(&prepared_all) {
        let line = b.line;
        let g = prepared.geometries()[0].scaled(format.position_lsb);
        let limits = element_limits(&g, axes, b.feed.unwrap_or(f64::INFINITY))
            .ok_or(PlayError::Still { line })?;
        let p = plan(
            &MoveRequest {
                distance: prepared.length_physical(format.position_lsb),
                method: Method::Order3 {
                    vmax: limits.velocity,
                    amax: limits.acceleration,
                    jmax: limits.jerk,
                },
            },
            format,
        )
        .map_err(|source| PlayError::Plan { line, source })?;
        let path = prepared.fit(p.final_state.x - p.start.x);
        trace.extend(
            Trace::new(&p.program, p.start, format.widths)
                .skip(1)
                .map(|t| path.at(t.state.x - p.start.x).expect("one element")),
        );
        played.push(Played {
            line,
            kind: match (&b.element, b.feed) {
                (_, None) => "rapid",
                (Element::Line { .. }, _) => "line",
                (Element::Arc { .. }, _) => "arc",
            },
            length: prepared.length_physical(format.position_lsb),
            limits,
            ticks: p.ticks_total(),
        });
    }
    Ok(Run {
        blocks: played,
        trace,
    })
}

/// Holds `run` against the path of `blocks` and the `axes`' limits (module documentation).
pub fn verify(run: &Run, blocks: &[Block], axes: &[Limits; 3], format: &Format) -> Checked {
    let mut at = vec![0i128; 3];
    let mut path = Vec::new();
    for b in blocks {
        let to: Vec<i128> = match &b.element {
            Element::Line { to } | Element::Arc { to, .. } => {
                to.iter().map(|&x| x.into()).collect()
            }
        };
        path.push(match &b.element {
            Element::Line { .. } => check::Element::Line(check::Line {
                from: at.clone(),
                to: to.clone(),
            }),
            Element::Arc {
                plane, centre, ccw, ..
            } => check::Element::Arc(check::Arc {
                plane: *plane,
                centre: [centre[0].into(), centre[1].into()],
                direction: if *ccw {
                    check::Direction::CounterClockwise
                } else {
                    check::Direction::Clockwise
                },
                from: at.clone(),
                to: to.clone(),
            }),
        });
        at = to;
    }
    let on_grid: Vec<Vec<i128>> = run
        .trace
        .iter()
        .map(|p| p.iter().map(|x| x >> FRAC_BITS).collect())
        .collect();
    let deviation = if path.is_empty() {
        None
    } else {
        match check::follow(&path, &on_grid, check::Bounds { line: 1, arc: 2 }) {
            Ok(Ok(_)) => None,
            Ok(Err(d)) => Some(d),
            Err(e) => unreachable!("the blocks' path is well formed: {e}"),
        }
    };
    let s = |q| format.scale(q);
    let raw: Vec<check::AxisLimits> = axes
        .iter()
        .map(|a| check::AxisLimits {
            velocity: (a.velocity * s(Quantity::Velocity)) as i128,
            acceleration: (a.acceleration * s(Quantity::Acceleration)) as i128,
            jerk: (a.jerk * s(Quantity::Jerk)) as i128,
        })
        .collect();
    let (exceeded, peaks) = match check::limits::check(&run.trace, &raw, None) {
        Ok(p) => (None, p),
        Err(e) => (Some(e), Default::default()),
    };
    Checked {
        deviation,
        exceeded,
        peaks: peaks
            .axes
            .iter()
            .map(|[v, a, j]| {
                [
                    v.as_f64() / s(Quantity::Velocity),
                    a.as_f64() / s(Quantity::Acceleration),
                    j.as_f64() / s(Quantity::Jerk),
                ]
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::read;

    const F: Format = Format {
        ts: 1e-4,
        ..snapgen_model::DEFAULT_FORMAT
    };
    const AXIS: Limits = Limits {
        velocity: 50.0,
        acceleration: 1000.0,
        jerk: 100_000.0,
    };

    #[test]
    fn a_small_part_stays_on_its_path_within_every_limit() {
        let src =
            "G21 G90 F1200\nG0 X5\nG1 X20\nG3 X20 Y10 J5\nG2 X10 Y20 Z-1 R10\nG1 X5 Y5\nM30\n";
        let blocks = read(src, F.position_lsb).unwrap();
        let run = play(&blocks, &[AXIS; 3], &F).unwrap();
        assert_eq!(run.blocks.len(), 5);
        assert_eq!(run.blocks[0].kind, "rapid");
        assert!(run.blocks[1].limits.velocity <= 20.0, "F1200 = 20 mm/s");
        let c = verify(&run, &blocks, &[AXIS; 3], &F);
        assert_eq!((c.deviation, c.exceeded), (None, None));
        // The end: (5, 5, -1) mm exactly.
        let end: Vec<i128> = run
            .trace
            .last()
            .unwrap()
            .iter()
            .map(|x| x >> FRAC_BITS)
            .collect();
        assert_eq!(end, vec![5_000_000, 5_000_000, -1_000_000]);
        // Not blind: the same trace checked against tighter axes fails.
        let tight = Limits {
            velocity: 10.0,
            ..AXIS
        };
        assert!(verify(&run, &blocks, &[tight; 3], &F).exceeded.is_some());
    }
}
