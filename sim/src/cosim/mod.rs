//! Lockstep co-simulation of the Verilated motion core and the clock-accurate model.
//!
//! A run splits into sessions (each its own Verilated core, model and sub-stream of moves, on
//! one worker thread per machine core). A session resets the core, then plays its moves:
//! most through the core's own ports ([`core_moves`]: played to the end, aborted, stopped,
//! or replanned by program swaps at random ticks), some as PLCopen event streams through the
//! host's own code and the board's executor ([`streams`]). Fabric and model receive the same
//! inputs on every clock and every output is compared after every rising edge
//! ([`lockstep`]). The first mismatch ends the session; it is then re-run with a trace build
//! to write the waves around it.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use snapgen_model::{CoreInputs, DEFAULT_FORMAT};

mod compare;
mod core_moves;
mod executor_link;
mod lockstep;
mod report;
mod streams;

pub use compare::{Fault, Mismatch, Register};
pub use executor_link::{CoreSide, ExecutorLink};
pub use lockstep::{Lockstep, ModelSide, BATCH};
pub use report::CosimReport;

use crate::build::build;
use crate::fabric::{Fabric, VcdWindow};
use crate::moves::{MoveSpec, MoveStream, OrderMix};
use crate::SimError;

/// Sessions a random run splits into unless told otherwise. Fixed, whatever the machine, so
/// that a seed means the same moves everywhere; many more than cores, so that worker threads
/// pulling sessions from a queue finish together even when one core is slower (seen here: the
/// two cores of a shared machine differing by 20 %).
pub const DEFAULT_SESSIONS: usize = 16;

/// Settings of a co-simulation run.
#[derive(Clone, Debug)]
pub struct CosimConfig {
    /// Moves to play.
    pub moves: usize,
    /// Seed of the move stream.
    pub seed: u64,
    /// Planners to use.
    pub mix: OrderMix,
    /// Share of the moves given a controlled stop at a random clock.
    pub stop_share: f64,
    /// Share of the other moves replanned on the way (program swaps at random ticks).
    pub replan_share: f64,
    /// Share of the moves played as PLCopen event streams through the host axis.
    pub stream_share: f64,
    /// Dump the whole run's waves here.
    pub vcd: Option<PathBuf>,
    /// Where to write the waves around a mismatch.
    pub mismatch_vcd: PathBuf,
    /// A deliberate fault (tests).
    pub fault: Option<Fault>,
    /// Play these moves instead of a random stream (`moves` and `seed` are then ignored).
    pub fixed: Option<Vec<MoveSpec>>,
    /// Sessions of a random stream: each its own Verilated core, model and sub-stream of
    /// moves; 1 with `vcd` or `fixed`. The moves played depend on it, not on the machine.
    pub session_count: usize,
    /// Index of this session (set by `run`).
    pub session: usize,
}

impl CosimConfig {
    /// Defaults for `moves` moves from `seed`.
    pub fn new(moves: usize, seed: u64) -> Self {
        CosimConfig {
            moves,
            seed,
            mix: OrderMix::Mixed,
            stop_share: crate::moves::DEFAULT_STOP_SHARE,
            replan_share: crate::moves::DEFAULT_REPLAN_SHARE,
            stream_share: crate::moves::DEFAULT_STREAM_SHARE,
            vcd: None,
            mismatch_vcd: PathBuf::from("cosim-mismatch.vcd"),
            fault: None,
            fixed: None,
            session_count: DEFAULT_SESSIONS,
            session: 0,
        }
    }

