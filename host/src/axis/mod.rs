//! A host-side axis that speaks PLCopen Motion Control: MC_MoveAbsolute with its buffer modes,
//! MC_MoveVelocity, MC_Halt and a feed override, each command reporting Busy, Active, Done
//! (InVelocity for MC_MoveVelocity), CommandAborted and Error with an ErrorID, as the
//! standard's function blocks do.
//!
//! The host computes, the fabric integrates. The axis keeps the [`Timeline`] the fabric plays:
//! parts, each one command's piece of trajectory, planned with [`snapgen_plan::online::plan_online`]
//! from the exact state it starts in. Because the chain is bit-exact, the state at any future
//! tick is known; a change (a new command, an override) is planned from the state at a swap
//! tick `T` chosen ahead of the link's latency, uploaded to the standby bank and armed with
//! `SWAP_AT T`: the fabric changes program at `T` exactly, continuing from its registers.
//!
//! * Aborting (and MC_Halt): everything pending is CommandAborted; one part from the state at
//!   `T` to the new goal.
//! * Buffered: the parts playing continue unchanged (their tails from `T` are re-uploaded) and
//!   the new move follows from the last one's end state.
//! * BlendingLow / Previous / Next / High: the last part is replanned to pass its target at
//!   the blend velocity (the lower, the previous, the next or the higher of the two moves'
//!   velocities, 0 when the second move reverses), and the new move continues from there. A
//!   blend the previous move can no longer reach before its target falls back to Buffered (the
//!   command's `note` says so).
//! * Override `k` (0–2): every part still to play is replanned from `T` with its velocity
//!   scaled by `k`; at `k = 0` the axis stops on its path with the moves' deceleration and
//!   the command stays Busy, to go on when the override rises again.
//!
//! This module and [`compose`] do no I/O; [`crate::driver`] runs the axis over any
//! [`crate::link::Link`] (the device model, the Verilated board, a serial port).

pub mod compose;
mod part;

pub use part::{cell_of, STOPPED_ON_TARGET};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use snapgen_model::chain::ChainState;
use snapgen_model::format::Format;
use snapgen_model::program::{Program, Segment};
use snapgen_plan::online::{OnlineError, OnlineLimits, OnlineOrder};

/// PLCopen's BufferMode of a move (how it follows the one before).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum BufferMode {
    /// Abort what runs; start now.
    #[default]
    Aborting,
    /// Start when the previous move is done (at rest on its target).
    Buffered,
    /// Blend at the lower of the two velocities.
    BlendingLow,
    /// Blend at the previous move's velocity.
    BlendingPrevious,
    /// Blend at this move's velocity.
    BlendingNext,
    /// Blend at the higher of the two velocities.
    BlendingHigh,
}

impl BufferMode {
    /// Every mode, in the standard's order.
    pub const ALL: [BufferMode; 6] = [
        BufferMode::Aborting,
        BufferMode::Buffered,
        BufferMode::BlendingLow,
        BufferMode::BlendingPrevious,
        BufferMode::BlendingNext,
        BufferMode::BlendingHigh,
    ];
}

/// A motion command (a function block's inputs). Units: the format's user unit and seconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MotionCommand {
    /// MC_MoveAbsolute.
    MoveAbsolute {
        /// Target position (unit).
        position: f64,
        /// Velocity (unit/s, > 0).
        velocity: f64,
        /// Acceleration (unit/s², > 0).
        acceleration: f64,
        /// Deceleration (unit/s², > 0).
        deceleration: f64,
        /// Jerk (unit/s³, > 0; ignored at order 2).
        jerk: f64,
        /// How it follows the move before.
        #[serde(default)]
        buffer_mode: BufferMode,
        /// On a path (an axis group's motion on its path length, `crate::path`): the speeds
        /// the element's geometry allows, which neither the override nor a blend may pass.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        path: Option<OnPath>,
    },
    /// MC_MoveVelocity: reach and hold a signed velocity (always Aborting).
    MoveVelocity {
        /// Velocity (unit/s, signed: its sign is the direction).
        velocity: f64,
        /// Acceleration (unit/s², > 0).
        acceleration: f64,
        /// Deceleration (unit/s², > 0).
        deceleration: f64,
        /// Jerk (unit/s³, > 0).
        jerk: f64,
    },
    /// MC_Halt: stop on the path with a deceleration and jerk (aborts what runs).
    Halt {
        /// Deceleration (unit/s², > 0).
        deceleration: f64,
        /// Jerk (unit/s³, > 0).
        jerk: f64,
    },
}

