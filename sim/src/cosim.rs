//! Lockstep co-simulation of the Verilated core and the clock-accurate model.
//!
//! A session resets the core, then for each move plans it from the model's exact state, writes
//! its segments into the standby bank, starts it and clocks until it is done (or stops it
//! midway). Fabric and model receive the same inputs on every clock and every output — x, v,
//! a, j, position, segment index, busy, done, aborted, tick count, tick, active bank — is
//! compared after every rising edge. The first mismatch ends the session; it is then re-run
//! with a trace build to write the waves around it.

use std::collections::VecDeque;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use snapgen_model::{plan_from, CoreInputs, CoreModel, CoreOutputs, Format, DEFAULT_FORMAT};

use crate::build::build;
use crate::fabric::{decode, Fabric, VcdWindow, OUT_WORDS};
use crate::moves::{MoveSpec, MoveStream, OrderMix};
use crate::SimError;

/// Clocks per call into the fabric: its output words (76 bytes a clock) stay in the L1/L2
/// cache between the fabric writing and the comparison reading them (a 65 536-clock batch,
/// 5 MB, did not).
const BATCH: u64 = 1 << 9;
/// Sessions a random run splits into unless told otherwise. Fixed, whatever the machine, so
/// that a seed means the same moves everywhere; many more than cores, so that worker threads
/// pulling sessions from a queue finish together even when one core is slower (seen here: the
/// two cores of a shared machine differing by 20 %).
pub const DEFAULT_SESSIONS: usize = 16;
/// Longest move the stream keeps, in ticks (keeps CI runs bounded).
const MAX_MOVE_TICKS: u64 = 400_000;

/// A compared output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Register {
    /// Position register.
    X,
    /// Velocity register.
    V,
    /// Acceleration register.
    A,
    /// Jerk register.
    J,
    /// Whole-LSB position output.
    Position,
    /// Segment index.
    Segment,
    /// Busy flag.
    Busy,
    /// Done flag.
    Done,
    /// Aborted flag.
    Aborted,
    /// Tick counter.
    TickCount,
    /// Tick enable.
    Tick,
    /// Active bank.
    ActiveBank,
    /// Standby program's segment count.
    StandbyCount,
}

impl Register {
    /// Every register, in comparison order.
    pub const ALL: [Register; 13] = [
        Register::X,
        Register::V,
        Register::A,
        Register::J,
        Register::Position,
        Register::Segment,
        Register::Busy,
        Register::Done,
        Register::Aborted,
        Register::TickCount,
        Register::Tick,
        Register::ActiveBank,
        Register::StandbyCount,
    ];

    /// Its name (as the Verilog port).
    pub fn name(self) -> &'static str {
        match self {
            Register::X => "x",
            Register::V => "v",
            Register::A => "a",
            Register::J => "j",
            Register::Position => "position",
            Register::Segment => "segment",
            Register::Busy => "busy",
            Register::Done => "done",
            Register::Aborted => "aborted",
            Register::TickCount => "tick_count",
            Register::Tick => "tick",
            Register::ActiveBank => "active_bank",
            Register::StandbyCount => "standby_count",
        }
    }

    /// Its width in bits.
    pub fn bits(self, f: &Format) -> u32 {
        match self {
            Register::X => f.widths.x,
            Register::V => f.widths.v,
            Register::A => f.widths.a,
            Register::J => f.widths.j,
            Register::Position | Register::TickCount => 32,
            Register::Segment | Register::StandbyCount => 6,
            _ => 1,
        }
    }

    /// Its raw bits in `o`, as an unsigned pattern of `bits` bits.
    pub fn bits_of(self, o: &CoreOutputs, f: &Format) -> u128 {
        let mask = |v: i128, b: u32| (v as u128) & (u128::MAX >> (128 - b));
        match self {
            Register::X => mask(o.x, f.widths.x),
            Register::V => mask(o.v, f.widths.v),
            Register::A => mask(o.a, f.widths.a),
            Register::J => mask(o.j, f.widths.j),
            Register::Position => u128::from(o.position),
            Register::Segment => u128::from(o.segment),
            Register::Busy => u128::from(o.busy),
            Register::Done => u128::from(o.done),
            Register::Aborted => u128::from(o.aborted),
            Register::TickCount => u128::from(o.tick_count),
            Register::Tick => u128::from(o.tick),
            Register::ActiveBank => u128::from(o.active_bank),
            Register::StandbyCount => u128::from(o.standby_count),
        }
    }

    /// `o` with bit `bit` of this register flipped.
    pub fn flip(self, o: &mut CoreOutputs, bit: u32, f: &Format) {
        let b = bit % self.bits(f);
        let w = |v: &mut i128, bits: u32| {
            *v = snapgen_model::chain::wrap(*v ^ (1i128 << b), bits);
        };
        match self {
            Register::X => w(&mut o.x, f.widths.x),
            Register::V => w(&mut o.v, f.widths.v),
            Register::A => w(&mut o.a, f.widths.a),
            Register::J => w(&mut o.j, f.widths.j),
            Register::Position => o.position ^= 1 << b,
            Register::Segment => o.segment ^= 1 << b,
            Register::Busy => o.busy = !o.busy,
            Register::Done => o.done = !o.done,
            Register::Aborted => o.aborted = !o.aborted,
            Register::TickCount => o.tick_count ^= 1 << b,
            Register::Tick => o.tick = !o.tick,
            Register::ActiveBank => o.active_bank = !o.active_bank,
            Register::StandbyCount => o.standby_count ^= 1 << b,
        }
    }
}

