//! The axis group on its path length: seed 002's architecture. One coordinate, the path
//! length `s`, is the chain the board integrates; each element of the path is an
//! MC_MoveAbsolute on `s` to the element's end (the lengths accumulated), and the
//! interpolator (`snapgen_model::path::interp`) maps `s` onto every axis on every tick.
//!
//! * **The motion planner** ([`Group::enter`]) gives each element the limits its geometry
//!   allows (`snapgen_plan::path::speed`, within the path's own when given), a speed limit no
//!   feed override passes, and the speed its junction with the element before may be passed
//!   at (`snapgen_plan::path::junction`: tangent elements join at speed, corners stop
//!   exactly; a rapid starts and ends at rest), with a look-ahead over the elements entered
//!   together.
//! * **Path extension**: an element entering while the path moves is a BlendingLow move
//!   queued behind the last one (the host axis replans the last one's end to pass its
//!   junction at speed), as seed 002's tangent move entering the buffer.
//! * **Feed override** 0–200 %, from its tick, through the host axis (`crate::axis`): every
//!   element keeps its speed limit, every junction its own.
//!
//! This runner is the host axis without a board: a change swaps at the tick it is due (a
//! board adds the link's latency: `crate::driver`). Pure, deterministic.

use ethnum::I256;
use snapgen_model::chain::{ChainState, Trace};
use snapgen_model::format::{Format, Quantity};
use snapgen_model::path::interp::Path;
use snapgen_model::FRAC_BITS;
use snapgen_plan::online::OnlineOrder;
use snapgen_plan::path::junction::{frames, junction_speed, lookahead, Ahead, Frame};
use snapgen_plan::path::speed::{element_limits, Limits, MARGIN};
use snapgen_plan::path::{prepare, raw, Element, Prepared};

use crate::axis::compose::Request;
use crate::axis::{
    AxisErrorId, AxisSettings, BufferMode, HostAxis, MotionCommand, OnPath, Outcome,
};

use super::PlayError;
use crate::gcode::Block;

/// The path's own limits on its length (units/s², /s³), beside each axis's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathLimits {
    /// Acceleration (speed growing).
    pub acceleration: f64,
    /// Deceleration (speed shrinking).
    pub deceleration: f64,
    /// Jerk.
    pub jerk: f64,
}

/// What happens at an event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathAction {
    /// Every element up to this one (index) enters the buffer.
    Enter(usize),
    /// The feed override becomes this factor (0–2).
    Override(f64),
}

/// A timed event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathEvent {
    /// Time from the start (ms).
    pub at_ms: f64,
    /// And not before the path length has reached this much (units), when given.
    pub at_length: Option<f64>,
    /// What happens.
    pub action: PathAction,
}

/// An element as the planner prepared it.
pub(super) struct Planned {
    /// Its limits on `s` (its feed and its geometry; the path's own apply on top).
    pub limits: Limits,
    /// Its speed limit whatever the feed (units/s).
    pub cap: f64,
    /// Its length (units).
    pub length: f64,
    /// Its direction and curvature at its start and end (unstretched).
    pub frames: (Frame, Frame),
    /// Measured, ready to be fitted onto its share of `s`.
    pub prepared: Prepared,
    /// The speed its start may be passed at (its junction's, unstretched; 0 from rest, at
    /// a corner, into or out of a rapid).
    pub junction: f64,
}

/// The group playing a program.
pub struct Group<'a> {
    legs: &'a [Block],
    axes: &'a [Limits],
    own: Option<PathLimits>,
    format: Format,
    planned: Vec<Planned>,
    /// The entry speed each entered element was given.
    entries: Vec<f64>,
    /// Where each entered element ends on `s` (raw, from the start's cell centre).
    bounds: Vec<i128>,
    /// Each entered element's stretch (its share of `s` over its length) and its rules.
    stretch: Vec<f64>,
    paths: Vec<Path>,
    /// The command each entered element is in (index in the axis's list; elements joined
    /// into one move share it).
    commands: Vec<usize>,
    /// Each move given, as the look-ahead saw it.
    moves: Vec<Ahead>,
    /// The output cell `s` starts in (0 here; a board's position register where it stands).
    origin_cell: i128,
    /// The path's length (units), a cell per element added.
    total: f64,
    /// The axis on `s`.
    pub axis: HostAxis,
    /// Overrides refused (event index, why).
    pub refused: Vec<(usize, AxisErrorId)>,
    /// The tick each event was taken on (None: its length was never reached).
    pub taken: Vec<Option<u64>>,
    /// Junction speeds are passed at this multiple of what the planner allows (1; the tests
    /// raise it to show that the limit is needed and that the check sees it).
    junction_scale: f64,
}

