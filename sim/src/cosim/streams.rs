//! PLCopen event streams on the lockstep core: random scripts of MC_MoveAbsolute (every
//! buffer mode, blends among them), MC_MoveVelocity, MC_Halt and feed-override changes at
//! random ticks — mid-jerk, mid-acceleration, at cruise, at rest — played by the host's own
//! code (`snapgen_host::online::play`: a session opened with PING, the stop limits written
//! by the one rule, POWER 1, then the driver, which plans every change from the exact state
//! at a swap tick ahead of the link's latency, uploads it, arms the swap and compares every
//! state it reads with its prediction). The link is the board's executor clocked beside the
//! core ([`ExecutorLink`]), at a UART's wire time for the stream's baud rate, so the host
//! leads its swaps as over a real link. Fabric and model are compared on every clock
//! meanwhile; a stream that ends moving is stopped with the board's STOP.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_host::axis::{BufferMode, MotionCommand, Outcome};
use snapgen_host::driver::{Action, Event, RunError, RunOptions, RunReport};
use snapgen_host::link::Link;
use snapgen_host::online::{play, PlayError, PlayOptions};
use snapgen_host::protocol::Command;
use snapgen_host::session::Session;
use snapgen_model::{CoreInputs, Format};
use snapgen_plan::online::OnlineOrder;

use super::executor_link::ExecutorLink;
use super::lockstep::Lockstep;
use super::{CosimReport, Mismatch};
use crate::moves::{log_uniform, MoveSpec};

/// Longest a stream's closing STOP may take (clocks) before the core is aborted.
const MAX_CLOSING_STOP_CLOCKS: u64 = 4_000_000;

/// Baud rates the streams' simulated links run at: mostly fast, now and then 115 200.
const BAUDS: [f64; 4] = [3e6, 3e6, 921_600.0, 115_200.0];

