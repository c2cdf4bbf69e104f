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
use snapgen_plan::path::speed::{element_limits, Geometry, Limits, MARGIN};
use snapgen_plan::path::{prepare, raw, Element, Prepared};

use crate::axis::compose::Request;
use crate::axis::{
    AxisErrorId, AxisSettings, BufferMode, Goal, HostAxis, MotionCommand, OnPath, Outcome,
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
#[derive(Clone)]
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
    /// Its limits before a junction took a share of them ([`Group::join`]).
    base: Limits,
    /// The path's own limits on it, when given.
    own: Option<PathLimits>,
    /// Its geometry (units).
    geometry: Geometry,
    /// The axes that keep half their limits for a junction at speed.
    spiked: Vec<bool>,
}

/// The group playing a program.
#[derive(Clone)]
pub struct Group {
    legs: Vec<Block>,
    axes: Vec<Limits>,
    /// The cells (LSB) every axis starts in.
    from: Vec<i64>,
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
    /// The board's controlled stop every move keeps within ([`Group::for_board_stop`]).
    stop: Option<BoardStop>,
}

/// The share of a board's stop limits the moves leave free ([`Group::for_board_stop`]): their
/// deceleration and jerk are at most `1 − STOP_MARGIN` of the stop's. The fabric's stop law and
/// the planner brake differently tick by tick; a stop taken in the middle of a long, soft brake
/// at the stop's own limits came to rest half a cell past the corner the brake was for (found
/// by the property test in `tests/tests/path_online.rs`). Braking harder than the moves by this
/// margin, it comes to rest before; only in a brake's last ticks, where the margin is worth
/// less than the law's rounding, can it land a hair past (docs/PATH.md).
pub const STOP_MARGIN: f64 = 0.02;

/// A board's controlled stop on the path length (units/s², /s³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardStop {
    /// Deceleration.
    pub deceleration: f64,
    /// Jerk.
    pub jerk: f64,
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

impl Group {
    /// Prepares every element of `legs` (a G-code program's blocks, or any path given as
    /// blocks) from the origin (all axes at 0) for `axes` limited by theirs and the path by
    /// `own`: an element that cannot be played is refused here, before anything moves. A
    /// block joins the one before at speed where both have a feed (no rapid) and their
    /// junction allows it.
    pub fn new(
        legs: &[Block],
        axes: &[Limits],
        own: Option<PathLimits>,
        format: &Format,
    ) -> Result<Self, PlayError> {
        let mut g = Group::starting_at(&vec![0; axes.len()], axes, format);
        for leg in legs {
            g.push(leg.clone(), true, own)?;
        }
        Ok(g)
    }

    /// A group with no element yet, its axes in the cells `from` (LSB) for `axes` limited by
    /// theirs: elements join it by [`Group::push`].
    pub fn starting_at(from: &[i64], axes: &[Limits], format: &Format) -> Self {
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
        Group {
            legs: Vec::new(),
            axes: axes.to_vec(),
            from: from.to_vec(),
            format: *format,
            planned: Vec::new(),
            entries: Vec::new(),
            bounds: Vec::new(),
            stretch: Vec::new(),
            paths: Vec::new(),
            commands: Vec::new(),
            moves: Vec::new(),
            origin_cell: 0,
            total: 0.0,
            axis: HostAxis::new(settings, 0, origin),
            refused: Vec::new(),
            taken: Vec::new(),
            junction_scale: 1.0,
            stop: None,
        }
    }