/// A move on `s` shorter than this many ticks at its speed shares a move with the element it
/// joins at speed: the online planner needs room to pass a blend point exactly at a speed
/// (docs/PATH.md).
pub const SHORT_TICKS: f64 = 200.0;

/// One move on `s`: one element, or several joined at speed where one is short.
struct Move {
    /// Its last element.
    last: usize,
    /// Its length (units).
    length: f64,
    /// Its set speed, speed limit, acceleration, deceleration and jerk on `s`: the smallest
    /// of its elements' (and of the junctions inside it).
    velocity: f64,
    cap: f64,
    acceleration: f64,
    deceleration: f64,
    jerk: f64,
    /// The speed its first element's junction allows (0: from rest, a corner).
    junction: f64,
}

/// The latest an event may be due (ms from the start: 10⁷ ms, 2.8 hours); a later one, or an
/// element that is not in the program, is not taken.
pub const MAX_EVENT_MS: f64 = 1e7;

impl Move {
    /// As the look-ahead sees it, entered at `entry`.
    fn ahead(&self, entry: f64) -> Ahead {
        Ahead {
            length: self.length,
            limits: Limits {
                velocity: self.velocity,
                acceleration: self.acceleration.min(self.deceleration),
                jerk: self.jerk,
            },
            entry,
        }
    }
}

/// `s` where the path starts: the centre of cell 0.
pub(super) fn s0() -> i128 {
    raw(0)
}

impl<'a> Group<'a> {
    /// Prepares every element of `legs` (a G-code program's blocks, or any path given as
    /// blocks) from the origin (all axes at 0) for `axes` limited by
    /// theirs and the path by `own`: an element that cannot be played is refused here,
    /// before anything moves.
    pub fn new(
        legs: &'a [Block],
        axes: &'a [Limits],
        own: Option<PathLimits>,
        format: &Format,
    ) -> Result<Self, PlayError> {
        let mut at = vec![0i64; axes.len()];
        let mut planned = Vec::new();
        let mut geometries = Vec::new();
        // The path length register: the host axis's positions (half its range, a cell per
        // element for the fitting).
        let most = format.physical_max(Quantity::Position) * 0.5;
        let mut total = 0.0;
        for leg in legs {
            let line = leg.line;
            let prepared = prepare(&at, std::slice::from_ref(&leg.element))
                .map_err(|source| PlayError::Path { line, source })?;
            let g = &prepared.geometries()[0];
            let physical = g.scaled(format.position_lsb);
            let geometric =
                element_limits(&physical, axes, f64::INFINITY).ok_or(PlayError::Still { line })?;
            geometries.push(physical.clone());
            let limits = Limits {
                velocity: geometric.velocity.min(leg.feed.unwrap_or(f64::INFINITY)),
                ..geometric
            };
            let length = prepared.length_physical(format.position_lsb);
            total += length + format.position_lsb;
            if total > most {
                return Err(PlayError::TooLong {
                    line,
                    length: total,
                    most,
                });
            }
            let frames = frames(
                &at,
                &leg.element,
                g,
                prepared.length() as f64 / 2f64.powi(FRAC_BITS as i32),
            );
            planned.push(Planned {
                limits,
                cap: geometric.velocity,
                length,
                frames,
                prepared,
                junction: 0.0,
            });
            at = leg.element.to().to_vec();
        }
        // Each junction's speed (0 from rest, at a corner, into or out of a rapid). On a line
        // that meets another element at speed, an axis whose direction share or curvature
        // changes there keeps half of its acceleration and jerk for that change, as an arc
        // keeps half for its centripetal terms (`snapgen_plan::path::junction`).
        let mut spiked = vec![vec![false; axes.len()]; planned.len()];
        for k in 1..planned.len() {
            if legs[k].feed.is_none() || legs[k - 1].feed.is_none() {
                continue;
            }
            let (before, after) = (&planned[k - 1].frames.1, &planned[k].frames.0);
            let v = junction_speed(before, after, axes, format.ts, format.position_lsb);
            if v > 0.0 {
                let changes: Vec<bool> = (0..axes.len())
                    .map(|i| {
                        before.direction[i] != after.direction[i]
                            || before.curvature[i] != after.curvature[i]
                    })
                    .collect();
                for e in [k - 1, k] {
                    for (s, &c) in spiked[e].iter_mut().zip(&changes) {
                        *s |= c;
                    }
                }
            }
            planned[k].junction = v;
        }
        for (k, leg) in legs.iter().enumerate() {
            if matches!(leg.element, Element::Line { .. }) && spiked[k].contains(&true) {
                let halved: Vec<Limits> = axes
                    .iter()
                    .zip(&spiked[k])
                    .map(|(l, &h)| {
                        let f = if h { 0.5 } else { 1.0 };
                        Limits {
                            velocity: l.velocity,
                            acceleration: l.acceleration * f,
                            jerk: l.jerk * f,
                        }
                    })
                    .collect();
                let p = &mut planned[k];
                if let Some(l) = element_limits(&geometries[k], &halved, f64::INFINITY) {
                    p.limits.acceleration = l.acceleration;
                    p.limits.jerk = l.jerk;
                }
            }
        }
        let settings = AxisSettings {
            format: *format,
            order: OnlineOrder::Three,
        };
        let origin = ChainState {
            x: s0(),
            v: 0,
            a: 0,
            j: 0,
        };
        Ok(Group {
            legs,
            axes,
            own,
            format: *format,
            planned,
            entries: Vec::new(),
            bounds: Vec::new(),
            stretch: Vec::new(),
            paths: Vec::new(),
            commands: Vec::new(),
            moves: Vec::new(),
            origin_cell: 0,
            total,
            axis: HostAxis::new(settings, 0, origin),
            refused: Vec::new(),
            taken: Vec::new(),
            junction_scale: 1.0,
        })
    }

