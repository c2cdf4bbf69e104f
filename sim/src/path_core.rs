//! The Verilated path core (`snapgen_path_core`: the motion core on the path length, driving
//! the path steppers on each of its ticks) in lockstep with its model
//! (`snapgen_model::path::core::PathCore`): every output compared on every clock, and each
//! axis's step and direction lines counted as its drive would count them.
//!
//! The stream, run after run (each begins with a reset, the drives disabled): a path of 1 to 6
//! lines, arcs and helices from the host's planner, written word by word into the ring and
//! extended; a move of the path length planned by the host's planner (order 2, 3 or 4, to the
//! path's end or part of the way) uploaded into the core's standby bank; the drives enabled
//! (each axis its own step length, 1–8 LSB; a common pulse timing, 1–6 clocks each) three ticks
//! after the path is in, then the program started. Its speed limit is what the slowest axis's
//! pulses follow in a tick, times 0.2–1. A third of the moves get a **group stop** (the core's
//! controlled stop on the path length, random stop limits) at a random clock, a twentieth an
//! abort (the emergency stop); two fifths get 1 to 3 **feed overrides** at random clocks: the
//! move replanned online from the state the model predicts for a tick 2 to 40 ahead, its speed
//! limit 0–2 times the move's (within what the pulses follow; under 5 % a stop on the path),
//! uploaded while it plays and swapped in at that tick (the core's `swap`: the whole group's).
//! The run ends 20 ticks after the chain is at rest.
//!
//! Checked beside the lockstep, from the fabric's lines alone: `late` and `refused` never
//! raised; in a run whose every tick moves each axis, by the rule (`Path::at` of the chain's
//! position on each tick), no further than its pulses follow in a tick, no axis raises
//! `overrun` and each axis's steps (rising edges, signed by its direction line) equal
//! `⌊(end − start) / step⌋` of its positions by the rule at the chain's last position and at
//! its first.

use std::path::Path as FsPath;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_model::path::core::PathCore;
use snapgen_model::path::engine::load_inputs;
use snapgen_model::path::interp::Path;
use snapgen_model::path::sequencer::worst_clocks;
use snapgen_model::stop::StopLimits;
use snapgen_model::{
    Format, PathCoreInputs, PathCoreOutputs, PathSeqInputs, Quantity, DEFAULT_FORMAT, FRAC_BITS,
};
use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_plan::{plan_from, Method, MoveRequest};
use snapgen_spec::widths::MAX_SEGMENTS;

use crate::drive_lines::{count_error, verdict, whole, Counted, DriveLines, EndFlags, Verdict};
use crate::interp::random_path;
use crate::layout::{harness_header, port_layout, Batch};
pub use crate::layout::{PortFault, PortMismatch};
use crate::moves::log_uniform;
use crate::path_seq::segment_words;
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_path_core_ports!(port_layout! {
    PATH_CORE_INPUTS, PATH_CORE_OUTPUTS, PathCoreInputs, PathCoreOutputs;
});

/// The path core's tag in the harness's ABI word.
pub(crate) const PATH_CORE_TAG: u32 = 7;

/// Clocks the model runs before the fabric runs them in one call.
const BATCH: usize = 65_536;

/// Ticks a run lasts at most after its start (a longer plan is drawn again).
const MAX_RUN_TICKS: u64 = 3_000;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn path_core_layout_header() -> String {
    harness_header(
        &PATH_CORE_INPUTS,
        &PATH_CORE_OUTPUTS,
        abi(PATH_CORE_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&PathCoreInputs::default()),
    )
}