    /// Prepares `leg` as the path's next element, within the path's `own` limits when given:
    /// refused (nothing changes) if it cannot be played. With `blend`, it joins the element
    /// before at the speed their junction allows (0 at a corner, from or into a rapid); an
    /// element already entered is never replanned, so a junction that needs the line before
    /// it to keep part of an axis's limits (it was entered with them whole) is a stop.
    pub fn push(
        &mut self,
        leg: Block,
        blend: bool,
        own: Option<PathLimits>,
    ) -> Result<(), PlayError> {
        let format = self.format;
        let at = self
            .legs
            .last()
            .map_or_else(|| self.from.clone(), |b| b.element.to().to_vec());
        let line = leg.line;
        let prepared = prepare(&at, std::slice::from_ref(&leg.element))
            .map_err(|source| PlayError::Path { line, source })?;
        let g = &prepared.geometries()[0];
        let physical = g.scaled(format.position_lsb);
        let geometric = element_limits(&physical, &self.axes, f64::INFINITY)
            .ok_or(PlayError::Still { line })?;
        let base = Limits {
            velocity: geometric.velocity.min(leg.feed.unwrap_or(f64::INFINITY)),
            ..geometric
        };
        // The path length register: the host axis's positions (half its range, a cell per
        // element for the fitting).
        let most = format.physical_max(Quantity::Position) * 0.5;
        let length = prepared.length_physical(format.position_lsb);
        let total = self.total + length + format.position_lsb;
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
        self.total = total;
        self.planned.push(Planned {
            limits: base,
            base,
            own,
            cap: geometric.velocity,
            length,
            frames,
            prepared,
            junction: 0.0,
            geometry: physical,
            spiked: vec![false; self.axes.len()],
        });
        self.legs.push(leg);
        let k = self.legs.len() - 1;
        if k > 0 && blend && self.legs[k].feed.is_some() && self.legs[k - 1].feed.is_some() {
            self.join(k);
        }
        self.relimit(k);
        Ok(())
    }

    /// Element `k`'s junction with the one before, at speed where it allows (0: a corner).
    /// On a line that meets another element at speed, an axis whose direction share or
    /// curvature changes there keeps half of its acceleration and jerk for that change, as
    /// an arc keeps half for its centripetal terms (`snapgen_plan::path::junction`).
    fn join(&mut self, k: usize) {
        let (before, after) = (&self.planned[k - 1].frames.1, &self.planned[k].frames.0);
        let v = junction_speed(
            before,
            after,
            &self.axes,
            self.format.ts,
            self.format.position_lsb,
        );
        if v <= 0.0 {
            return;
        }
        let changes: Vec<bool> = (0..self.axes.len())
            .map(|i| {
                before.direction[i] != after.direction[i]
                    || before.curvature[i] != after.curvature[i]
            })
            .collect();
        let line_before = matches!(self.legs[k - 1].element, Element::Line { .. });
        let entered = k - 1 < self.entries.len();
        let spiked = &self.planned[k - 1].spiked;
        if entered && line_before && changes.iter().zip(spiked).any(|(&c, &h)| c && !h) {
            return;
        }
        for e in [k - 1, k] {
            for (h, &c) in self.planned[e].spiked.iter_mut().zip(&changes) {
                *h |= c;
            }
        }
        if !entered {
            self.relimit(k - 1);
        }
        self.planned[k].junction = v;
    }