    /// Where a run entering later continues one at speed, the stretch changes at the
    /// junction (`f0` to `f1`): every moving axis's speed steps by its share times
    /// `|1/f0 − 1/f1|`, on elements that may use their whole limits there; the step is kept
    /// within the share of each limit the elements leave (`1 − MARGIN`). Unbounded when the
    /// stretch does not change.
    fn restretched(&self, end: &Frame, start: &Frame, f0: f64, f1: f64) -> f64 {
        let df = (1.0 / f0 - 1.0 / f1).abs();
        let ts = self.format.ts;
        let mut v = f64::INFINITY;
        for (i, l) in self.axes.iter().enumerate() {
            let step = end.direction[i].abs().max(start.direction[i].abs()) * df;
            if step > 0.0 {
                let room = 1.0 - MARGIN;
                v = v
                    .min(room * l.acceleration * ts / step)
                    .min(room * l.jerk * ts * ts / step);
            }
        }
        v
    }

    /// An element's acceleration, deceleration and jerk on `s`: its geometry's, within the
    /// path's own.
    fn own_limits(&self, l: &Limits) -> (f64, f64, f64) {
        match self.own {
            Some(o) => (
                l.acceleration.min(o.acceleration),
                l.acceleration.min(o.deceleration),
                l.jerk.min(o.jerk),
            ),
            None => (l.acceleration, l.acceleration, l.jerk),
        }
    }

    /// The elements' plans (limits, speed cap, length) in order.
    pub(super) fn planned(&self) -> &[Planned] {
        &self.planned
    }

    /// The entry speed of each element entered so far.
    pub fn entries(&self) -> &[f64] {
        &self.entries
    }

    /// Where each element entered so far ends on `s` (raw, from the start's cell centre).
    pub fn bounds(&self) -> &[i128] {
        &self.bounds
    }

    /// The command of each element entered so far.
    pub fn commands(&self) -> &[usize] {
        &self.commands
    }

