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
mod fallback;
mod fit;
pub mod position;
mod problem;
pub mod transition;

use serde::Serialize;
use thiserror::Error;

use snapgen_model::chain::ChainState;
use snapgen_model::format::{Format, Quantity, FRAC_BITS};
use snapgen_model::program::Program;

use exact::{Caps, ExactFailure};
use position::Branch;
use problem::{build, Built, Profile, Rounding, Setup};
use transition::{Entry, Shape, TickLimits};

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
#[derive(Clone, Copy, Debug)]
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
    // The raw limit, exact, and as a real (kept, not converted back: a 128-bit conversion is
    // a library call).
    let one = |name, value: f64, q: Quantity| -> Result<(i128, f64), OnlineError> {
        let bad = OnlineError::Limit { name, value };
        if !(value.is_finite() && value > 0.0) {
            return Err(bad);
        }
        let raw = crate::planner::fmath::floor(value * format.scale(q));
        let cap = Format::register_max(format.width(q));
        if raw < 1.0 {
            return Err(bad);
        }
        Ok(if raw >= cap as f64 {
            (cap, cap as f64)
        } else {
            (raw as i128, raw)
        })
    };
    let v = one("velocity", l.velocity, Quantity::Velocity)?;
    let acc = one("acceleration", l.acceleration, Quantity::Acceleration)?;
    let dec = one("deceleration", l.deceleration, Quantity::Acceleration)?;
    let j = match order {
        OnlineOrder::Three => one("jerk", l.jerk, Quantity::Jerk)?,
        OnlineOrder::Two => (i128::MAX, i128::MAX as f64),
    };
    Ok(RawLimits {
        v: v.0,
        acc: acc.0,
        dec: dec.0,
        j: j.0,
        tick: TickLimits {
            v: v.1,
            acc: acc.1,
            dec: dec.1,
            j: j.1,
        },
    })
}

/// Plans from `start` to `target` (module documentation). The result is exact: the final
/// state is `(target velocity, 0, 0)` bit for bit, a position target's output cell is the
/// target cell, and from a state within the limits no limit is exceeded on any tick.
///
/// The plan is the time-optimal profile's, realised on whole ticks ([`exact`]); where that
/// cannot be made exact within the limits (a refusal, rare: docs/MODEL.md §11), a target at
/// rest or a velocity is reached by braking to rest exactly and moving on from there
/// ([`fallback`]; [`Branch::Stop`]). Only a blend point is then refused.
pub fn plan_online(
    start: &ChainState,
    target: &OnlineTarget,
    limits: &OnlineLimits,
    order: OnlineOrder,
    format: &Format,
) -> Result<OnlinePlan, OnlineError> {
    let setup = setup(start, target, limits, order, format)?;
    match attempts(&setup, format) {
        Err(OnlineError::NotRealisable(why)) => {
            fallback::stop_and_go(&setup, limits, order, format).map_err(|e| match e {
                OnlineError::NotRealisable(_) => OnlineError::NotRealisable(why),
                e => e,
            })
        }
        r => r,
    }
}

