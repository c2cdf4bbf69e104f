//! Online planning: from any exact chain state to a position at rest (MC_MoveAbsolute), to a
//! set velocity (MC_MoveVelocity, seed 002's set speed) or to a position passed at a given
//! velocity (the end of a move blended into a tangent next move). Orders 3 (jerk-limited, seed
//! 002's case) and 2 (trapezoid), with separate acceleration and deceleration limits.
//!
//! * [`transition`] — seed 002's velocity transitions, one function per order, the seed's cases
//!   named in [`transition::Entry`] and [`transition::Shape`].
//! * [`position`] — transition, cruise, transition: the cruise speed from the distance.
//! * [`exact`] — the exact integer program from an arbitrary start (docs/MODEL.md §11).
//!
//! Order 4 online is not built; [`OnlineOrder`] is where it will go.

pub mod exact;
pub mod position;
pub mod transition;

use serde::Serialize;
use thiserror::Error;

use crate::chain::ChainState;
use crate::format::{Format, Quantity, FRAC_BITS};
use crate::program::Program;

use arrayvec::ArrayVec;
use exact::{Caps, Condition, DPiece, ExactFailure, Problem, MAX_FREE, MAX_PIECES};
use position::{Branch, PositionProfile};
use transition::{Entry, Shape, TickLimits, Transition};

/// Profile order of an online plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum OnlineOrder {
    /// Jerk-limited S-curve (seed 002).
    Three,
    /// Acceleration-limited trapezoid.
    Two,
}

impl OnlineOrder {
    /// 3 or 2.
    pub fn number(self) -> u8 {
        match self {
            OnlineOrder::Three => 3,
            OnlineOrder::Two => 2,
        }
    }
}

/// Limits of an online plan, physical (unit/s, unit/s², unit/s³), all > 0. PLCopen's
/// Acceleration applies while |v| grows, its Deceleration while |v| shrinks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OnlineLimits {
    /// Velocity limit.
    pub velocity: f64,
    /// Acceleration limit (|v| growing).
    pub acceleration: f64,
    /// Deceleration limit (|v| shrinking).
    pub deceleration: f64,
    /// Jerk limit (order 3).
    pub jerk: f64,
}

/// What an online plan ends in.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum OnlineTarget {
    /// At output cell `cell` (absolute output LSBs) with velocity `velocity` (unit/s; 0: at
    /// rest, MC_MoveAbsolute; otherwise the blend velocity, a = j = 0, at the blend tick).
    Position {
        /// Output cell (absolute output LSBs).
        cell: i128,
        /// Velocity there (unit/s).
        velocity: f64,
    },
    /// Holding `velocity` (unit/s) with a = j = 0 (MC_MoveVelocity).
    Velocity(f64),
}

/// Why an online plan was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OnlineError {
    /// A limit that is not a finite positive number, or below one raw LSB.
    #[error("{name} = {value} is invalid: give a finite value > 0 that the format resolves (at least one raw LSB)")]
    Limit {
        /// Limit name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A target velocity beyond the velocity limit or not finite.
    #[error("target velocity {velocity} is beyond the velocity limit {limit}: lower it or raise the limit")]
    Velocity {
        /// Requested.
        velocity: f64,
        /// Limit.
        limit: f64,
    },
    /// A blend point behind the point where the blend velocity can first be reached.
    #[error("the blend velocity cannot be reached before the blend point: move the point further or lower the blend velocity")]
    BlendUnreachable,
    /// The move does not fit the registers or the tick counter.
    #[error("the move does not fit the chain's registers (too long or too fast for this format)")]
    Overflow,
    /// More segments than the program memory holds.
    #[error(
        "the online program needs {count} segments but the format holds {max}: raise max_segments"
    )]
    TooManySegments {
        /// Needed.
        count: usize,
        /// Held.
        max: usize,
    },
    /// The realisation could not be made exact within the limits (a bug: please report the
    /// start state and request).
    #[error("no exact program within the limits was found from this state ({0})")]
    NotRealisable(&'static str),
}

