//! The Verilated path steppers (`snapgen_path_steppers` with the sequencer, the interpolator
//! and a step/dir generator per axis) in lockstep with their model
//! (`snapgen_model::path::steppers::PathSteppers`): every output compared on every clock, and
//! each axis's step and direction lines counted as its drive would count them.
//!
//! The stream, run after run (each begins with a reset and the drives disabled): a path of 1
//! to 6 lines, arcs and helices from the host's planner (elements up to about 10³ or 10⁴ LSB,
//! so that a run is some hundreds of ticks), written word by word and extended; two ticks at
//! the start (the axes take the path's start), then the drives enabled, each axis with its own
//! step length (1–8 LSB) and a common pulse timing (1–6 clocks each); ticks `worst_clocks` (for
//! a tick that crosses every segment) to 1 000 clocks more apart, the path length moving on by
//! up to what the slowest axis's pulses can follow in a tick (now and then staying, or back
//! within a cell), to the end and 20 ticks more. A fifth of the runs move 4 to 8 times faster
//! than the pulses can follow.
//!
//! Checked beside the lockstep, from the fabric's lines alone: in a run within the rate no
//! axis raises `overrun` and each axis's steps (rising edges, signed by its direction line)
//! equal `⌊(end − start) / step⌋` of its position at the path's end and at its start, by the
//! rule (`Path::at`); in a run with a tick that moves an axis, by the rule, further than its
//! pulses can follow in a tick, that axis raises `overrun`.

use std::path::Path as FsPath;

use rand::{Rng, SeedableRng};
use snapgen_model::path::engine::load_inputs;
use snapgen_model::path::interp::Path;
use snapgen_model::path::sequencer::worst_clocks;
use snapgen_model::path::steppers::PathSteppers;
use snapgen_model::{PathSeqInputs, PathSteppersInputs, PathSteppersOutputs, FRAC_BITS};

use crate::drive_lines::{count_error, verdict, whole, Counted, DriveLines, EndFlags, Verdict};
use crate::interp::random_path;
use crate::layout::{harness_header, port_layout, Batch};
pub use crate::layout::{PortFault, PortMismatch};
use crate::path_seq::segment_words;
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_path_steppers_ports!(port_layout! {
    PATH_STEPPERS_INPUTS, PATH_STEPPERS_OUTPUTS, PathSteppersInputs, PathSteppersOutputs;
});

/// The stage's tag in the harness's ABI word.
const PATH_STEPPERS_TAG: u32 = 6;

/// Clocks the model runs before the fabric runs them in one call.
const BATCH: usize = 65_536;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn path_steppers_layout_header() -> String {
    harness_header(
        &PATH_STEPPERS_INPUTS,
        &PATH_STEPPERS_OUTPUTS,
        abi(PATH_STEPPERS_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&PathSteppersInputs::default()),
    )
}

/// A run's settings.
#[derive(Clone, Debug)]
pub struct PathSteppersConfig {
    /// Axes of the design (1 to 8).
    pub axes: u8,
    /// Clocks to run.
    pub clocks: u64,
    /// Seed of the stream.
    pub seed: u64,
    /// Test hook: flip a bit of an output of the fabric's (`port` indexes
    /// [`PATH_STEPPERS_OUTPUTS`]).
    pub fault: Option<PortFault>,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PathSteppersReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Runs (paths) played to their end.
    pub runs: u64,
    /// Ticks given.
    pub ticks: u64,
    /// Steps counted on the fabric's lines (every axis).
    pub steps: u64,
    /// Runs within the rate whose step counts were checked.
    pub checked: u64,
    /// Runs faster than the pulses.
    pub fast: u64,
    /// Runs with a tick whose jump, by the rule, is more steps than an axis's pulses can
    /// make in a tick; and of those how many raised `overrun` (all must).
    pub must: u64,
    /// See [`PathSteppersReport::must`].
    pub flagged: u64,
    /// What the drives' view found wrong, first only.
    pub violation: Option<String>,
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
}

