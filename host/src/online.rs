//! A timed script of PLCopen commands on a board, as every host sets it up: a [`Session`]
//! (PING, the board's format), the stop limits from the script by the one rule
//! ([`crate::limits`]: the given ones, or the script's largest deceleration and jerk), the
//! axis powered, then the [`crate::driver`] run. `snapgen online` plays scripts with it on a
//! serial port or a virtual board, Python's `Board.play` on any board; the co-simulation plays
//! random ones on the Verilated core. [`Script`] is the script (docs/ONLINE.md) and its rules.

use serde::{Deserialize, Serialize};
use snapgen_model::format::{Format, Quantity};
use snapgen_model::stop::StopLimits;
use snapgen_plan::online::OnlineOrder;

use crate::axis::{AxisErrorId, AxisSettings, Goal, MotionCommand, Outcome};
use crate::driver::{run, Action, Event, RunError, RunOptions, RunReport};
use crate::limits::{stop_limits, LimitSource};
use crate::link::Link;
use crate::session::{Failure, Session};

/// How a script is played.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlayOptions {
    /// Profile order.
    pub order: OnlineOrder,
    /// The board's controlled stop: deceleration (unit/s²) [default: the script's largest].
    pub stop_deceleration: Option<f64>,
    /// Its jerk (unit/s³) [default: the script's largest].
    pub stop_jerk: Option<f64>,
    /// The driver's poll and settle times.
    pub run: RunOptions,
}

/// Why a play stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlayError {
    /// The set-up (the board, the stop limits, the amplifier).
    #[error(transparent)]
    Setup(#[from] Failure),
    /// The run.
    #[error(transparent)]
    Run(#[from] RunError),
}

/// The largest deceleration and jerk of the script's commands (unit/s², unit/s³).
pub fn script_peaks(events: &[Event]) -> (f64, f64) {
    let (mut d, mut j) = (0.0f64, 0.0f64);
    for e in events {
        if let Action::Command(c) = e.action {
            let (dc, jc) = match c {
                MotionCommand::MoveAbsolute {
                    deceleration, jerk, ..
                }
                | MotionCommand::MoveVelocity {
                    deceleration, jerk, ..
                }
                | MotionCommand::Halt { deceleration, jerk } => (deceleration, jerk),
            };
            d = d.max(dc);
            j = j.max(jc);
        }
    }
    (d, j)
}

/// The stop limits a script is played with, in `format`, and the rule's warnings.
pub fn script_stop_limits(
    events: &[Event],
    opts: &PlayOptions,
    format: &Format,
) -> Result<(StopLimits, Vec<String>), Failure> {
    let (d, j) = script_peaks(events);
    let raw = |v: f64, q| (v * format.scale(q)).floor().min(i128::MAX as f64) as i128;
    Ok(stop_limits(
        LimitSource {
            flag: "stop_deceleration",
            given: opts.stop_deceleration,
            peak: raw(d, Quantity::Acceleration),
        },
        LimitSource {
            flag: "stop_jerk",
            given: opts.stop_jerk,
            peak: raw(j, Quantity::Jerk),
        },
        format,
    )?)
}

/// Plays `events` on the board of `session`: the stop limits written, the axis powered,
/// the script run. The warnings of the stop-limit rule come back with the report.
pub fn play<L: Link>(
    session: &mut Session<L>,
    events: &[Event],
    opts: &PlayOptions,
) -> Result<(RunReport, StopLimits, Vec<String>), PlayError> {
    let (limits, warnings) = script_stop_limits(events, opts, &session.format)?;
    session.power_up(limits).map_err(Failure::from)?;
    let settings = AxisSettings {
        format: session.format,
        order: opts.order,
    };
    let report = run(&mut session.link, settings, events, &opts.run)?;
    Ok((report, limits, warnings))
}

/// A timed script of PLCopen commands (docs/ONLINE.md): what `snapgen online --script` reads
/// (TOML) and Python's `Board.play` takes (a TOML text or a dict).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Script {
    /// Profile order: 3 or 2.
    #[serde(default = "three")]
    pub order: u8,
    /// The board's controlled stop: deceleration (unit/s²) [default: the largest of the
    /// script].
    #[serde(default)]
    pub stop_deceleration: Option<f64>,
    /// Its jerk (unit/s³) [default: the largest of the script].
    #[serde(default)]
    pub stop_jerk: Option<f64>,
    /// The events, in time order.
    #[serde(rename = "event")]
    pub events: Vec<Event>,
}

