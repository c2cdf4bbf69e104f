//! Moves played on the lockstep core through its own ports, one clock a request, as the
//! core-level tests of the sequencer, the stop unit and the program swap: a move planned from
//! the model's exact state, uploaded into the standby bank, started and played to its end;
//! or aborted at a random clock; or given a controlled stop (a second request ignored, an
//! abort on the way); or replanned — a chain of program swaps at random ticks, each planned
//! online from the state the model predicts for its tick, some of them late (the core must
//! change nothing) or cancelled by a stop. These drive the core's swap and stop inputs
//! directly, below the executor's rules, to reach edge cases a host never sends (a swap one
//! tick late, a stop on the arming edge); the host's own path to the core is the streams'
//! ([`super::streams`]).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_model::{ChainState, CoreInputs, Format, Program, Segment};
use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_plan::plan_from;

use super::lockstep::{Lockstep, ModelSide, BATCH};
use super::{kind_of, CosimReport, Mismatch};
use crate::moves::{log_uniform, MoveSpec};

/// Longest move the stream keeps, in ticks (keeps CI runs bounded).
const MAX_MOVE_TICKS: u64 = 400_000;
/// A controlled stop still running this many clocks after its request is aborted (each stop
/// tick waits for the stop unit's decision, so a long stop costs many clocks).
pub(super) const MAX_STOP_CLOCKS: u64 = 600_000;

/// The core's inputs between requests: nothing asked, ticking every `tick_div + 1` clocks.
pub(super) fn idle(spec: &MoveSpec) -> CoreInputs {
    CoreInputs {
        tick_div: spec.tick_div,
        ..Default::default()
    }
}

/// At rest, the reference takes the position `to` (POWER 1's load of an encoder count).
pub(super) fn load(ls: &mut Lockstep, spec: &MoveSpec, to: u32) -> Result<(), Mismatch> {
    let idle = idle(spec);
    ls.drive(
        &CoreInputs {
            load: true,
            load_position: to,
            ..idle
        },
        1,
    )?;
    ls.drive(&idle, 1)
}

/// Plays `spec` from the model's state (see the module documentation): false when the
/// planner refused it or it is longer than [`MAX_MOVE_TICKS`] (skipped, nothing driven).
pub(super) fn play(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    report: &mut CosimReport,
) -> Result<bool, Mismatch> {
    let f = Format::with_ts(spec.ts);
    let plan = match plan_from(&spec.request, &f, ls.side.model.chain()) {
        Ok(p) if p.ticks_total() <= MAX_MOVE_TICKS => p,
        _ => return Ok(false),
    };
    let idle = idle(spec);
    upload(ls, &plan.program, &idle)?;
    ls.drive(
        &CoreInputs {
            start: true,
            ..idle
        },
        1,
    )?;
    // One clock for the start to pass the input register (both sides).
    ls.drive(&idle, 1)?;
    let per_tick = u64::from(spec.tick_div) + 1;
    let budget = (plan.ticks_total() + 2) * per_tick + 2;
    if let Some(after) = spec.abort_after {
        ls.drive(&idle, after.min(budget))?;
        ls.drive(
            &CoreInputs {
                abort_move: true,
                ..idle
            },
            1,
        )?;
        report.aborted += 1;
    } else if let Some(after) = spec.stop_after {
        ls.drive(&idle, after.min(budget))?;
        controlled_stop(
            ls,
            spec,
            &idle,
            spec.stop_again_after,
            spec.abort_stop_after,
            report,
        )?;
    } else if spec.replans > 0 {
        replan_chain(
            ls,
            spec,
            plan.ticks_total(),
            plan.final_state,
            &idle,
            report,
        )?;
    } else {
        run_out(ls, &idle, budget)?;
        // The clock-accurate model must land where the planner said.
        if ls.side.model.chain() != plan.final_state {
            report.planner_disagreements += 1;
        }
    }
    Ok(true)
}

/// Idle clocks while the program plays, `budget` at most.
fn run_out(ls: &mut Lockstep, idle: &CoreInputs, budget: u64) -> Result<(), Mismatch> {
    let mut left = budget;
    while ls.side.model.busy() && left > 0 {
        let k = left.min(BATCH);
        ls.drive(idle, k)?;
        left -= k;
    }
    Ok(())
}