/// The speeds an element of a path allows its move on the path length (unit/s, > 0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnPath {
    /// Along the element (the geometry's limit: the feed override is cut to it).
    pub velocity: f64,
    /// At its start, the fastest a blend into it passes: its junction's (a curvature jump or a
    /// small kink at speed costs a jerk there: `snapgen_plan::path::junction`), lowered by the
    /// look-ahead so that the path can still brake where it must.
    pub entry: f64,
}

impl MotionCommand {
    /// A move's set speed at override `k`: its velocity times `k`, cut to its path's limit.
    pub fn set_speed(&self, k: f64) -> Option<f64> {
        match *self {
            MotionCommand::MoveAbsolute { velocity, path, .. } => {
                Some(path.map_or(velocity * k, |p| (velocity * k).min(p.velocity)))
            }
            _ => None,
        }
    }

    /// The function block's name.
    pub fn name(&self) -> &'static str {
        match self {
            MotionCommand::MoveAbsolute { .. } => "MC_MoveAbsolute",
            MotionCommand::MoveVelocity { .. } => "MC_MoveVelocity",
            MotionCommand::Halt { .. } => "MC_Halt",
        }
    }

    fn buffer_mode(&self) -> BufferMode {
        match self {
            MotionCommand::MoveAbsolute { buffer_mode, .. } => *buffer_mode,
            _ => BufferMode::Aborting,
        }
    }
}

/// PLCopen ErrorID of a command that ended in Error.
#[derive(Clone, Debug, PartialEq, Error, Serialize)]
#[serde(tag = "error", content = "detail", rename_all = "snake_case")]
pub enum AxisErrorId {
    /// The planner refused the command (its input or the state it had to start from).
    #[error("the planner refused the move: {0}")]
    Planner(String),
    /// An input out of range.
    #[error("{0}")]
    InvalidInput(String),
    /// The board refused a command or the link failed.
    #[error("the board: {0}")]
    Board(String),
    /// The change's program is longer than the program memory and the link cannot upload
    /// its rest before the board has played what it holds.
    #[error("the link is too slow for this change: its program is longer than the board's program memory ({segments} segments) and the rest cannot be uploaded before the board plays what it holds; raise the baud rate or give longer moves")]
    LinkTooSlow {
        /// The program memory (segments).
        segments: usize,
    },
    /// The board's registers differ from the host's prediction: the trajectory is not the
    /// one planned (everything stops).
    #[error("the board's registers at tick {tick} differ from the plan's")]
    Diverged {
        /// The tick read.
        tick: u64,
    },
}

impl AxisErrorId {
    /// Its ErrorID as docs/ONLINE.md lists it (`invalid_input`, `planner`, `board`,
    /// `link_too_slow`, `diverged`); the message is its `Display`.
    pub fn name(&self) -> &'static str {
        match self {
            AxisErrorId::Planner(_) => "planner",
            AxisErrorId::InvalidInput(_) => "invalid_input",
            AxisErrorId::Board(_) => "board",
            AxisErrorId::LinkTooSlow { .. } => "link_too_slow",
            AxisErrorId::Diverged { .. } => "diverged",
        }
    }
}

/// How a command ended, or where it stands.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Accepted, not yet playing.
    Busy,
    /// Playing.
    Active,
    /// Reached its goal (MC_MoveAbsolute at rest or at its blend point, MC_Halt at rest).
    Done,
    /// MC_MoveVelocity holds its velocity (it stays Busy until aborted).
    InVelocity,
    /// Replaced by another command before it was done.
    CommandAborted,
    /// Refused or failed.
    Error(AxisErrorId),
}

impl Outcome {
    /// PLCopen's Busy output.
    pub fn busy(&self) -> bool {
        matches!(self, Outcome::Busy | Outcome::Active | Outcome::InVelocity)
    }

    /// True once the command will not change any more.
    pub fn is_final(&self) -> bool {
        matches!(
            self,
            Outcome::Done | Outcome::CommandAborted | Outcome::Error(_)
        )
    }

    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            Outcome::Busy => "Busy",
            Outcome::Active => "Active",
            Outcome::Done => "Done",
            Outcome::InVelocity => "InVelocity",
            Outcome::CommandAborted => "CommandAborted",
            Outcome::Error(_) => "Error",
        }
    }
}

/// What a part of the timeline ends in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// At output cell `cell`, at velocity `velocity` (unit/s; 0: at rest).
    Position {
        /// Output cell.
        cell: i128,
        /// Velocity there.
        velocity: f64,
    },
    /// Holding `velocity` (unit/s).
    Velocity(f64),
}