fn three() -> u8 {
    3
}

/// Why a script cannot be played.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScriptError {
    /// Not a script's syntax or fields.
    #[error("not a valid script (docs/ONLINE.md): {0}")]
    Syntax(String),
    /// No event.
    #[error("the script has no [[event]]")]
    NoEvents,
    /// An order other than 3 or 2.
    #[error("order = {0}: give 3 (jerk-limited) or 2 (trapezoid)")]
    Order(u8),
    /// A time out of order.
    #[error(
        "event {event}: at_ms = {at_ms} must be finite, ≥ 0 and not before the event before it"
    )]
    Time {
        /// The event's index.
        event: usize,
        /// Its time.
        at_ms: f64,
    },
    /// A path element's caps, which only `snapgen path` sets.
    #[error("event {0}: `path` (an element's caps) is set by `snapgen path`, not by a script: remove it")]
    PathCaps(usize),
}

impl Script {
    /// A script from its TOML text, checked.
    pub fn from_toml(text: &str) -> Result<Script, ScriptError> {
        let s: Script = toml::from_str(text).map_err(|e| ScriptError::Syntax(e.to_string()))?;
        s.check()?;
        Ok(s)
    }

    /// A script from its JSON text (the same fields as the TOML), checked.
    pub fn from_json(text: &str) -> Result<Script, ScriptError> {
        let s: Script =
            serde_json::from_str(text).map_err(|e| ScriptError::Syntax(e.to_string()))?;
        s.check()?;
        Ok(s)
    }

    /// Times in order and not negative, an order of 3 or 2, at least one event, no path caps.
    pub fn check(&self) -> Result<(), ScriptError> {
        if self.events.is_empty() {
            return Err(ScriptError::NoEvents);
        }
        if !matches!(self.order, 2 | 3) {
            return Err(ScriptError::Order(self.order));
        }
        let mut last = 0.0;
        for (k, e) in self.events.iter().enumerate() {
            if !(e.at_ms.is_finite() && e.at_ms >= last) {
                return Err(ScriptError::Time {
                    event: k,
                    at_ms: e.at_ms,
                });
            }
            last = e.at_ms;
            if matches!(
                e.action,
                Action::Command(MotionCommand::MoveAbsolute { path: Some(_), .. })
            ) {
                return Err(ScriptError::PathCaps(k));
            }
        }
        Ok(())
    }

    /// Its profile order.
    pub fn order(&self) -> OnlineOrder {
        if self.order == 2 {
            OnlineOrder::Two
        } else {
            OnlineOrder::Three
        }
    }

    /// How the host plays it, with the link's run options `run`.
    pub fn options(&self, run: RunOptions) -> PlayOptions {
        PlayOptions {
            order: self.order(),
            stop_deceleration: self.stop_deceleration,
            stop_jerk: self.stop_jerk,
            run,
        }
    }
}

/// One command of a played script: what became of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CommandLine {
    /// The event's index in the script.
    pub event: usize,
    /// Its time (ms from the script's start).
    pub at_ms: f64,
    /// The command (`MC_MoveAbsolute`, `MC_MoveVelocity`, `MC_Halt`).
    pub command: &'static str,
    /// Its outcome (`Done`, `CommandAborted`, `Busy`, `Active`, `InVelocity`, `Error`; `NotGiven`: its position was
    /// never reached).
    pub outcome: &'static str,
    /// Its ErrorID when refused (docs/ONLINE.md's names: `invalid_input`, `planner`, …).
    pub error_id: Option<&'static str>,
    /// The refusal's message.
    pub error: Option<String>,
    /// What the axis noted about it.
    pub note: Option<String>,
    /// The tick it was due on (its time, or when its position was reached), when it was taken.
    pub due_tick: Option<u64>,
    /// The tick of the swap that realised it (the first tick that obeyed it), when it had one.
    pub swap_tick: Option<u64>,
    /// From the tick it was due to the first tick that obeyed it (its swap), when it had one.
    pub latency_ms: Option<f64>,
}