/// A controlled stop with the move's stop limits, run to its end: a second request (ignored)
/// `again` clocks after the first and an abort `abort` clocks after it when set, and an abort
/// if it runs past [`MAX_STOP_CLOCKS`].
fn controlled_stop(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    idle: &CoreInputs,
    mut again: Option<u64>,
    abort: Option<u64>,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let stop = CoreInputs {
        stop: true,
        stop_jerk: spec.stop_limits.jerk,
        stop_accel: spec.stop_limits.accel,
        ..*idle
    };
    ls.drive(&stop, 1)?;
    report.stopped += 1;
    let mut clocks = 1u64;
    while ls.side.model.stopping() || ls.side.pending.stop {
        let next = [again, abort, Some(MAX_STOP_CLOCKS)]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(MAX_STOP_CLOCKS);
        if clocks < next {
            let k = (next - clocks).min(BATCH);
            ls.drive(idle, k)?;
            clocks += k;
            continue;
        }
        if again == Some(clocks) {
            ls.drive(&stop, 1)?;
            again = None;
        } else {
            ls.drive(
                &CoreInputs {
                    abort_move: true,
                    ..*idle
                },
                1,
            )?;
            if abort == Some(clocks) {
                report.stops_aborted += 1;
            } else {
                report.stops_timed_out += 1;
            }
            // Past the abort (and the input register): nothing runs any more.
            ls.drive(idle, 1)?;
            break;
        }
        clocks += 1;
    }
    let o = ls.side.model.outputs();
    if o.stop_over {
        report.stops_over += 1;
    }
    // Wherever the stop began, the chain ends at rest (unless it was aborted, which also
    // leaves it at rest).
    if !ls.side.model.chain().is_at_rest() {
        report.stops_not_at_rest += 1;
    }
    Ok(())
}

/// The chain's registers when the time base reaches `at` with nothing else asked of the core:
/// what a host knows from the model before it plans a swap for that tick.
fn state_at(side: &ModelSide, idle: &CoreInputs, at: u64) -> ChainState {
    let mut m = side.model.clone();
    m.edge(&side.pending);
    while m.outputs().ticks < at {
        m.edge(idle);
    }
    m.chain()
}

/// Writes `program` into the standby bank and commits it, one clock a segment.
fn upload(ls: &mut Lockstep, program: &Program, idle: &CoreInputs) -> Result<(), Mismatch> {
    for (k, s) in program.segments.iter().enumerate() {
        ls.drive(
            &CoreInputs {
                write_enable: true,
                write_address: k as u8,
                write_ticks: s.ticks,
                write_snap: s.snap,
                ..*idle
            },
            1,
        )?;
    }
    ls.drive(
        &CoreInputs {
            count_enable: true,
            count_value: program.segments.len() as u8,
            ..*idle
        },
        1,
    )
}

/// Drives idle clocks until the model's time base reaches `at` (or `budget` clocks pass).
fn drive_until_tick(
    ls: &mut Lockstep,
    idle: &CoreInputs,
    at: u64,
    budget: u64,
) -> Result<(), Mismatch> {
    let mut left = budget;
    while ls.side.model.outputs().ticks < at && left > 0 {
        let per_tick = u64::from(idle.tick_div) + 1;
        let k = ((at - ls.side.model.outputs().ticks) * per_tick)
            .min(BATCH)
            .min(left);
        ls.drive(idle, k)?;
        left -= k;
    }
    Ok(())
}

/// Online limits drawn log-uniformly (unit/s, /s², /s³): each the active one in some replans,
/// some far below the state a replan starts from.
fn random_limits(rng: &mut StdRng) -> OnlineLimits {
    OnlineLimits {
        velocity: log_uniform(rng, 0.02, 10.0),
        acceleration: log_uniform(rng, 1.0, 1000.0),
        deceleration: log_uniform(rng, 1.0, 1000.0),
        jerk: log_uniform(rng, 50.0, 2e5),
    }
}

