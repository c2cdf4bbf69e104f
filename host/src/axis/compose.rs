//! Composing a change: which parts of the timeline keep playing, which are replanned, from
//! which exact state, and the program the fabric plays from the swap tick.

use snapgen_model::format::Quantity;
use snapgen_plan::online::OnlineError;

use super::part::{check_inputs, checkpoints, plan_part, prefix, PASSED_ON, STOPPED_ON_TARGET};
use super::{
    AxisErrorId, BufferMode, Change, Goal, HostAxis, MotionCommand, Outcome, Part, Timeline,
};

/// What changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Request {
    /// Command `k` was submitted.
    Command(usize),
    /// The override becomes this factor (0–2).
    Override(f64),
}

/// Why a change could not be planned: the command to put in Error and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// The command that fails (the new one, or for an override the one it replans).
    pub command: Option<usize>,
    /// Why.
    pub error: AxisErrorId,
}

/// Largest override (PLCopen: 0–200 %).
pub const MAX_OVERRIDE: f64 = 2.0;

impl HostAxis {
    /// Records `cmd` (Busy) and returns its index; its inputs are checked here (a bad input
    /// is an Error at once and needs no change).
    pub fn submit(&mut self, cmd: MotionCommand) -> usize {
        let outcome = match check_inputs(&cmd, &self.settings.format) {
            Ok(()) => Outcome::Busy,
            Err(e) => Outcome::Error(e),
        };
        self.commands.push(super::CommandRecord {
            command: cmd,
            outcome,
            note: None,
        });
        self.commands.len() - 1
    }

    /// Commands still to be done at tick `at`: busy, with a part that ends after `at`, a
    /// paused or velocity-holding part, or no part yet.
    fn live(&self, at: u64) -> Vec<usize> {
        let mut out: Vec<usize> = Vec::new();
        for (k, rec) in self.commands.iter().enumerate() {
            if !rec.outcome.busy() {
                continue;
            }
            let part = self.timeline.parts.iter().rev().find(|p| p.command == k);
            let live = match part {
                None => true,
                Some(p) => {
                    p.end_tick() > at || p.paused || matches!(p.goal, Goal::Velocity(v) if v != 0.0)
                }
            };
            if live {
                out.push(k);
            }
        }
        out
    }

    /// The change that realises `req` with the swap at tick `at` (the host chooses `at`
    /// ahead of the link's latency). A blend the planner cannot realise from the state the
    /// previous move is in at `at` falls back to Buffered (the previous move unchanged; the
    /// command's note says so).
    pub fn plan_change(&self, at: u64, req: Request) -> Result<Change, Refusal> {
        if let Request::Override(k) = req {
            return self.plan_override(at, k);
        }
        // The move a blend replans (the last one) overshooting its target and coming back
        // from `at` (its target too near to pass at the blend, and a replan to rest from where
        // it is running past it), or turning back where its plan did not: it plays on
        // unchanged instead, as when it cannot be replanned.
        let previous = self.timeline.parts.last().map(|p| p.command);
        let blended = self.plan_change_with(at, req, true, false);
        let overshoots = blended.as_ref().is_ok_and(|c| {
            previous.is_some_and(|p| {
                self.overshoots(c, p, at)
                    || (self.reverses(&c.timeline, p, at) && !self.reverses(&self.timeline, p, at))
            })
        });
        match blended {
            Err(_) if self.blends(req) => self.buffered(at, req, "could not be replanned"),
            Ok(_) if overshoots && self.blends(req) => {
                self.buffered(at, req, "would have overshot its target")
            }
            r => r,
        }
    }

    /// `req` planned without its blend (the previous move unchanged), noted with `why`.
    fn buffered(&self, at: u64, req: Request, why: &str) -> Result<Change, Refusal> {
        let mut c = self.plan_change_with(at, req, false, false)?;
        if let Request::Command(k) = req {
            c.notes.push((
                k,
                format!("the previous move {why} to blend from where it was: buffered instead"),
            ));
        }
        Ok(c)
    }

