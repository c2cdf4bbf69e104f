//! A path (a G-code program's blocks) played by the axis group on the bit-accurate model, and
//! checked.
//!
//! [`group`] plays the path length `s` through the PLCopen host axis, each block a move on it
//! with the limits the element allows (`snapgen_plan::path::speed`: the block's feed, or for a
//! rapid the axes' own limits, and whatever the geometry takes from each axis); tangent blocks
//! join at the speed their junction allows, corners stop exactly. The interpolator's rules map
//! `s` onto the axes on every tick. The whole trace is then held, from the positions alone,
//! against the path as programmed and each axis's limits (`snapgen_verify::path`): lines within
//! 1 LSB on every axis, arcs within 2.

pub mod board;
pub mod group;
pub mod plcopen;

use snapgen_model::{Format, Quantity, FRAC_BITS};
use snapgen_plan::path::speed::Limits;
use snapgen_plan::path::{Element, PathError};
use snapgen_verify::path as check;

use crate::axis::{AxisErrorId, HostAxis, Outcome};
use crate::gcode::Block;
pub use group::{BoardStop, Group, PathAction, PathEvent, PathLimits};

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
    /// The path is longer than the path-length register holds.
    #[error("line {line}: the path reaches {length:.3} units there, beyond the {most:.3} its length register holds: split the program or give a coarser --lsb")]
    TooLong {
        /// The block.
        line: usize,
        /// The path's length at its end (units).
        length: f64,
        /// The most the register holds (units).
        most: f64,
    },
    /// The block's move ended in Error.
    #[error("line {line}: {source}")]
    Move {
        /// Its line.
        line: usize,
        /// Why.
        source: AxisErrorId,
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
    /// The limits its path length was planned with (its feed, its geometry).
    pub limits: Limits,
    /// The speed its start was allowed to be passed at (0: from rest, a corner).
    pub entry: f64,
    /// Played in one move with the element before it (a short element joined at speed: its
    /// move has the smaller limits of the two).
    pub joined: bool,
    /// Its move's outcome (`Done`, or how it ended).
    pub outcome: Outcome,
    /// Ticks the path length spent on it.
    pub ticks: u64,
}

/// A program played: each block, and every axis's raw position on every tick (from the
/// start, at rest).
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The blocks that entered the buffer.
    pub blocks: Vec<Played>,
    /// Every axis on every tick (raw, the chain's format).
    pub trace: Vec<Vec<i128>>,
    /// The path length on every tick (raw `s`, from the start's cell centre).
    pub lengths: Vec<i128>,
    /// The tick each event was taken on, from the start (None: not taken: its length never
    /// reached, or an event the group does not take, `Group::takes`).
    pub taken: Vec<Option<u64>>,
    /// Overrides refused (event index, why).
    pub refused: Vec<(usize, AxisErrorId)>,
    /// On a board: its controlled stop (the group stop), which every move kept within
    /// (`Group::for_board_stop`).
    pub stop: Option<BoardStop>,
}

impl Run {
    /// The output cell every axis ends in.
    pub fn end_cells(&self) -> Vec<i128> {
        self.trace
            .last()
            .map_or_else(Vec::new, |p| p.iter().map(|x| x >> FRAC_BITS).collect())
    }
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
    /// On every tick, how far the axes are from the element they follow (LSB, `f64`:
    /// `snapgen_verify::path::Element::distance`), for pictures and reports.
    pub distance: Vec<f64>,
}

/// Plays `blocks` from the origin with `axes` (X, Y, Z) limits in `format` (mm, its LSB and
/// Ts): every block enters the buffer at once, tangent blocks join at speed, corners stop.
pub fn play(blocks: &[Block], axes: &[Limits], format: &Format) -> Result<Run, PlayError> {
    let events = match blocks.len() {
        0 => vec![],
        n => vec![PathEvent {
            at_ms: 0.0,
            at_length: None,
            action: PathAction::Enter(n - 1),
        }],
    };
    play_events(blocks, axes, None, format, &events)
}

/// Plays `blocks` as `events` let them enter, with the path's `own` limits (when given)
/// beside each axis's.
pub fn play_events(
    blocks: &[Block],
    axes: &[Limits],
    own: Option<PathLimits>,
    format: &Format,
    events: &[PathEvent],
) -> Result<Run, PlayError> {
    let mut g = Group::new(blocks, axes, own, format)?;
    g.play(events);
    let mut run = collect(&g, &g.axis, blocks, g.lengths())?;
    run.taken = g.taken.clone();
    run.refused = g.refused.clone();
    Ok(run)
}