/// A run's settings.
#[derive(Clone, Debug)]
pub struct PathCoreConfig {
    /// Axes of the design (1 to 8).
    pub axes: u8,
    /// Clocks to run.
    pub clocks: u64,
    /// Seed of the stream.
    pub seed: u64,
    /// Test hook: flip a bit of an output of the fabric's (`port` indexes
    /// [`PATH_CORE_OUTPUTS`]).
    pub fault: Option<PortFault>,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PathCoreReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Runs (paths) played to their end.
    pub runs: u64,
    /// Ticks of the chain.
    pub ticks: u64,
    /// Runs with a group stop, and with an abort.
    pub stops: u64,
    /// Feed overrides swapped in (program swaps at a tick while the move plays).
    pub swaps: u64,
    /// See [`PathCoreReport::stops`].
    pub aborts: u64,
    /// Steps counted on the fabric's lines (every axis).
    pub steps: u64,
    /// Runs within the rate whose step counts were checked.
    pub checked: u64,
    /// What the drives' view found wrong, first only.
    pub violation: Option<String>,
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
}

/// What the run does next once its words are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Waiting for ticks before enabling the drives, then starting.
    Settle,
    /// The program plays; a stop or an abort may come at a clock.
    Moving,
    /// At rest: ticks left.
    Tail(u64),
}

/// One run: its path, settings and where it is.
struct Run {
    path: Path,
    /// Queued inputs (the ring's words, the extension, the program's upload).
    queue: std::collections::VecDeque<PathCoreInputs>,
    /// The inputs between requests (tick divider, stop limits, drives' settings).
    rest: PathCoreInputs,
    stage: Stage,
    /// Ticks since the words were in.
    ticks: u64,
    /// Clocks since the start; the stop's or abort's clock.
    clocks: u64,
    stop_at: Option<u64>,
    abort_at: Option<u64>,
    /// Clocks since the start at which the move is replanned (a feed override), in order.
    replan_at: Vec<u64>,
    /// The move's limits on the path length (units/s, /s², /s³), the speed the slowest
    /// axis's pulses follow, the cell it goes to, and the tick its program ends on (before
    /// the start: its length in ticks).
    limits: OnlineLimits,
    follow_speed: f64,
    end_cell: i128,
    ends_at: u64,
    /// Each axis's steps a tick at most (within the rate), whole positions at the anchor,
    /// steps counted on its lines, its position by the rule at the last tick, and whether a
    /// tick moved it further than its pulses follow.
    follows: Vec<i64>,
    start: Vec<i64>,
    counted: Vec<i64>,
    at: Vec<i64>,
    fast: bool,
    /// The chain's position at its last tick.
    x: i128,
}

impl Counted for Run {
    fn counted(&mut self) -> &mut [i64] {
        &mut self.counted
    }
}