    /// An override to factor `k` from tick `at`: the parts from `at` replanned with it, unless
    /// the move playing at `at` only slows down from there (its final brake), the new set
    /// speed is not below the speed it slows from, and the replanned move would not end sooner
    /// (the path left is too short to go faster; a replan from such a state may have to stop
    /// and go again): then that move plays on as planned and only the ones after it are
    /// replanned. So it does at override 0 when a stop on the path would come to rest on or
    /// past the move's target ([`STOPPED_ON_TARGET`]): the brake it is in stops it there.
    fn plan_override(&self, at: u64, k: f64) -> Result<Change, Refusal> {
        let replanned = self.plan_change_with(at, Request::Override(k), false, false);
        let Some(p) = self.timeline.parts.iter().find(|p| p.end_tick() > at) else {
            return replanned;
        };
        // A change the move playing at `at` cannot follow without overshooting its target and
        // coming back (too near to slow to the new speed, to the blend it asks, or to rest, in
        // time): that move plays on as planned, the override acts from the next one.
        // (Or a replan that turns back where the plan did not: the planner's realisation of a
        // stop, or of a move's end, from some states in a final brake swings back by a few
        // raw units.)
        // At override 0 only for a move to a position in its final brake, or one the stop
        // ends on its target anyway: elsewhere (a stop early in a move, a velocity) the stop
        // is made as planned. A raised or lowered override may always wait for the next move.
        let braking = matches!(p.goal, Goal::Position { .. }) && self.slows_to_its_end(p, at);
        let turns = |c: &Change| {
            let on_target = k == 0.0
                && c.notes
                    .iter()
                    .any(|(n, note)| *n == p.command && note == STOPPED_ON_TARGET);
            (k > 0.0 || braking || on_target)
                && self.reverses(&c.timeline, p.command, at)
                && !self.reverses(&self.timeline, p.command, at)
        };
        // (Not a stop on the path: a paused move is replanned whole when the override rises.)
        if !p.paused
            && replanned
                .as_ref()
                .is_ok_and(|c| self.overshoots(c, p.command, at) || turns(c))
        {
            let kept = self.plan_change_with(at, Request::Override(k), false, true);
            if kept
                .as_ref()
                .is_ok_and(|c| !self.overshoots(c, p.command, at))
            {
                return kept.map(|mut c| {
                    if k == 0.0 && !c.notes.iter().any(|(n, _)| *n == p.command) {
                        let note = match p.goal {
                            Goal::Position { velocity, .. } if velocity != 0.0 => PASSED_ON,
                            _ => STOPPED_ON_TARGET,
                        };
                        c.notes.push((p.command, note.into()));
                    }
                    c
                });
            }
        }
        if k == 0.0 {
            let past = replanned.as_ref().is_ok_and(|c| {
                c.notes
                    .iter()
                    .any(|(c, n)| *c == p.command && n == STOPPED_ON_TARGET)
            });
            return if past && self.slows_to_its_end(p, at) {
                let kept = self.plan_change_with(at, Request::Override(k), false, true);
                kept.map(|mut c| {
                    c.notes.push((p.command, STOPPED_ON_TARGET.into()));
                    c
                })
            } else {
                replanned
            };
        }
        let keeps = k > 0.0
            && self.slows_to_its_end(p, at)
            && self.commands[p.command]
                .command
                .set_speed(k)
                .is_some_and(|v| v >= self.speed_at(at));
        if !keeps {
            return replanned;
        }
        let ends = |c: &Change| {
            c.timeline
                .parts
                .iter()
                .find(|q| q.command == p.command && q.end_tick() > at)
                .map_or(0, |q| q.end_tick())
        };
        match replanned {
            Ok(c) if ends(&c) < p.end_tick() => Ok(c),
            _ => self.plan_change_with(at, Request::Override(k), false, true),
        }
    }

    /// True when part `p` (a move to a position) only slows down (or holds its speed) from tick
    /// `at` to its end: moving at `at`, its acceleration never along the motion and its
    /// velocity never crossing zero before its end. (A cruise before the brake passes: the
    /// caller keeps the part only when a replan would not end sooner.) The acceleration is linear between segment ends (orders 2 and 3),
    /// so the segment ends decide.
    fn slows_to_its_end(&self, p: &Part, at: u64) -> bool {
        let f = &self.settings.format;
        if !matches!(p.goal, Goal::Position { .. }) || p.start_tick >= at || p.end_tick() <= at {
            return false;
        }
        let now = self.timeline.state_at(at, f);
        let dir = now.v.signum();
        if dir == 0 || now.a * dir > 0 {
            return false;
        }
        let mut tick = p.start_tick;
        for s in &p.program.segments {
            tick += u64::from(s.ticks);
            if tick <= at || tick >= p.end_tick() {
                continue;
            }
            let b = self.timeline.state_at(tick, f);
            if b.v * dir <= 0 || b.a * dir > 0 {
                return false;
            }
        }
        true
    }