/// The seed 002 cases an online plan went through.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Cases {
    /// The first transition: rises (true) or falls, its entry and shape.
    pub first: (bool, Entry, Shape),
    /// The second transition (position targets).
    pub second: Option<(bool, Entry, Shape)>,
    /// How the cruise speed was chosen (position targets).
    pub branch: Option<Branch>,
}

/// An online plan: the program that takes the chain from `start` to the target exactly.
#[derive(Clone, Debug, PartialEq)]
pub struct OnlinePlan {
    /// Start state (exact registers).
    pub start: ChainState,
    /// The program (snap segments) from `start`.
    pub program: Program,
    /// The exact final state.
    pub final_state: ChainState,
    /// The continuous profile's duration (ticks, real): what rounding to ticks is measured by.
    pub continuous_ticks: f64,
    /// Cases.
    pub cases: Cases,
}

impl OnlinePlan {
    /// Ticks the program lasts.
    pub fn ticks(&self) -> u64 {
        self.program.total_ticks()
    }
}

/// Raw integer limits and their real forms.
struct RawLimits {
    v: i128,
    acc: i128,
    dec: i128,
    j: i128,
    tick: TickLimits,
}

fn raw_limits(
    l: &OnlineLimits,
    order: OnlineOrder,
    format: &Format,
) -> Result<RawLimits, OnlineError> {
    let one = |name, value: f64, q: Quantity| -> Result<i128, OnlineError> {
        let bad = OnlineError::Limit { name, value };
        if !(value.is_finite() && value > 0.0) {
            return Err(bad);
        }
        let raw = crate::planner::fmath::floor(value * format.scale(q));
        let cap = Format::register_max(format.width(q));
        if raw < 1.0 {
            return Err(bad);
        }
        Ok(if raw >= cap as f64 { cap } else { raw as i128 })
    };
    let v = one("velocity", l.velocity, Quantity::Velocity)?;
    let acc = one("acceleration", l.acceleration, Quantity::Acceleration)?;
    let dec = one("deceleration", l.deceleration, Quantity::Acceleration)?;
    let j = match order {
        OnlineOrder::Three => one("jerk", l.jerk, Quantity::Jerk)?,
        OnlineOrder::Two => i128::MAX,
    };
    Ok(RawLimits {
        v,
        acc,
        dec,
        j,
        tick: TickLimits {
            v: v as f64,
            acc: acc as f64,
            dec: dec as f64,
            j: j as f64,
        },
    })
}

/// Ticks of a piece: `t` rounded up (1e-6-tick tolerance, as the other planners), at least
/// `min`.
fn ticks(t: f64, min: u64) -> u64 {
    (crate::planner::ceil_ticks(t)).max(min)
}

/// Appends the discrete pieces of a transition: jerk pieces free (order 3), the hold fixed at
/// zero jerk; order 2: its acceleration piece free.
fn push_transition(
    pieces: &mut ArrayVec<DPiece, MAX_PIECES>,
    guess: &mut [f64; MAX_FREE],
    free: &mut usize,
    t: &Transition,
    order: u8,
    cap: usize,
) {
    for (i, p) in t.pieces().iter().enumerate() {
        let is_hold = order == 3 && i == 1;
        if is_hold {
            let n = ticks(p.t, 0);
            if n > 0 {
                pieces.push(DPiece {
                    ticks: n,
                    free: None,
                    cap,
                    slack: true,
                });
            }
        } else {
            guess[*free] = p.level;
            pieces.push(DPiece {
                ticks: ticks(p.t, 1),
                free: Some(*free),
                cap,
                slack: false,
            });
            *free += 1;
        }
    }
}