/// A new run for `axes` axes from `rng` (see the module documentation).
fn new_run(rng: &mut StdRng, axes: u8) -> Run {
    let n = usize::from(axes);
    let cell = 1i128 << FRAC_BITS;
    loop {
        let scale = rng.gen_range(3..=4);
        let Some(path) = random_path(rng, n, scale) else {
            continue;
        };
        if !path.segments.iter().all(|g| load_inputs(g, axes).is_ok()) {
            continue;
        }
        let segments = path.segments.len();
        let steps: Vec<u16> = (0..n).map(|_| rng.gen_range(1..=8)).collect();
        let mut rest = PathCoreInputs {
            high_clocks: rng.gen_range(1..=6),
            low_clocks: rng.gen_range(1..=6),
            setup_clocks: rng.gen_range(1..=6),
            ..Default::default()
        };
        for (k, &st) in steps.iter().enumerate() {
            rest.step_lsb |= u128::from(st) << (16 * k);
        }
        // A tick long enough for one that crosses every segment (never late).
        let period = worst_clocks(axes, segments as u64) + rng.gen_range(0..1_000);
        rest.tick_div = period as u32 - 1;
        // What each axis's pulses follow in a tick, with a reversal on every step.
        let per_step = 2
            + u64::from(rest.high_clocks)
            + u64::from(rest.low_clocks)
            + u64::from(rest.setup_clocks);
        let follows: Vec<i64> = steps
            .iter()
            .map(|&st| (period / per_step) as i64 * i64::from(st) - 2)
            .collect();
        let slowest = *follows.iter().min().expect("an axis");
        if slowest < 4 {
            continue;
        }
        // The move on the path length, at Ts 100 µs and the default format (an axis moves at
        // most as far as the path: every share ≤ 1).
        let ts = 1e-4;
        let f = Format::with_ts(ts);
        let lsb = DEFAULT_FORMAT.position_lsb;
        let v = slowest as f64 * lsb / ts * rng.gen_range(0.2..=1.0);
        let a = v / ts / log_uniform(rng, 5.0, 200.0);
        let j = a / ts / log_uniform(rng, 2.0, 100.0);
        let d = j / ts / log_uniform(rng, 2.0, 50.0);
        let method = match rng.gen_range(0..3) {
            0 => Method::Order2 { vmax: v, amax: a },
            1 => Method::Order3 {
                vmax: v,
                amax: a,
                jmax: j,
            },
            _ => Method::Order4 {
                vmax: v,
                amax: a,
                jmax: j,
                dmax: d,
            },
        };
        let total = path.length();
        let cells = if rng.gen_bool(0.7) {
            total / cell + 1
        } else {
            total / cell * rng.gen_range(1..=9) / 10
        };
        let request = MoveRequest {
            distance: cells as f64 * lsb,
            method,
        };
        let home = snapgen_model::ChainState {
            x: f.home_raw(),
            ..Default::default()
        };
        let Ok(plan) = plan_from(&request, &f, home) else {
            continue;
        };
        if plan.ticks_total() > MAX_RUN_TICKS || plan.ticks_total() == 0 {
            continue;
        }
        // Stop limits, raw: an acceleration that stops the top speed in 2 to 300 ticks and a
        // jerk that reaches it in 1 to 100.
        let v_raw = (v * f.scale(Quantity::Velocity)).max(1.0);
        let accel = ((v_raw / log_uniform(rng, 2.0, 300.0)) as i128).max(1);
        let jerk = ((accel as f64 / log_uniform(rng, 1.0, 100.0)) as i128).clamp(1, accel);
        let limits = StopLimits { jerk, accel };
        rest.stop_jerk = limits.jerk;
        rest.stop_accel = limits.accel;
        let mut queue = std::collections::VecDeque::new();
        let mut start = 0i128;
        for (k, g) in path.segments.iter().enumerate() {
            for w in segment_words(rng, k as u16, start, g, axes) {
                queue.push_back(PathCore::host_inputs(&w, &rest));
            }
            start += g.length;
        }
        queue.push_back(PathCore::host_inputs(
            &PathSeqInputs {
                seg_index: segments as u16 - 1,
                extend: true,
                ..Default::default()
            },
            &rest,
        ));
        for (k, s) in plan.program.segments.iter().enumerate() {
            queue.push_back(PathCoreInputs {
                write_enable: true,
                write_address: k as u8,
                write_ticks: s.ticks,
                write_snap: s.snap,
                ..rest
            });
        }
        queue.push_back(PathCoreInputs {
            count_enable: true,
            count_value: plan.program.segments.len() as u8,
            ..rest
        });
        let clocks = plan.ticks_total() * period;
        let stop_at = rng.gen_bool(0.33).then(|| rng.gen_range(1..=clocks));
        let abort_at = (stop_at.is_none() && rng.gen_bool(0.05)).then(|| rng.gen_range(1..=clocks));
        let mut replan_at: Vec<u64> = if rng.gen_bool(0.4) {
            (0..rng.gen_range(1..=3))
                .map(|_| rng.gen_range(1..=clocks))
                .collect()
        } else {
            Vec::new()
        };
        replan_at.sort_unstable();
        return Run {
            path,
            queue,
            rest,
            stage: Stage::Settle,
            ticks: 0,
            clocks: 0,
            stop_at,
            abort_at,
            replan_at,
            limits: OnlineLimits {
                velocity: v,
                acceleration: a,
                deceleration: a,
                jerk: j,
            },
            follow_speed: slowest as f64 * lsb / ts,
            end_cell: f.output_lsb(home.x) + cells,
            // The program's ticks until it starts (then the tick it ends on).
            ends_at: plan.ticks_total(),
            follows,
            start: vec![0; n],
            counted: vec![0; n],
            at: Vec::new(),
            fast: false,
            x: home.x,
        };
    }
}