    /// True when `timeline` makes command `command`'s motion after tick `at` go against the
    /// direction it moves in at `at`, judged at every segment's end and middle.
    fn reverses(&self, timeline: &Timeline, command: usize, at: u64) -> bool {
        let f = &self.settings.format;
        let dir = self.timeline.state_at(at, f).v.signum();
        dir != 0
            && timeline
                .parts
                .iter()
                .filter(|q| q.command == command && q.end_tick() > at)
                .any(|q| {
                    let after = i128::from(at) - i128::from(q.start_tick);
                    checkpoints(&q.start, &q.program, after, f).any(|s| s.v * dir < 0)
                })
    }

    /// True when change `c` makes command `command`'s move to a position pass its target cell
    /// after tick `at` (to come back to it), judged at every segment's end and middle.
    fn overshoots(&self, c: &Change, command: usize, at: u64) -> bool {
        let f = &self.settings.format;
        c.timeline
            .parts
            .iter()
            .filter(|q| q.command == command && q.end_tick() > at)
            .any(|q| {
                let Goal::Position { cell, .. } = q.goal else {
                    return false;
                };
                let from = at.max(q.start_tick);
                let x = if q.start_tick >= at {
                    q.start.x
                } else {
                    self.timeline.state_at(at, f).x
                };
                let dir = (cell - f.output_lsb(x)).signum();
                let after = i128::from(from) - i128::from(q.start_tick);
                checkpoints(&q.start, &q.program, after, f)
                    .any(|s| (f.output_lsb(s.x) - cell) * dir > 0)
            })
    }

    /// The speed at tick `at` (unit/s).
    fn speed_at(&self, at: u64) -> f64 {
        let f = &self.settings.format;
        f.to_physical(Quantity::Velocity, self.timeline.state_at(at, f).v.abs())
    }

    /// True when `req` is a blending move.
    fn blends(&self, req: Request) -> bool {
        matches!(req, Request::Command(k) if !matches!(
            self.commands[k].command.buffer_mode(),
            BufferMode::Aborting | BufferMode::Buffered
        ))
    }