/// Plans from `start` to `target` (module documentation). The result is exact: the final
/// state is `(target velocity, 0, 0)` bit for bit, a position target's output cell is the
/// target cell, and from a state within the limits no limit is exceeded on any tick.
pub fn plan_online(
    start: &ChainState,
    target: &OnlineTarget,
    limits: &OnlineLimits,
    order: OnlineOrder,
    format: &Format,
) -> Result<OnlinePlan, OnlineError> {
    let lim = raw_limits(limits, order, format)?;
    let o = order.number();
    let v_target = match *target {
        OnlineTarget::Position { velocity, .. } | OnlineTarget::Velocity(velocity) => velocity,
    };
    let v_raw_f = crate::planner::fmath::round(v_target * format.scale(Quantity::Velocity));
    if !v_raw_f.is_finite() || v_raw_f.abs() > lim.v as f64 {
        return Err(OnlineError::Velocity {
            velocity: v_target,
            limit: limits.velocity,
        });
    }
    let v_end = v_raw_f as i128;
    let (v0, a0) = (start.v as f64, if o == 2 { 0.0 } else { start.a as f64 });
    // Caps: the limits, or the start's inevitable excursion beyond them.
    let vi = if o == 2 {
        v0
    } else {
        transition::intermediate_speed(v0, a0, lim.tick.j)
    };
    let next_a = start.a.saturating_add(start.j);
    // A start whose speed is or will be beyond the limit (limits lowered mid-move) is only
    // promised to come back without reversal: its velocity is capped by the register alone.
    let outside = vi.abs() > lim.tick.v || start.v.abs() > lim.v;
    let excursion_v = if outside {
        Format::register_max(format.widths.v)
    } else {
        start.v.saturating_add(start.a).saturating_abs()
    };
    let a_entry = start.a.saturating_abs().max(next_a.saturating_abs());
    let mut caps = Caps {
        v: lim.v.max(excursion_v),
        acc: lim.acc,
        dec: lim.dec,
        entry: 0,
        a: [
            0, // filled per transition below
            0,
            lim.acc.max(lim.dec).max(a_entry),
        ],
        j: lim.j.max(start.j.saturating_abs()),
    };
    // A start whose acceleration is beyond the limit of its direction keeps it while its first
    // transition brings it back.
    let a_range = (start.a.min(next_a), start.a.max(next_a));
    if a_entry
        > caps.a_cap(
            (start.v, start.v),
            a_range,
            start.v.saturating_add(start.a),
            1,
        )
    {
        caps.entry = a_entry;
    }
    let mut program = Program::empty();
    // Rounding up leaves no slack when a piece lasts a whole number of ticks, and the
    // discrete chain (a rectangle rule) can then ask a level a few parts in 10⁵ above its
    // limit; the exact position moves the cruise speed by what the rounding of every piece
    // added. Each (scale, extra ticks) pair plans with limits lowered by the scale and every
    // piece but the settle lengthened; `fit` then gives more ticks to a piece whose level is
    // over its limit, and a cruise over the velocity limit lowers the planning velocity.
    // The checks use the true limits throughout.
    let mut last = ExactFailure::Limit;
    for (scale, extra) in PLANNING_SCALES {
        let mut tick = TickLimits {
            v: lim.tick.v * scale,
            acc: lim.tick.acc * scale,
            dec: lim.tick.dec * scale,
            j: lim.tick.j * scale,
        };
        for retarget in 0..=RETARGETS {
            let (mut problem, caps, cases, continuous) = build(
                start, target, o, &lim, &tick, v_end, a_entry, caps, extra, format,
            )?;
            let lin = match fit(&mut problem, start, &caps) {
                Ok(lin) => lin,
                Err(ExactFailure::Overflow) => return Err(OnlineError::Overflow),
                Err(e) => {
                    last = e;
                    break;
                }
            };
            if let Some(vc) = lin.cruise_v {
                let over = vc.abs() - caps.v as f64;
                let lowered = tick.v - 2.0 * over - 1.0;
                if over > 0.0 && retarget < RETARGETS && lowered > 0.5 * tick.v {
                    tick.v = lowered;
                    continue;
                }
            }
            match exact::realise(&problem, start, &caps, &lin, &mut program) {
                Ok(fin) => return finish(start, target, format, program, fin, continuous, cases),
                Err(ExactFailure::Overflow) => return Err(OnlineError::Overflow),
                Err(e) => {
                    last = e;
                    break;
                }
            }
        }
    }
    Err(map(last))
}

