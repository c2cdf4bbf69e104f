//! Planning one part of a change: a command's inputs checked, the online plan from the exact
//! state its part begins at to its goal (a position at rest, a blend point, a velocity), and
//! the velocity a blend passes its target at.

use snapgen_model::chain::ChainState;
use snapgen_model::format::{Format, Quantity};
use snapgen_model::program::{Program, Segment};
use snapgen_plan::online::{plan_online, OnlineError, OnlineLimits, OnlineOrder, OnlineTarget};

use super::{scaled, AxisErrorId, BufferMode, Goal, HostAxis, MotionCommand, OnPath};

impl HostAxis {
    /// The velocity the timeline's last part would pass its target at with command `next`
    /// blending into it (0: no blend, a reversal, or not a position move).
    pub(super) fn blend_at_last(&self, next: usize) -> f64 {
        let Some(last) = self.timeline.parts.last() else {
            return 0.0;
        };
        let (Goal::Position { cell, .. }, MotionCommand::MoveAbsolute { velocity, .. }) =
            (last.goal, self.commands[last.command].command)
        else {
            return 0.0;
        };
        let f = &self.settings.format;
        let dist = cell - f.output_lsb(last.start.x);
        blend_velocity(dist, cell, velocity, &self.commands[next].command, f)
    }
}

/// The first `n` ticks of `p`.
pub(super) fn prefix(p: &Program, n: u64) -> Program {
    let mut left = n;
    let mut segments = Vec::new();
    for s in &p.segments {
        if left == 0 {
            break;
        }
        let t = left.min(u64::from(s.ticks));
        segments.push(Segment {
            ticks: t as u32,
            snap: s.snap,
        });
        left -= t;
    }
    Program { segments }
}

/// Inputs every command needs: finite, positive limits; a position the register holds.
pub(super) fn check_inputs(c: &MotionCommand, f: &Format) -> Result<(), AxisErrorId> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(AxisErrorId::InvalidInput(format!(
                "{} {name} = {v}: give a finite value > 0",
                c.name()
            )))
        }
    };
    match *c {
        MotionCommand::MoveAbsolute {
            position,
            velocity,
            acceleration,
            deceleration,
            jerk,
            path,
            ..
        } => {
            positive("velocity", velocity)?;
            positive("acceleration", acceleration)?;
            positive("deceleration", deceleration)?;
            positive("jerk", jerk)?;
            if let Some(p) = path {
                positive("path velocity", p.velocity)?;
                if !(p.entry.is_finite() && p.entry >= 0.0) {
                    return Err(AxisErrorId::InvalidInput(format!(
                        "MC_MoveAbsolute path entry = {}: give a finite speed ≥ 0",
                        p.entry
                    )));
                }
            }
            let most = f.physical_max(Quantity::Position) * 0.5;
            if !position.is_finite() || position.abs() > most {
                return Err(AxisErrorId::InvalidInput(format!(
                    "MC_MoveAbsolute position = {position}: give a position within ±{most:.6} (half the position register)"
                )));
            }
        }
        MotionCommand::MoveVelocity {
            velocity,
            acceleration,
            deceleration,
            jerk,
        } => {
            if !velocity.is_finite() {
                return Err(AxisErrorId::InvalidInput(format!(
                    "MC_MoveVelocity velocity = {velocity}: give a finite value"
                )));
            }
            positive("acceleration", acceleration)?;
            positive("deceleration", deceleration)?;
            positive("jerk", jerk)?;
        }
        MotionCommand::Halt { deceleration, jerk } => {
            positive("deceleration", deceleration)?;
            positive("jerk", jerk)?;
        }
    }
    Ok(())
}

type Planned = (Program, ChainState, Goal, bool, Option<String>);

/// The note of a move whose stop on the path (override 0) would have come to rest on or past
/// its target: it stops on the target instead.
pub const STOPPED_ON_TARGET: &str =
    "override 0 too near the target to stop before it: stopped on it";

/// The shares of a stop's deceleration tried, in turn, when the planner's stop swings back.
const GENTLER: [f64; 4] = [0.99, 0.97, 0.93, 0.85];