impl std::str::FromStr for Register {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Register::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| format!("unknown register {s:?}"))
    }
}

/// A deliberate one-bit error in the captured fabric stream, to prove the comparison fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    /// Clock at which to flip.
    pub clock: u64,
    /// Register to flip.
    pub register: Register,
    /// Bit to flip.
    pub bit: u32,
}

/// The first difference between fabric and model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// Parallel session that found it (each session is its own core and move stream).
    pub session: usize,
    /// Clock (rising edges since power-up of that session's core, from 0).
    pub clock: u64,
    /// Move being played (0-based).
    pub move_index: usize,
    /// Register that differs.
    pub register: Register,
    /// Model's bits.
    pub expected: u128,
    /// Fabric's bits.
    pub actual: u128,
    /// Width of the register.
    pub bits: u32,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let digits = self.bits.div_ceil(4) as usize;
        write!(
            f,
            "first mismatch in session {} at clock {} (move {}): register {} expected {:#0w$x} got {:#0w$x} (differing bits {:#x})",
            self.session,
            self.clock,
            self.move_index,
            self.register.name(),
            self.expected,
            self.actual,
            self.expected ^ self.actual,
            w = digits + 2
        )
    }
}

/// Settings of a co-simulation run.
#[derive(Clone, Debug)]
pub struct CosimConfig {
    /// Moves to play.
    pub moves: usize,
    /// Seed of the move stream.
    pub seed: u64,
    /// Planners to use.
    pub mix: OrderMix,
    /// Dump the whole run's waves here.
    pub vcd: Option<PathBuf>,
    /// Where to write the waves around a mismatch.
    pub mismatch_vcd: PathBuf,
    /// A deliberate fault (tests).
    pub fault: Option<Fault>,
    /// Show a progress bar (only when stderr is a terminal).
    pub progress: bool,
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
            vcd: None,
            mismatch_vcd: PathBuf::from("cosim-mismatch.vcd"),
            fault: None,
            progress: true,
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

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct CosimReport {
    /// Moves played.
    pub moves: usize,
    /// Moves aborted midway.
    pub stopped: usize,
    /// Moves given a controlled stop.
    pub soft_stopped: usize,
    /// Moves the stream drew but the planner refused or that were too long (skipped).
    pub skipped: usize,
    /// Clocks compared.
    pub clocks: u64,
    /// Program ticks compared (clocks on which the chain stepped with a program playing).
    pub ticks: u64,
    /// Seconds spent clocking and comparing.
    pub seconds: f64,
    /// The first mismatch.
    pub mismatch: Option<Mismatch>,
    /// Waves written.
    pub vcd: Option<PathBuf>,
    /// The library was already built.
    pub cached_build: bool,
    /// Moves after which the clock-accurate model did not stand where the planner said.
    pub planner_disagreements: usize,
    /// Worker threads the sessions ran on (one per core, at most one per session).
    pub threads: usize,
}

impl CosimReport {
    /// Ticks per second.
    pub fn ticks_per_second(&self) -> f64 {
        self.ticks as f64 / self.seconds.max(1e-9)
    }
}

/// The model's side of the lockstep.
struct ModelSide {
    model: CoreModel,
    /// Inputs of the previous clock: the fabric's wrapper registers every input, so the core
    /// sees them one clock late, and so does the model.
    pending: CoreInputs,
    /// The chain steps with a program playing on the next clock (`tick && busy` now).
    ticking: bool,
}

impl ModelSide {
    fn new(format: &Format) -> Self {
        ModelSide {
            model: CoreModel::new(format),
            pending: CoreInputs::default(),
            ticking: false,
        }
    }