/// Runs the stream of `cfg` on the library `library` (built by
/// [`crate::build::build_path_core`] for `cfg.axes` axes).
pub fn run(library: &FsPath, cfg: &PathCoreConfig) -> Result<PathCoreReport, SimError> {
    let axes = cfg.axes;
    let mut fabric = Verilated::open(library, None, PATH_CORE_TAG, IN_WORDS, OUT_WORDS)?;
    let mut lines = DriveLines::of(&PATH_CORE_OUTPUTS, &OUT_SLOTS);
    let mut rng = StdRng::seed_from_u64(cfg.seed);
    let mut model =
        PathCore::new(&DEFAULT_FORMAT, axes).map_err(|e| SimError::Config(e.to_string()))?;
    let mut r = PathCoreReport::default();
    let mut batch = Batch::new(&PATH_CORE_OUTPUTS, &OUT_SLOTS, OUT_WORDS, cfg.fault);
    let mut ended: Vec<(u64, Run)> = Vec::new();
    let mut current: Option<Run> = None;
    while r.clocks < cfg.clocks {
        let i = match current.as_mut() {
            None => {
                let run = new_run(&mut rng, axes);
                let i = PathCoreInputs {
                    reset: true,
                    ..run.rest
                };
                current = Some(run);
                i
            }
            Some(run) => next_inputs(run, &model, &mut r, &mut rng),
        };
        model.clock(&i);
        let o = model.outputs();
        batch.push(&encode_inputs(&i), &encode_outputs(&o));
        r.clocks += 1;
        if let Some(run) = current.as_mut() {
            if o.tick {
                r.ticks += 1;
            }
            if run.stage == Stage::Tail(0) {
                let run = current.take().expect("a run");
                ended.push((r.clocks, run));
            }
        }
        if batch.len() >= BATCH || r.clocks == cfg.clocks {
            if let Some(m) = batch.run(&mut fabric) {
                r.clocks = m.clock + 1;
                r.mismatch = Some(m);
                return Ok(r);
            }
            // The drives' view of the batch's lines, run by run.
            let (got, first) = (batch.got(), batch.first);
            lines.count(got, first, &mut ended, current.as_mut(), |run, flags| {
                judge(&run, flags, &mut r);
            });
            r.steps = lines.steps;
            batch.next();
        }
    }
    Ok(r)
}

/// The run's inputs for the next clock, from the model's outputs as they stand.
fn next_inputs(
    run: &mut Run,
    model: &PathCore,
    r: &mut PathCoreReport,
    rng: &mut StdRng,
) -> PathCoreInputs {
    if let Some(w) = run.queue.pop_front() {
        return w;
    }
    let o = model.outputs();
    let all = ((1u16 << model.steppers.position.len()) - 1) as u8;
    let mut i = run.rest;
    if o.tick {
        // The chain steps on this clock's edge; the steppers take its position on the next.
        run.ticks += 1;
    }
    // Each tick the chain has made: where the rule puts every axis, and how far it moved.
    let x = model.core.chain().x;
    if x != run.x || run.at.is_empty() {
        run.x = x;
        let at: Vec<i64> = run
            .path
            .at(x)
            .expect("a segment")
            .iter()
            .map(|&p| whole(p))
            .collect();
        if !run.at.is_empty() {
            for (k, (&now, &was)) in at.iter().zip(&run.at).enumerate() {
                if (now - was).abs() > run.follows[k] {
                    run.fast = true;
                }
            }
        }
        run.at = at;
    }
    match run.stage {
        Stage::Settle => {
            // From the third tick on the drives follow: the second's commit has put every
            // axis on the path at the chain's position a tick before.
            if run.ticks >= 3 {
                i.enable = all;
            }
            if run.ticks == 3 && o.tick {
                run.start = run.at.clone();
            }
            if run.ticks == 4 && o.tick {
                i.start = true;
                run.stage = Stage::Moving;
                // From here every input, queued ones too, keeps the drives following.
                run.rest.enable = all;
                run.ends_at += o.ticks + 1;
            }
        }
        Stage::Moving => {
            i.enable = all;
            run.clocks += 1;
            if run.stop_at == Some(run.clocks) {
                i.stop = true;
                r.stops += 1;
            }
            if run.abort_at == Some(run.clocks) {
                i.abort_move = true;
                r.aborts += 1;
            }
            if run.replan_at.first() == Some(&run.clocks) {
                run.replan_at.remove(0);
                replan(run, model, r, rng);
            }
            if run.clocks > 2 && !o.busy && !o.stopping && !o.swap_pending && o.at_rest {
                run.stage = Stage::Tail(20);
            }
        }
        Stage::Tail(left) => {
            i.enable = all;
            if o.tick {
                run.stage = Stage::Tail(left - 1);
            }
        }
    }
    i
}