/// Checks the request and prepares what every attempt shares: the raw limits, the end
/// velocity, the caps (the limits, or a start's inevitable excursion beyond them) and, for a
/// position target, the goal and the direction.
fn setup<'a>(
    start: &'a ChainState,
    target: &OnlineTarget,
    limits: &OnlineLimits,
    order: OnlineOrder,
    format: &Format,
) -> Result<Setup<'a>, OnlineError> {
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
    // The continuous profile the chain plays from here (problem::Continuous): its speed once
    // the ticks already decided have played, and the speed braking its acceleration at full
    // jerk reaches (seed 002 eq 32).
    let cont = problem::Continuous::of(start, o);
    let (v0, a0) = (cont.v, cont.a);
    let vi = if o == 2 {
        v0
    } else {
        transition::intermediate_speed(v0, a0, lim.tick.j)
    };
    let next_a = start.a.saturating_add(start.j);
    // The velocities after the first two ticks, whose accelerations (a, then a + j) are
    // already decided: no program changes them.
    let v1 = start.v.saturating_add(start.a);
    let v2 = v1.saturating_add(next_a);
    // The speed the chain reaches releasing the acceleration at full jerk from the third tick
    // on (order 3): `a₁ − mJ` for m = 1, 2, … while it keeps a₁'s sign, each added to the
    // velocity, `M·a₁ − J·M(M+1)/2` in all (M terms) — the discrete counterpart of v_i.
    let vi_ticks = if o == 3 {
        let a1 = exact::to_f64(next_a);
        let j = lim.tick.j;
        let m = ((a1.abs() / j) - 1e-9).ceil().max(1.0) - 1.0;
        exact::to_f64(v2) + a1.signum() * (m * a1.abs() - j * m * (m + 1.0) / 2.0)
    } else {
        exact::to_f64(v2)
    };
    // A start whose speed is or will be beyond the limit (limits lowered mid-move) is only
    // promised to come back without reversal: its velocity is capped by the register alone.
    let outside = vi.abs() > lim.tick.v
        || vi_ticks.abs() > lim.tick.v
        || start.v.abs() > lim.v
        || v1.saturating_abs() > lim.v
        || v2.saturating_abs() > lim.v;
    let excursion_v = if outside {
        Format::register_max(format.widths.v)
    } else {
        v1.saturating_abs().max(v2.saturating_abs())
    };
    let a_entry = start.a.saturating_abs().max(next_a.saturating_abs());
    let mut caps = Caps {
        v: lim.v.max(excursion_v),
        acc: lim.acc,
        dec: lim.dec,
        entry: 0,
        a: [
            0, // filled per transition
            0,
            lim.acc.max(lim.dec).max(a_entry),
        ],
        j: lim.j.max(start.j.saturating_abs()),
        heading: 0,
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
    // So does a start braking so hard that releasing the brake at full jerk still takes it
    // through zero speed with the acceleration beyond the limit of the other side (where |v|
    // grows: the acceleration limit, often far below the deceleration one): at the crossing
    // `a_z² = a₀² − 2J·|v₀|` (the speed the release loses, `(a₀² − a_z²)/2J`, is |v₀|). No
    // program avoids that excursion.
    if o == 3 && v0 * vi < 0.0 {
        let a_z = (a0 * a0 - 2.0 * lim.tick.j * v0.abs()).max(0.0).sqrt();
        if a_z > lim.tick.acc {
            caps.entry = caps.entry.max(a_entry);
        }
    }
    // And a start whose first two ticks (decided) take it through zero speed with an
    // acceleration beyond the smaller limit (a crossing tick counts as both).
    let crosses = |p: i128, q: i128| p.signum() * q.signum() < 0;
    if (crosses(start.v, v1) || crosses(v1, v2)) && a_entry > lim.acc.min(lim.dec) {
        caps.entry = caps.entry.max(a_entry);
    }
    let goal = match *target {
        OnlineTarget::Velocity(_) => None,
        OnlineTarget::Position { cell, .. } => {
            let centre = cell
                .checked_shl(FRAC_BITS)
                .and_then(|c| c.checked_add(format.half_lsb_raw()))
                .filter(|c| (*c >> FRAC_BITS) == cell)
                .ok_or(OnlineError::Overflow)?;
            // The continuous profile ends one tick of v_end past where the program before
            // the tail ends, and the tail moves the position by 3·v_end (exact::realise).
            let end = v_end
                .checked_mul(2)
                .and_then(|t| centre.checked_sub(t))
                .ok_or(OnlineError::Overflow)?;
            let dist =
                exact::to_f64(end.checked_sub(start.x).ok_or(OnlineError::Overflow)?) - cont.dx;
            let dir = position::direction(o, cont.v, cont.a, dist, v_end as f64, &lim.tick);
            // A start not moving away from the target, nor bound to (its first two ticks are
            // decided, and releasing its acceleration at full jerk reaches `vi_ticks`), is taken
            // there without reversing: an exact program that would dip back is not taken (the
            // next attempt, or stop and go, is).
            let heading = dir as i128;
            if [start.v, v1, v2].iter().all(|v| v.signum() * heading >= 0) && vi_ticks * dir >= 0.0
            {
                caps.heading = heading;
            }
            Some((centre, dist, dir))
        }
    };
    Ok(Setup {
        start,
        target: *target,
        o,
        lim,
        v_end,
        a_entry,
        caps,
        cont,
        goal,
    })
}

