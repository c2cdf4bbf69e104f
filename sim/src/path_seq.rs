//! The Verilated path sequencer (`snapgen_path_sequencer`) in lockstep with its model
//! (`snapgen_model::path::sequencer::PathSequencer`): every output compared on every clock,
//! and the positions its commits publish checked against the rule, [`Path::at`].
//!
//! The stream, run after run (each begins with a reset): a path of 1 to 200 segments from the
//! host's planner (random paths of [`crate::interp`]'s kind, end to end, so the ring of
//! `PATH_SLOTS` wraps and forgets), written word by word with random gaps as the ring makes
//! room ahead of the current segment and extended a few segments at a time; ticks every
//! `worst_clocks` to 2000 clocks more, now and then one too soon (`late`); the path length at
//! each tick moving on by a random fraction of a segment, staying, jumping several segments,
//! stepping back within a cell or back across a segment start, back to within a cell of the
//! lowest it may reach (a cell and a half before the path's start, or the start of the segment
//! before the one it was in), and running a few cells past the end of the path written so
//! far. Once per run in a fifth of the runs, a write or an
//! extension that must be refused (a segment of the path rewritten, one too far ahead, an
//! axis the design lacks, an extension past the ring); the other runs must never raise
//! `refused`.
//!
//! The interpolator beside it is its model (`snapgen_model::path::engine::Engine`, itself
//! checked against its fabric in [`crate::interp`]), driven by the sequencer's outputs; the
//! axes' registers take its writes and the commits. At each commit the positions must equal
//! `Path::at(s)` for the `s` of the computation committed, on the path as it was extended
//! when that computation began (a computation during which the path was extended is not
//! checked: its last segment is ambiguous). So the model's seek and clamps are checked by a
//! second implementation, not by themselves.

use std::path::Path as FsPath;

use rand::{Rng, SeedableRng};
use snapgen_model::path::engine::{load_inputs, Engine};
use snapgen_model::path::interp::{Path, Segment};
use snapgen_model::path::sequencer::{segment_writes, worst_clocks, PathSequencer};
use snapgen_model::{PathSeqInputs, PathSeqOutputs, FRAC_BITS};
use snapgen_spec::widths::{MAX_AXES, PATH_SLOTS};

use crate::interp::random_path;
use crate::layout::{harness_header, port_layout, Batch};
pub use crate::layout::{PortFault, PortMismatch};
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_path_sequencer_ports!(port_layout! {
    PATH_SEQ_INPUTS, PATH_SEQ_OUTPUTS, PathSeqInputs, PathSeqOutputs;
});

/// The sequencer's tag in the harness's ABI word.
const PATH_SEQ_TAG: u32 = 5;

/// Clocks the model runs before the fabric runs them in one call.
const BATCH: usize = 65_536;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn path_seq_layout_header() -> String {
    harness_header(
        &PATH_SEQ_INPUTS,
        &PATH_SEQ_OUTPUTS,
        abi(PATH_SEQ_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&PathSeqInputs::default()),
    )
}

/// A run's settings.
#[derive(Clone, Debug)]
pub struct PathSeqConfig {
    /// Axes of the design (1 to 8).
    pub axes: u8,
    /// Clocks to run.
    pub clocks: u64,
    /// Seed of the stream.
    pub seed: u64,
    /// Test hook: flip a bit of an output of the fabric's (`port` indexes
    /// [`PATH_SEQ_OUTPUTS`]).
    pub fault: Option<PortFault>,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PathSeqReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Runs (paths) played.
    pub runs: u64,
    /// Segments written (every word) and extended.
    pub segments: u64,
    /// Runs whose ring wrapped (a segment forgotten).
    pub wrapped: u64,
    /// Ticks given.
    pub ticks: u64,
    /// Ticks given too soon on purpose, and runs that raised `late`.
    pub early: u64,
    /// See [`PathSeqReport::early`].
    pub late_runs: u64,
    /// Seek steps back and on (moves of the current segment).
    pub moves: u64,
    /// Commits.
    pub commits: u64,
    /// Commits checked against the rule (every one).
    pub checked: u64,
    /// Of those, how many had the path length sent below the oldest segment kept (at the end
    /// of a run whose ring wrapped).
    pub below_oldest: u64,
    /// Of those, the first that differed (must be None).
    pub rule_error: Option<String>,
    /// Writes or extensions that must be refused, and of those how many were.
    pub probes: u64,
    /// See [`PathSeqReport::probes`].
    pub refused: u64,
    /// Runs without a probe that raised `refused` (must be 0).
    pub false_refusals: u64,
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
}