    /// The elements up to `last` enter the buffer at tick `at`: their moves on `s`, each
    /// element's entry speed by its junction and the look-ahead over them.
    ///
    /// Each run of elements joined at speed (up to a corner or the batch's end) is fitted
    /// onto `s` with one stretch, so that it ends on a cell's centre (where the chain comes
    /// to rest, exactly) and the axes' speeds do not jump at its junctions; a run that
    /// continues one already entered at speed changes the stretch at its first junction,
    /// which that junction's speed accounts for (a kink of the stretch's change).
    pub fn enter(&mut self, last: usize, at: u64) {
        let mut reqs = Vec::new();
        for cmd in self.moves_for(last) {
            let k = self.axis.submit(cmd);
            // A move whose inputs were refused is in Error already.
            if !self.axis.commands[k].outcome.is_final() {
                reqs.push(Request::Command(k));
            }
        }
        if reqs.is_empty() {
            return;
        }
        let (change, refused) = self.axis.plan_batch(at, &reqs);
        if let Some(c) = change {
            self.axis.apply(c);
        }
        // As the driver does: a move the planner refused is in Error.
        for (r, why) in refused {
            if let Request::Command(k) = r {
                self.axis.commands[k].outcome = Outcome::Error(why.error);
            }
        }
    }

    /// The moves on `s` that make the elements up to `last` enter ([`Group::enter`]), in
    /// order: the host axis's next commands (its `k`-th command is the group's `k`-th move).
    pub fn moves_for(&mut self, last: usize) -> Vec<MotionCommand> {
        let first = self.entries.len();
        if last < first || last >= self.legs.len() {
            return Vec::new();
        }
        let one = 1i128 << FRAC_BITS;
        // The runs and their stretches.
        let mut start = self.bounds.last().copied().unwrap_or(0);
        let mut k = first;
        while k <= last {
            let mut b = k;
            while b < last && self.planned[b + 1].junction > 0.0 {
                b += 1;
            }
            let whole: i128 = (k..=b).map(|i| self.planned[i].prepared.length()).sum();
            // The next cell centre at or past the run's length: stretched by at most a cell,
            // never shrunk (the axes then move at most as far as `s`, and a chain that comes
            // to rest within half a cell of the end stays in the end point's cell).
            let end = (((start + whole + one - 1) >> FRAC_BITS) << FRAC_BITS).max(start + one);
            let f = (end - start) as f64 / whole.max(1) as f64;
            let mut sum = 0i128;
            let mut from = start;
            for i in k..=b {
                sum += self.planned[i].prepared.length();
                let to = if i == b {
                    end
                } else {
                    let share = (I256::from(sum) * I256::from(end - start)) / I256::from(whole);
                    (start + share.as_i128()).max(from + 1)
                };
                self.paths.push(self.planned[i].prepared.fit(to - from));
                self.bounds.push(to);
                self.stretch.push(f);
                from = to;
            }
            start = end;
            k = b + 1;
        }
        // Each new element's junction speed, with the stretches (0: from rest or a corner).
        let junctions: Vec<f64> = (first..=last)
            .map(|k| {
                let p = &self.planned[k];
                if p.junction <= 0.0 {
                    return 0.0;
                }
                let q = &self.planned[k - 1];
                let (f0, f1) = (self.stretch[k - 1], self.stretch[k]);
                self.junction_scale
                    * junction_speed(
                        &q.frames.1.stretched(f0),
                        &p.frames.0.stretched(f1),
                        self.axes,
                        self.format.ts,
                        self.format.position_lsb,
                    )
                    .min(self.restretched(&q.frames.1, &p.frames.0, f0, f1))
                    .min(p.cap)
                    .min(q.cap)
            })
            .collect();
        // The moves: an element joined at speed to a short one (or short itself) shares its
        // move, with the smallest limits of the two and its junction's speed as a speed limit.
        let mut moves: Vec<Move> = Vec::new();
        for k in first..=last {
            let p = &self.planned[k];
            let (acceleration, deceleration, jerk) = self.own_limits(&p.limits);
            let junction = junctions[k - first];
            let short = |length: f64, speed: f64| length < speed * self.format.ts * SHORT_TICKS;
            // Joined while the move so far is short (a long move is not slowed to a short
            // element's speed: the short one starts a move of its own); the last element of
            // the batch, short, joins the move before it.
            let end_of_batch = k == last;
            let join = moves.last().is_some_and(|m| {
                junction > 0.0
                    && (short(m.length, m.velocity.min(junction))
                        || (end_of_batch && short(p.length, p.limits.velocity.min(junction))))
            });
            if join {
                let m = moves.last_mut().expect("joined to a move");
                m.last = k;
                m.length += p.length;
                m.velocity = m.velocity.min(p.limits.velocity).min(junction);
                m.cap = m.cap.min(p.cap).min(junction);
                m.acceleration = m.acceleration.min(acceleration);
                m.deceleration = m.deceleration.min(deceleration);
                m.jerk = m.jerk.min(jerk);
            } else {
                moves.push(Move {
                    last: k,
                    length: p.length,
                    velocity: p.limits.velocity,
                    cap: p.cap,
                    acceleration,
                    deceleration,
                    jerk,
                    junction,
                });
            }
        }
        // The look-ahead over the move before (its entry fixed) and the new ones.
        let fixed = self.moves.last().copied();
        let window: Vec<Ahead> = fixed
            .into_iter()
            .chain(moves.iter().map(|m| m.ahead(m.junction)))
            .collect();
        let skip = window.len() - moves.len();
        let speeds = lookahead(&window);
        let mut out = Vec::new();
        let mut k = first;
        for (m, &entry) in moves.iter().zip(&speeds[skip..]) {
            // The cell the move's last element ends in (`s` from the start's cell centre).
            let cell = self.origin_cell + ((s0() + self.bounds[m.last]) >> FRAC_BITS);
            let cmd = MotionCommand::MoveAbsolute {
                position: cell as f64 * self.format.position_lsb,
                velocity: m.velocity,
                acceleration: m.acceleration,
                deceleration: m.deceleration,
                jerk: m.jerk,
                buffer_mode: if entry > 0.0 {
                    BufferMode::BlendingLow
                } else {
                    BufferMode::Buffered
                },
                path: Some(OnPath {
                    velocity: m.cap,
                    entry,
                }),
            };
            let c = self.moves.len();
            self.moves.push(m.ahead(entry));
            for i in k..=m.last {
                self.entries
                    .push(if i == k { entry } else { junctions[i - first] });
                self.commands.push(c);
            }
            k = m.last + 1;
            out.push(cmd);
        }
        out
    }