/// The move's replans: `spec.replans` program swaps at random ticks (mid-jerk, mid-acceleration,
/// at cruise, after the end), each planned online from the state the model predicts for its
/// tick to a position at rest, a set velocity or a blend point (the last to a position at
/// rest), uploaded while the current program plays and armed for that tick; now and then a
/// late swap (it must change nothing) or a stop while one is armed (it cancels it). At the end
/// the chain must stand where the last plan said.
fn replan_chain(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    first_ticks: u64,
    first_final: ChainState,
    idle: &CoreInputs,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let mut rng = StdRng::seed_from_u64(spec.replan_seed);
    let f = Format::with_ts(spec.ts);
    let per_tick = u64::from(spec.tick_div) + 1;
    let mut program_ticks = first_ticks;
    // Where the program playing ends, when it ends at rest.
    let mut ends_at: Option<ChainState> = Some(first_final);
    let mut done = 0u8;
    let mut attempts = 0u32;
    while done < spec.replans || ends_at.is_none() {
        attempts += 1;
        if attempts > 4 * u32::from(spec.replans) + 16 {
            break;
        }
        // A random while into the program playing (or past its end).
        let wait = log_uniform(&mut rng, 1.0, (program_ticks as f64 * 1.2).max(2.0)) as u64;
        let now = ls.side.model.outputs().ticks;
        drive_until_tick(ls, idle, now + wait, (wait + 2) * per_tick + 2)?;
        let now = ls.side.model.outputs().ticks;
        if rng.gen_bool(0.05) {
            // Late: a tick the time base has reached, or reaches on the arming edge. The core
            // must not arm it (the next upload replaces this program).
            let one = Program {
                segments: vec![Segment { ticks: 5, snap: 7 }],
            };
            upload(ls, &one, idle)?;
            // (The core wants three ticks of lead over the time base before the arming edge,
            // which is at least `now`: two or fewer are refused whenever it sees them.)
            let late_at = ls
                .side
                .model
                .outputs()
                .ticks
                .wrapping_add_signed(rng.gen_range(-2..=2));
            ls.drive(
                &CoreInputs {
                    swap: true,
                    swap_last: late_at.wrapping_sub(1) as u32,
                    ..*idle
                },
                1,
            )?;
            ls.drive(idle, 2)?;
            report.late_swaps += 1;
            if ls.side.model.outputs().swap_pending {
                report.late_swaps_taken += 1;
            }
            continue;
        }
        let last = done + 1 >= spec.replans;
        let lead = log_uniform(&mut rng, 2.0, 3000.0) as u64;
        // Room for the upload (at most 34 clocks) before the tick, and the core's lead of 3.
        let at = now + 40 + lead;
        let start = state_at(&ls.side, idle, at);
        let limits = random_limits(&mut rng);
        let order = if rng.gen_bool(0.7) {
            OnlineOrder::Three
        } else {
            OnlineOrder::Two
        };
        let sign = if rng.gen_bool(0.5) { 1 } else { -1 };
        let cell = f.output_lsb(start.x) + sign * log_uniform(&mut rng, 1.0, 2e6) as i128;
        let speed = limits.velocity * rng.gen_range(0.05..=1.0);
        let target = match (last, rng.gen_range(0..5)) {
            (false, 0) => OnlineTarget::Velocity(f64::from(sign as i32) * speed),
            (false, 1) => OnlineTarget::Position {
                cell,
                velocity: f64::from(sign as i32) * speed,
            },
            _ => OnlineTarget::Position {
                cell,
                velocity: 0.0,
            },
        };
        let plan = match plan_online(&start, &target, &limits, order, &f) {
            Ok(p) if p.program.total_ticks() <= MAX_MOVE_TICKS => p,
            Ok(_) => {
                report.replans_too_long += 1;
                continue;
            }
            Err(e) => {
                *report.replans_refused.entry(kind_of(&e)).or_default() += 1;
                continue;
            }
        };
        upload(ls, &plan.program, idle)?;
        ls.drive(
            &CoreInputs {
                swap: true,
                swap_last: (at - 1) as u32,
                ..*idle
            },
            1,
        )?;
        // Past the input register: armed.
        ls.drive(idle, 1)?;
        if !ls.side.model.outputs().swap_pending {
            report.swaps_not_armed += 1;
            continue;
        }
        if rng.gen_bool(0.03) {
            // A stop while the swap is armed cancels it; the stop brings the chain to rest.
            let before = (at - ls.side.model.outputs().ticks) * per_tick;
            ls.drive(idle, rng.gen_range(0..before.max(1)))?;
            controlled_stop(ls, spec, idle, None, None, report)?;
            report.swaps_cancelled += 1;
            return Ok(());
        }
        drive_until_tick(ls, idle, at, (lead + 45) * per_tick + 4)?;
        report.replans += 1;
        done += 1;
        program_ticks = plan.program.total_ticks();
        ends_at = match target {
            OnlineTarget::Position { velocity: 0.0, .. } => Some(plan.final_state),
            _ => None,
        };
    }
    match ends_at {
        Some(end) => {
            run_out(ls, idle, (program_ticks + 2) * per_tick + 2)?;
            if ls.side.model.chain() != end {
                report.planner_disagreements += 1;
            }
        }
        // Still moving (no rest target could be planned): the fabric's stop brings it to rest.
        None => controlled_stop(ls, spec, idle, None, None, report)?,
    }
    Ok(())
}