/// The attempts of one plan (the ladder [`ATTEMPTS`]), the first exact one.
fn attempts(setup: &Setup, format: &Format) -> Result<OnlinePlan, OnlineError> {
    let (start, lim) = (setup.start, &setup.lim);
    let mut program = Program::empty();
    // Rounding up leaves no slack when a piece lasts a whole number of ticks, and the
    // discrete chain (a rectangle rule) can then ask a level a few parts in 10⁵ above its
    // limit; the exact position moves the cruise speed by what the rounding of every piece
    // added. Each attempt plans with limits lowered by its scale, every piece but the settle
    // lengthened by its extra ticks and its pieces rounded its way; `fit` then gives more
    // ticks to a piece whose level is over its limit, and a cruise over the velocity limit
    // lowers the planning velocity. The checks use the true limits throughout.
    let mut last = ExactFailure::Limit;
    for (scale, extra, rounding, profile) in ATTEMPTS {
        let mut tick = TickLimits {
            v: lim.tick.v * scale,
            acc: lim.tick.acc * scale,
            dec: lim.tick.dec * scale,
            j: lim.tick.j * scale,
        };
        for retarget in 0..=RETARGETS {
            let Some(Built {
                mut problem,
                caps,
                cases,
                continuous,
            }) = build(setup, &tick, extra, rounding, profile)?
            else {
                // No profile in this direction with these planning limits.
                if setup.v_end != 0 && scale == 1.0 && profile == Profile::Optimal {
                    return Err(OnlineError::BlendUnreachable);
                }
                break;
            };
            let lin = match fit::fit(&mut problem, start, &caps) {
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
                Ok(fin) => {
                    return finish(
                        start,
                        &setup.target,
                        format,
                        program,
                        fin,
                        continuous,
                        cases,
                    )
                }
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

/// The attempts [`plan_online`] makes in order: the limits the continuous profile is planned
/// with (a fraction of the true ones), the ticks added to every piece but the settle, and how
/// the pieces are rounded to ticks.
const ATTEMPTS: [(f64, u64, Rounding, Profile); 13] = [
    (1.0, 0, Rounding::Up, Profile::Optimal),
    (1.0, 0, Rounding::Nearest, Profile::Optimal),
    (1.0, 0, Rounding::Up, Profile::Ease),
    (1.0, 0, Rounding::Nearest, Profile::Ease),
    (1.0, 1, Rounding::Up, Profile::Optimal),
    (1.0 - 1e-4, 0, Rounding::Up, Profile::Optimal),
    (1.0 - 1e-4, 1, Rounding::Up, Profile::Optimal),
    (1.0 - 1e-3, 0, Rounding::Up, Profile::Optimal),
    (1.0 - 1e-3, 2, Rounding::Up, Profile::Optimal),
    (0.99, 0, Rounding::Up, Profile::Optimal),
    (0.99, 4, Rounding::Up, Profile::Optimal),
    (0.95, 0, Rounding::Up, Profile::Optimal),
    (0.95, 8, Rounding::Up, Profile::Optimal),
];

/// Plans per scale with a lowered planning velocity when the level solution cruises above the
/// velocity limit.
const RETARGETS: usize = 2;

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