/// A path of `segments` or so segments, end to end from random planner paths (their
/// positions jump where two meet: the sequencer does not care, the rule neither).
fn long_path(rng: &mut impl Rng, axes: u8, segments: usize, max_exponent: u32) -> Path {
    let mut all = Vec::new();
    while all.len() < segments {
        if let Some(p) = random_path(rng, usize::from(axes), max_exponent) {
            let fits = p.segments.iter().all(|g| load_inputs(g, axes).is_ok());
            if fits {
                all.extend(p.segments);
            }
        }
    }
    all.truncate(segments);
    Path { segments: all }
}

/// The host: the path, what it has written and extended, and the words queued.
struct Host {
    path: Path,
    starts: Vec<i128>,
    /// Segments extended (the path's last is `extended − 1`).
    extended: usize,
    /// Segments written (every word).
    written: usize,
    /// Words of the segment being written.
    queue: std::collections::VecDeque<PathSeqInputs>,
    /// The probe of this run: at which tick.
    probe_at: Option<u64>,
    /// The run has ended: clocks left before the next run's reset (the last tick's commit
    /// is still checked).
    ending: Option<u32>,
    /// At the end of a run whose ring wrapped: the path length has been sent below the oldest
    /// segment kept, and the run ends with the tick after that computation.
    dived: bool,
}

/// The computation running or last ended: its `s`, the path's length in segments when it
/// began, and whether the path was extended while it ran.
#[derive(Clone, Copy, Debug, Default)]
struct Computation {
    s: i128,
    extended: usize,
    changed: bool,
    /// The start of the oldest segment kept, when segments have been forgotten and `s` was
    /// sent below it (the sequencer stays on that segment's start).
    floor: Option<i128>,
}

/// The words that write segment `index` of `g` for `axes` axes: the model's, the span and the
/// shape on one clock or (half the time) on two.
pub(crate) fn segment_words(
    rng: &mut impl Rng,
    index: u16,
    start: i128,
    g: &Segment,
    axes: u8,
) -> Vec<PathSeqInputs> {
    let mut out = segment_writes(index, start, g, axes).expect("checked when the path was made");
    if rng.gen_bool(0.5) {
        let both = out[0];
        out[0].write_span = false;
        out.insert(
            1,
            PathSeqInputs {
                seg_index: index,
                write_span: true,
                seg_start: both.seg_start,
                seg_length: both.seg_length,
                ..Default::default()
            },
        );
    }
    out
}

/// A write or extension that the sequencer must refuse, given its registers.
fn probe(rng: &mut impl Rng, seq: &PathSequencer, axes: u8) -> PathSeqInputs {
    let r = seq.reg;
    match rng.gen_range(0..4) {
        // A segment of the path (the current one) rewritten.
        0 => PathSeqInputs {
            seg_index: r.k,
            write_span: true,
            ..Default::default()
        },
        // A segment out of order: past the one after the highest written.
        1 => PathSeqInputs {
            seg_index: r.highest.wrapping_add(2 + rng.gen_range(0..100)),
            write_shape: true,
            ..Default::default()
        },
        // An axis the design lacks (or, with every axis, an extension backwards).
        2 if axes < MAX_AXES as u8 => PathSeqInputs {
            seg_index: r.highest.wrapping_add(1),
            write_axis: true,
            seg_axis: rng.gen_range(axes..MAX_AXES as u8),
            ..Default::default()
        },
        2 => PathSeqInputs {
            seg_index: r.last.wrapping_sub(1),
            extend: true,
            ..Default::default()
        },
        // An extension past the highest written.
        _ => PathSeqInputs {
            seg_index: r.highest.wrapping_add(1 + rng.gen_range(0..100)),
            extend: true,
            ..Default::default()
        },
    }
}