/// One command's piece of the trajectory the fabric plays.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The command (index in the axis's command list).
    pub command: usize,
    /// Absolute tick the part begins on.
    pub start_tick: u64,
    /// The exact state it begins in.
    pub start: ChainState,
    /// Its program (reaches the goal at its end).
    pub program: Program,
    /// The exact state at its end.
    pub end: ChainState,
    /// What it ends in.
    pub goal: Goal,
    /// Planned with the override at 0 (a stop on the path, the command not done).
    pub paused: bool,
    /// Cut short by a change (its command went on in a later part, or was aborted).
    pub cut: bool,
}

impl Part {
    /// Absolute tick the goal is reached on.
    pub fn end_tick(&self) -> u64 {
        self.start_tick + self.program.total_ticks()
    }
}

/// The trajectory the fabric plays: contiguous parts from a known state (rest before the first
/// part; after the last, its end state with a = j = 0 held, v = 0 at rest or a held velocity).
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// The state the trajectory begins in and its tick (the registers as read at rest, or
    /// the end of the last part that was dropped).
    pub origin: (u64, ChainState),
    /// The parts, in time order.
    pub parts: Vec<Part>,
}

impl Timeline {
    /// At rest in `state` at `tick`, nothing to play.
    pub fn at_rest(tick: u64, state: ChainState) -> Self {
        Timeline {
            origin: (tick, state),
            parts: Vec::new(),
        }
    }

    /// The exact registers at absolute tick `t` (≥ the origin's).
    pub fn state_at(&self, t: u64, format: &Format) -> ChainState {
        let w = &format.widths;
        // Between parts the chain runs on with snap 0 from the last end.
        let (mut tick, mut s) = self.origin;
        for p in &self.parts {
            if t < p.start_tick {
                break;
            }
            if t < p.end_tick() {
                return p.start.after_ticks(&p.program, t - p.start_tick, w);
            }
            (tick, s) = (p.end_tick(), p.end);
        }
        s.after_ticks(&Program::empty(), t.saturating_sub(tick), w)
    }

    /// The tick the last part ends on (the origin's when there is none).
    pub fn end_tick(&self) -> u64 {
        self.parts.last().map_or(self.origin.0, |p| p.end_tick())
    }

    /// Everything played from the origin to tick `until` as one program (parts, pauses
    /// between them, a held velocity), for traces and plots (not bounded by the program
    /// memory).
    pub fn played(&self, until: u64) -> Program {
        let mut segments = Vec::new();
        let mut tick = self.origin.0;
        for p in &self.parts {
            hold(&mut segments, p.start_tick.saturating_sub(tick));
            segments.extend(p.program.segments.iter().copied());
            tick = p.end_tick();
        }
        hold(&mut segments, until.saturating_sub(tick));
        let mut left = until.saturating_sub(self.origin.0);
        segments.retain_mut(|s| {
            let n = u64::from(s.ticks).min(left);
            left -= n;
            s.ticks = n as u32;
            n > 0
        });
        Program { segments }
    }

    /// The program the fabric must play from tick `t` on: the parts' segments from `t`, and,
    /// when the last part holds a velocity, cruise segments (snap 0) while the position
    /// register holds; the first `max_segments` of them (the rest goes up in a later swap).
    pub fn program_from(&self, t: u64, format: &Format) -> Program {
        let mut segments = self.segments_from(t, format);
        segments.truncate(format.max_segments);
        Program { segments }
    }

    /// What the fabric plays from tick `t` on, whole: [`Timeline::program_from`] before it
    /// is cut to the program memory (a long change goes up in several uploads).
    pub fn segments_from(&self, t: u64, format: &Format) -> Vec<Segment> {
        let mut segments = Vec::with_capacity(format.max_segments);
        let mut tick = self.origin.0;
        for p in &self.parts {
            if p.start_tick > tick && p.start_tick > t {
                // A pause between parts: snap 0 until the next begins.
                hold(&mut segments, p.start_tick - tick.max(t));
            }
            tick = p.end_tick();
            if tick <= t {
                // Played out before `t`.
                continue;
            }
            let mut skip = t.saturating_sub(p.start_tick);
            for s in &p.program.segments {
                let n = u64::from(s.ticks);
                if skip >= n {
                    skip -= n;
                    continue;
                }
                segments.push(Segment {
                    ticks: (n - skip) as u32,
                    snap: s.snap,
                });
                skip = 0;
            }
        }
        if let Some(p) = self.parts.last() {
            if p.end.v != 0 {
                let room = cruise_room(&p.end, format);
                let left = room.saturating_sub(t.saturating_sub(p.end_tick()));
                let most = u64::from(u32::MAX) * format.max_segments as u64;
                hold(&mut segments, left.min(most));
            }
        }
        segments
    }
}

