//! Lockstep co-simulation of the Verilated core and the clock-accurate model.
//!
//! A session resets the core, then for each move plans it from the model's exact state, writes
//! its segments into the standby bank, starts it and clocks until it is done (or stops it
//! midway, or replans it: a chain of program swaps at random ticks, each planned online from
//! the state the model predicts for its tick, as a host does). Fabric and model receive the
//! same inputs on every clock and every output — x, v, a, j, position, segment index, busy,
//! done, aborted, tick count, tick, active bank, swap pending — is compared after every rising
//! edge. The first mismatch ends the session; it is then re-run
//! with a trace build to write the waves around it.

use std::collections::VecDeque;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_model::{ChainState, CoreInputs, CoreModel, CoreOutputs, Format, DEFAULT_FORMAT};
use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_plan::plan_from;

mod streams;

use crate::build::build;
use crate::fabric::{Fabric, VcdWindow, CORE_OUTPUTS, OUTPUT_BITS, OUT_SLOTS, OUT_WORDS};
use crate::moves::{log_uniform, MoveSpec, MoveStream, OrderMix};
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
/// A controlled stop still running this many clocks after its request is aborted (each stop
/// tick waits for the stop unit's decision, so a long stop costs many clocks).
const MAX_STOP_CLOCKS: u64 = 600_000;

/// A compared output: an index into [`CORE_OUTPUTS`] (the spec's port list), which gives its
/// name and width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Register(usize);

impl Register {
    /// Every register, in comparison order.
    pub fn all() -> impl Iterator<Item = Register> {
        (0..CORE_OUTPUTS.len()).map(Register)
    }

    /// The register called `name` (its Verilog port).
    pub fn named(name: &str) -> Option<Register> {
        CORE_OUTPUTS
            .iter()
            .position(|p| p.name == name)
            .map(Register)
    }

    /// Its name (as the Verilog port).
    pub fn name(self) -> &'static str {
        CORE_OUTPUTS[self.0].name
    }

    /// Its width in bits.
    pub fn bits(self) -> u32 {
        CORE_OUTPUTS[self.0].bits
    }

    /// Its raw bits in `o`, as an unsigned pattern of its width.
    #[inline(always)]
    pub fn bits_of(self, o: &CoreOutputs) -> u128 {
        OUTPUT_BITS[self.0](o) & (u128::MAX >> (128 - self.bits()))
    }

    /// Its bits in a clock's output words.
    pub fn bits_in(self, words: &[u32]) -> u128 {
        OUT_SLOTS[self.0].get(words)
    }

    /// Flips bit `bit` (modulo its width) of this register in a clock's output words.
    pub fn flip(self, words: &mut [u32], bit: u32) {
        let slot = OUT_SLOTS[self.0];
        let v = slot.get(words) ^ (1u128 << (bit % self.bits()));
        slot.put(words, v);
    }
}