/// The states `program` from `start` passes at every segment's middle and end, those after
/// tick `after` (relative to `start`; may be negative): where the host judges a plan's
/// direction (the acceleration is linear within a segment at orders 2 and 3).
pub(super) fn checkpoints<'a>(
    start: &'a ChainState,
    program: &'a Program,
    after: i128,
    f: &'a Format,
) -> impl Iterator<Item = ChainState> + 'a {
    let mut tick = 0u64;
    program
        .segments
        .iter()
        .flat_map(move |s| {
            let half = tick + u64::from(s.ticks) / 2;
            tick += u64::from(s.ticks);
            [half, tick]
        })
        .filter(move |&t| i128::from(t) > after)
        .map(move |t| start.after_ticks(program, t, &f.widths))
}

/// True when `program` from `from` moves against `from`'s velocity at a segment's end or
/// middle.
fn turns_back(from: &ChainState, program: &Program, f: &Format) -> bool {
    let dir = from.v.signum();
    dir != 0 && checkpoints(from, program, -1, f).any(|s| s.v * dir < 0)
}

/// The note of a move on a path whose stop (override 0) would have come to rest past its
/// end: it passes on into the next element, which stops on its path.
pub(super) const PASSED_ON: &str =
    "override 0 too near the element's end to stop before it: passed on";