/// What `g` played of `blocks` through `axis` (its commands' outcomes), its path length on
/// every tick being `lengths` (raw `s`); no event recorded.
pub fn collect(
    g: &Group,
    axis: &HostAxis,
    blocks: &[Block],
    lengths: Vec<i128>,
) -> Result<Run, PlayError> {
    // Ticks on each element: those whose `s` lies within its share.
    let mut on = vec![0u64; g.bounds().len()];
    for &s in &lengths {
        let r = g.along(s);
        // At rest on an end, within half a cell past it: still that element's.
        let k = g
            .bounds()
            .partition_point(|&b| b <= r - (1 << (FRAC_BITS - 1)));
        let last = on.len().saturating_sub(1);
        if let Some(n) = on.get_mut(k.min(last)) {
            *n += 1;
        }
    }
    let mut played = Vec::new();
    for (k, (&entry, &c)) in g.entries().iter().zip(g.commands()).enumerate() {
        let b = &blocks[k];
        // Elements whose move was never given (its event not taken) were not played.
        let Some(rec) = axis.commands.get(c) else {
            break;
        };
        if let Outcome::Error(e) = &rec.outcome {
            return Err(PlayError::Move {
                line: b.line,
                source: e.clone(),
            });
        }
        let p = &g.planned()[k];
        played.push(Played {
            line: b.line,
            kind: match (&b.element, b.feed) {
                (_, None) => "rapid",
                (Element::Line { .. }, _) => "line",
                (Element::Arc { .. }, _) => "arc",
            },
            length: p.length,
            limits: p.limits,
            entry,
            joined: k > 0 && g.commands().get(k - 1) == Some(&c),
            outcome: rec.outcome.clone(),
            ticks: on[k],
        });
    }
    Ok(Run {
        blocks: played,
        trace: g.map(&lengths),
        lengths,
        taken: Vec::new(),
        refused: Vec::new(),
        stop: None,
    })
}

/// Holds `run` against the path of `blocks` and the `axes`' limits (module documentation).
pub fn verify(run: &Run, blocks: &[Block], axes: &[Limits], format: &Format) -> Checked {
    verify_from(run, blocks, &vec![0; axes.len()], axes, format)
}

/// [`verify`] for a path whose axes start in the cells `from` (LSB).
pub fn verify_from(
    run: &Run,
    blocks: &[Block],
    from: &[i64],
    axes: &[Limits],
    format: &Format,
) -> Checked {
    let mut at: Vec<i128> = from.iter().map(|&x| x.into()).collect();
    let mut path = Vec::new();
    for b in &blocks[..run.blocks.len()] {
        let to: Vec<i128> = b.element.to().iter().map(|&x| x.into()).collect();
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
    // The distance from the element followed: the next one once it is nearer.
    let lsb = |x: i128| x as f64 / 2f64.powi(FRAC_BITS as i32) - 0.5;
    let mut k = 0;
    let distance: Vec<f64> = run
        .trace
        .iter()
        .map(|p| {
            let p: Vec<f64> = p.iter().map(|&x| lsb(x)).collect();
            let Some(mut d) = path.get(k).map(|e| e.distance(&p)) else {
                return 0.0;
            };
            while let Some(next) = path.get(k + 1).map(|e| e.distance(&p)) {
                if next > d {
                    break;
                }
                (k, d) = (k + 1, next);
            }
            d
        })
        .collect();
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
        distance,
    }
}

/// The most a board's stop may carry the path length past a corner or the path's end (cells):
/// the fabric's stop law and the planner land differently in their last ticks (measured:
/// docs/PATH.md). Half a cell: the corner is a cell centre, so no axis's output cell changes
/// (which [`verify_stop`] checks on its own).
pub const STOP_PAST_MAX: f64 = 0.5;

/// Why a board's stop failed its check ([`verify_stop`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StopFault {
    /// It left the path.
    #[error("off the path: {0:?}")]
    Off(check::Deviation),
    /// An axis's limit exceeded before it passed a rest of the path.
    #[error("an axis's limit exceeded: {0:?}")]
    Exceeded(check::Exceeded),
    /// It came to rest too far past a corner or the path's end.
    #[error("{past} cells past a corner or the path's end (at most {STOP_PAST_MAX})")]
    Past {
        /// How far (cells of the path length).
        past: f64,
    },
    /// Past one, an axis left the cell of that corner.
    #[error("past a corner or the path's end, an axis left its cell")]
    LeftCell,
    /// The stop's limits cannot be given to a board, or the path was not played.
    #[error("{0}")]
    Setup(String),
}