    fn plan_change_with(
        &self,
        at: u64,
        req: Request,
        blend: bool,
        keep_playing: bool,
    ) -> Result<Change, Refusal> {
        let f = &self.settings.format;
        let mut k = self.override_factor;
        let mut live = self.live(at);
        let mut aborts = Vec::new();
        let mut notes = Vec::new();
        // Parts to keep whole (their index in the timeline), then specs to plan.
        let playing_from = self
            .timeline
            .parts
            .iter()
            .position(|p| p.end_tick() > at)
            .unwrap_or(self.timeline.parts.len());
        let mut keep = self.timeline.parts.len();
        match req {
            Request::Override(f) => {
                if !(0.0..=MAX_OVERRIDE).contains(&f) {
                    return Err(Refusal {
                        command: None,
                        error: AxisErrorId::InvalidInput(format!(
                            "override {f} is outside 0–{MAX_OVERRIDE}: give a factor from 0 to 2 (0–200 %)"
                        )),
                    });
                }
                k = f;
                keep = playing_from;
                if keep_playing {
                    keep = (playing_from + 1).min(self.timeline.parts.len());
                }
            }
            Request::Command(new) => {
                let cmd = self.commands[new].command;
                // Commands given after this one (due in the same batch) are planned with their
                // own requests.
                live.retain(|&c| c < new);
                let mode = cmd.buffer_mode();
                let last_paused = self.timeline.parts.last().is_some_and(|p| p.paused);
                let holding = self
                    .timeline
                    .parts
                    .last()
                    .is_some_and(|p| matches!(p.goal, Goal::Velocity(v) if v != 0.0));
                // A held velocity never ends: a move after it takes over as an aborting one.
                if mode == BufferMode::Aborting || holding {
                    aborts = live.clone();
                    live.clear();
                    keep = playing_from;
                } else if last_paused || live.is_empty() {
                    // Nothing to follow, or the axis waits at override 0: the new move queues.
                    keep = playing_from;
                } else if blend
                    && mode != BufferMode::Buffered
                    && self.blend_at_last(new) != 0.0
                    && self
                        .timeline
                        .parts
                        .last()
                        .is_some_and(|p| matches!(p.goal, Goal::Position { .. }))
                {
                    // Blends: the last part is replanned to its blend point.
                    let last = self.timeline.parts.len() - 1;
                    if self.timeline.parts[last].end_tick() > at {
                        keep = last;
                    } else {
                        notes.push((new, "blend too late: the previous move had ended".into()));
                    }
                }
                live.push(new);
            }
        }
        // The kept parts; the part playing at `at` among the replanned ones is cut there.
        let parts = &self.timeline.parts;
        let mut out: Vec<Part> = parts[..keep].to_vec();
        let (mut tick, mut state) = match out.last() {
            Some(p) => (
                p.end_tick().max(at),
                self.timeline.state_at(p.end_tick().max(at), f),
            ),
            None => (at, self.timeline.state_at(at, f)),
        };
        if let Some(p) = parts.get(keep) {
            if p.start_tick >= at {
                tick = p.start_tick;
                state = p.start;
            } else {
                let cut = at - p.start_tick;
                out.push(Part {
                    program: prefix(&p.program, cut),
                    end: self.timeline.state_at(at, f),
                    paused: false,
                    cut: true,
                    ..p.clone()
                });
                tick = at;
                state = self.timeline.state_at(at, f);
            }
        }
        // Specs to plan: live commands without a kept part still to play (a paused or
        // velocity-holding part that has ended is replanned).
        let kept: Vec<usize> = out
            .iter()
            .filter(|p| !p.cut && p.end_tick() > at)
            .map(|p| p.command)
            .collect();
        let specs: Vec<usize> = live.into_iter().filter(|c| !kept.contains(c)).collect();
        let mut next_state = state;
        for (i, &c) in specs.iter().enumerate() {
            let next = specs.get(i + 1).map(|&n| self.commands[n].command);
            let planned = plan_part(
                &self.commands[c].command,
                next.as_ref(),
                &next_state,
                k,
                self,
            )
            .map_err(|e| Refusal {
                command: Some(c),
                error: e.into(),
            })?;
            let (program, end, goal, paused, note) = planned;
            if let Some(n) = note {
                notes.push((c, n));
            }
            let part = Part {
                command: c,
                start_tick: tick,
                start: next_state,
                end,
                program,
                goal,
                paused,
                cut: false,
            };
            tick = part.end_tick();
            next_state = end;
            out.push(part);
            if paused || matches!(goal, Goal::Velocity(_)) {
                // Nothing follows a pause or a held velocity.
                break;
            }
        }
        let timeline = Timeline {
            origin: self.timeline.origin,
            parts: out,
        };
        let program = timeline.program_from(at, f);
        // A part must fit the program memory whole (the parts after it go up in later swaps).
        if let Some(p) = timeline
            .parts
            .iter()
            .find(|p| p.end_tick() > at && p.program.segments.len() > f.max_segments)
        {
            return Err(Refusal {
                command: Some(p.command),
                error: AxisErrorId::Planner(
                    OnlineError::TooManySegments {
                        count: p.program.segments.len(),
                        max: f.max_segments,
                    }
                    .to_string(),
                ),
            });
        }
        Ok(Change {
            at,
            program,
            timeline,
            aborts,
            notes,
            override_factor: k,
        })
    }

    /// Makes `c` the axis's state (after the board acknowledged its SWAP_AT).
    pub fn apply(&mut self, c: Change) {
        for &a in &c.aborts {
            self.commands[a].outcome = Outcome::CommandAborted;
        }
        for (k, n) in c.notes {
            self.commands[k].note = Some(n);
        }
        self.override_factor = c.override_factor;
        self.timeline = c.timeline;
    }
}

