//! Runs a timed script of motion commands on a board over a [`Link`]: every change is
//! planned from the exact state at a swap tick chosen ahead of the link's measured latency,
//! uploaded and armed with SWAP_AT; every READ_STATE (one per poll) is compared bit for bit
//! with the state the host predicts for its tick.
//!
//! The board's time base is the clock: a script's times count from the tick of its first
//! READ_STATE. The latency of a command is the time from the tick it was due to the first tick
//! that obeys it (its swap tick).

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::axis::compose::Request;
use crate::axis::{AxisErrorId, AxisSettings, HostAxis, MotionCommand, Outcome};
use crate::link::{Link, LinkError};
use crate::protocol::{Command, Reply, StateReply};
use snapgen_model::chain::ChainState;

mod runner;

use runner::{regs, ticks_of, FrameBytes, Runner};

/// What a script event does.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Action {
    /// A motion command.
    Command(MotionCommand),
    /// The feed override (0–2).
    Override {
        /// Factor.
        r#override: f64,
    },
}

/// One timed event.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Time from the script's start (ms).
    pub at_ms: f64,
    /// And, when given, not before the axis has reached this position (unit), moving toward
    /// it from where the script began (a tangent move entering the buffer at a point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_position: Option<f64>,
    /// What happens.
    #[serde(flatten)]
    pub action: Action,
}

/// Run options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunOptions {
    /// Status poll period (ms), also the watchdog's food.
    pub poll_ms: f64,
    /// Longest run after the last event (ms) before the run ends with commands still busy
    /// (a held velocity).
    pub settle_ms: f64,
    /// Ticks of lead a swap gets beyond its upload's estimate: the host's and the link's
    /// timing jitter. A swap armed too late is refused (NAK LATE) and planned again with
    /// twice the lead, so this trades latency against retries.
    pub safety_ticks: u64,
}

/// The safety lead over a serial link: USB serial adapters and the host's scheduler.
pub const SERIAL_SAFETY_TICKS: u64 = 20;

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            poll_ms: 2.0,
            settle_ms: 10_000.0,
            safety_ticks: SERIAL_SAFETY_TICKS,
        }
    }
}

impl RunOptions {
    /// Over a memory-mapped link (the station's AXI4-Lite registers): no wire and no adapter,
    /// so the lead beyond the upload's estimate is the device's own minimum
    /// ([`SWAP_MIN_LEAD`](snapgen_spec::rules::SWAP_MIN_LEAD)) and one tick.
    pub fn memory_mapped() -> Self {
        RunOptions {
            safety_ticks: snapgen_spec::rules::SWAP_MIN_LEAD as u64 + 1,
            ..Self::default()
        }
    }
}

/// One program swap.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SwapRecord {
    /// The events it realised (indices in the script; several when they were due together).
    pub events: Vec<usize>,
    /// The swap tick.
    pub tick: u64,
    /// Ticks from the first event's due tick to the swap tick: its latency.
    pub latency_ticks: u64,
    /// Segments uploaded.
    pub segments: usize,
    /// SWAP_AT refused as late before this one was taken.
    pub late_retries: u32,
}

/// What a run did.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// The axis at the end (commands, outcomes, the timeline played).
    pub axis: HostAxis,
    /// Which command each event gave (None: an override).
    pub event_commands: Vec<Option<usize>>,
    /// The tick each event was due on: its time, or the tick the event before it was due if
    /// later (events are taken in order), or the tick its position was seen reached; events
    /// never taken (a position not reached) are missing at the end.
    pub event_ticks: Vec<u64>,
    /// Override events refused (event index, why).
    pub refused_overrides: Vec<(usize, AxisErrorId)>,
    /// Program swaps.
    pub swaps: Vec<SwapRecord>,
    /// The tick the script started on.
    pub start_tick: u64,
    /// The last READ_STATE.
    pub last: StateReply,
    /// READ_STATE replies compared with the prediction (all equal, or the run failed).
    pub checks: u64,
    /// Swaps that uploaded the rest of a change longer than the program memory.
    pub extensions: u32,
}

/// Why a run stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RunError {
    /// The link failed.
    #[error("link: {0}")]
    Link(#[from] LinkError),
    /// The board answered what a run cannot go on from.
    #[error("the board answered {what}: {detail}")]
    Board {
        /// The command.
        what: &'static str,
        /// The answer.
        detail: String,
    },
    /// The board's registers differ from the host's prediction (a stop was sent).
    #[error("the board's registers at tick {tick} are {got:?}, the plan says {want:?}: stopped")]
    Diverged {
        /// The tick.
        tick: u64,
        /// Read.
        got: Box<ChainState>,
        /// Predicted.
        want: Box<ChainState>,
    },
    /// The axis was moving when the script began.
    #[error("the axis is moving (v, a or j ≠ 0): start a script at rest")]
    Moving,
}