/// One feed-override change of a played script.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OverrideLine {
    /// The event's index in the script.
    pub event: usize,
    /// Its time (ms from the script's start).
    pub at_ms: f64,
    /// The feed override (0–2).
    pub factor: f64,
    /// Refused (its ErrorID), or taken.
    pub error_id: Option<&'static str>,
    /// The refusal's message.
    pub error: Option<String>,
    /// The tick it was due on.
    pub due_tick: Option<u64>,
    /// The tick of the swap that realised it, when it had one.
    pub swap_tick: Option<u64>,
    /// From the tick it was due to the first tick that obeyed it (its swap), when it had one.
    pub latency_ms: Option<f64>,
}

/// The tick of the swap that realised event `k`, if one did.
pub fn swap_tick(r: &RunReport, k: usize) -> Option<u64> {
    r.swaps
        .iter()
        .find(|s| s.events.contains(&k))
        .map(|s| s.tick)
}

/// The latency of event `k` (ms): from its due tick to the swap that realised it.
pub fn latency_ms(r: &RunReport, k: usize) -> Option<f64> {
    let due = *r.event_ticks.get(k)?;
    swap_tick(r, k).map(|t| t.saturating_sub(due) as f64 * r.axis.settings.format.ts * 1e3)
}

/// What became of each command of `events` in the run `r`.
pub fn command_lines(r: &RunReport, events: &[Event]) -> Vec<CommandLine> {
    let mut out = Vec::new();
    for (k, e) in events.iter().enumerate() {
        let Some(taken) = r.event_commands.get(k) else {
            if let Action::Command(c) = e.action {
                out.push(CommandLine {
                    event: k,
                    at_ms: e.at_ms,
                    command: c.name(),
                    outcome: "NotGiven",
                    error_id: None,
                    error: None,
                    note: Some("its position was not reached before the run ended".into()),
                    due_tick: None,
                    swap_tick: None,
                    latency_ms: None,
                });
            }
            continue;
        };
        let Some(c) = taken else {
            continue;
        };
        let rec = &r.axis.commands[*c];
        out.push(CommandLine {
            event: k,
            at_ms: e.at_ms,
            command: rec.command.name(),
            outcome: rec.outcome.name(),
            error_id: match &rec.outcome {
                Outcome::Error(id) => Some(id.name()),
                _ => None,
            },
            error: match &rec.outcome {
                Outcome::Error(id) => Some(id.to_string()),
                _ => None,
            },
            note: rec.note.clone(),
            due_tick: r.event_ticks.get(k).copied(),
            swap_tick: swap_tick(r, k),
            latency_ms: latency_ms(r, k),
        });
    }
    out
}

/// What became of each feed-override change of `events` that was taken in the run `r`.
pub fn override_lines(r: &RunReport, events: &[Event]) -> Vec<OverrideLine> {
    let mut out = Vec::new();
    for (k, e) in events.iter().enumerate() {
        let Action::Override { r#override } = e.action else {
            continue;
        };
        if r.event_ticks.get(k).is_none() {
            continue;
        }
        let refused = r
            .refused_overrides
            .iter()
            .find(|(ev, _)| *ev == k)
            .map(|(_, id)| id);
        out.push(OverrideLine {
            event: k,
            at_ms: e.at_ms,
            factor: r#override,
            error_id: refused.map(AxisErrorId::name),
            error: refused.map(|id| id.to_string()),
            due_tick: r.event_ticks.get(k).copied(),
            swap_tick: swap_tick(r, k),
            latency_ms: latency_ms(r, k),
        });
    }
    out
}