/// A random script of `n` events from a state at rest at `home` (unit): moves of a few
/// hundred to tens of thousands of ticks with random limits and buffer modes, velocities,
/// halts and override changes, a few to a few thousand ticks apart; then a move back near
/// `home` (Aborting) and the override back to 1, so that the stream ends at rest.
fn script(rng: &mut StdRng, f: &Format, n: u8, home: f64) -> Vec<Event> {
    let ms = |ticks: f64| ticks * f.ts * 1e3;
    let modes = BufferMode::ALL;
    let mut events = Vec::with_capacity(usize::from(n) + 2);
    let mut t = 0.0;
    let limits = |rng: &mut StdRng| {
        let v = log_uniform(rng, 0.05, 5.0);
        (
            v,
            log_uniform(rng, 1.0, 1000.0),
            log_uniform(rng, 1.0, 1000.0),
            log_uniform(rng, 50.0, 2e5),
        )
    };
    for _ in 0..n {
        t += log_uniform(rng, 2.0, 5000.0);
        let r: f64 = rng.gen();
        let action = if r < 0.55 {
            let (v, a, d, j) = limits(rng);
            // A move of a few hundred to tens of thousands of ticks at its speed.
            let dist = v * log_uniform(rng, 200.0, 30_000.0) * f.ts;
            let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
            Action::Command(MotionCommand::MoveAbsolute {
                position: home + sign * dist,
                velocity: v,
                acceleration: a,
                deceleration: d,
                jerk: j,
                buffer_mode: modes[rng.gen_range(0..modes.len())],
                path: None,
            })
        } else if r < 0.65 {
            let (v, a, d, j) = limits(rng);
            let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
            Action::Command(MotionCommand::MoveVelocity {
                velocity: sign * v * rng.gen_range(0.1..1.0),
                acceleration: a,
                deceleration: d,
                jerk: j,
            })
        } else if r < 0.75 {
            let (_, _, d, j) = limits(rng);
            Action::Command(MotionCommand::Halt {
                deceleration: d,
                jerk: j,
            })
        } else {
            Action::Override {
                r#override: (rng.gen_range(0.0..2.0f64) * 20.0).round() / 20.0,
            }
        };
        events.push(Event {
            at_ms: ms(t),
            at_position: None,
            action,
        });
    }
    // Back near home, briskly: held velocities may have carried the axis far.
    t += log_uniform(rng, 2.0, 3000.0);
    events.push(Event {
        at_ms: ms(t),
        at_position: None,
        action: Action::Command(MotionCommand::MoveAbsolute {
            position: home + log_uniform(rng, 20.0, 3000.0) * f.ts,
            velocity: 5.0,
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 2e5,
            buffer_mode: BufferMode::Aborting,
            path: None,
        }),
    });
    events.push(Event {
        at_ms: ms(t + 1.0),
        at_position: None,
        action: Action::Override { r#override: 1.0 },
    });
    events
}

/// Plays a stream of `spec.stream` random PLCopen events on the lockstep core through the
/// host's code and the board's executor (module documentation), from the state at rest the
/// session is in; at its end the core is at rest again.
pub(super) fn stream(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    idle: &CoreInputs,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let mut rng = StdRng::seed_from_u64(spec.replan_seed);
    let f = Format::with_ts(spec.ts);
    // POWER 1 loads the reference at the encoder's cell, where the core stands.
    let cell = ls.side.model.chain().x >> snapgen_model::FRAC_BITS;
    let home = cell as f64 * f.position_lsb;
    let events = script(&mut rng, &f, spec.stream, home);
    let order = if rng.gen_bool(0.75) {
        OnlineOrder::Three
    } else {
        OnlineOrder::Two
    };
    let baud = BAUDS[rng.gen_range(0..BAUDS.len())];
    let link = ExecutorLink::new(ls, &f, spec.tick_div, baud);
    let opts = PlayOptions {
        order,
        stop_deceleration: None,
        stop_jerk: None,
        run: RunOptions {
            // A poll every 100 ticks; the run ends when the axis has settled after the last
            // event (the stream's last events bring it to rest), at the latest 10^6 ticks on.
            poll_ms: 100.0 * spec.ts * 1e3,
            settle_ms: 1e6 * spec.ts * 1e3,
            ..RunOptions::default()
        },
    };
    let mut session = match Session::open(link, f.position_lsb) {
        Ok(s) => s,
        Err(e) => {
            // Only a mismatch fails PING on this link.
            *report.streams_failed.entry(format!("{e}")).or_default() += 1;
            return Ok(());
        }
    };
    let result = play(&mut session, &events, &opts);
    let link = &mut session.link;
    if let Some(m) = link.take_mismatch() {
        return Err(m);
    }
    report.streams += 1;
    match result {
        Ok((r, _, _)) => tally(&r, report),
        Err(PlayError::Run(e @ RunError::Diverged { .. })) => {
            let ex = link.executor_outputs();
            let ls = link.lockstep();
            report.streams_diverged += 1;
            report.divergences.push(format!(
                "session {} move {}: {e} (axis {:?}, error {:?})",
                ls.session, ls.move_index, ex.state, ex.error
            ));
        }
        Err(e) => {
            *report.streams_failed.entry(format!("{e}")).or_default() += 1;
        }
    }
    // A stream that ended moving (a velocity held, a failed run) is stopped with the board's
    // STOP, as a host does, and run to rest; the core is aborted (past the executor) only if
    // that stop does not end.
    if !at_rest(link.lockstep()) {
        report.streams_stopped += 1;
        let _ = link.ask(&Command::Stop);
        let per_tick = u64::from(spec.tick_div) + 1;
        let mut left = MAX_CLOSING_STOP_CLOCKS / (100 * per_tick);
        while !at_rest(link.lockstep()) && left > 0 {
            link.wait(100.0 * spec.ts);
            left -= 1;
        }
    }
    if let Some(m) = link.take_mismatch() {
        return Err(m);
    }
    let ls = link.lockstep();
    if !at_rest(ls) {
        ls.drive(
            &CoreInputs {
                abort_move: true,
                ..*idle
            },
            1,
        )?;
        ls.drive(idle, 2)?;
    }
    Ok(())
}

fn at_rest(ls: &Lockstep) -> bool {
    let m = &ls.side.model;
    m.chain().is_at_rest() && !m.busy() && !m.stopping()
}

/// Adds a finished run to the report: its swaps (replans and extensions), commands and their
/// outcomes, and whether the core stands where the timeline says.
fn tally(r: &RunReport, report: &mut CosimReport) {
    report.stream_swaps += r.swaps.len();
    report.stream_extensions += r.extensions as usize;
    report.stream_commands += r.axis.commands.len();
    for c in &r.axis.commands {
        if let Outcome::Error(e) = &c.outcome {
            *report.stream_errors.entry(super::kind_of(e)).or_default() += 1;
        }
    }
    let want = r
        .axis
        .timeline
        .state_at(r.last.ticks, &r.axis.settings.format);
    let got = snapgen_model::ChainState {
        x: r.last.x,
        v: r.last.v,
        a: r.last.a,
        j: r.last.j,
    };
    if got != want {
        report.planner_disagreements += 1;
    }
}