/// One run: its path and settings, and where it is.
struct Run {
    path: Path,
    /// Queued inputs (the writes, then the extension).
    queue: std::collections::VecDeque<PathSteppersInputs>,
    /// The drives' settings (the stage's inputs other than the path's).
    drives: PathSteppersInputs,
    /// Path length per tick at most (raw).
    ds: i128,
    fast: bool,
    period: u64,
    until_tick: u64,
    /// Ticks given; ticks left after the path's end.
    ticks: u64,
    tail: u64,
    s: i128,
    /// Each axis's position at the start (whole LSB), and steps counted on its lines.
    start: Vec<i64>,
    counted: Vec<i64>,
    /// The rule's positions at the last tick's `s`, and the axes a tick moved further than
    /// their pulses can follow (bit k).
    at: Vec<i128>,
    must: u8,
}

impl Counted for Run {
    fn counted(&mut self) -> &mut [i64] {
        &mut self.counted
    }
}

/// Runs the stream of `cfg` on the library `library` (built by
/// [`crate::build::build_path_steppers`] for `cfg.axes` axes).
pub fn run(library: &FsPath, cfg: &PathSteppersConfig) -> Result<PathSteppersReport, SimError> {
    let axes = cfg.axes;
    let n = usize::from(axes);
    let mut fabric = Verilated::open(library, None, PATH_STEPPERS_TAG, IN_WORDS, OUT_WORDS)?;
    let mut lines = DriveLines::of(&PATH_STEPPERS_OUTPUTS, &OUT_SLOTS);
    let mut rng = rand::rngs::StdRng::seed_from_u64(cfg.seed);
    let mut model = PathSteppers::new(axes).map_err(|e| SimError::Config(e.to_string()))?;
    let mut r = PathSteppersReport::default();
    let cell = 1i128 << FRAC_BITS;
    let mut batch = Batch::new(&PATH_STEPPERS_OUTPUTS, &OUT_SLOTS, OUT_WORDS, cfg.fault);
    // Each clock of the batch: the run it belongs to is `current` (its counts are updated when
    // the batch is compared), and whether the run ended on it.
    let mut ended: Vec<(u64, Run)> = Vec::new();
    let mut current: Option<Run> = None;
    while r.clocks < cfg.clocks {
        let mut i;
        match current.as_mut() {
            None => {
                // A new run: reset, the path, the drives' settings.
                // One planner's path: continuous (paths end to end would jump).
                let path = loop {
                    let scale = rng.gen_range(3..=4);
                    let p = random_path(&mut rng, n, scale);
                    if let Some(p) =
                        p.filter(|p| p.segments.iter().all(|g| load_inputs(g, axes).is_ok()))
                    {
                        break p;
                    }
                };
                let segments = path.segments.len();
                let mut queue = std::collections::VecDeque::new();
                let mut start = 0i128;
                for (k, g) in path.segments.iter().enumerate() {
                    queue.extend(
                        segment_words(&mut rng, k as u16, start, g, axes)
                            .iter()
                            .map(PathSteppers::host_inputs),
                    );
                    start += g.length;
                }
                queue.push_back(PathSteppers::host_inputs(&PathSeqInputs {
                    seg_index: segments as u16 - 1,
                    extend: true,
                    ..Default::default()
                }));
                let steps: Vec<u16> = (0..n).map(|_| rng.gen_range(1..=8)).collect();
                let mut drives = PathSteppersInputs {
                    high_clocks: rng.gen_range(1..=6),
                    low_clocks: rng.gen_range(1..=6),
                    setup_clocks: rng.gen_range(1..=6),
                    ..Default::default()
                };
                for (k, &st) in steps.iter().enumerate() {
                    drives.step_lsb |= u128::from(st) << (16 * k);
                }
                // Long enough for a tick that crosses every segment (never late).
                let period = worst_clocks(axes, segments as u64) + rng.gen_range(0..1_000);
                // What the slowest axis follows in a tick, with a reversal on every step, in
                // its LSBs; an axis moves at most as far as the path (a share ≤ 1).
                let per_step = 2
                    + u64::from(drives.high_clocks)
                    + u64::from(drives.low_clocks)
                    + u64::from(drives.setup_clocks);
                let min_step = i128::from(*steps.iter().min().expect("an axis"));
                let follows = i128::from(period / per_step) * min_step - 2;
                let fast = rng.gen_bool(0.2);
                let ds = if fast {
                    follows * rng.gen_range(4..=8) * cell
                } else {
                    follows.max(0) * cell
                };
                current = Some(Run {
                    path,
                    queue,
                    drives,
                    ds,
                    fast,
                    period,
                    until_tick: 0,
                    ticks: 0,
                    tail: 20,
                    s: 0,
                    start: vec![0; n],
                    counted: vec![0; n],
                    at: Vec::new(),
                    must: 0,
                });
                i = PathSteppersInputs {
                    reset: true,
                    ..Default::default()
                };
            }
            Some(run) => {
                if let Some(w) = run.queue.pop_front() {
                    i = w;
                } else {
                    i = PathSteppersInputs {
                        s: run.s,
                        ..run.drives
                    };
                    // Enabled from the third tick on: the second's commit has put every axis
                    // on the path's start a tick before.
                    if run.ticks >= 3 {
                        i.enable = ((1u16 << n) - 1) as u8;
                    }
                    if run.until_tick == 0 {
                        let total = run.path.length();
                        if run.ticks == 2 {
                            // The drives start from the path's start, as the rule puts it.
                            let at = run.path.at(0).expect("a segment");
                            run.start = at.iter().map(|&x| whole(x)).collect();
                        }
                        // (Once at the end, it stays: the axes end where the rule says.)
                        if run.ticks >= 2 && run.s < total {
                            run.s += match rng.gen_range(0..20) {
                                0 => 0,
                                1 => -rng.gen_range(0..cell),
                                _ => rng.gen_range(0..=run.ds),
                            };
                            run.s = run.s.clamp(0, total);
                        }
                        if run.s == total {
                            run.tail -= 1;
                        }
                        // Steps an axis's pulses make in a tick at most (a decision, high, low).
                        let most = run.period
                            / (1 + u64::from(run.drives.high_clocks)
                                + u64::from(run.drives.low_clocks));
                        let at = run.path.at(run.s).expect("a segment");
                        if run.ticks >= 3 {
                            for (k, (&x, &y)) in at.iter().zip(&run.at).enumerate() {
                                let step = i64::from((run.drives.step_lsb >> (16 * k)) as u16);
                                let jump = (whole(x) - whole(y)).abs() / step;
                                if jump >= most as i64 + 2 {
                                    run.must |= 1 << k;
                                }
                            }
                        }
                        run.at = at;
                        i.tick = true;
                        i.s = run.s;
                        run.ticks += 1;
                        r.ticks += 1;
                        run.until_tick = run.period;
                    }
                    run.until_tick -= 1;
                }
            }
        }
        model.clock(&i);
        batch.push(&encode_inputs(&i), &encode_outputs(&model.outputs()));
        r.clocks += 1;
        if current
            .as_ref()
            .is_some_and(|run| run.tail == 0 && run.until_tick == 0)
        {
            let run = current.take().expect("a run");
            ended.push((r.clocks, run));
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

/// The drives' view of a run that ended with the fabric's `overrun`, `late` and `refused`
/// as `flags` (see the module documentation).
fn judge(run: &Run, flags: EndFlags, r: &mut PathSteppersReport) {
    r.runs += 1;
    if run.must != 0 {
        // Every axis that could not follow says so.
        r.must += 1;
        r.flagged += u64::from(flags.overrun & run.must == run.must);
    }
    let end: Vec<i64> = (run.path.at(run.path.length()).expect("a segment").iter())
        .map(|&x| whole(x))
        .collect();
    match verdict(flags, run.fast, || {
        count_error(&run.counted, &run.start, &end, run.drives.step_lsb)
    }) {
        Verdict::Checked => r.checked += 1,
        Verdict::Fast => r.fast += 1,
        Verdict::Wrong(what) => {
            r.violation.get_or_insert(format!("run {}: {what}", r.runs));
        }
    }
}
