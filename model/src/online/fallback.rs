//! What a plan falls back on when the time-optimal profile cannot be realised exactly within
//! the limits ([`super::OnlineError::NotRealisable`], docs/MODEL.md §11): brake to rest
//! exactly, then move on from rest — to the target cell with the rest-to-rest planner
//! (exact by its scaled unit program, docs/MODEL.md §5) or to the set velocity with a
//! transition from rest. Both parts are exact and within the limits, so a target at rest or a
//! velocity is always reached; the cost is the time of stopping on the way
//! ([`super::position::Branch::Stop`]). A blend point is not: it is refused.

use crate::chain::ChainState;
use crate::error::PlanError;
use crate::format::Format;
use crate::planner::{plan_from, Method, MoveRequest};
use crate::program::Program;

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