    /// One clock with inputs `i`: the outputs after it, and whether the chain stepped on it
    /// with a program playing (a tick of the program).
    #[inline(always)]
    fn clock(&mut self, i: &CoreInputs) -> (CoreOutputs, bool) {
        let ticked = self.ticking;
        self.model.edge(&self.pending);
        // The registered tick_div already holds this clock's value, and the combinational
        // `tick` output compares against it.
        self.model.set_tick_div(i.tick_div);
        let m = self.model.outputs();
        self.ticking = m.tick && m.busy;
        self.pending = *i;
        (m, ticked)
    }
}

/// The two sides in lockstep.
struct Lockstep {
    fabric: Option<Fabric>,
    side: ModelSide,
    format: Format,
    clock: u64,
    ticks: u64,
    buf: Vec<u32>,
    fault: Option<Fault>,
    move_index: usize,
    session: usize,
}

impl Lockstep {
    /// `n` clocks with inputs `i` on both sides, compared.
    fn drive(&mut self, i: &CoreInputs, n: u64) -> Result<(), Mismatch> {
        let f = self.format;
        if let Some(fab) = self.fabric.as_mut() {
            fab.set(i);
        }
        let masks = Masks::new(&f);
        let mut left = n;
        while left > 0 {
            let k = left.min(BATCH);
            match self.fabric.as_mut() {
                Some(fab) => {
                    fab.run(k as usize, &mut self.buf);
                    for words in self.buf[..k as usize * OUT_WORDS].chunks_exact(OUT_WORDS) {
                        let words: &[u32; OUT_WORDS] =
                            words.try_into().expect("chunks of OUT_WORDS words");
                        let (m, ticked) = self.side.clock(i);
                        let faulty = self.fault.is_some_and(|fl| fl.clock == self.clock);
                        // A word differs (or the fault is due): compare register by register;
                        // bits outside every register (the harness never sets them) are no
                        // mismatch.
                        if faulty || differs(&m, words, &masks) {
                            let mut o = decode(words, &f);
                            if let Some(fl) = self.fault.filter(|_| faulty) {
                                fl.register.flip(&mut o, fl.bit, &f);
                            }
                            if let Some(register) = Register::ALL
                                .into_iter()
                                .find(|r| r.bits_of(&m, &f) != r.bits_of(&o, &f))
                            {
                                return Err(Mismatch {
                                    session: self.session,
                                    clock: self.clock,
                                    move_index: self.move_index,
                                    register,
                                    expected: register.bits_of(&m, &f),
                                    actual: register.bits_of(&o, &f),
                                    bits: register.bits(&f),
                                });
                            }
                        }
                        self.ticks += u64::from(ticked);
                        self.clock += 1;
                    }
                }
                None => {
                    // Model only (the benchmark's reference).
                    for _ in 0..k {
                        let (m, ticked) = self.side.clock(i);
                        std::hint::black_box(m);
                        self.ticks += u64::from(ticked);
                        self.clock += 1;
                    }
                }
            }
            left -= k;
        }
        Ok(())
    }
}

/// Masks of the wide registers: the fabric's words hold them zero-extended.
struct Masks {
    x: u128,
    v: u128,
    a: u128,
    j: u128,
}

impl Masks {
    fn new(f: &Format) -> Self {
        let m = |bits: u32| u128::MAX >> (128 - bits);
        Masks {
            x: m(f.widths.x),
            v: m(f.widths.v),
            a: m(f.widths.a),
            j: m(f.widths.j),
        }
    }
}

/// Whether the fabric's words differ from the model's outputs anywhere (the same layout as
/// [`crate::fabric::encode`], compared without building it: every term OR-ed, no early exit).
#[inline(always)]
fn differs(m: &CoreOutputs, w: &[u32; OUT_WORDS], masks: &Masks) -> bool {
    let wide = |k: usize| {
        u128::from(w[k])
            | (u128::from(w[k + 1]) << 32)
            | (u128::from(w[k + 2]) << 64)
            | (u128::from(w[k + 3]) << 96)
    };
    let flags = u32::from(m.segment)
        | u32::from(m.busy) << 8
        | u32::from(m.done) << 9
        | u32::from(m.aborted) << 10
        | u32::from(m.tick) << 11
        | u32::from(m.active_bank) << 12
        | u32::from(m.standby_count) << 16;
    let wide_diff = ((m.x as u128 & masks.x) ^ wide(0))
        | ((m.v as u128 & masks.v) ^ wide(4))
        | ((m.a as u128 & masks.a) ^ wide(8))
        | ((m.j as u128 & masks.j) ^ wide(12));
    let narrow_diff = (m.position ^ w[16]) | (flags ^ w[17]) | (m.tick_count ^ w[18]);
    wide_diff != 0 || narrow_diff != 0
}

/// Plays the session on `fabric` (or on the model alone when `None`).
fn session(
    cfg: &CosimConfig,
    fabric: Option<Fabric>,
    report: &mut CosimReport,
    bar: &ProgressBar,
) -> Result<(), Mismatch> {
    let format = DEFAULT_FORMAT;
    let mut ls = Lockstep {
        fabric,
        side: ModelSide::new(&format),
        format,
        clock: 0,
        ticks: 0,
        buf: Vec::new(),
        fault: cfg.fault,
        move_index: 0,
        session: cfg.session,
    };
    let start_time = Instant::now();
    let result = (|| {
        ls.drive(
            &CoreInputs {
                reset: true,
                ..Default::default()
            },
            2,
        )?;
        let mut stream = MoveStream::new(cfg.seed, cfg.mix);
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
            let f = Format::with_ts(spec.ts);
            let plan = match plan_from(&spec.request, &f, ls.side.model.chain()) {
                Ok(p) if p.ticks_total() <= MAX_MOVE_TICKS => p,
                _ => {
                    report.skipped += 1;
                    continue;
                }
            };
            ls.move_index = played;
            let idle = CoreInputs {
                tick_div: spec.tick_div,
                ..Default::default()
            };
            for (k, s) in plan.program.segments.iter().enumerate() {
                ls.drive(
                    &CoreInputs {
                        write_enable: true,
                        write_address: k as u8,
                        write_ticks: s.ticks,
                        write_snap: s.snap,
                        ..idle
                    },
                    1,
                )?;
            }
            ls.drive(
                &CoreInputs {
                    count_enable: true,
                    count_value: plan.program.segments.len() as u8,
                    cruise_value: plan.cruise_segment.map_or(63, |c| c as u8),
                    ..idle
                },
                1,
            )?;
            ls.drive(
                &CoreInputs {
                    start: true,
                    ..idle
                },
                1,
            )?;
            // One clock for the start to pass the input register (both sides).
            ls.drive(&idle, 1)?;
            let per_tick = u64::from(spec.tick_div) + 1;
            let mut budget = (plan.ticks_total() + 2) * per_tick + 2;
            if let Some(after) = spec.stop_after {
                ls.drive(&idle, after.min(budget))?;
                ls.drive(&CoreInputs { stop: true, ..idle }, 1)?;
                report.stopped += 1;
            } else {
                if let Some(after) = spec.soft_stop_after {
                    let k = after.min(budget);
                    ls.drive(&idle, k)?;
                    budget -= k;
                    ls.drive(
                        &CoreInputs {
                            soft_stop: true,
                            ..idle
                        },
                        1,
                    )?;
                    report.soft_stopped += 1;
                }
                while ls.side.model.busy() && budget > 0 {
                    let k = budget.min(BATCH);
                    ls.drive(&idle, k)?;
                    budget -= k;
                }
                // The clock-accurate model must land where the planner said (with the cruise cut
                // short after a controlled stop).
                let want = plan.end_after(u64::from(ls.side.model.outputs().tick_count));
                if ls.side.model.chain() != want {
                    report.planner_disagreements += 1;
                }
            }
            // A few idle clocks between moves, compared too.
            ls.drive(&idle, 3)?;
            played += 1;
            report.moves = played;
            bar.inc(1);
        }
        Ok(())
    })();
    report.seconds = start_time.elapsed().as_secs_f64();
    report.clocks = ls.clock;
    report.ticks = ls.ticks;
    result
}

