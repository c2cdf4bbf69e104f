//! The axis group on a board: the board's chain integrates the path length `s` (its position
//! register), as the seed's trajectory generator does; the host gives it the group's moves and
//! overrides through the driver (`crate::driver`, every READ_STATE checked bit for bit against
//! the host's prediction) and maps the register's trace onto the axes with the interpolator's
//! rules. The board's format (its Ts and widths) and its position at rest are read from it
//! before anything is planned.
//!
//! The interpolator runs on the host here; a board with the path core (the interpolator in
//! its fabric) also takes the path before the run ([`play_on_board_with`]).

use snapgen_model::chain::Trace;
use snapgen_model::path::interp::Path;
use snapgen_plan::online::OnlineOrder;
use snapgen_plan::path::speed::Limits;

use crate::driver::{Action, Event, RunOptions, RunReport};
use crate::gcode::Block;
use crate::link::Link;
use crate::online::{play, PlayError as ScriptError, PlayOptions};
use crate::session::Session;

use super::group::{Group, PathAction, PathEvent, PathLimits};
use super::{collect, PlayError, Run};

/// Why a path could not be played on a board.
#[derive(Debug, thiserror::Error)]
pub enum BoardError {
    /// The path (see the message), before anything moved.
    #[error(transparent)]
    Path(#[from] PlayError),
    /// The board: its set-up, the link, or the run.
    #[error(transparent)]
    Board(#[from] ScriptError),
    /// Reading the board's state before the run.
    #[error("reading the board's state: {0}")]
    State(String),
    /// Giving the board the path before the run.
    #[error("giving the board the path: {0}")]
    Load(String),
}

/// The driver's script for the group's `events`: each element entering is its moves (at the
/// event's time, or once the register has reached its length), each override an override.
/// Returns the script and, for each path event, its first script event (None: not taken, as
/// [`Group::play`] does not take it: an element not in the program or already entered, a
/// time past `MAX_EVENT_MS`, a length that is not a finite number ≥ 0). On a board an event
/// whose length is never reached holds the ones after it (the driver takes events in order)
/// until the run ends.
fn script(g: &mut Group, events: &[PathEvent]) -> (Vec<Event>, Vec<Option<usize>>) {
    let mut out = Vec::new();
    let mut first = Vec::new();
    for e in events {
        if !g.takes(e) {
            first.push(None);
            continue;
        }
        let at_position = e.at_length.map(|l| g.position_of(l));
        let actions: Vec<Action> = match e.action {
            PathAction::Enter(k) => g.moves_for(k).into_iter().map(Action::Command).collect(),
            PathAction::Override(k) => vec![Action::Override { r#override: k }],
        };
        first.push((!actions.is_empty()).then_some(out.len()));
        out.extend(actions.into_iter().map(|action| Event {
            at_ms: e.at_ms,
            at_position,
            action,
        }));
    }
    (out, first)
}

/// Plays `blocks` as `events` let them enter, with the path's `own` limits, on the board of
/// `session`: the run's report and the path played (every axis on every tick from the
/// board's register), with the stop-limit rule's warnings. The board's controlled stop is
/// the path's largest within every axis on every element (`Group::stop_limits`), every move
/// within it (`Group::for_board_stop`): a group stop from any tick stays on the path within
/// the axes' limits.
pub fn play_on_board<L: Link>(
    session: &mut Session<L>,
    blocks: &[Block],
    axes: &[Limits],
    own: Option<PathLimits>,
    events: &[PathEvent],
    run: RunOptions,
) -> Result<(Run, RunReport, Vec<String>), BoardError> {
    play_on_board_with(session, blocks, axes, own, events, run, |_, _, _| Ok(()))
}

/// [`play_on_board`] on a board that takes the path itself: `load` is given the session, the
/// whole path (every element the events enter) and the path length register's value where it
/// starts, once it is known and before anything moves (an error stops the run there).
pub fn play_on_board_with<L: Link>(
    session: &mut Session<L>,
    blocks: &[Block],
    axes: &[Limits],
    own: Option<PathLimits>,
    events: &[PathEvent],
    run: RunOptions,
    load: impl FnOnce(&mut Session<L>, &Path, i128) -> Result<(), String>,
) -> Result<(Run, RunReport, Vec<String>), BoardError> {
    let format = session.format;
    let at = session
        .state()
        .map_err(|e| BoardError::State(e.to_string()))?;
    let mut g = Group::new(blocks, axes, own, &format)?
        .on_board(at.x)?
        .for_board_stop();
    let stop = g.stop_limits();
    let (driver_events, first) = script(&mut g, events);
    load(session, &g.path(), g.start_register()).map_err(BoardError::Load)?;
    let opts = PlayOptions {
        order: OnlineOrder::Three,
        stop_deceleration: Some(stop.deceleration),
        stop_jerk: Some(stop.jerk),
        run,
    };
    let (report, _, warnings) = play(session, &driver_events, &opts)?;
    let t = &report.axis.timeline;
    let (t0, origin) = t.origin;
    let program = t.played(report.last.ticks);
    let lengths: Vec<i128> = Trace::new(&program, origin, format.widths)
        .map(|k| k.state.x)
        .collect();
    let mut played = collect(&g, &report.axis, blocks, lengths)?;
    played.stop = Some(stop);
    played.taken = first
        .iter()
        .map(|f| {
            f.and_then(|i| report.event_ticks.get(i))
                .map(|t| t.saturating_sub(t0))
        })
        .collect();
    played.refused = report
        .refused_overrides
        .iter()
        .filter_map(|(i, why)| {
            first
                .iter()
                .position(|f| *f == Some(*i))
                .map(|k| (k, why.clone()))
        })
        .collect();
    Ok((played, report, warnings))
}
