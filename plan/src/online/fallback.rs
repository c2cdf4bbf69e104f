//! What a plan falls back on when the time-optimal profile cannot be realised exactly within
//! the limits ([`super::OnlineError::NotRealisable`], docs/MODEL.md §11): brake to rest
//! exactly, then move on from rest — to the target cell with the rest-to-rest planner
//! (exact by its scaled unit program, docs/MODEL.md §5) or to the set velocity with a
//! transition from rest. Both parts are exact and within the limits, so a target at rest or a
//! velocity is always reached; the cost is the time of stopping on the way
//! ([`super::position::Branch::Stop`]). A blend point is not: it is refused.

use crate::error::PlanError;
use crate::planner::{plan_from, Method, MoveRequest};
use snapgen_model::chain::ChainState;
use snapgen_model::format::Format;
use snapgen_model::program::Program;

use super::position::Branch;
use super::problem::Setup;
use super::{
    attempts, setup, Cases, OnlineError, OnlineLimits, OnlineOrder, OnlinePlan, OnlineTarget,
};

/// Brakes to rest and moves on from there (module documentation).
pub(super) fn stop_and_go(
    plan: &Setup,
    limits: &OnlineLimits,
    order: OnlineOrder,
    format: &Format,
) -> Result<OnlinePlan, OnlineError> {
    let refused = OnlineError::NotRealisable("no exact program within the limits");
    if plan.goal.is_some() && plan.v_end != 0 {
        return Err(refused);
    }
    let start = plan.start;
    let brake = attempts(
        &setup(start, &OnlineTarget::Velocity(0.0), limits, order, format)?,
        format,
    )?;
    let rest = brake.final_state;
    let (next, next_cases, next_continuous, final_state) = match plan.target {
        OnlineTarget::Position { cell, .. } => {
            let here = format.output_lsb(rest.x);
            if here == cell {
                (Program::empty(), None, 0.0, rest)
            } else {
                let method = match order {
                    OnlineOrder::Three => Method::Order3 {
                        vmax: limits.velocity,
                        amax: limits.acceleration.min(limits.deceleration),
                        jmax: limits.jerk,
                    },
                    OnlineOrder::Two => Method::Order2 {
                        vmax: limits.velocity,
                        amax: limits.acceleration.min(limits.deceleration),
                    },
                };
                let request = MoveRequest {
                    distance: (cell - here) as f64 * format.position_lsb,
                    method,
                };
                let p = plan_from(&request, format, rest).map_err(|e| match e {
                    PlanError::DistanceOutOfRange { .. } => OnlineError::Overflow,
                    _ => refused.clone(),
                })?;
                if p.final_state != ChainState::at_rest(p.final_state.x)
                    || format.output_lsb(p.final_state.x) != cell
                {
                    return Err(refused);
                }
                let ticks = p.program.total_ticks() as f64;
                (p.program, None, ticks, p.final_state)
            }
        }
        OnlineTarget::Velocity(_) => {
            let from_rest = ChainState::at_rest(rest.x);
            let p = attempts(
                &setup(&from_rest, &plan.target, limits, order, format)?,
                format,
            )?;
            (
                p.program,
                Some(p.cases.first),
                p.continuous_ticks,
                p.final_state,
            )
        }
    };
    let mut program = brake.program;
    program.segments.extend_from_slice(&next.segments);
    if program.segments.len() > format.max_segments {
        return Err(OnlineError::TooManySegments {
            count: program.segments.len(),
            max: format.max_segments,
        });
    }
    Ok(OnlinePlan {
        start: *start,
        program,
        final_state,
        continuous_ticks: brake.continuous_ticks + next_continuous,
        cases: Cases {
            first: brake.cases.first,
            second: next_cases,
            branch: Some(Branch::Stop),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_model::format::{Quantity, Widths};

    /// Steps `program` from `s` tick by tick; the end, and whether every tick kept the
    /// velocity, acceleration (while |v| grows) or deceleration (while it shrinks) and (order 3)
    /// jerk limits.
    fn step(
        s: ChainState,
        program: &Program,
        l: &OnlineLimits,
        order: OnlineOrder,
        f: &Format,
    ) -> (ChainState, bool) {
        let w = Widths {
            x: 127,
            v: 127,
            a: 127,
            j: 127,
            d: 127,
        };
        let raw = |x: f64, q| (x * f.scale(q)).floor() as i128;
        let (vm, am, dm, jm) = (
            raw(l.velocity, Quantity::Velocity),
            raw(l.acceleration, Quantity::Acceleration),
            raw(l.deceleration, Quantity::Acceleration),
            raw(l.jerk, Quantity::Jerk),
        );
        let mut s = s;
        let mut within = true;
        for seg in &program.segments {
            for k in 0..seg.ticks {
                s = s.step(if k == 0 { seg.snap } else { 0 }, &w);
                let next = s.v + s.a;
                let grows = next.abs() > s.v.abs() || next.signum() * s.v.signum() < 0;
                let shrinks = next.abs() < s.v.abs() || next.signum() * s.v.signum() < 0;
                within &= s.v.abs() <= vm
                    && (order == OnlineOrder::Two || s.j.abs() <= jm)
                    && !(grows && s.a.abs() > am)
                    && !(shrinks && s.a.abs() > dm);
            }
        }
        (s, within)
    }

    /// Braking to rest and moving on lands exactly, within the limits, from moving states
    /// and to a target ahead, behind or where the brake ends, and to a velocity.
    #[test]
    fn stop_and_go_is_exact_and_within_the_limits() {
        let f = Format::default();
        let l = OnlineLimits {
            velocity: 0.5,
            acceleration: 2.0,
            deceleration: 1.5,
            jerk: 20.0,
        };
        let start = ChainState {
            x: f.home_raw(),
            v: (0.4 * f.scale(Quantity::Velocity)) as i128,
            a: (-0.8 * f.scale(Quantity::Acceleration)) as i128,
            j: 0,
        };
        for order in [OnlineOrder::Three, OnlineOrder::Two] {
            let start = if order == OnlineOrder::Two {
                ChainState { a: 0, ..start }
            } else {
                start
            };
            for target in [
                OnlineTarget::Position {
                    cell: 300_000,
                    velocity: 0.0,
                },
                OnlineTarget::Position {
                    cell: -20_000,
                    velocity: 0.0,
                },
                OnlineTarget::Velocity(-0.3),
            ] {
                let s = setup(&start, &target, &l, order, &f).expect("valid");
                let p = stop_and_go(&s, &l, order, &f).expect("plans");
                assert_eq!(p.cases.branch, Some(Branch::Stop));
                let (end, within) = step(start, &p.program, &l, order, &f);
                assert_eq!(end, p.final_state, "{order:?} {target:?}");
                assert!(within, "{order:?} {target:?}: a limit exceeded");
                match target {
                    OnlineTarget::Position { cell, .. } => {
                        assert!(end.is_at_rest());
                        assert_eq!(f.output_lsb(end.x), cell);
                    }
                    OnlineTarget::Velocity(v) => {
                        let raw = (v * f.scale(Quantity::Velocity)).round() as i128;
                        assert_eq!((end.v, end.a, end.j), (raw, 0, 0));
                    }
                }
            }
            // Where the brake ends: nothing more than the brake.
            let brake = attempts(
                &setup(&start, &OnlineTarget::Velocity(0.0), &l, order, &f).expect("valid"),
                &f,
            )
            .expect("brakes");
            let cell = f.output_lsb(brake.final_state.x);
            let target = OnlineTarget::Position {
                cell,
                velocity: 0.0,
            };
            let p = stop_and_go(
                &setup(&start, &target, &l, order, &f).expect("valid"),
                &l,
                order,
                &f,
            )
            .expect("plans");
            assert_eq!(p.program, brake.program);
        }
        // A blend point is refused.
        let target = OnlineTarget::Position {
            cell: 300_000,
            velocity: 0.2,
        };
        let s = setup(&start, &target, &l, OnlineOrder::Three, &f).expect("valid");
        assert!(matches!(
            stop_and_go(&s, &l, OnlineOrder::Three, &f),
            Err(OnlineError::NotRealisable(_))
        ));
    }
}