/// Plans one command's part from `from` with override `k`: a position move to its target at
/// rest or at the blend velocity with `next`, a velocity, a halt.
pub(super) fn plan_part(
    cmd: &MotionCommand,
    next: Option<&MotionCommand>,
    from: &ChainState,
    k: f64,
    axis: &HostAxis,
) -> Result<Planned, OnlineError> {
    let f = &axis.settings.format;
    let order = axis.settings.order;
    let run = |target: OnlineTarget, limits: OnlineLimits| {
        plan_online(from, &target, &limits, order, f).map(|p| (p.program, p.final_state))
    };
    // A stop on the path (override 0, MC_Halt) with the command's deceleration; at rest, a
    // tick of standing still (the planner's exact realisation of "to velocity 0" from rest is
    // a six-tick wiggle of a few raw units).
    let at_rest = from.v == 0 && from.a == 0 && from.j == 0;
    let stop = |l: OnlineLimits| {
        if at_rest {
            let hold = Program {
                segments: vec![Segment { ticks: 1, snap: 0 }],
            };
            return Ok((hold, *from));
        }
        // The planner's exact stop swings back by a few raw units from some states: a
        // slightly gentler deceleration, when one does not.
        let first = run(OnlineTarget::Velocity(0.0), l)?;
        if !turns_back(from, &first.0, f) {
            return Ok(first);
        }
        let gentler = GENTLER.iter().find_map(|&share| {
            let l = OnlineLimits {
                deceleration: l.deceleration * share,
                ..l
            };
            run(OnlineTarget::Velocity(0.0), l)
                .ok()
                .filter(|(p, _)| !turns_back(from, p, f))
        });
        Ok(gentler.unwrap_or(first))
    };
    match *cmd {
        MotionCommand::Halt { deceleration, jerk } => {
            let l = OnlineLimits {
                velocity: f.physical_max(Quantity::Velocity),
                acceleration: deceleration,
                deceleration,
                jerk,
            };
            let (p, e) = stop(l)?;
            Ok((p, e, Goal::Velocity(0.0), false, None))
        }
        MotionCommand::MoveVelocity {
            velocity,
            acceleration,
            deceleration,
            jerk,
        } => {
            let l = OnlineLimits {
                velocity: if k > 0.0 {
                    velocity.abs() * k
                } else {
                    velocity.abs()
                },
                acceleration,
                deceleration,
                jerk,
            };
            let v = velocity * k;
            let (p, e) = if velocity == 0.0 {
                stop(OnlineLimits {
                    velocity: f.physical_max(Quantity::Velocity),
                    ..l
                })?
            } else {
                run(OnlineTarget::Velocity(v), l)?
            };
            Ok((p, e, Goal::Velocity(v), k == 0.0, None))
        }
        MotionCommand::MoveAbsolute {
            position,
            velocity,
            acceleration,
            deceleration,
            jerk,
            path,
            ..
        } => {
            let l = OnlineLimits {
                velocity,
                acceleration,
                deceleration,
                jerk,
            };
            let cell = cell_of(position, f);
            let here = f.output_lsb(from.x);
            if k == 0.0 {
                // A stop on the path, unless it would come to rest on or past the target
                // (the axis would then have to come back): the move ends on its target
                // instead, braking as it would have.
                let (p, e) = stop(l)?;
                let dir = if from.v != 0 {
                    from.v.signum()
                } else {
                    (cell - here).signum()
                };
                if (f.output_lsb(e.x) - cell) * dir < 0 {
                    return Ok((p, e, Goal::Velocity(0.0), true, None));
                }
                // On a path, with an element after this one, the stop goes on into it: the
                // target is passed at the lowest speed found (up to the next element's entry
                // speed), and the next move stops on its path.
                let vb = next.map_or(0.0, |n| blend_velocity(cell - here, cell, velocity, n, f));
                if path.is_some() && vb != 0.0 {
                    let most = blend_cap(path, next).min(vb.abs());
                    let through = PASS_THROUGH.iter().find_map(|&share| {
                        let v = most * share * vb.signum();
                        let l = OnlineLimits {
                            velocity: l.velocity.max(v.abs()),
                            ..l
                        };
                        let target = OnlineTarget::Position { cell, velocity: v };
                        run(target, l).ok().map(|r| (v, r))
                    });
                    if let Some((v, (p, e))) = through {
                        let goal = Goal::Position { cell, velocity: v };
                        return Ok((p, e, goal, false, Some(PASSED_ON.into())));
                    }
                }
                let (p, e) = run(
                    OnlineTarget::Position {
                        cell,
                        velocity: 0.0,
                    },
                    l,
                )?;
                let goal = Goal::Position {
                    cell,
                    velocity: 0.0,
                };
                return Ok((p, e, goal, false, Some(STOPPED_ON_TARGET.into())));
            }
            let vb = next.map_or(0.0, |n| blend_velocity(cell - here, cell, velocity, n, f));
            // On a path, the element's geometry caps the set speed and the junction's the
            // blend, whatever the override (and a blend is never passed faster: below).
            let aim = blend_cap(path, next);
            let l = scaled(l, k);
            let l = OnlineLimits {
                velocity: path.map_or(l.velocity, |p| l.velocity.min(p.velocity)),
                ..l
            };
            let vb = (vb * k).clamp(-aim, aim);
            let l = OnlineLimits {
                velocity: l.velocity.max(vb.abs()),
                ..l
            };
            let at = |v: f64| OnlineTarget::Position { cell, velocity: v };
            // The blend given up: to rest on the target, the next move from there.
            let buffered = || {
                let (p, e) = run(at(0.0), l)?;
                Ok((
                    p,
                    e,
                    Goal::Position {
                        cell,
                        velocity: 0.0,
                    },
                    false,
                    Some("blend not reachable before the blend point: buffered instead".into()),
                ))
            };
            let blend = |v: f64| {
                let l = OnlineLimits {
                    velocity: l.velocity.max(v.abs()),
                    ..l
                };
                run(at(v), l)
            };
            // The blend point passed at `v` instead of the blend velocity, and why.
            let passed = |v: f64, (p, e): (Program, ChainState), why: &str| {
                let goal = Goal::Position {
                    cell,
                    velocity: v * vb.signum(),
                };
                let note = format!(
                    "{why}: the blend velocity {:.3} passed at {v:.3} instead",
                    vb.abs()
                );
                (p, e, goal, false, Some(note))
            };
            match run(at(vb), l) {
                Ok((p, e)) => Ok((p, e, Goal::Position { cell, velocity: vb }, false, None)),
                Err(OnlineError::NotRealisable(_)) if vb != 0.0 => {
                    // No exact program passes the blend point at that velocity: on a path, a
                    // slightly slower pass; else as buffered.
                    let slower = path.and_then(|_| {
                        SLOWER.iter().find_map(|&f| {
                            let v = vb.abs() * f;
                            blend(v * vb.signum()).ok().map(|r| (v, r))
                        })
                    });
                    match slower {
                        Some((v, r)) => Ok(passed(
                            v,
                            r,
                            "no exact program passes the blend point at it",
                        )),
                        None => buffered(),
                    }
                }
                Err(OnlineError::BlendUnreachable) if vb != 0.0 => {
                    // Too fast to slow to the blend velocity by the blend point (an override
                    // cut on a short move): the lowest
                    // blend velocity that can be reached, up to the speed the axis reaches
                    // releasing its acceleration at full jerk (seed 002 eq 32), found to 1/64
                    // of the way; else as buffered.
                    let to = |q, r: i128| f.to_physical(q, r);
                    let (v, a) = (
                        to(Quantity::Velocity, from.v),
                        to(Quantity::Acceleration, from.a),
                    );
                    let release = match axis.settings.order {
                        OnlineOrder::Three => a * a.abs() / (2.0 * jerk),
                        OnlineOrder::Two => 0.0,
                    };
                    let reached = (v + release).abs().max(v.abs());
                    let mut hi = reached.max(vb.abs() * (1.0 + 1.0 / 64.0));
                    let mut found = blend(hi * vb.signum()).ok().map(|r| (hi, r));
                    if found.is_some() {
                        let mut lo = vb.abs();
                        for _ in 0..6 {
                            let mid = 0.5 * (lo + hi);
                            match blend(mid * vb.signum()) {
                                Ok(r) => {
                                    hi = mid;
                                    found = Some((mid, r));
                                }
                                Err(_) => lo = mid,
                            }
                        }
                    }
                    // On a path, never faster than the next element's entry speed (its
                    // junction's, and what the look-ahead lets it brake from): else as buffered,
                    // which the axis turns into the previous plan when it would overshoot.
                    match found.filter(|(v, _)| *v <= aim) {
                        Some((v, r)) => {
                            Ok(passed(v, r, "too fast to slow to it by the blend point"))
                        }
                        None => buffered(),
                    }
                }
                Err(e) => Err(e),
            }
        }
    }
}