/// The position (output LSBs) the run's last command that was not refused ends on, if it
/// ends on one (a move to rest, not cut).
pub fn target_lsb(r: &RunReport) -> Option<i128> {
    let axis = &r.axis;
    let last = axis
        .commands
        .iter()
        .rposition(|c| !matches!(c.outcome, Outcome::Error(_)))?;
    axis.timeline
        .parts
        .iter()
        .rev()
        .find(|q| q.command == last && !q.cut)
        .and_then(|q| match q.goal {
            Goal::Position {
                cell,
                velocity: 0.0,
            } => Some(cell),
            _ => None,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The script format's example in docs/ONLINE.md parses, passes the checks, and holds
    /// every kind of event.
    #[test]
    fn the_documented_script_is_valid() {
        let doc = include_str!("../../docs/ONLINE.md");
        let start = doc.find("```toml\n").expect("a TOML block") + 8;
        let len = doc[start..].find("```").unwrap();
        let s = Script::from_toml(&doc[start..start + len]).unwrap();
        assert_eq!(s.events.len(), 4);
        assert!(matches!(
            s.events[0].action,
            Action::Command(MotionCommand::MoveAbsolute { .. })
        ));
        assert!(matches!(s.events[1].action, Action::Override { .. }));
        assert_eq!(s.events[2].at_position, Some(300.0));
        assert!(matches!(
            s.events[3].action,
            Action::Command(MotionCommand::Halt { .. })
        ));
        // The same script as JSON (what Python's dicts become) is the same script.
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(Script::from_json(&json).unwrap(), s);
    }

    /// The ErrorID names the summaries give are the ones the error's serialisation (and
    /// docs/ONLINE.md) uses.
    #[test]
    fn error_id_names_are_the_serialised_tags() {
        use crate::axis::AxisErrorId;
        for id in [
            AxisErrorId::Planner("p".into()),
            AxisErrorId::InvalidInput("i".into()),
            AxisErrorId::Board("b".into()),
            AxisErrorId::LinkTooSlow { segments: 1 },
            AxisErrorId::Diverged { tick: 1 },
        ] {
            let tag = serde_json::to_value(&id).unwrap()["error"].clone();
            assert_eq!(tag, id.name(), "{id:?}");
            assert!(include_str!("../../docs/ONLINE.md").contains(&format!("`{}`", id.name())));
        }
    }

    #[test]
    fn bad_scripts_are_refused_with_the_rule_they_break() {
        let ev = |at: f64| {
            format!("[[event]]\nat_ms = {at:?}\nkind = \"halt\"\ndeceleration = 1.0\njerk = 1.0\n")
        };
        let ok = format!("{}{}", ev(0.0), ev(5.0));
        assert!(Script::from_toml(&ok).is_ok());
        assert_eq!(
            Script::from_toml(&format!("order = 4\n{ok}")),
            Err(ScriptError::Order(4))
        );
        assert_eq!(
            Script::from_toml(&format!("{}{}", ev(5.0), ev(1.0))),
            Err(ScriptError::Time {
                event: 1,
                at_ms: 1.0
            })
        );
        assert_eq!(
            Script::from_json(r#"{"event": []}"#),
            Err(ScriptError::NoEvents)
        );
        assert!(matches!(
            Script::from_json(r#"{"event": [{"at_ms": -1.0, "override": 1.0}]}"#),
            Err(ScriptError::Time { event: 0, .. })
        ));
        let on_path = r#"{"event": [{"at_ms": 0.0, "kind": "move_absolute", "position": 1.0,
            "velocity": 1.0, "acceleration": 1.0, "deceleration": 1.0, "jerk": 1.0,
            "path": {"velocity": 1.0, "entry": 1.0}}]}"#;
        assert_eq!(Script::from_json(on_path), Err(ScriptError::PathCaps(0)));
        assert!(matches!(
            Script::from_toml(&format!("speed = 1\n{ok}")),
            Err(ScriptError::Syntax(_))
        ));
    }
}