/// Reads the state.
pub fn read_state<L: Link>(link: &mut L) -> Result<StateReply, RunError> {
    match link.ask(&Command::ReadState)? {
        Reply::State(s) => Ok(s),
        r => Err(RunError::Board {
            what: "READ_STATE",
            detail: format!("{r:?}"),
        }),
    }
}

/// Runs `script` (events in time order) on the board behind `link`, which must be powered,
/// at rest and configured (stop limits) for the axis's format.
pub fn run<L: Link>(
    link: &mut L,
    settings: AxisSettings,
    script: &[Event],
    opts: &RunOptions,
) -> Result<RunReport, RunError> {
    let first = read_state(link)?;
    if (first.v, first.a, first.j) != (0, 0, 0) {
        return Err(RunError::Moving);
    }
    let ts = settings.format.ts;
    let mut r = Runner {
        link,
        ts,
        axis: HostAxis::new(settings, first.ticks, regs(&first)),
        checks: 0,
        last: first,
        overhead: 0.0,
        armed: None,
        covered: first.ticks,
        extensions: 0,
        poll_ticks: ticks_of(opts.poll_ms, ts).max(1),
        safety: opts.safety_ticks,
        polled: 0.0,
        reply_wire: 0.0,
        planning: 0,
        defer_until: None,
        bytes: FrameBytes::of(&settings.format, first),
    };
    let start = first.ticks;
    let f = settings.format;
    let home = f.position_physical(first.x);
    let mut swaps = Vec::new();
    let mut event_commands = Vec::new();
    let mut refused_overrides = Vec::new();
    let mut event_ticks = Vec::new();
    let mut next = 0;
    let last_due = script
        .last()
        .map_or(start, |e| start + ticks_of(e.at_ms, ts));
    // A position trigger never reached ends the run at the settle time after the last event.
    let end_by = last_due + ticks_of(opts.settle_ms, ts);
    loop {
        r.poll()?;
        let now = r.last.ticks;
        let here = f.position_physical(r.last.x);
        let is_due = |e: &Event| {
            let reached = e.at_position.is_none_or(|p| {
                let toward = (p - home).signum();
                (here - p) * toward >= 0.0
            });
            start + ticks_of(e.at_ms, ts) <= now && reached
        };
        // The rest of a long change goes up when it can wait no longer, unless a change is due
        // (which replaces it, or uploads it first when it must: `Runner::change`).
        if !script.get(next).is_some_and(is_due) {
            r.extend(false)?;
        }
        if let Some(e) = script.get(next) {
            if is_due(e) {
                // Every event due by now, planned together. Events are taken in order: one is
                // due at its time, or when the event before it was due if that is later (held
                // back behind a position trigger); a position trigger is due on the tick it was
                // seen reached.
                let released = |e: &Event, before: u64| {
                    if e.at_position.is_some() {
                        now
                    } else {
                        (start + ticks_of(e.at_ms, ts)).max(before)
                    }
                };
                let first = next;
                let mut reqs = Vec::new();
                while let Some(e) = script.get(next) {
                    if !is_due(e) {
                        break;
                    }
                    let before = event_ticks.last().copied().unwrap_or(start);
                    event_ticks.push(released(e, before));
                    match e.action {
                        Action::Command(c) => {
                            let k = r.axis.submit(c);
                            event_commands.push(Some(k));
                            if !r.axis.commands[k].outcome.is_final() {
                                reqs.push((next, Request::Command(k)));
                            }
                        }
                        Action::Override { r#override } => {
                            event_commands.push(None);
                            reqs.push((next, Request::Override(r#override)));
                        }
                    }
                    next += 1;
                }
                if reqs.is_empty() {
                    continue;
                }
                let only: Vec<Request> = reqs.iter().map(|(_, q)| *q).collect();
                let events: Vec<usize> = reqs.iter().map(|(e, _)| *e).collect();
                let due = event_ticks[events[0]];
                let (swap, refused) = r.change(&events, due, &only)?;
                swaps.extend(swap);
                // A refused command is in Error; a refused override changes nothing.
                for (q, refusal) in refused {
                    match q {
                        Request::Command(k) => {
                            r.axis.commands[k].outcome = Outcome::Error(refusal.error)
                        }
                        Request::Override(_) => {
                            let ev = reqs
                                .iter()
                                .find(|(_, x)| *x == q)
                                .map_or(first, |(e, _)| *e);
                            refused_overrides.push((ev, refusal.error))
                        }
                    }
                }
                continue;
            }
            if now >= end_by {
                // A position never reached: the events from here are not played.
                break;
            }
            let wait = (start + ticks_of(e.at_ms, ts)).saturating_sub(now);
            r.wait_ticks(r.poll_ticks.min(wait).max(1));
            continue;
        }
        if r.settled(now) || now >= end_by {
            break;
        }
        r.wait_ticks(r.poll_ticks);
    }
    r.poll()?;
    Ok(RunReport {
        checks: r.checks,
        extensions: r.extensions,
        last: r.last,
        axis: r.axis,
        event_commands,
        event_ticks,
        refused_overrides,
        swaps,
        start_tick: start,
    })
}