/// A feed override while the move plays: the move replanned online (order 3) from the state
/// the model predicts for a tick 2 to 40 ahead, its speed limit the move's times 0–2 (at most
/// what the slowest axis's pulses follow; below 5 %: a stop on the path), to the move's cell
/// at rest; uploaded into the standby bank and swapped in at that tick. Skipped when the
/// program ends before then, a stop runs or a swap is armed.
fn replan(run: &mut Run, model: &PathCore, r: &mut PathCoreReport, rng: &mut StdRng) {
    let o = model.outputs();
    let at = o.ticks + rng.gen_range(2..=40);
    if at + 2 >= run.ends_at || o.swap_pending || o.stopping {
        return;
    }
    let idle = PathCore::core_inputs(&run.rest);
    let mut m = model.core.clone();
    while m.outputs().ticks < at {
        m.edge(&idle);
    }
    let start = m.chain();
    let k: f64 = rng.gen_range(0.0..=2.0);
    let limits = OnlineLimits {
        velocity: (run.limits.velocity * k).clamp(1e-9, run.follow_speed),
        ..run.limits
    };
    let target = if k < 0.05 {
        OnlineTarget::Velocity(0.0)
    } else {
        OnlineTarget::Position {
            cell: run.end_cell,
            velocity: 0.0,
        }
    };
    let f = Format::with_ts(1e-4);
    let Ok(plan) = plan_online(&start, &target, &limits, OnlineOrder::Three, &f) else {
        return;
    };
    let program = &plan.program;
    if program.total_ticks() > MAX_RUN_TICKS || program.segments.len() > MAX_SEGMENTS as usize {
        return;
    }
    for (k, seg) in program.segments.iter().enumerate() {
        run.queue.push_back(PathCoreInputs {
            write_enable: true,
            write_address: k as u8,
            write_ticks: seg.ticks,
            write_snap: seg.snap,
            ..run.rest
        });
    }
    run.queue.push_back(PathCoreInputs {
        count_enable: true,
        count_value: program.segments.len() as u8,
        ..run.rest
    });
    run.queue.push_back(PathCoreInputs {
        swap: true,
        swap_last: (at - 1) as u32,
        ..run.rest
    });
    run.ends_at = at + program.total_ticks();
    r.swaps += 1;
}

/// The drives' view of a run that ended with the fabric's `overrun`, `late` and `refused`
/// as `flags` (see the module documentation).
fn judge(run: &Run, flags: EndFlags, r: &mut PathCoreReport) {
    r.runs += 1;
    match verdict(flags, run.fast, || {
        count_error(&run.counted, &run.start, &run.at, run.rest.step_lsb)
    }) {
        Verdict::Checked => r.checked += 1,
        Verdict::Fast => {}
        Verdict::Wrong(what) => {
            r.violation.get_or_insert(format!("run {}: {what}", r.runs));
        }
    }
}