/// Appends `n` ticks of snap 0 (segments of at most 2³² − 1 ticks).
fn hold(segments: &mut Vec<Segment>, n: u64) {
    let mut left = n;
    while left > 0 {
        let k = left.min(u64::from(u32::MAX));
        segments.push(Segment {
            ticks: k as u32,
            snap: 0,
        });
        left -= k;
    }
}

/// Ticks a held velocity can cruise from `s` before the position register would overflow.
fn cruise_room(s: &ChainState, format: &Format) -> u64 {
    let max = Format::register_max(format.widths.x);
    if s.v == 0 {
        return u64::MAX;
    }
    let room = if s.v > 0 { max - s.x } else { s.x + max };
    (room / s.v.abs()).clamp(0, u64::MAX as i128) as u64
}

/// A command as the axis holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandRecord {
    /// The function block's inputs.
    pub command: MotionCommand,
    /// Where it stands.
    pub outcome: Outcome,
    /// A remark (a blend that fell back to Buffered).
    pub note: Option<String>,
}

/// Axis settings shared by every command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisSettings {
    /// The board's format (its Ts and widths, as read from it).
    pub format: Format,
    /// Profile order of every plan.
    pub order: OnlineOrder,
}

/// The pure axis: commands, override, the timeline.
#[derive(Clone, Debug)]
pub struct HostAxis {
    /// Settings.
    pub settings: AxisSettings,
    /// Every command given, in order.
    pub commands: Vec<CommandRecord>,
    /// Feed override (0–2).
    pub override_factor: f64,
    /// What the fabric plays.
    pub timeline: Timeline,
}

/// What a change asks of the fabric: play `program` from tick `at` (via SWAP_AT), after
/// which the axis's timeline is `timeline`.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    /// Swap tick.
    pub at: u64,
    /// The program from `at`.
    pub program: Program,
    /// The timeline it realises.
    pub timeline: Timeline,
    /// Commands it aborts (their outcome becomes CommandAborted once it is armed).
    pub aborts: Vec<usize>,
    /// Remarks on commands (a blend that fell back to Buffered).
    pub notes: Vec<(usize, String)>,
    /// The override it was planned with.
    pub override_factor: f64,
}

impl HostAxis {
    /// An axis at rest in `state` at `tick`.
    pub fn new(settings: AxisSettings, tick: u64, state: ChainState) -> Self {
        HostAxis {
            settings,
            commands: Vec::new(),
            override_factor: 1.0,
            timeline: Timeline::at_rest(tick, state),
        }
    }

    /// The outcomes at tick `t`: parts begun are Active, parts ended Done (InVelocity for a
    /// held velocity). Call with the board's tick after it was read and checked.
    pub fn update(&mut self, t: u64) {
        let parts = &self.timeline.parts;
        for (i, p) in parts.iter().enumerate() {
            let rec = &mut self.commands[p.command];
            if rec.outcome.is_final() || p.cut {
                continue;
            }
            let followed = parts.get(i + 1).is_some_and(|n| t >= n.start_tick);
            if followed && !p.paused && matches!(p.goal, Goal::Velocity(v) if v != 0.0) {
                // A held velocity a buffered move took over from.
                rec.outcome = Outcome::CommandAborted;
            } else if t >= p.end_tick() && !p.paused {
                rec.outcome = match rec.command {
                    MotionCommand::MoveVelocity { .. } => Outcome::InVelocity,
                    _ => Outcome::Done,
                };
            } else if t >= p.start_tick && rec.outcome == Outcome::Busy {
                rec.outcome = Outcome::Active;
            }
        }
    }

    /// The last command still to be done (Busy, Active or InVelocity), if any.
    pub fn pending(&self) -> impl Iterator<Item = usize> + '_ {
        self.commands
            .iter()
            .enumerate()
            .filter(|(_, c)| c.outcome.busy())
            .map(|(k, _)| k)
    }
}

/// A command's error from a planner error.
impl From<OnlineError> for AxisErrorId {
    fn from(e: OnlineError) -> Self {
        AxisErrorId::Planner(e.to_string())
    }
}

/// The limits of a move with the override applied to its velocity (never below `floor`).
pub(crate) fn scaled(l: OnlineLimits, k: f64) -> OnlineLimits {
    OnlineLimits {
        velocity: l.velocity * k,
        ..l
    }
}