impl std::str::FromStr for Register {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Register::named(s).ok_or_else(|| {
            let names: Vec<&str> = CORE_OUTPUTS.iter().map(|p| p.name).collect();
            format!("unknown register {s:?} (one of {})", names.join(", "))
        })
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
            stop_share: crate::moves::DEFAULT_STOP_SHARE,
            replan_share: crate::moves::DEFAULT_REPLAN_SHARE,
            stream_share: crate::moves::DEFAULT_STREAM_SHARE,
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
    pub aborted: usize,
    /// Positions loaded at rest (the reference taking an encoder's position).
    pub loads: usize,
    /// Moves given a controlled stop.
    pub stopped: usize,
    /// Stops aborted on the way by the stream.
    pub stops_aborted: usize,
    /// Stops aborted for running past [`MAX_STOP_CLOCKS`].
    pub stops_timed_out: usize,
    /// Stops that began outside their limits (and landed regardless of them).
    pub stops_over: usize,
    /// Stops after which the chain was not at rest (must be 0).
    pub stops_not_at_rest: usize,
    /// Moves the stream drew but the planner refused or that were too long (skipped).
    pub skipped: usize,
    /// Program swaps played (online replans from the state at their tick).
    pub replans: usize,
    /// Replans the online planner refused, by reason (its error's variant): not played.
    pub replans_refused: std::collections::BTreeMap<String, usize>,
    /// Replans longer than the stream keeps (`MAX_MOVE_TICKS`): not played.
    pub replans_too_long: usize,
    /// Swaps armed for a tick already reached (each must change nothing).
    pub late_swaps: usize,
    /// Late swaps the core armed anyway (must be 0).
    pub late_swaps_taken: usize,
    /// Timely swaps the core did not arm (must be 0).
    pub swaps_not_armed: usize,
    /// Armed swaps cancelled by a controlled stop before their tick.
    pub swaps_cancelled: usize,
    /// PLCopen event streams played (each a random script through the host axis and its
    /// driver).
    pub streams: usize,
    /// Program swaps the streams' driver made (each planned from the exact state at its tick
    /// and armed ahead of the link), extensions of long changes among them.
    pub stream_swaps: usize,
    /// Of `stream_swaps`, those that only uploaded the rest of a change longer than the
    /// program memory.
    pub stream_extensions: usize,
    /// Commands the streams gave.
    pub stream_commands: usize,
    /// Commands that ended in Error, by ErrorID (a planner refusal, a link too slow).
    pub stream_errors: std::collections::BTreeMap<String, usize>,
    /// Streams whose driver read registers that differ from its prediction (must be 0).
    pub streams_diverged: usize,
    /// Streams whose run ended otherwise in error, by message.
    pub streams_failed: std::collections::BTreeMap<String, usize>,
    /// Streams still moving when their script ended (a velocity held), aborted at the end.
    pub streams_aborted: usize,
    /// Clocks compared.
    pub clocks: u64,
    /// Ticks compared (clocks on which the chain stepped with a program or a stop).
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
    /// Swaps the core handled against the rules: a late one armed or a timely one not (both
    /// must be 0).
    pub fn swap_faults(&self) -> usize {
        self.late_swaps_taken + self.swaps_not_armed
    }

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
    /// The chain steps with a program or a stop on the next clock.
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
        self.ticking = m.tick && (m.busy || m.stopping);
        self.pending = *i;
        (m, ticked)
    }
}