/// A board's controlled stop, with limits `stop` (as the board takes them: `crate::limits`),
/// taken after tick `t` of `g`'s path (the fabric's law played from the exact state the
/// path's length is in: `snapgen_model::stop::play`), held against the path of `blocks` and
/// the `axes`' limits by the independent check: on the path and within every limit up to where
/// it comes to rest or passes a rest of the path (a corner, the end of what has entered); past
/// one by at most [`STOP_PAST_MAX`] of a cell, every axis in the cell of that rest. How far past
/// one it came (cells; 0 if none), or why it failed.
pub fn verify_stop(
    g: &Group,
    blocks: &[Block],
    axes: &[Limits],
    stop: BoardStop,
    t: u64,
) -> Result<f64, StopFault> {
    use crate::limits::{stop_limits, LimitSource};
    let format = g.format();
    let given = |flag, v| LimitSource {
        flag,
        given: Some(v),
        peak: 0,
    };
    let (raw, _) = stop_limits(
        given("deceleration", stop.deceleration),
        given("jerk", stop.jerk),
        &format,
    )
    .map_err(|e| StopFault::Setup(e.to_string()))?;
    let one = 2f64.powi(FRAC_BITS as i32);
    let bounds = g.bounds();
    let rests: Vec<i128> = (0..bounds.len())
        .filter(|&k| g.rests_after(k))
        .map(|k| bounds[k])
        .collect();
    let lengths = g.lengths();
    let t = (t as usize).min(lengths.len().saturating_sub(1));
    let at = g.axis.timeline.state_at(t as u64, &format);
    let (after, _) = snapgen_model::stop::play(at, raw, 100_000_000);
    let mut s: Vec<i128> = lengths[..=t].to_vec();
    s.extend(after.iter().map(|k| k.x));
    let last = g.along(s[s.len() - 1]);
    let from = g.along(at.x);
    let mut upto = s.len();
    let mut past = 0.0;
    if let Some(&b) = rests.iter().find(|&&b| from < b && b < last) {
        past = (last - b) as f64 / one;
        if past > STOP_PAST_MAX {
            return Err(StopFault::Past { past });
        }
        upto = s.iter().position(|&x| g.along(x) > b).unwrap_or(s.len());
        let cells = |p: &[i128]| p.iter().map(|x| x >> FRAC_BITS).collect::<Vec<_>>();
        let there = cells(&g.map(&[b + g.start_register()])[0]);
        if g.map(&s[upto.saturating_sub(1)..])
            .iter()
            .any(|p| cells(p) != there)
        {
            return Err(StopFault::LeftCell);
        }
    }
    let run = collect(g, &g.axis, blocks, s).map_err(|e| StopFault::Setup(e.to_string()))?;
    let c = verify_from(&run, blocks, g.from(), axes, &format);
    if let Some(e) = c.exceeded.filter(|e| e.tick < upto) {
        return Err(StopFault::Exceeded(e));
    }
    match c.deviation {
        None | Some(check::Deviation::End { .. }) => Ok(past),
        Some(d) => Err(StopFault::Off(d)),
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

    /// A CAM arc whose end is 1 µm off its circle (its centre corrected by the reader) is
    /// played on the path (the circle through both points) within every limit.
    #[test]
    fn a_cam_arc_is_played_on_its_corrected_circle() {
        let src = "G21 G90 F1200\nG1 X10\nG3 X0 Y10.001 I-10 J0\nG1 X-5\nM30\n";
        let lsb = 1e-6;
        let f = Format {
            position_lsb: lsb,
            ..F
        };
        let blocks = read(src, lsb).unwrap();
        let run = play(&blocks, &[AXIS; 3], &f).unwrap();
        let c = verify(&run, &blocks, &[AXIS; 3], &f);
        assert!(c.deviation.is_none() && c.exceeded.is_none(), "{c:?}");
        assert_eq!(run.end_cells(), vec![-5_000_000, 10_001_000, 0]);
    }

    #[test]
    fn a_small_part_stays_on_its_path_within_every_limit() {
        let src =
            "G21 G90 F1200\nG0 X5\nG1 X20\nG3 X20 Y10 J5\nG2 X10 Y20 Z-1 R10\nG1 X5 Y5\nM30\n";
        let blocks = read(src, F.position_lsb).unwrap();
        let run = play(&blocks, &[AXIS; 3], &F).unwrap();
        assert_eq!(run.blocks.len(), 5);
        assert_eq!(run.blocks[0].kind, "rapid");
        assert!(run.blocks[1].limits.velocity <= 20.0, "F1200 = 20 mm/s");
        // G1 X20 runs into the tangent G3 at speed; the G2 after it meets it at a corner,
        // and so does the G1 after the G2.
        let entries: Vec<f64> = run.blocks.iter().map(|b| b.entry).collect();
        // R = 5 mm: v²/(R·Ts) within half the jerk, √(0.49·1e5·1e-4·5) = 4.95 mm/s.
        assert!((entries[2] - 4.9497).abs() < 1e-3, "{entries:?}");
        assert_eq!(
            (entries[0], entries[1], entries[3], entries[4]),
            (0.0, 0.0, 0.0, 0.0)
        );
        let c = verify(&run, &blocks, &[AXIS; 3], &F);
        assert_eq!((c.deviation, c.exceeded), (None, None));
        // The end: (5, 5, -1) mm exactly.
        assert_eq!(run.end_cells(), vec![5_000_000, 5_000_000, -1_000_000]);
        // Not blind: the same trace checked against tighter axes fails.
        let tight = Limits {
            velocity: 10.0,
            ..AXIS
        };
        assert!(verify(&run, &blocks, &[tight; 3], &F).exceeded.is_some());
    }
}