    /// The override becomes `k` at tick `at`; refused: why.
    pub fn set_override(&mut self, k: f64, at: u64) -> Result<(), AxisErrorId> {
        let (change, refused) = self.axis.plan_batch(at, &[Request::Override(k)]);
        if let Some(c) = change {
            self.axis.apply(c);
        }
        match refused.into_iter().next() {
            Some((_, r)) => Err(r.error),
            None => Ok(()),
        }
    }

    /// Whether event `e` can be taken: an element of the program not yet entered, a time from
    /// 0 to [`MAX_EVENT_MS`], a length (when given) that is a finite number ≥ 0.
    pub fn takes(&self, e: &PathEvent) -> bool {
        let known = match e.action {
            PathAction::Enter(k) => k < self.legs.len() && k >= self.entries.len(),
            PathAction::Override(k) => k.is_finite(),
        };
        known
            && e.at_ms.is_finite()
            && (0.0..=MAX_EVENT_MS).contains(&e.at_ms)
            && e.at_length.is_none_or(|l| l.is_finite() && l >= 0.0)
    }

    /// Plays `events` in order (each at its time, or later when its length is reached),
    /// then until the path has come to rest.
    pub fn play(&mut self, events: &[PathEvent]) {
        let ts = self.format.ts;
        let mut now = 0u64;
        for (i, e) in events.iter().enumerate() {
            if !self.takes(e) {
                self.taken.push(None);
                continue;
            }
            let due = ((e.at_ms * 1e-3 / ts).round().max(0.0) as u64).max(now);
            let due = match e.at_length {
                None => Some(due),
                Some(len) => self.reaches(len, due),
            };
            let Some(mut due) = due else {
                self.taken.push(None);
                continue;
            };
            // An override that raises the speed while a stop on the path is still braking acts
            // once it has come to rest (a replan from its last ticks may swing back).
            if matches!(e.action, PathAction::Override(k) if k > 0.0) {
                if let Some(p) = self
                    .axis
                    .timeline
                    .parts
                    .iter()
                    .find(|p| p.paused && p.start_tick <= due && due < p.end_tick())
                {
                    due = p.end_tick();
                }
            }
            now = due;
            self.taken.push(Some(due));
            match e.action {
                PathAction::Enter(k) => self.enter(k, due),
                PathAction::Override(k) => {
                    if let Err(r) = self.set_override(k, due) {
                        self.refused.push((i, r));
                    }
                }
            }
            self.axis.update(due);
        }
        self.axis.update(self.axis.timeline.end_tick());
    }