impl HostAxis {
    /// Several requests due together, planned one after the other for the same swap tick
    /// `at` (a move and the blending move queued behind it are planned as one program): the
    /// change, if any request was taken, and the refused ones.
    pub fn plan_batch(
        &self,
        at: u64,
        reqs: &[Request],
    ) -> (Option<Change>, Vec<(Request, Refusal)>) {
        let mut work = self.clone();
        let (mut aborts, mut notes, mut refused) = (Vec::new(), Vec::new(), Vec::new());
        for &r in reqs {
            match work.plan_change(at, r) {
                Ok(c) => {
                    aborts.extend(c.aborts.iter().copied());
                    notes.extend(c.notes.iter().cloned());
                    work.apply(c);
                }
                Err(e) => refused.push((r, e)),
            }
        }
        if refused.len() == reqs.len() {
            return (None, refused);
        }
        let f = &self.settings.format;
        let change = Change {
            at,
            program: work.timeline.program_from(at, f),
            timeline: work.timeline,
            aborts,
            notes,
            override_factor: work.override_factor,
        };
        (Some(change), refused)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::AxisSettings;
    use snapgen_model::chain::ChainState;
    use snapgen_model::DEFAULT_FORMAT;
    use snapgen_plan::online::OnlineOrder;

    fn mv(position: f64, velocity: f64) -> MotionCommand {
        MotionCommand::MoveAbsolute {
            position,
            velocity,
            acceleration: 4000.0,
            deceleration: 3000.0,
            jerk: 200_000.0,
            buffer_mode: BufferMode::Aborting,
            path: None,
        }
    }

    /// An axis that has started a move to `position` at `velocity` on tick 0.
    fn moving(order: OnlineOrder, position: f64, velocity: f64) -> HostAxis {
        let f = DEFAULT_FORMAT;
        let settings = AxisSettings { format: f, order };
        let mut axis = HostAxis::new(settings, 0, ChainState::at_rest(f.home_raw()));
        let k = axis.submit(mv(position, velocity));
        let (c, refused) = axis.plan_batch(0, &[Request::Command(k)]);
        assert!(refused.is_empty());
        axis.apply(c.unwrap());
        axis
    }

    /// The velocity on every tick of `t` from `from` to its end (raw).
    fn velocities(t: &Timeline, from: u64) -> Vec<i128> {
        let f = DEFAULT_FORMAT;
        (from..t.end_tick()).map(|k| t.state_at(k, &f).v).collect()
    }

    /// A tick a third of the way into the move's final brake (from the last tick at its top
    /// speed to its end), and the speed there (raw).
    fn in_final_brake(axis: &HostAxis) -> (u64, i128) {
        let v = velocities(&axis.timeline, 0);
        let k = brake_start(axis) as usize;
        let at = k + (v.len() - k) / 3;
        (at as u64, v[at].abs())
    }

    /// The last tick at the move's top speed (its final brake begins after it).
    fn brake_start(axis: &HostAxis) -> u64 {
        let v = velocities(&axis.timeline, 0);
        let top = v.iter().map(|v| v.abs()).max().unwrap();
        v.iter().rposition(|v| v.abs() == top).unwrap() as u64
    }

    #[test]
    fn an_override_raised_during_the_final_brake_keeps_the_brake() {
        for order in [OnlineOrder::Three, OnlineOrder::Two] {
            let axis = moving(order, 20.0, 200.0);
            let (at, speed) = in_final_brake(&axis);
            let speed = DEFAULT_FORMAT.to_physical(Quantity::Velocity, speed);
            assert!(speed > 20.0, "{order:?}: {speed} at {at}");
            let (c, refused) = axis.plan_batch(at, &[Request::Override(2.0)]);
            assert!(refused.is_empty());
            let c = c.unwrap();
            assert!(
                velocities(&c.timeline, at) == velocities(&axis.timeline, at),
                "{order:?}: the brake changed"
            );
            // Asking for less than the speed it brakes from replans it: slower from there on.
            let (c, _) = axis.plan_batch(at, &[Request::Override(0.1 * speed / 200.0)]);
            let (old, new) = (
                velocities(&axis.timeline, at),
                velocities(&c.unwrap().timeline, at),
            );
            assert!(
                new.len() > old.len(),
                "{order:?}: a cut did not slow the brake"
            );
        }
    }

    /// An override cut on a short blended move that leaves it too fast to slow to the new
    /// blend velocity by the blend point: it passes the point at the lowest velocity it can
    /// (not at rest, as a buffered move would), exactly, and the next move goes on from there.
    #[test]
    fn a_blend_velocity_an_override_cut_puts_out_of_reach_is_raised_not_dropped() {
        let f = DEFAULT_FORMAT;
        let settings = AxisSettings {
            format: f,
            order: OnlineOrder::Three,
        };
        let mut axis = HostAxis::new(settings, 0, ChainState::at_rest(f.home_raw()));
        let move_to = |position, velocity, buffer_mode| MotionCommand::MoveAbsolute {
            position,
            velocity,
            acceleration: 4000.0,
            deceleration: 3000.0,
            jerk: 500_000.0,
            buffer_mode,
            path: None,
        };
        let first = axis.submit(move_to(3.0, 100.0, BufferMode::Aborting));
        let next = axis.submit(move_to(5.0, 60.0, BufferMode::BlendingLow));
        let (c, _) = axis.plan_batch(0, &[Request::Command(first), Request::Command(next)]);
        axis.apply(c.unwrap());
        // 25 ms in, at about 77 mm/s and still accelerating: 50 % asks for a blend at 30 mm/s,
        // which braking from there cannot reach by 3 mm.
        let at = 2500;
        let now = f.to_physical(Quantity::Velocity, axis.timeline.state_at(at, &f).v);
        let (c, refused) = axis.plan_batch(at, &[Request::Override(0.5)]);
        assert!(refused.is_empty());
        let c = c.unwrap();
        let note = &c.notes.iter().find(|(k, _)| *k == first).unwrap().1;
        assert!(note.contains("passed at"), "{note}");
        let part = c
            .timeline
            .parts
            .iter()
            .find(|p| p.command == first && !p.cut)
            .unwrap();
        let Goal::Position { velocity, .. } = part.goal else {
            panic!("{:?}", part.goal)
        };
        assert!(velocity > 30.0 && velocity < now, "{velocity} (now {now})");
        // Stepped tick by tick: on 3 mm at that velocity, a = j = 0.
        let mut s = part.start;
        for seg in &part.program.segments {
            for _ in 0..seg.ticks {
                s = s.step(seg.snap, &f.widths);
            }
        }
        let v_raw = (velocity * f.scale(Quantity::Velocity)).round() as i128;
        assert_eq!((s.v, s.a, s.j), (v_raw, 0, 0));
        assert_eq!(f.output_lsb(s.x), 3_000_000);
        // The next move goes on from there to 5 mm at rest.
        let last = c.timeline.parts.last().unwrap();
        assert_eq!(last.command, next);
        assert_eq!(last.start, s);
        assert!(last.end.is_at_rest());
        assert_eq!(f.output_lsb(last.end.x), 5_000_000);
    }

    #[test]
    fn an_override_raised_while_slowing_to_a_lower_cruise_speeds_up() {
        for order in [OnlineOrder::Three, OnlineOrder::Two] {
            let mut axis = moving(order, 100.0, 200.0);
            // At cruise, cut to 10 %; then, while it slows down, back to 100 %.
            let cruise = axis.timeline.end_tick() / 3;
            let (c, _) = axis.plan_batch(cruise, &[Request::Override(0.1)]);
            axis.apply(c.unwrap());
            let at = cruise + 500;
            let v = velocities(&axis.timeline, at);
            assert!(
                v[0].abs() > v[1].abs(),
                "{order:?}: not slowing down at {at}"
            );
            let (c, refused) = axis.plan_batch(at, &[Request::Override(1.0)]);
            assert!(refused.is_empty());
            let new = velocities(&c.unwrap().timeline, at);
            assert!(
                new.len() < v.len(),
                "{order:?}: raised again, the move did not end sooner ({} ticks, was {})",
                new.len(),
                v.len()
            );
        }
    }

    /// Override 0 a few ticks into the final brake (the brake at full deceleration cannot stop
    /// before the target): the move stops on its target, never past it and back, and is done
    /// there; earlier, at cruise, it stops on the path (paused) short of the target.
    #[test]
    fn an_override_of_zero_in_the_final_brake_stops_on_the_target() {
        let f = DEFAULT_FORMAT;
        for order in [OnlineOrder::Three, OnlineOrder::Two] {
            let axis = moving(order, 20.0, 200.0);
            let brake = brake_start(&axis);
            for at in [brake + 5, brake + 50] {
                let (c, refused) = axis.plan_batch(at, &[Request::Override(0.0)]);
                assert!(refused.is_empty());
                let c = c.unwrap();
                let last = c.timeline.parts.last().unwrap();
                assert!(!last.paused, "{order:?} at {at}: paused past the target");
                assert!(last.end.is_at_rest());
                assert_eq!(f.output_lsb(last.end.x), 20_000_000, "{order:?} at {at}");
                let w = velocities(&c.timeline, at);
                assert!(w.iter().all(|v| *v >= 0), "{order:?} at {at}: reversed");
                assert!(c.notes.iter().any(|(_, n)| n.contains("stopped on it")));
            }
            let (c, _) = axis.plan_batch(brake / 2, &[Request::Override(0.0)]);
            let last = c.unwrap().timeline.parts.last().unwrap().clone();
            assert!(
                last.paused && last.end.is_at_rest(),
                "{order:?}: not paused"
            );
            assert!(f.output_lsb(last.end.x) < 20_000_000);
        }
    }
}