fn progress_bar(cfg: &CosimConfig) -> ProgressBar {
    if cfg.progress && std::io::stderr().is_terminal() {
        let b = ProgressBar::new(cfg.moves as u64);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} moves {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    }
}

/// Runs a co-simulation of `verilog` (the motion core) against the model: its sessions (see
/// [`CosimConfig::sessions`]) on one worker thread per core.
pub fn run(verilog: &str, cfg: &CosimConfig) -> Result<CosimReport, SimError> {
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
    let bar = progress_bar(cfg);
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
                let res = session(&sessions[k], Some(fab), &mut r, &bar);
                outcomes.lock().unwrap_or_else(|e| e.into_inner())[k] = Some((r, res));
            });
        }
    });
    bar.finish_and_clear();
    let mut report = CosimReport {
        cached_build: built.cached,
        vcd: cfg.vcd.clone(),
        seconds: wall.elapsed().as_secs_f64(),
        threads,
        ..Default::default()
    };
    let mut first: Option<Mismatch> = None;
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
    for (r, res) in outcomes.into_iter().flatten() {
        report.moves += r.moves;
        report.stopped += r.stopped;
        report.soft_stopped += r.soft_stopped;
        report.skipped += r.skipped;
        report.clocks += r.clocks;
        report.ticks += r.ticks;
        report.planner_disagreements += r.planner_disagreements;
        if let Err(m) = res {
            if first.is_none() {
                first = Some(m);
            }
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
            let _ = session(
                &CosimConfig {
                    progress: false,
                    ..sessions[m.session].clone()
                },
                Some(fab),
                &mut again,
                &ProgressBar::hidden(),
            );
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
        let _ = session(
            &CosimConfig {
                progress: false,
                fault: None,
                ..s
            },
            None,
            &mut r,
            &ProgressBar::hidden(),
        );
        report.moves += r.moves;
        report.clocks += r.clocks;
        report.ticks += r.ticks;
    }
    report.seconds = wall.elapsed().as_secs_f64();
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabric::encode;

    /// Outputs with every field drawn from `seed` (registers wrapped to their widths).
    fn outputs(seed: u64, f: &Format) -> CoreOutputs {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut wide = |bits| snapgen_model::chain::wrap(rng.gen::<i128>(), bits);
        let (x, v, a, j) = (
            wide(f.widths.x),
            wide(f.widths.v),
            wide(f.widths.a),
            wide(f.widths.j),
        );
        CoreOutputs {
            x,
            v,
            a,
            j,
            position: rng.gen(),
            segment: rng.gen_range(0..64),
            busy: rng.gen(),
            done: rng.gen(),
            aborted: rng.gen(),
            tick_count: rng.gen(),
            tick: rng.gen(),
            active_bank: rng.gen(),
            standby_count: rng.gen_range(0..64),
        }
    }

    #[test]
    fn the_comparison_sees_every_bit_of_every_word() {
        let f = DEFAULT_FORMAT;
        let masks = Masks::new(&f);
        for seed in 0..64 {
            let m = outputs(seed, &f);
            let words = encode(&m, &f);
            assert_eq!(decode(&words, &f), m, "layout round trip, seed {seed}");
            assert!(!differs(&m, &words, &masks), "equal outputs, seed {seed}");
            for k in 0..OUT_WORDS {
                for bit in 0..32 {
                    let mut bad = words;
                    bad[k] ^= 1 << bit;
                    assert!(
                        differs(&m, &bad, &masks),
                        "word {k} bit {bit} flipped unseen, seed {seed}"
                    );
                }
            }
        }
    }
}