    /// The first tick from `from` on which `s` has reached `length` (units), if it does.
    fn reaches(&self, length: f64, from: u64) -> Option<u64> {
        let f = &self.format;
        let cell = (length / f.position_lsb).round() as i128;
        let t = &self.axis.timeline;
        let (t0, s) = t.origin;
        let program = t.played(t.end_tick().max(from));
        Trace::new(&program, s, f.widths)
            .map(|k| (t0 + k.tick, k.state.x))
            .find(|&(tick, x)| tick >= from && f.output_lsb(x - s0()) >= cell)
            .map(|(tick, _)| tick)
    }

    /// The path length on every tick from the start to the end of the timeline (raw `s`).
    pub fn lengths(&self) -> Vec<i128> {
        let t = &self.axis.timeline;
        let (_, s) = t.origin;
        let program = t.played(t.end_tick());
        Trace::new(&program, s, self.format.widths)
            .map(|k| k.state.x)
            .collect()
    }

    /// Every axis on every tick (raw), `s` mapped through the entered elements' rules.
    pub fn trace(&self) -> Vec<Vec<i128>> {
        self.map(&self.lengths())
    }

    /// Every axis at each path length of `lengths` (raw `s`, the chain's register: from a
    /// board, its position register), through the entered elements' rules.
    pub fn map(&self, lengths: &[i128]) -> Vec<Vec<i128>> {
        let path = self.path();
        let origin: Vec<i128> = self.axes.iter().map(|_| raw(0)).collect();
        lengths
            .iter()
            .map(|&s| path.at(self.along(s)).unwrap_or_else(|| origin.clone()))
            .collect()
    }

    /// The entered elements as one path, its length measured from its start (the rules
    /// [`Group::map`] applies at [`Group::along`] of a path length register).
    pub fn path(&self) -> Path {
        let segments = self
            .paths
            .iter()
            .flat_map(|p| p.segments.iter().cloned())
            .collect();
        Path { segments }
    }

    /// The path length register's value (raw) where the path starts: [`Group::along`] is 0
    /// there.
    pub fn start_register(&self) -> i128 {
        (self.origin_cell << FRAC_BITS) + s0()
    }

    /// How far along the path (raw, from its start's cell centre) a path length register of
    /// `s` is.
    pub fn along(&self, s: i128) -> i128 {
        s - self.start_register()
    }

    /// The position (units) of `length` units along the path on the path length register.
    pub fn position_of(&self, length: f64) -> f64 {
        self.origin_cell as f64 * self.format.position_lsb + length
    }