    /// The sessions this run splits into: session `s` of `n` plays every move of the stream
    /// seeded with `seed` (s = 0) or `seed ^ s·φ` (s > 0), `moves / n` of them (the first
    /// sessions take the remainder). The fault goes to session 0.
    pub fn sessions(&self) -> Vec<CosimConfig> {
        let n = if self.fixed.is_some() || self.vcd.is_some() {
            1
        } else {
            self.session_count.clamp(1, self.moves.max(1))
        };
        (0..n)
            .map(|s| CosimConfig {
                moves: self.moves / n + usize::from(s < self.moves % n),
                seed: if s == 0 {
                    self.seed
                } else {
                    self.seed ^ (s as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                },
                fault: if s == 0 { self.fault } else { None },
                session_count: 1,
                session: s,
                ..self.clone()
            })
            .collect()
    }

    /// A run of the given moves, in order.
    pub fn fixed(moves: Vec<MoveSpec>) -> Self {
        CosimConfig {
            moves: moves.len(),
            fixed: Some(moves),
            ..CosimConfig::new(0, 0)
        }
    }
}

/// Plays the session on `fabric` (or on the model alone when `None`), calling `on_move`
/// after each move played.
fn session(
    cfg: &CosimConfig,
    fabric: Option<Fabric>,
    report: &mut CosimReport,
    on_move: &(dyn Fn() + Sync),
) -> Result<(), Mismatch> {
    let mut ls = Lockstep::new(fabric, &DEFAULT_FORMAT, cfg.fault, cfg.session);
    let start_time = Instant::now();
    let result = (|| {
        ls.drive(
            &CoreInputs {
                reset: true,
                ..Default::default()
            },
            2,
        )?;
        let mut stream = MoveStream::new(
            cfg.seed,
            cfg.mix,
            cfg.stop_share,
            cfg.replan_share,
            cfg.stream_share,
        );
        let mut fixed = cfg.fixed.iter().flatten();
        let mut played = 0;
        while played < cfg.moves {
            let spec = match cfg.fixed {
                Some(_) => match fixed.next() {
                    Some(s) => *s,
                    None => break,
                },
                None => stream.next_move(),
            };
            // Now and then, at rest, the reference takes another position (POWER 1's load).
            if played % 8 == 5 && ls.side.model.chain().is_at_rest() && !ls.side.model.busy() {
                let cell = (ls.side.model.chain().x >> snapgen_model::FRAC_BITS) as i32;
                let to = cell.wrapping_add((played as i32).wrapping_mul(7919) % 2001 - 1000);
                core_moves::load(&mut ls, &spec, to as u32)?;
                report.loads += 1;
            }
            ls.move_index = played;
            let idle = core_moves::idle(&spec);
            if spec.stream > 0 {
                streams::stream(&mut ls, &spec, &idle, report)?;
            } else if !core_moves::play(&mut ls, &spec, report)? {
                report.skipped += 1;
                continue;
            }
            // A few idle clocks between moves, compared too.
            ls.drive(&idle, 3)?;
            played += 1;
            report.moves = played;
            on_move();
        }
        Ok(())
    })();
    report.seconds = start_time.elapsed().as_secs_f64();
    report.clocks = ls.clock;
    report.ticks = ls.ticks;
    result
}

/// Runs a co-simulation of `verilog` (the motion core) against the model: its sessions (see
/// [`CosimConfig::sessions`]) on one worker thread per core.
pub fn run(verilog: &str, cfg: &CosimConfig) -> Result<CosimReport, SimError> {
    run_observed(verilog, cfg, &|| {})
}

/// [`run`], calling `on_move` (from the worker threads) after each move played: the
/// binary's progress bar.
pub fn run_observed(
    verilog: &str,
    cfg: &CosimConfig,
    on_move: &(dyn Fn() + Sync),
) -> Result<CosimReport, SimError> {
    let built = build(verilog, cfg.vcd.is_some())?;
    let window = cfg.vcd.as_ref().map(|p| VcdWindow {
        path: p.clone(),
        from: 0,
        to: u64::MAX,
    });
    let sessions = cfg.sessions();
    let mut fabrics = Vec::with_capacity(sessions.len());
    for _ in &sessions {
        fabrics.push(Fabric::open(&built.library, window.as_ref())?);
    }
    // One worker per core; each takes the next session from the queue until none is left.
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(sessions.len());
    type Outcome = (CosimReport, Result<(), Mismatch>);
    let queue: Mutex<VecDeque<(usize, Fabric)>> =
        Mutex::new(fabrics.into_iter().enumerate().collect());
    let outcomes: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; sessions.len()]);
    let wall = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let next = queue.lock().unwrap_or_else(|e| e.into_inner()).pop_front();
                let Some((k, fab)) = next else { break };
                let mut r = CosimReport::default();
                let res = session(&sessions[k], Some(fab), &mut r, on_move);
                outcomes.lock().unwrap_or_else(|e| e.into_inner())[k] = Some((r, res));
            });
        }
    });
    let mut report = CosimReport {
        cached_build: built.cached,
        vcd: cfg.vcd.clone(),
        seconds: wall.elapsed().as_secs_f64(),
        threads,
        ..Default::default()
    };
    let outcomes = outcomes.into_inner().unwrap_or_else(|e| e.into_inner());
    // A fault goes to session 0 and ends it with a mismatch once injected; a session 0 that
    // ran clean never reached the fault's clock, and a clean report would mislead.
    if let (Some(fault), Some((r0, Ok(())))) =
        (cfg.fault, outcomes.first().and_then(|o| o.as_ref()))
    {
        return Err(SimError::FaultNotReached {
            clock: fault.clock,
            clocks: r0.clocks,
        });
    }
    // Every session ran to its end or its first mismatch; the lowest session's is reported.
    let mut first: Option<Mismatch> = None;
    for (r, res) in outcomes.into_iter().flatten() {
        report.add(&r);
        if let Err(m) = res {
            first.get_or_insert(m);
        }
    }
    if let Some(m) = first {
        // Re-run that session with a trace build and dump the clocks around the mismatch.
        if cfg.vcd.is_none() {
            let traced = build(verilog, true)?;
            let w = VcdWindow {
                path: cfg.mismatch_vcd.clone(),
                from: m.clock.saturating_sub(64),
                to: m.clock + 16,
            };
            let fab = Fabric::open(&traced.library, Some(&w))?;
            let mut again = CosimReport::default();
            let _ = session(&sessions[m.session], Some(fab), &mut again, &|| {});
            report.vcd = Some(cfg.mismatch_vcd.clone());
        }
        report.mismatch = Some(m);
    }
    Ok(report)
}

/// Runs the same sessions one after the other on the model alone (no fabric): the reference
/// for the co-sim/model throughput ratio (single-threaded; divide the co-simulation's by its
/// thread count for a per-core comparison).
pub fn run_model_only(cfg: &CosimConfig) -> CosimReport {
    let mut report = CosimReport::default();
    let wall = Instant::now();
    for s in cfg.sessions() {
        let mut r = CosimReport::default();
        let _ = session(&CosimConfig { fault: None, ..s }, None, &mut r, &|| {});
        report.add(&r);
    }
    report.seconds = wall.elapsed().as_secs_f64();
    report
}

/// The name of an error's variant (its `Debug` up to the first field), a report's key.
fn kind_of(e: &impl std::fmt::Debug) -> String {
    let text = format!("{e:?}");
    text.split(['(', ' ', '{'])
        .next()
        .unwrap_or("?")
        .to_string()
}