/// The two sides in lockstep.
struct Lockstep {
    fabric: Option<Fabric>,
    side: ModelSide,
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
        if let Some(fab) = self.fabric.as_mut() {
            fab.set(i);
        }
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
                        // A word differs (or the fault is due): compare register by register.
                        if faulty || differs(&m, words) {
                            let mut words = *words;
                            if let Some(fl) = self.fault.filter(|_| faulty) {
                                fl.register.flip(&mut words, fl.bit);
                            }
                            // Every bit of every word belongs to a register (tested), so a
                            // difference is always found here.
                            if let Some(register) =
                                Register::all().find(|r| r.bits_of(&m) != r.bits_in(&words))
                            {
                                return Err(Mismatch {
                                    session: self.session,
                                    clock: self.clock,
                                    move_index: self.move_index,
                                    register,
                                    expected: register.bits_of(&m),
                                    actual: register.bits_in(&words),
                                    bits: register.bits(),
                                });
                            }
                            panic!(
                                "the harness set output bits outside every register at clock {}",
                                self.clock
                            );
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

/// Whether the fabric's words differ from the model's outputs anywhere: the model's outputs
/// encoded in the same layout ([`crate::fabric::encode`]) and compared word for word (the
/// differences ORed together, without a branch or a call per word).
#[inline(always)]
fn differs(m: &CoreOutputs, w: &[u32; OUT_WORDS]) -> bool {
    let e = crate::fabric::encode(m);
    e.iter().zip(w).fold(0u32, |acc, (x, y)| acc | (x ^ y)) != 0
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
                let idle = CoreInputs {
                    tick_div: spec.tick_div,
                    ..Default::default()
                };
                ls.drive(
                    &CoreInputs {
                        load: true,
                        load_position: to as u32,
                        ..idle
                    },
                    1,
                )?;
                ls.drive(&idle, 1)?;
                report.loads += 1;
            }
            if spec.stream > 0 {
                ls.move_index = played;
                let idle = CoreInputs {
                    tick_div: spec.tick_div,
                    ..Default::default()
                };
                streams::stream(&mut ls, &spec, &idle, report)?;
                ls.drive(&idle, 3)?;
                played += 1;
                report.moves = played;
                bar.inc(1);
                continue;
            }
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
            let budget = (plan.ticks_total() + 2) * per_tick + 2;
            if let Some(after) = spec.abort_after {
                ls.drive(&idle, after.min(budget))?;
                ls.drive(
                    &CoreInputs {
                        abort_move: true,
                        ..idle
                    },
                    1,
                )?;
                report.aborted += 1;
            } else if let Some(after) = spec.stop_after {
                ls.drive(&idle, after.min(budget))?;
                controlled_stop(
                    &mut ls,
                    &spec,
                    &idle,
                    spec.stop_again_after,
                    spec.abort_stop_after,
                    report,
                )?;
            } else if spec.replans > 0 {
                replan_chain(
                    &mut ls,
                    &spec,
                    plan.ticks_total(),
                    plan.final_state,
                    &idle,
                    report,
                )?;
            } else {
                let mut left = budget;
                while ls.side.model.busy() && left > 0 {
                    let k = left.min(BATCH);
                    ls.drive(&idle, k)?;
                    left -= k;
                }
                // The clock-accurate model must land where the planner said.
                if ls.side.model.chain() != plan.final_state {
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

/// A controlled stop with the move's stop limits, run to its end: a second request (ignored)
/// `again` clocks after the first and an abort `abort` clocks after it when set, and an abort
/// if it runs past [`MAX_STOP_CLOCKS`].
fn controlled_stop(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    idle: &CoreInputs,
    mut again: Option<u64>,
    abort: Option<u64>,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let stop = CoreInputs {
        stop: true,
        stop_jerk: spec.stop_limits.jerk,
        stop_accel: spec.stop_limits.accel,
        ..*idle
    };
    ls.drive(&stop, 1)?;
    report.stopped += 1;
    let mut clocks = 1u64;
    while ls.side.model.stopping() || ls.side.pending.stop {
        let next = [again, abort, Some(MAX_STOP_CLOCKS)]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(MAX_STOP_CLOCKS);
        if clocks < next {
            let k = (next - clocks).min(BATCH);
            ls.drive(idle, k)?;
            clocks += k;
            continue;
        }
        if again == Some(clocks) {
            ls.drive(&stop, 1)?;
            again = None;
        } else {
            ls.drive(
                &CoreInputs {
                    abort_move: true,
                    ..*idle
                },
                1,
            )?;
            if abort == Some(clocks) {
                report.stops_aborted += 1;
            } else {
                report.stops_timed_out += 1;
            }
            // Past the abort (and the input register): nothing runs any more.
            ls.drive(idle, 1)?;
            break;
        }
        clocks += 1;
    }
    let o = ls.side.model.outputs();
    if o.stop_over {
        report.stops_over += 1;
    }
    // Wherever the stop began, the chain ends at rest (unless it was aborted, which also
    // leaves it at rest).
    if !ls.side.model.chain().is_at_rest() {
        report.stops_not_at_rest += 1;
    }
    Ok(())
}

/// The chain's registers when the time base reaches `at` with nothing else asked of the core:
/// what a host knows from the model before it plans a swap for that tick.
fn state_at(side: &ModelSide, idle: &CoreInputs, at: u64) -> ChainState {
    let mut m = side.model.clone();
    m.edge(&side.pending);
    while m.outputs().ticks < at {
        m.edge(idle);
    }
    m.chain()
}

/// Writes `program` into the standby bank and commits it, one clock a segment.
fn upload(
    ls: &mut Lockstep,
    program: &snapgen_model::Program,
    idle: &CoreInputs,
) -> Result<(), Mismatch> {
    for (k, s) in program.segments.iter().enumerate() {
        ls.drive(
            &CoreInputs {
                write_enable: true,
                write_address: k as u8,
                write_ticks: s.ticks,
                write_snap: s.snap,
                ..*idle
            },
            1,
        )?;
    }
    ls.drive(
        &CoreInputs {
            count_enable: true,
            count_value: program.segments.len() as u8,
            ..*idle
        },
        1,
    )
}

/// Drives idle clocks until the model's time base reaches `at` (or `budget` clocks pass).
fn drive_until_tick(
    ls: &mut Lockstep,
    idle: &CoreInputs,
    at: u64,
    budget: u64,
) -> Result<(), Mismatch> {
    let mut left = budget;
    while ls.side.model.outputs().ticks < at && left > 0 {
        let per_tick = u64::from(idle.tick_div) + 1;
        let k = ((at - ls.side.model.outputs().ticks) * per_tick)
            .min(BATCH)
            .min(left);
        ls.drive(idle, k)?;
        left -= k;
    }
    Ok(())
}

/// Online limits drawn log-uniformly (unit/s, /s², /s³): each the active one in some replans,
/// some far below the state a replan starts from.
fn random_limits(rng: &mut StdRng) -> OnlineLimits {
    OnlineLimits {
        velocity: log_uniform(rng, 0.02, 10.0),
        acceleration: log_uniform(rng, 1.0, 1000.0),
        deceleration: log_uniform(rng, 1.0, 1000.0),
        jerk: log_uniform(rng, 50.0, 2e5),
    }
}

/// The move's replans: `spec.replans` program swaps at random ticks (mid-jerk, mid-acceleration,
/// at cruise, after the end), each planned online from the state the model predicts for its
/// tick to a position at rest, a set velocity or a blend point (the last to a position at
/// rest), uploaded while the current program plays and armed for that tick; now and then a
/// late swap (it must change nothing) or a stop while one is armed (it cancels it). At the end
/// the chain must stand where the last plan said.
fn replan_chain(
    ls: &mut Lockstep,
    spec: &MoveSpec,
    first_ticks: u64,
    first_final: ChainState,
    idle: &CoreInputs,
    report: &mut CosimReport,
) -> Result<(), Mismatch> {
    let mut rng = StdRng::seed_from_u64(spec.replan_seed);
    let f = Format::with_ts(spec.ts);
    let per_tick = u64::from(spec.tick_div) + 1;
    let mut program_ticks = first_ticks;
    // Where the program playing ends, when it ends at rest.
    let mut ends_at: Option<ChainState> = Some(first_final);
    let mut done = 0u8;
    let mut attempts = 0u32;
    while done < spec.replans || ends_at.is_none() {
        attempts += 1;
        if attempts > 4 * u32::from(spec.replans) + 16 {
            break;
        }
        // A random while into the program playing (or past its end).
        let wait = log_uniform(&mut rng, 1.0, (program_ticks as f64 * 1.2).max(2.0)) as u64;
        let now = ls.side.model.outputs().ticks;
        drive_until_tick(ls, idle, now + wait, (wait + 2) * per_tick + 2)?;
        let now = ls.side.model.outputs().ticks;
        if rng.gen_bool(0.05) {
            // Late: a tick the time base has reached, or reaches on the arming edge. The core
            // must not arm it (the next upload replaces this program).
            let one = snapgen_model::Program {
                segments: vec![snapgen_model::Segment { ticks: 5, snap: 7 }],
            };
            upload(ls, &one, idle)?;
            // (The core wants three ticks of lead over the time base before the arming edge,
            // which is at least `now`: two or fewer are refused whenever it sees them.)
            let late_at = ls
                .side
                .model
                .outputs()
                .ticks
                .wrapping_add_signed(rng.gen_range(-2..=2));
            ls.drive(
                &CoreInputs {
                    swap: true,
                    swap_last: late_at.wrapping_sub(1) as u32,
                    ..*idle
                },
                1,
            )?;
            ls.drive(idle, 2)?;
            report.late_swaps += 1;
            if ls.side.model.outputs().swap_pending {
                report.late_swaps_taken += 1;
            }
            continue;
        }
        let last = done + 1 >= spec.replans;
        let lead = log_uniform(&mut rng, 2.0, 3000.0) as u64;
        // Room for the upload (at most 34 clocks) before the tick, and the core's lead of 3.
        let at = now + 40 + lead;
        let start = state_at(&ls.side, idle, at);
        let limits = random_limits(&mut rng);
        let order = if rng.gen_bool(0.7) {
            OnlineOrder::Three
        } else {
            OnlineOrder::Two
        };
        let sign = if rng.gen_bool(0.5) { 1 } else { -1 };
        let cell = f.output_lsb(start.x) + sign * log_uniform(&mut rng, 1.0, 2e6) as i128;
        let speed = limits.velocity * rng.gen_range(0.05..=1.0);
        let target = match (last, rng.gen_range(0..5)) {
            (false, 0) => OnlineTarget::Velocity(f64::from(sign as i32) * speed),
            (false, 1) => OnlineTarget::Position {
                cell,
                velocity: f64::from(sign as i32) * speed,
            },
            _ => OnlineTarget::Position {
                cell,
                velocity: 0.0,
            },
        };
        let plan = match plan_online(&start, &target, &limits, order, &f) {
            Ok(p) if p.program.total_ticks() <= MAX_MOVE_TICKS => p,
            Ok(_) => {
                report.replans_too_long += 1;
                continue;
            }
            Err(e) => {
                *report.replans_refused.entry(kind_of(&e)).or_default() += 1;
                continue;
            }
        };
        upload(ls, &plan.program, idle)?;
        ls.drive(
            &CoreInputs {
                swap: true,
                swap_last: (at - 1) as u32,
                ..*idle
            },
            1,
        )?;
        // Past the input register: armed.
        ls.drive(idle, 1)?;
        if !ls.side.model.outputs().swap_pending {
            report.swaps_not_armed += 1;
            continue;
        }
        if rng.gen_bool(0.03) {
            // A stop while the swap is armed cancels it; the stop brings the chain to rest.
            let before = (at - ls.side.model.outputs().ticks) * per_tick;
            ls.drive(idle, rng.gen_range(0..before.max(1)))?;
            controlled_stop(ls, spec, idle, None, None, report)?;
            report.swaps_cancelled += 1;
            return Ok(());
        }
        drive_until_tick(ls, idle, at, (lead + 45) * per_tick + 4)?;
        report.replans += 1;
        done += 1;
        program_ticks = plan.program.total_ticks();
        ends_at = match target {
            OnlineTarget::Position { velocity: 0.0, .. } => Some(plan.final_state),
            _ => None,
        };
    }
    match ends_at {
        Some(end) => {
            let budget = (program_ticks + 2) * per_tick + 2;
            let mut left = budget;
            while ls.side.model.busy() && left > 0 {
                let k = left.min(BATCH);
                ls.drive(idle, k)?;
                left -= k;
            }
            if ls.side.model.chain() != end {
                report.planner_disagreements += 1;
            }
        }
        // Still moving (no rest target could be planned): the fabric's stop brings it to rest.
        None => controlled_stop(ls, spec, idle, None, None, report)?,
    }
    Ok(())
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
        report.aborted += r.aborted;
        report.loads += r.loads;
        report.stopped += r.stopped;
        report.stops_aborted += r.stops_aborted;
        report.stops_timed_out += r.stops_timed_out;
        report.stops_over += r.stops_over;
        report.stops_not_at_rest += r.stops_not_at_rest;
        report.skipped += r.skipped;
        report.replans += r.replans;
        for (k, n) in &r.replans_refused {
            *report.replans_refused.entry(k.clone()).or_default() += n;
        }
        report.replans_too_long += r.replans_too_long;
        report.late_swaps += r.late_swaps;
        report.late_swaps_taken += r.late_swaps_taken;
        report.swaps_not_armed += r.swaps_not_armed;
        report.swaps_cancelled += r.swaps_cancelled;
        report.streams += r.streams;
        report.stream_swaps += r.stream_swaps;
        report.stream_extensions += r.stream_extensions;
        report.stream_commands += r.stream_commands;
        for (k, n) in &r.stream_errors {
            *report.stream_errors.entry(k.clone()).or_default() += n;
        }
        report.streams_diverged += r.streams_diverged;
        for (k, n) in &r.streams_failed {
            *report.streams_failed.entry(k.clone()).or_default() += n;
        }
        report.streams_aborted += r.streams_aborted;
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

/// The name of an error's variant (its `Debug` up to the first field), a report's key.
fn kind_of(e: &impl std::fmt::Debug) -> String {
    let text = format!("{e:?}");
    text.split(['(', ' ', '{'])
        .next()
        .unwrap_or("?")
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabric::{decode, encode};

    /// Outputs with every port's bits drawn from `seed` (random words, decoded).
    fn outputs(seed: u64) -> CoreOutputs {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let words: Vec<u32> = (0..OUT_WORDS).map(|_| rng.gen()).collect();
        decode(&words)
    }

    /// Every bit of every output word belongs to a register: a flip anywhere is seen by the
    /// comparison and found in a register.
    #[test]
    fn the_comparison_sees_every_bit_of_every_word() {
        for seed in 0..64 {
            let m = outputs(seed);
            let words = encode(&m);
            assert_eq!(decode(&words), m, "layout round trip, seed {seed}");
            assert!(!differs(&m, &words), "equal outputs, seed {seed}");
            for k in 0..OUT_WORDS {
                for bit in 0..32 {
                    let mut bad = words;
                    bad[k] ^= 1 << bit;
                    let found = Register::all().any(|r| r.bits_of(&m) != r.bits_in(&bad));
                    let used = OUT_SLOTS.iter().any(|s| s.covers(k, bit));
                    assert!(differs(&m, &bad), "word {k} bit {bit} unseen, seed {seed}");
                    assert_eq!(found, used, "word {k} bit {bit}, seed {seed}");
                }
            }
        }
    }
}