/// Runs the stream of `cfg` on the library `library` (built by
/// [`crate::build::build_path_sequencer`] for `cfg.axes` axes).
pub fn run(library: &FsPath, cfg: &PathSeqConfig) -> Result<PathSeqReport, SimError> {
    let axes = cfg.axes;
    let mut fabric = Verilated::open(library, None, PATH_SEQ_TAG, IN_WORDS, OUT_WORDS)?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(cfg.seed);
    let mut seq = PathSequencer::new(axes).map_err(|e| SimError::Config(e.to_string()))?;
    let mut engine = Engine::new(axes);
    let mut r = PathSeqReport::default();
    let cell = 1i128 << FRAC_BITS;
    let shortest = worst_clocks(axes, 1);
    let mut batch = Batch::new(&PATH_SEQ_OUTPUTS, &OUT_SLOTS, OUT_WORDS, cfg.fault);
    let mut next_pos = vec![0i128; usize::from(axes)];
    // The stream's state, run by run.
    let mut host: Option<Host> = None;
    let (mut s, mut until_tick, mut period, mut run_ticks) = (0i128, 0u64, shortest, 0u64);
    let (mut running, mut ended): (Option<Computation>, Option<Computation>) = (None, None);
    let (mut probed, mut probe_given) = (false, false);
    // The path length never goes below `s_low`, the start of the segment before the one it
    // was in (`k_low`): so a seek never ends below `k_low`, and the sequencer's segment never
    // goes below the lower of `k_low` and where it is (a tick dropped or a seek running leaves
    // it behind); the host writes less than a ring ahead of that.
    let (mut s_low, mut k_low) = (i128::MIN, 0usize);
    while r.clocks < cfg.clocks {
        let o = seq.outputs();
        let e = engine.outputs();
        let mut i = PathSeqInputs {
            done: e.done,
            s,
            ..Default::default()
        };
        if e.out_write {
            next_pos[usize::from(e.out_axis)] = e.out_value;
        }
        if std::mem::take(&mut probe_given) {
            r.refused += u64::from(o.refused);
        }
        if o.commit {
            r.commits += 1;
            let h = host.as_ref().expect("a run");
            let c = ended.take();
            if c.is_none() && r.rule_error.is_none() {
                r.rule_error = Some(format!("clock {}: a commit with no computation", r.clocks));
            }
            if let Some(c) = c {
                // The path as it stood when the computation decided: as it began, or (the
                // path extended meanwhile) as any extension since left it.
                let s_at = c.floor.map_or(c.s, |f| c.s.max(f));
                let mut expect = Vec::new();
                for extended in c.extended..=if c.changed { h.extended } else { c.extended } {
                    let prefix = Path {
                        segments: h.path.segments[..extended].to_vec(),
                    };
                    expect = prefix.at(s_at).expect("a segment");
                    if expect == next_pos {
                        break;
                    }
                }
                r.checked += 1;
                r.below_oldest += u64::from(c.floor.is_some_and(|f| c.s < f));
                if expect != next_pos && r.rule_error.is_none() {
                    r.rule_error = Some(format!(
                        "clock {}: s = {} on {} segments: committed {next_pos:?}, the rule says {expect:?}",
                        r.clocks, c.s, c.extended
                    ));
                }
            }
        }
        if e.done {
            ended = running.take();
        }
        if let Some(h) = host.as_mut() {
            if let Some(left) = h.ending.as_mut() {
                *left = left.saturating_sub(1);
                if *left == 0 {
                    host = None;
                }
            }
        }
        match host.as_mut() {
            Some(h) if h.ending.is_some() => {}
            None => {
                // A new run: reset, and a new path.
                i.reset = true;
                let n = if rng.gen_bool(0.3) {
                    rng.gen_range(1..=8)
                } else {
                    rng.gen_range(9..=200)
                };
                let path = long_path(&mut rng, axes, n, 8);
                let mut starts = Vec::with_capacity(n);
                let mut at = 0i128;
                for g in &path.segments {
                    starts.push(at);
                    at += g.length;
                }
                s = rng.gen_range(-cell..cell / 2);
                i.s = s;
                period = shortest + rng.gen_range(0..2_000);
                until_tick = period;
                run_ticks = 0;
                running = None;
                ended = None;
                probed = false;
                (s_low, k_low) = (-cell - cell / 2, 0);
                host = Some(Host {
                    path,
                    starts,
                    extended: 0,
                    written: 0,
                    queue: Default::default(),
                    probe_at: rng.gen_bool(0.2).then(|| rng.gen_range(1..30)),
                    ending: None,
                    dived: false,
                });
                r.runs += 1;
                next_pos.fill(0);
            }
            Some(h) => {
                let n = h.path.segments.len();
                // The host's writes: as the ring makes room ahead of the current segment.
                if let Some(w) = h.queue.pop_front() {
                    i = PathSeqInputs {
                        done: i.done,
                        s,
                        ..w
                    };
                    if h.queue.is_empty() {
                        h.written += 1;
                        r.segments += 1;
                    }
                } else if h.probe_at == Some(run_ticks) && !probed && rng.gen_bool(0.01) {
                    i = PathSeqInputs {
                        done: i.done,
                        s,
                        ..probe(&mut rng, &seq, axes)
                    };
                    // Refused on this clock (a false refusal before it would hide it).
                    r.false_refusals += u64::from(o.refused);
                    probed = true;
                    probe_given = true;
                    r.probes += 1;
                } else if h.written < n
                    && h.written < lowest(k_low, o.path_segment) + PATH_SLOTS as usize - 1
                    && rng.gen_bool(0.3)
                {
                    let k = h.written;
                    h.queue =
                        segment_words(&mut rng, k as u16, h.starts[k], &h.path.segments[k], axes)
                            .into();
                } else if h.extended < h.written
                    && (h.written - h.extended >= rng.gen_range(1..=4) || h.written == n)
                    && rng.gen_bool(0.2)
                {
                    i.seg_index = (h.written - 1) as u16;
                    i.extend = true;
                    h.extended = h.written;
                    if let Some(c) = running.as_mut() {
                        c.changed = true;
                    }
                }
                // The ticks.
                until_tick = until_tick.saturating_sub(1);
                if until_tick == 0 && h.dived && o.running {
                    until_tick = 1;
                } else if until_tick == 0 && h.dived {
                    // The dive's positions are committed on this tick; the run ends.
                    i.tick = true;
                    i.s = s;
                    r.ticks += 1;
                    end_of_run(&mut r, &seq, probed);
                    h.ending = Some(3);
                } else if until_tick == 0 && h.extended > 0 {
                    let total: i128 =
                        h.starts[h.extended - 1] + h.path.segments[h.extended - 1].length;
                    let here = h.starts.partition_point(|&st| st <= s).max(1) - 1;
                    let seg_len = h.path.segments[here].length.max(1);
                    s += match rng.gen_range(0..100) {
                        0..=4 => s_low + rng.gen_range(0..cell) - s,
                        5..=64 => rng.gen_range(0..=seg_len / 8 + 1),
                        65..=74 => 0,
                        75..=84 => rng.gen_range(0..=(total / 4).max(1)),
                        85..=89 => -rng.gen_range(0..cell),
                        90..=94 => -rng.gen_range(0..=seg_len / 4 + 1),
                        _ => rng.gen_range(0..4 * cell),
                    };
                    s = s.clamp(s_low, total + 3 * cell);
                    let here = h.starts.partition_point(|&st| st <= s).max(1) - 1;
                    if here.saturating_sub(1) > k_low {
                        k_low = here - 1;
                        s_low = h.starts[k_low];
                    }
                    i.tick = true;
                    i.s = s;
                    r.ticks += 1;
                    run_ticks += 1;
                    // The end of a run whose ring wrapped, the path extended to its end and
                    // every word written: once, the path length below the oldest segment kept.
                    let oldest = n.saturating_sub(PATH_SLOTS as usize);
                    let dive = h.extended == n
                        && n > PATH_SLOTS as usize
                        && s >= total
                        && h.queue.is_empty()
                        && !o.running;
                    if dive {
                        s = h.starts[oldest] - rng.gen_range(1..=4 * cell);
                        i.s = s;
                        h.dived = true;
                    }
                    if o.running {
                        // Dropped (late): the computation running goes on.
                    } else {
                        running = Some(Computation {
                            s,
                            extended: h.extended,
                            changed: i.extend,
                            floor: dive.then(|| h.starts[oldest]),
                        });
                    }
                    let early = rng.gen_bool(0.02) && !dive;
                    r.early += u64::from(early);
                    until_tick = if early {
                        rng.gen_range(1..shortest)
                    } else {
                        period
                    };
                    // A run ends once its path is played and left behind.
                    let ends = h.extended == n && s >= total && h.queue.is_empty();
                    if ends && n <= PATH_SLOTS as usize && rng.gen_bool(0.2) {
                        end_of_run(&mut r, &seq, probed);
                        h.ending = Some(3);
                    }
                }
            }
        }
        let k_before = seq.reg.k;
        seq.clock(&i);
        engine.clock(&PathSequencer::interp_inputs(&o, i.reset));
        r.moves += u64::from(seq.reg.k != k_before && !i.reset);
        batch.push(&encode_inputs(&i), &encode_outputs(&seq.outputs()));
        r.clocks += 1;
        if batch.len() >= BATCH || r.clocks == cfg.clocks {
            if let Some(m) = batch.run(&mut fabric) {
                r.clocks = m.clock + 1;
                r.mismatch = Some(m);
                return Ok(r);
            }
            batch.next();
        }
    }
    Ok(r)
}

/// The lowest segment the sequencer may be on from now: the lower of `k_low` and its
/// `segment` output (wrapping: the index nearest `k_low`).
fn lowest(k_low: usize, segment: u16) -> usize {
    let off = i64::from(segment.wrapping_sub(k_low as u16) as i16);
    (k_low as i64 + off.min(0)).max(0) as usize
}

/// A run's end in the report: whether it was late, wrapped, or refused with no probe.
fn end_of_run(r: &mut PathSeqReport, seq: &PathSequencer, probed: bool) {
    let o = seq.outputs();
    r.late_runs += u64::from(o.late);
    r.wrapped += u64::from(seq.reg.oldest != 0 || !seq.reg.whole);
    r.false_refusals += u64::from(!probed && o.refused);
}
