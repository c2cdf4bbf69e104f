//! PLCopen event streams on the lockstep core: random scripts of MC_MoveAbsolute (every
//! buffer mode, blends among them), MC_MoveVelocity, MC_Halt and feed-override changes at
//! random ticks — mid-jerk, mid-acceleration, at cruise, at rest — played by the host's own
//! driver (`snapgen_host::axis::driver::run`): it plans every change from the exact state at
//! a swap tick ahead of the link's latency, uploads it, arms the swap and compares every state
//! it reads with its prediction. The link here is the core's own ports, one clock per segment
//! written, with the wire time of a UART at the stream's baud rate passing on the core as
//! idle clocks, so the host leads its swaps as it does over a real link. Fabric and model
//! are compared on every clock meanwhile; each stream ends at rest where its timeline says.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_host::axis::driver::{
    run, Action, Event, Link, LinkError, RunError, RunOptions, RunReport,
};
use snapgen_host::axis::{AxisSettings, BufferMode, MotionCommand, Outcome};
use snapgen_host::protocol::{Command, Reason, Reply, StateReply};
use snapgen_model::{CoreInputs, Format};
use snapgen_plan::online::OnlineOrder;

use super::{CosimReport, Lockstep, Mismatch, BATCH};
use crate::moves::{log_uniform, MoveSpec};

/// The host's link to the lockstep core (module documentation).
struct CoreLink<'l> {
    ls: &'l mut Lockstep,
    idle: CoreInputs,
    /// Clocks per tick.
    per_tick: u64,
    /// Board ticks a byte takes on the simulated wire.
    byte_ticks: f64,
    /// The format frames are encoded with (their lengths give the wire time).
    format: Format,
    /// Wire time not yet passed on the core (a fraction of a tick).
    owed: f64,
    /// The first mismatch: every request fails after it.
    mismatch: Option<Mismatch>,
    /// Timely SWAP_ATs the core did not arm (must be 0).
    not_armed: usize,
}

impl CoreLink<'_> {
    /// Lets `ticks` (real) ticks pass on the core, idle.
    fn pass(&mut self, ticks: f64) {
        self.owed += ticks;
        let whole = self.owed.floor();
        self.owed -= whole;
        let mut left = whole as u64 * self.per_tick;
        while left > 0 && self.mismatch.is_none() {
            let k = left.min(BATCH);
            if let Err(m) = self.ls.drive(&self.idle, k) {
                self.mismatch = Some(m);
            }
            left -= k;
        }
    }

    /// One clock with inputs `i`.
    fn clock(&mut self, i: &CoreInputs) {
        if self.mismatch.is_none() {
            if let Err(m) = self.ls.drive(i, 1) {
                self.mismatch = Some(m);
            }
        }
    }
}

impl Link for CoreLink<'_> {
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError> {
        let ack = Reply::Ack { cmd: c.code() };
        let reply = match *c {
            Command::ReadState => {
                let o = self.ls.side.model.outputs();
                Reply::State(StateReply {
                    ticks: o.ticks,
                    x: o.x,
                    v: o.v,
                    a: o.a,
                    j: o.j,
                })
            }
            Command::LoadSegment { index, segment } => {
                self.clock(&CoreInputs {
                    write_enable: true,
                    write_address: index,
                    write_ticks: segment.ticks,
                    write_snap: segment.snap,
                    ..self.idle
                });
                ack
            }
            Command::Commit { count } => {
                self.clock(&CoreInputs {
                    count_enable: true,
                    count_value: count,
                    ..self.idle
                });
                ack
            }
            Command::SwapAt { tick } => {
                // The executor's rule (docs/PROTOCOL.md): five ticks or more ahead of the time
                // base, else LATE and nothing changes.
                let now = self.ls.side.model.outputs().ticks;
                if tick < now + 5 {
                    Reply::Nak {
                        cmd: c.code(),
                        reason: Reason::Late,
                    }
                } else {
                    self.clock(&CoreInputs {
                        swap: true,
                        swap_last: tick.wrapping_sub(1) as u32,
                        ..self.idle
                    });
                    // Past the input register.
                    let idle = self.idle;
                    self.clock(&idle);
                    if !self.ls.side.model.outputs().swap_pending {
                        self.not_armed += 1;
                    }
                    ack
                }
            }
            Command::Stop => {
                // Only on a divergence (which fails the stream): abort at once.
                self.clock(&CoreInputs {
                    abort_move: true,
                    ..self.idle
                });
                let idle = self.idle;
                self.clock(&idle);
                ack
            }
            _ => return Err(LinkError(format!("{c:?}: not a request of the core link"))),
        };
        let bytes =
            c.to_frame(0, &self.format).to_bytes().len() + reply.to_frame(0).to_bytes().len();
        self.pass(bytes as f64 * self.byte_ticks);
        match self.mismatch {
            Some(_) => Err(LinkError("the fabric and the model differ".into())),
            None => Ok(reply),
        }
    }

    fn wait(&mut self, ticks: u64) {
        self.pass(ticks as f64);
    }

    fn host_ticks(&self) -> f64 {
        self.ls.side.model.outputs().ticks as f64 + self.owed
    }

    fn byte_ticks(&self) -> f64 {
        self.byte_ticks
    }
}

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
/// host's driver (module documentation), from the state at rest the session is in.
pub(super) fn stream(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    idle: &CoreInputs,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let mut rng = StdRng::seed_from_u64(spec.replan_seed);
    let f = Format::with_ts(spec.ts);
    let home = f.position_physical(ls.side.model.chain().x);
    let events = script(&mut rng, &f, spec.stream, home);
    let order = if rng.gen_bool(0.75) {
        OnlineOrder::Three
    } else {
        OnlineOrder::Two
    };
    let baud = BAUDS[rng.gen_range(0..BAUDS.len())];
    let per_tick = u64::from(idle.tick_div) + 1;
    let mut link = CoreLink {
        ls,
        idle: *idle,
        per_tick,
        byte_ticks: 10.0 / baud / spec.ts,
        format: f,
        owed: 0.0,
        mismatch: None,
        not_armed: 0,
    };
    let opts = RunOptions {
        // A poll every 100 ticks; the run ends when the axis has settled after the last
        // event (the stream's last events bring it to rest), at the latest 10^6 ticks on.
        poll_ms: 100.0 * spec.ts * 1e3,
        settle_ms: 1e6 * spec.ts * 1e3,
    };
    let result = run(&mut link, AxisSettings { format: f, order }, &events, &opts);
    if let Some(m) = link.mismatch.take() {
        return Err(m);
    }
    report.swaps_not_armed += link.not_armed;
    report.streams += 1;
    match result {
        Ok(r) => tally(&r, report),
        Err(RunError::Diverged { .. }) => report.streams_diverged += 1,
        Err(e) => {
            let kind = format!("{e}");
            *report.streams_failed.entry(kind).or_default() += 1;
        }
    }
    // Wherever the stream ended, the core ends it at rest: a run that ended on a held
    // velocity or failed is stopped here.
    if !ls_at_rest(link.ls) {
        link.ls.drive(
            &CoreInputs {
                abort_move: true,
                ..*idle
            },
            1,
        )?;
        link.ls.drive(idle, 2)?;
        report.streams_aborted += 1;
    }
    Ok(())
}

fn ls_at_rest(ls: &Lockstep) -> bool {
    ls.side.model.chain().is_at_rest() && !ls.side.model.busy()
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