    /// Element `k`'s limits: its own, a line's acceleration and jerk from the axes' halves
    /// where a junction at speed changes them ([`Group::join`]).
    fn relimit(&mut self, k: usize) {
        let halved: Vec<Limits> = self
            .axes
            .iter()
            .zip(&self.planned[k].spiked)
            .map(|(l, &h)| {
                let f = if h { 0.5 } else { 1.0 };
                Limits {
                    velocity: l.velocity,
                    acceleration: l.acceleration * f,
                    jerk: l.jerk * f,
                }
            })
            .collect();
        let line = matches!(self.legs[k].element, Element::Line { .. });
        let p = &mut self.planned[k];
        p.limits = p.base;
        if line && p.spiked.contains(&true) {
            if let Some(l) = element_limits(&p.geometry, &halved, f64::INFINITY) {
                p.limits.acceleration = l.acceleration;
                p.limits.jerk = l.jerk;
            }
        }
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
    fn own_limits(l: &Limits, own: Option<PathLimits>) -> (f64, f64, f64) {
        match own {
            Some(o) => (
                l.acceleration.min(o.acceleration),
                l.acceleration.min(o.deceleration),
                l.jerk.min(o.jerk),
            ),
            None => (l.acceleration, l.acceleration, l.jerk),
        }
    }

    /// Element `p`'s acceleration, deceleration and jerk on `s` as its move is planned: its
    /// own ([`Group::own_limits`]), the deceleration and jerk within a board's stop when
    /// one is set ([`Group::for_board_stop`]).
    fn move_limits(&self, p: &Planned) -> (f64, f64, f64) {
        let (a, d, j) = Self::own_limits(&p.limits, p.own);
        match self.stop {
            Some(s) => {
                let k = 1.0 - STOP_MARGIN;
                (a, d.min(k * s.deceleration), j.min(k * s.jerk))
            }
            None => (a, d, j),
        }
    }

    /// The largest controlled stop (deceleration and jerk on `s`, units/s², /s³) within every
    /// axis's limits on every element of the path: the smallest that the elements' geometry
    /// allows (the path's own limits are the moves', not the stop's: a stop may brake harder
    /// than a move, within the axes).
    pub fn stop_limits(&self) -> BoardStop {
        let mut s = BoardStop {
            deceleration: f64::INFINITY,
            jerk: f64::INFINITY,
        };
        for p in &self.planned {
            s.deceleration = s.deceleration.min(p.limits.acceleration);
            s.jerk = s.jerk.min(p.limits.jerk);
        }
        s
    }

    /// The group for a board whose controlled stop (the group stop: the chain decelerates on
    /// `s` by the fabric's own law, from whatever state it is in) takes [`Group::stop_limits`]:
    /// every move decelerates and jerks within them too, [`STOP_MARGIN`] below. A stop then
    /// stays within every axis's limits on every element (no element allows less); braking at
    /// once and harder than the moves, it comes to rest before they would, never past a corner
    /// or the path's end at speed, where the axes cannot follow; ramping its acceleration down
    /// faster than they do, it never speeds up past them. Begun in a brake's last ticks before
    /// a corner, the fabric's law (whose last ticks land differently from the planner's) can
    /// carry it a hair past (measured: under 0.08 of a cell over 7 200 stops on random paths),
    /// inside the corner's cell (a corner is a cell centre), so no axis's output moves
    /// ([`crate::path::verify_stop`] checks a stop). Call it once every element has been
    /// pushed.
    pub fn for_board_stop(mut self) -> Self {
        self.stop = Some(self.stop_limits());
        self
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
                        &self.axes,
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
            let (acceleration, deceleration, jerk) = self.move_limits(p);
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

    /// The tick an override to `k` asked at `due` is taken: an override that raises the
    /// speed while a stop on the path is still braking acts once it has come to rest (a
    /// replan from its last ticks may swing back).
    pub fn override_due(&self, k: f64, due: u64) -> u64 {
        let braking = self
            .axis
            .timeline
            .parts
            .iter()
            .find(|p| p.paused && p.start_tick <= due && due < p.end_tick());
        match braking {
            Some(p) if k > 0.0 => p.end_tick(),
            _ => due,
        }
    }

    /// MC_Halt on the path length from tick `at`: every move still to play is aborted and `s`
    /// comes to rest on the path with `deceleration` and `jerk` (units/s², /s³), cut to the
    /// limits of every element it may still pass (their geometry's and the path's own), so
    /// that no axis exceeds its limits while it brakes. It never passes the path's next stop
    /// (a corner, the end of what has entered): where it would, the moves play on as planned
    /// to that stop (they brake there within their limits) and everything after it is
    /// aborted. The host axis's halt command (None: the path stops at its next stop), or why
    /// it was refused.
    pub fn halt(
        &mut self,
        deceleration: f64,
        jerk: f64,
        at: u64,
    ) -> Result<Option<usize>, AxisErrorId> {
        let s = self.axis.timeline.state_at(at, &self.format).x;
        let here = self.along(s);
        let n = self.entries.len();
        let first = self.bounds.partition_point(|&b| b <= here);
        // The next stop: the end of the first element from here whose successor starts from
        // rest, or of the last one entered.
        let last = (first..n)
            .find(|&k| self.rests_after(k))
            .unwrap_or(n.saturating_sub(1));
        let (mut dm, mut jm) = (f64::INFINITY, f64::INFINITY);
        for p in self.planned.iter().take(last + 1).skip(first) {
            let (_, dd, jj) = self.move_limits(p);
            (dm, jm) = (dm.min(dd), jm.min(jj));
        }
        let stop = self.bounds.get(last).copied();
        let planned = |d: f64, j: f64| -> Result<(HostAxis, usize), AxisErrorId> {
            let mut axis = self.axis.clone();
            let k = axis.submit(MotionCommand::Halt {
                deceleration: d,
                jerk: j,
            });
            if let Outcome::Error(e) = &axis.commands[k].outcome {
                return Err(e.clone());
            }
            let (change, refused) = axis.plan_batch(at, &[Request::Command(k)]);
            if let Some((_, why)) = refused.into_iter().next() {
                return Err(why.error);
            }
            if let Some(c) = change {
                axis.apply(c);
            }
            Ok((axis, k))
        };
        // The farthest the path length goes on `axis`'s timeline (a halt begun braking harder
        // than its own deceleration may pass its rest and come back).
        let reaches = |axis: &HostAxis| {
            let t = &axis.timeline;
            let (_, origin) = t.origin;
            let program = t.played(t.end_tick());
            Trace::new(&program, origin, self.format.widths)
                .map(|k| self.along(k.state.x))
                .max()
                .unwrap_or(here)
        };
        let Some(b) = stop else {
            let (axis, k) = planned(deceleration, jerk)?;
            self.axis = axis;
            return Ok(Some(k));
        };
        let rests = |axis: &HostAxis| {
            let t = &axis.timeline;
            self.along(t.state_at(t.end_tick(), &self.format).x)
        };
        // As given (cut to the elements' limits), else with their whole limits; one that
        // passes where it comes to rest and turns back is not taken.
        for (d, j) in [(deceleration.min(dm), jerk.min(jm)), (dm, jm)] {
            let (axis, k) = planned(d, j)?;
            let far = reaches(&axis);
            if far <= b && far == rests(&axis) {
                self.axis = axis;
                return Ok(Some(k));
            }
        }
        // Up to the stop as planned, when its move plays to rest there; or the stop already
        // planned (an earlier halt, an override of 0) when it rests before. What follows is
        // aborted.
        let c = self.commands[last];
        let parts = &self.axis.timeline.parts;
        let whole = parts.iter().rposition(|p| p.command == c).filter(|&i| {
            let p = &parts[i];
            !p.cut
                && !p.paused
                && matches!(p.goal, Goal::Position { velocity, .. } if velocity == 0.0)
        });
        if let Some(i) = whole {
            self.axis.timeline.parts.truncate(i + 1);
        } else if reaches(&self.axis) > b {
            return Err(AxisErrorId::Planner(format!(
                "the path cannot come to rest before its next stop {} units ahead: give a higher deceleration",
                (b - here) as f64 / 2f64.powi(FRAC_BITS as i32) * self.format.position_lsb
            )));
        }
        let skip = if whole.is_some() { c + 1 } else { 0 };
        for rec in self.axis.commands.iter_mut().skip(skip) {
            if rec.outcome.busy() {
                rec.outcome = Outcome::CommandAborted;
            }
        }
        Ok(None)
    }

    /// The board's format the group plans in.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Whether the path comes to rest at the end of entered element `k`: the last one
    /// entered, or one whose successor starts from rest (a corner, a rapid).
    pub fn rests_after(&self, k: usize) -> bool {
        k + 1 >= self.entries.len() || self.entries[k + 1] <= 0.0
    }

    /// The elements pushed so far, in order.
    pub fn blocks(&self) -> &[Block] {
        &self.legs
    }

    /// The cells (LSB) the axes start in.
    pub fn from(&self) -> &[i64] {
        &self.from
    }

    /// Where the path ends so far (cells, LSB): its last element's end, or its start.
    pub fn end(&self) -> &[i64] {
        self.legs.last().map_or(&self.from, |b| b.element.to())
    }

    /// The outcome of the move element `k` is in, once it has entered.
    pub fn outcome_of(&self, k: usize) -> Option<&Outcome> {
        let c = *self.commands.get(k)?;
        self.axis.commands.get(c).map(|r| &r.outcome)
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
            if let PathAction::Override(k) = e.action {
                due = self.override_due(k, due);
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
        let origin: Vec<i128> = self.from.iter().map(|&c| raw(c)).collect();
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
pub(super) mod tests {
    use super::*;
    use crate::path::verify;

    /// The tests' format: 100 µs ticks, 1 µm cells.
    pub(in crate::path) const F: Format = Format {
        ts: 1e-4,
        position_lsb: 1e-3,
        ..snapgen_model::DEFAULT_FORMAT
    };
    /// The tests' axes.
    pub(in crate::path) const AXIS: Limits = Limits {
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

    /// The chain with a corner after it: back along X to (20, 30).
    fn cornered(feed: f64) -> Vec<Block> {
        let mut blocks = chain(feed);
        blocks.push(Block {
            line: 4,
            element: Element::Line {
                to: vec![20_000, 30_000],
            },
            feed: Some(feed),
        });
        blocks
    }

    /// Ticks between the stops tried (1 by hand: every tick).
    const STRIDE: usize = 97;

    /// [`crate::path::verify_stop`] after every [`STRIDE`]th tick of `g`'s path with the
    /// board's `stop`: the farthest past a rest of the path, or the first failure.
    fn stops(g: &Group, blocks: &[Block], stop: BoardStop) -> Result<f64, String> {
        let mut farthest = 0.0f64;
        for t in (0..g.lengths().len()).step_by(STRIDE) {
            let past = crate::path::verify_stop(g, blocks, &[AXIS; 2], stop, t as u64)
                .map_err(|e| format!("stop after tick {t}: {e}"))?;
            farthest = farthest.max(past);
        }
        Ok(farthest)
    }

    #[test]
    fn a_board_stop_from_any_tick_stays_on_the_path_within_every_limit() {
        let blocks = cornered(250.0);
        let events = [enter(0.0, None, 3)];
        let mut g = Group::new(&blocks, &[AXIS; 2], None, &F)
            .unwrap()
            .for_board_stop();
        g.play(&events);
        let stop = g.stop_limits();
        // Half the axes' (0.98 of it): the arc keeps half for its centripetal terms.
        assert!((stop.deceleration - 0.49 * 5000.0).abs() < 1.0, "{stop:?}");
        // Measured on every tick by hand (`STRIDE` 1): 0.043 of a cell.
        let past = stops(&g, &blocks, stop).unwrap();
        assert!(past < crate::path::STOP_PAST_MAX, "{past}");
        // Not blind: without the moves kept within it, the same stop exceeds an axis's limits
        // (begun while a line accelerates harder than it ramps down, it speeds an axis past
        // its velocity limit: after tick 499, by hand); and a stop at the moves' largest
        // limits (the driver's default for one axis) exceeds an axis's limits on the arc.
        let mut free = Group::new(&blocks, &[AXIS; 2], None, &F).unwrap();
        free.play(&events);
        let e = stops(&free, &blocks, stop).unwrap_err();
        assert!(e.contains("Exceeded"), "{e}");
        let largest = BoardStop {
            deceleration: 5000.0,
            jerk: 2e6,
        };
        let e = stops(&g, &blocks, largest).unwrap_err();
        assert!(e.contains("Exceeded"), "{e}");
    }
}