/// The shares of the speed a blend aims at (its entry into the next element) tried, slowest
/// first, for a move on a path that an override of 0 cannot stop before its end: it passes
/// on into the next element at the first that plans.
const PASS_THROUGH: [f64; 8] = [0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0];

/// The shares of a blend velocity tried, in turn, when a move on a path can pass its blend
/// point at it (no exact program does).
const SLOWER: [f64; 8] = [0.995, 0.98, 0.95, 0.9, 0.8, 0.65, 0.5, 0.3];

/// The fastest a move on a path (`path`) passes its end with `next` blending into it: the
/// smaller element's speed limit and the next one's entry speed (its junction's, lowered by
/// the look-ahead); unbounded off a path.
fn blend_cap(path: Option<OnPath>, next: Option<&MotionCommand>) -> f64 {
    let next = match next {
        Some(MotionCommand::MoveAbsolute { path, .. }) => *path,
        _ => None,
    };
    [
        path.map(|p| p.velocity),
        next.map(|p| p.velocity),
        next.map(|p| p.entry),
    ]
    .into_iter()
    .flatten()
    .fold(f64::INFINITY, f64::min)
}

/// The output cell of a position (unit).
pub fn cell_of(position: f64, f: &Format) -> i128 {
    snapgen_plan::planner::fmath::round(position / f.position_lsb) as i128
}

/// The velocity a move (`dist` cells toward its target `cell`, velocity `v`) passes its
/// target at when `next` blends into it: per `next`'s BufferMode, signed as the motion, 0
/// when the next move reverses, stands still or is not a blending move.
pub(super) fn blend_velocity(
    dist: i128,
    cell: i128,
    v: f64,
    next: &MotionCommand,
    f: &Format,
) -> f64 {
    let MotionCommand::MoveAbsolute {
        position,
        velocity: vn,
        buffer_mode,
        ..
    } = *next
    else {
        return 0.0;
    };
    let onward = cell_of(position, f) - cell;
    if dist == 0 || onward == 0 || dist.signum() != onward.signum() {
        return 0.0;
    }
    let m = match buffer_mode {
        BufferMode::BlendingLow => v.min(vn),
        BufferMode::BlendingPrevious => v,
        BufferMode::BlendingNext => vn,
        BufferMode::BlendingHigh => v.max(vn),
        BufferMode::Aborting | BufferMode::Buffered => 0.0,
    };
    m * dist.signum() as f64
}