    /// The group for a board whose position register (`s`) stands at `x` (raw) at rest: the
    /// path must fit the register from there (else [`PlayError::TooLong`], before anything
    /// moves).
    pub fn on_board(mut self, x: i128) -> Result<Self, PlayError> {
        self.origin_cell = x >> FRAC_BITS;
        let most = self.format.physical_max(Quantity::Position) * 0.5;
        let from = (self.origin_cell as f64 * self.format.position_lsb).abs();
        if from + self.total > most {
            return Err(PlayError::TooLong {
                line: self.legs.last().map_or(0, |b| b.line),
                length: from + self.total,
                most,
            });
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::verify;

    const F: Format = Format {
        ts: 1e-4,
        position_lsb: 1e-3,
        ..snapgen_model::DEFAULT_FORMAT
    };
    const AXIS: Limits = Limits {
        velocity: 250.0,
        acceleration: 5000.0,
        jerk: 2e6,
    };

    /// 40 mm along X, then a quarter turn of radius 20 mm counter-clockwise (tangent), then
    /// 10 mm along Y (tangent again), at `feed`.
    fn chain(feed: f64) -> Vec<Block> {
        let b = |line, element| Block {
            line,
            element,
            feed: Some(feed),
        };
        vec![
            b(
                1,
                Element::Line {
                    to: vec![40_000, 0],
                },
            ),
            b(
                2,
                Element::Arc {
                    plane: [0, 1],
                    centre: [40_000, 20_000],
                    ccw: true,
                    to: vec![60_000, 20_000],
                },
            ),
            b(
                3,
                Element::Line {
                    to: vec![60_000, 30_000],
                },
            ),
        ]
    }

    fn enter(at_ms: f64, at_length: Option<f64>, last: usize) -> PathEvent {
        PathEvent {
            at_ms,
            at_length,
            action: PathAction::Enter(last),
        }
    }

    fn over(at_ms: f64, k: f64) -> PathEvent {
        PathEvent {
            at_ms,
            at_length: None,
            action: PathAction::Override(k),
        }
    }

    /// The path's speed on each tick (raw `s` per tick).
    fn speeds(run: &crate::path::Run) -> Vec<i128> {
        run.lengths.windows(2).map(|w| w[1] - w[0]).collect()
    }

    #[test]
    fn tangent_elements_entering_at_speed_join_without_stopping_and_stay_within_limits() {
        let blocks = chain(150.0);
        // The arc enters at 10 mm, the last line at 45 mm; the override changes twice.
        let events = [
            enter(0.0, None, 0),
            enter(0.0, Some(10.0), 1),
            over(150.0, 1.6),
            enter(0.0, Some(45.0), 2),
            over(400.0, 0.3),
        ];
        let run = crate::path::play_events(&blocks, &[AXIS; 2], None, &F, &events).unwrap();
        assert!(run.taken.iter().all(Option::is_some), "{:?}", run.taken);
        let c = verify(&run, &blocks, &[AXIS; 2], &F);
        assert_eq!((c.deviation, c.exceeded), (None, None));
        // Never at rest between the start and the end: the junctions are passed at speed,
        // and the override cut (in the arc's final brake, too late to slow to its new speed's
        // blend) does not reverse the path: the brake plays on.
        let v = speeds(&run);
        let moving = v.iter().position(|&x| x > 0).unwrap();
        let last = v.iter().rposition(|&x| x > 0).unwrap();
        assert!(v[moving..=last].iter().all(|&x| x > 0));
        assert!(run.lengths.windows(2).all(|w| w[1] >= w[0]));
        assert!(run.blocks[1].entry > 10.0 && run.blocks[2].entry > 10.0);
        // The end exactly on its cell.
        assert_eq!(run.end_cells(), vec![60_000, 30_000]);
    }

    #[test]
    fn the_junction_limit_is_what_keeps_the_curvature_jump_within_the_jerk() {
        let blocks = chain(250.0);
        let events = [enter(0.0, None, 2)];
        let play = |scale| {
            let mut g = Group::new(&blocks, &[AXIS; 2], None, &F).unwrap();
            g.junction_scale = scale;
            g.play(&events);
            let run = crate::path::collect(&g, &g.axis, &blocks, g.lengths()).unwrap();
            (g.entries().to_vec(), run)
        };
        let (entries, run) = play(1.0);
        let check = |run: &crate::path::Run| verify(run, &blocks, &[AXIS; 2], &F);
        assert_eq!(check(&run).exceeded, None);
        // √(½·0.98·2e6·1e-4·20) = 44.3 mm/s at both junctions.
        assert!((entries[1] - 44.27).abs() < 0.01, "{entries:?}");
        // Passed 2.5 times faster, the curvature jump exceeds a jerk limit.
        let (_, fast) = play(2.5);
        let e = check(&fast)
            .exceeded
            .expect("the jerk at the junction is seen");
        assert!(
            format!("{e:?}").contains("Jerk") || format!("{e:?}").contains("jerk"),
            "{e:?}"
        );
    }

    #[test]
    fn a_full_override_never_passes_an_elements_speed_limit() {
        // A feed the lines cannot take at 200 %: their cap (the axes' velocity) holds, and the
        // arc's (its centripetal limit) too.
        let blocks = chain(250.0);
        let events = [over(0.0, 2.0), enter(0.0, None, 2)];
        let run = crate::path::play_events(&blocks, &[AXIS; 2], None, &F, &events).unwrap();
        let c = verify(&run, &blocks, &[AXIS; 2], &F);
        assert_eq!((c.deviation, c.exceeded), (None, None));
        // The axis's own velocity limit is the line's cap: 0.98 · 250.
        let top = speeds(&run).into_iter().max().unwrap() as f64 / 2f64.powi(FRAC_BITS as i32)
            * F.position_lsb
            / F.ts;
        assert!(top <= 0.98 * 250.0 + 1e-6 && top > 200.0, "{top}");
    }
}