/// The (planning scale, extra ticks) pairs [`plan_online`] tries in order: the limits the
/// continuous profile is planned with (a fraction of the true ones) and the ticks added to
/// every piece but the settle.
const PLANNING_SCALES: [(f64, u64); 10] = [
    (1.0, 0),
    (1.0, 1),
    (1.0 - 1e-4, 0),
    (1.0 - 1e-4, 1),
    (1.0 - 1e-3, 0),
    (1.0 - 1e-3, 2),
    (0.99, 0),
    (0.99, 4),
    (0.95, 0),
    (0.95, 8),
];

/// Plans per scale with a lowered planning velocity when the level solution cruises above the
/// velocity limit.
const RETARGETS: usize = 2;

/// Rounds of [`fit`].
const FIT_ROUNDS: usize = 8;

/// Ticks [`fit`] may add to a plan beyond those it takes from holds and the cruise.
const FIT_GROWTH: u64 = 24;

/// Fits the tick counts to the levels (docs/MODEL.md §11, "Fitting the ticks to the levels"),
/// on the real solution of the level equations:
///
/// * a free piece whose level exceeds its limit by a ratio `r` (order 3: the jerk; order 2:
///   the acceleration) is lengthened by `n·(√r − 1) + 1` ticks (order 3: a jerk piece's
///   velocity change grows with `n²`) or `n·(r − 1) + 1` (order 2);
/// * a hold (order 3) whose acceleration exceeds its limit by `r` is lengthened by
///   `(n + m)·(r − 1) + 1`, `m` the ticks of the jerk pieces beside it (its velocity change
///   grows with `n + m`);
///
/// the ticks taken (a jerk piece) from the hold beside it, else from the cruise where there
/// is one, and the levels solved again. Ticks nobody lends lengthen the plan, at most
/// [`FIT_GROWTH`] in all. Returns the real solution of the last solve (the limits are checked
/// on the integers afterwards).
fn fit(p: &mut Problem, start: &ChainState, caps: &Caps) -> Result<exact::Linear, ExactFailure> {
    let mut grown = 0u64;
    let mut lin = exact::linearise(p, start)?;
    for _ in 0..FIT_ROUNDS {
        let mut changed = false;
        for i in 0..p.pieces.len() {
            let d = p.pieces[i];
            let is_hold = |j: usize| {
                j < p.pieces.len() && {
                    let h = &p.pieces[j];
                    h.slack && h.free.is_none() && h.cap == d.cap && Some(j) != p.cruise
                }
            };
            let jerk_ticks = |j: usize| {
                p.pieces
                    .get(j)
                    .filter(|q| q.free.is_some())
                    .map_or(0, |q| q.ticks)
            };
            // The planned sign of a piece's level or acceleration: the guess of its level, or
            // (a hold) of the jerk piece before it. The other sign gets the smaller limit.
            let limit = |value: f64, planned: f64| {
                if value.signum() != planned.signum() {
                    caps.acc.min(caps.dec) as f64
                } else {
                    caps.a[d.cap] as f64
                }
            };
            let grow = match d.free {
                Some(k) => {
                    let level = lin.levels[k];
                    let ratio = if p.order == 3 {
                        level.abs() / caps.j as f64
                    } else {
                        level.abs() / limit(level, p.guess[k])
                    };
                    if !ratio.is_finite() {
                        return Err(ExactFailure::Overflow);
                    }
                    if ratio <= 1.0 - 1e-9 {
                        continue;
                    }
                    let factor = if p.order == 3 { ratio.sqrt() } else { ratio };
                    (d.ticks as f64 * (factor - 1.0)).ceil().min(1e12) as u64 + 1
                }
                None if p.order == 3 && is_hold(i) && i > 0 => {
                    let a = lin.piece_a[i];
                    let planned = p.pieces[i - 1].free.map_or(a, |k| p.guess[k]);
                    let ratio = a.abs() / limit(a, planned);
                    if !ratio.is_finite() {
                        return Err(ExactFailure::Overflow);
                    }
                    if ratio <= 1.0 - 1e-9 {
                        continue;
                    }
                    let span = d.ticks + jerk_ticks(i - 1) + jerk_ticks(i + 1);
                    (span as f64 * (ratio - 1.0)).ceil().min(1e12) as u64 + 1
                }
                None => continue,
            };
            let hold_beside = [i + 1, i.wrapping_sub(1)].into_iter().find(|&j| is_hold(j));
            p.pieces[i].ticks += grow;
            let donor = if d.free.is_some() {
                hold_beside.or(p.cruise)
            } else {
                p.cruise
            };
            let lent = donor.map_or(0, |j| {
                let t = grow.min(p.pieces[j].ticks.saturating_sub(1));
                p.pieces[j].ticks -= t;
                t
            });
            grown += grow - lent;
            if grown > FIT_GROWTH {
                return Err(ExactFailure::Limit);
            }
            changed = true;
        }
        if !changed {
            return Ok(lin);
        }
        lin = exact::linearise(p, start)?;
    }
    Ok(lin)
}

/// The discrete problem for planning limits `tick` (true limits in `lim`), every piece but
/// the settle lengthened by `extra` ticks; with its caps, cases and continuous duration.
#[allow(clippy::too_many_arguments)]
fn build(
    start: &ChainState,
    target: &OnlineTarget,
    o: u8,
    lim: &RawLimits,
    tick: &TickLimits,
    v_end: i128,
    a_entry: i128,
    caps: Caps,
    extra: u64,
    format: &Format,
) -> Result<(Problem, Caps, Cases, f64), OnlineError> {
    let (v0, a0) = (start.v as f64, if o == 2 { 0.0 } else { start.a as f64 });
    let raw_of = |a: f64| {
        if a == tick.acc {
            lim.acc
        } else {
            lim.dec
        }
    };
    let mut guess = [0.0; MAX_FREE];
    let mut free = 0;
    let mut pieces = ArrayVec::new();
    let mut conditions = ArrayVec::new();
    let mut cruise = None;
    let (cases, continuous, x_centre, rise, caps) = match *target {
        OnlineTarget::Velocity(_) => {
            let t = transition::velocity(o, v0, a0, v_end as f64, tick);
            push_transition(&mut pieces, &mut guess, &mut free, &t, o, 0);
            let caps = Caps {
                a: [raw_of(t.accel_limit).max(a_entry), 0, caps.a[2]],
                ..caps
            };
            (
                Cases {
                    first: (t.rise, t.entry, t.shape),
                    second: None,
                    branch: None,
                },
                t.duration(),
                0,
                t.rise,
                caps,
            )
        }
        OnlineTarget::Position { cell, .. } => {
            let centre = cell
                .checked_shl(FRAC_BITS)
                .and_then(|c| c.checked_add(format.half_lsb_raw()))
                .filter(|c| (*c >> FRAC_BITS) == cell)
                .ok_or(OnlineError::Overflow)?;
            let goal = centre
                .checked_sub(v_end.checked_mul(3).ok_or(OnlineError::Overflow)?)
                .ok_or(OnlineError::Overflow)?;
            let dist = goal.checked_sub(start.x).ok_or(OnlineError::Overflow)? as f64;
            let prof: PositionProfile = position::plan(o, v0, a0, dist, v_end as f64, tick)
                .ok_or(OnlineError::BlendUnreachable)?;
            push_transition(&mut pieces, &mut guess, &mut free, &prof.first, o, 0);
            cruise = Some(pieces.len());
            pieces.push(DPiece {
                ticks: ticks(prof.cruise, 1),
                free: None,
                cap: 2,
                slack: true,
            });
            if o == 3 {
                conditions.push(Condition::A(pieces.len() - 1));
            }
            push_transition(&mut pieces, &mut guess, &mut free, &prof.second, o, 1);
            let caps = Caps {
                a: [
                    raw_of(prof.first.accel_limit).max(a_entry),
                    raw_of(prof.second.accel_limit),
                    caps.a[2],
                ],
                ..caps
            };
            (
                Cases {
                    first: (prof.first.rise, prof.first.entry, prof.first.shape),
                    second: Some((prof.second.rise, prof.second.entry, prof.second.shape)),
                    branch: Some(prof.branch),
                },
                prof.duration(),
                centre,
                prof.second.rise,
                caps,
            )
        }
    };
    // The settle piece: the highest derivative back to zero (order 2 needs two ticks: the
    // acceleration step and the jerk back to zero).
    pieces.push(DPiece {
        ticks: if o == 2 { 2 } else { 1 },
        free: None,
        cap: 2,
        slack: false,
    });
    if o == 3 {
        conditions.push(Condition::A(pieces.len() - 1));
    }
    conditions.push(Condition::V);
    if matches!(target, OnlineTarget::Position { .. }) {
        conditions.push(Condition::X);
    }
    debug_assert_eq!(conditions.len(), free);
    let settle = pieces.len() - 1;
    for d in &mut pieces[..settle] {
        d.ticks += extra;
    }
    // The tick counter and the closed form's binomials bound a piece (2^40 ticks is 127 days
    // at 10 µs): longer is refused, never wrapped.
    if pieces.iter().any(|d| d.ticks >= 1 << 40) {
        return Err(OnlineError::Overflow);
    }
    let problem = Problem {
        order: o,
        pieces,
        free,
        conditions,
        v_end,
        approach: if rise { 1 } else { -1 },
        x_centre,
        guess,
        cruise,
    };
    Ok((problem, caps, cases, continuous))
}

fn map(e: ExactFailure) -> OnlineError {
    match e {
        ExactFailure::Overflow => OnlineError::Overflow,
        ExactFailure::Singular => OnlineError::NotRealisable("singular level equations"),
        ExactFailure::Limit => OnlineError::NotRealisable("a limit would be exceeded"),
    }
}

fn finish(
    start: &ChainState,
    target: &OnlineTarget,
    format: &Format,
    program: Program,
    fin: ChainState,
    continuous: f64,
    cases: Cases,
) -> Result<OnlinePlan, OnlineError> {
    if program.segments.len() > format.max_segments {
        return Err(OnlineError::TooManySegments {
            count: program.segments.len(),
            max: format.max_segments,
        });
    }
    if let OnlineTarget::Position { cell, .. } = *target {
        if format.output_lsb(fin.x) != cell {
            return Err(OnlineError::NotRealisable("the position missed its cell"));
        }
    }
    Ok(OnlinePlan {
        start: *start,
        program,
        final_state: fin,
        continuous_ticks: continuous,
        cases,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plans from seeded random states (the realisation cross-checks its piece-level limit
    /// check with the segment-level one on every plan, `exact::tests::cross_check`).
    #[test]
    fn the_piece_level_check_agrees_with_the_segment_level_one() {
        let f = Format::default();
        // A small deterministic generator (no dependency): xorshift64*.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut unit = move || {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut made = 0;
        for i in 0..3000 {
            let lu = |u: f64, lo: f64, hi: f64| lo * (hi / lo).powf(u);
            let l = OnlineLimits {
                velocity: lu(unit(), 0.01, 1.0),
                acceleration: lu(unit(), 0.1, 10.0),
                deceleration: lu(unit(), 0.1, 10.0),
                jerk: lu(unit(), 1.0, 1000.0),
            };
            let order = if i % 3 == 2 {
                OnlineOrder::Two
            } else {
                OnlineOrder::Three
            };
            let scale = |q| f.scale(q);
            let start = ChainState {
                x: f.home_raw(),
                v: ((unit() * 2.0 - 1.0) * l.velocity * scale(Quantity::Velocity)) as i128,
                a: if order == OnlineOrder::Two {
                    0
                } else {
                    ((unit() * 1.8 - 0.9)
                        * l.acceleration.min(l.deceleration)
                        * scale(Quantity::Acceleration)) as i128
                },
                j: 0,
            };
            let cell = ((unit() * 2.0 - 1.0) * 3e5) as i128;
            let target = if i % 4 == 0 {
                OnlineTarget::Velocity((unit() * 2.0 - 1.0) * l.velocity)
            } else {
                OnlineTarget::Position {
                    cell,
                    velocity: 0.0,
                }
            };
            made += usize::from(plan_online(&start, &target, &l, order, &f).is_ok());
        }
        assert!(made > 2900, "{made} of 3000 planned");
    }
}
