//! The Verilated path interpolator (`snapgen_interpolator`) in lockstep with its model
//! (`snapgen_model::path::engine::Engine`): every output compared on every clock, under a
//! random stream of segments and computations.
//!
//! The stream: segments of random paths made by the host's own planner
//! (`snapgen_plan::path`: lines, arcs and helices in random planes, joined end to end), each
//! loaded as the host would load it and computed at 1 to 4 random distances along it (a cell
//! before its start to a cell past its end); now and then a segment of random bits instead
//! (every register's wrapping is part of the contract), a start, an axis load or a shape load
//! while a computation runs, or a reset (while computing or idle). Each computation of a
//! planner's segment that nothing disturbed is also checked against the rule itself,
//! [`Segment::at`]: the model's writes must equal it.
//!
//! As in the core's lockstep, the model runs a batch of clocks first (its inputs and its
//! outputs in the harness's word layout), the fabric the same clocks in one call, and the two
//! output vectors are compared as one slice; a fault (a test hook) flips one output bit of the
//! fabric's at a chosen clock, to show that a difference is found.

use std::path::Path as FsPath;

use rand::{Rng, SeedableRng};
use snapgen_model::path::engine::{load_inputs, Engine};
use snapgen_model::path::interp::{Path, Segment};
use snapgen_model::{InterpInputs, InterpOutputs, FRAC_BITS};
use snapgen_plan::path::{prepare, Element};

use crate::layout::{first_difference, harness_header, port_layout};
pub use crate::layout::{PortFault, PortMismatch};
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_interpolator_ports!(port_layout! {
    INTERP_INPUTS, INTERP_OUTPUTS, InterpInputs, InterpOutputs;
});

/// The interpolator's tag in the harness's ABI word.
const INTERP_TAG: u32 = 3;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn interp_layout_header() -> String {
    harness_header(
        &INTERP_INPUTS,
        &INTERP_OUTPUTS,
        abi(INTERP_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&InterpInputs::default()),
    )
}

/// A run's settings.
#[derive(Clone, Debug)]
pub struct InterpConfig {
    /// Axes of the design (1 to 8).
    pub axes: u8,
    /// Clocks to run.
    pub clocks: u64,
    /// Seed of the stream.
    pub seed: u64,
    /// Test hook: flip a bit of an output of the fabric's (`port` indexes
    /// [`INTERP_OUTPUTS`]).
    pub fault: Option<PortFault>,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InterpReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Segments loaded (from the planner or of random bits).
    pub segments: u64,
    /// Computations that ran to their end.
    pub computations: u64,
    /// Axis positions written.
    pub writes: u64,
    /// Computations of a planner's segment checked against [`Segment::at`].
    pub checked: u64,
    /// Of those, how many the model got wrong (must be 0).
    pub rule_errors: u64,
    /// Segments of random bits loaded.
    pub random_segments: u64,
    /// Disturbances while computing: starts, axis loads, shape loads (random bits), resets;
    /// and resets while idle.
    pub disturbances: [u64; 5],
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
}

/// A random path of `axes` axes from the planner: 1 to 6 lines and arcs (helices when there
/// are more than two axes) from a random start, within ±2^30 output LSBs, each element up to
/// 10^`max_exponent` LSBs long or so.
pub(crate) fn random_path(rng: &mut impl Rng, axes: usize, max_exponent: u32) -> Option<Path> {
    let mut at: Vec<i64> = (0..axes)
        .map(|_| rng.gen_range(-(1 << 30)..1 << 30))
        .collect();
    let start = at.clone();
    let mut elements = Vec::new();
    for _ in 0..rng.gen_range(1..=6) {
        let scale = 10i64.pow(rng.gen_range(0..=max_exponent));
        let mut to: Vec<i64> = at
            .iter()
            .map(|&x| (x + rng.gen_range(-scale..=scale)).clamp(-(1 << 30), 1 << 30))
            .collect();
        if axes >= 2 && rng.gen_bool(0.5) {
            let p = rng.gen_range(0..axes);
            let q = (p + rng.gen_range(1..axes)) % axes;
            let radius = rng.gen_range(2..=scale.max(2)) as f64;
            let phi = rng.gen_range(0.0..std::f64::consts::TAU);
            let centre = [
                at[p] - (radius * phi.cos()).round() as i64,
                at[q] - (radius * phi.sin()).round() as i64,
            ];
            let r0 = ((at[p] - centre[0]) as f64).hypot((at[q] - centre[1]) as f64);
            let end = rng.gen_range(0.0..std::f64::consts::TAU);
            to[p] = centre[0] + (r0 * end.cos()).round() as i64;
            to[q] = centre[1] + (r0 * end.sin()).round() as i64;
            elements.push(Element::Arc {
                plane: [p, q],
                centre,
                ccw: rng.gen(),
                to,
            });
        } else {
            elements.push(Element::Line { to });
        }
        at = elements.last().map(|e| e.to().to_vec()).unwrap_or(at);
    }
    let prepared = prepare(&start, &elements).ok()?;
    // The chain's displacement for the path is its length within a few per cent.
    let total = prepared.length() / 1000 * rng.gen_range(970..=1030);
    Some(prepared.fit(total.max(1)))
}

/// Random bits for every input of a load (a segment no planner would make).
fn random_load(rng: &mut impl Rng, axes: u8) -> Vec<InterpInputs> {
    let mut shape = InterpInputs {
        load_shape: true,
        arc: rng.gen(),
        ccw: rng.gen(),
        plane_first: rng.gen_range(0..8),
        plane_second: rng.gen_range(0..8),
        centre_first: rng.gen(),
        centre_second: rng.gen(),
        radius: rng.gen(),
        growth: rng.gen(),
        start_angle: rng.gen(),
        rate: rng.gen(),
        ..Default::default()
    };
    // Sometimes a plane that the axes have, so that other axes follow it.
    if rng.gen_bool(0.5) && axes >= 2 {
        shape.plane_first = rng.gen_range(0..axes);
        shape.plane_second = (shape.plane_first + rng.gen_range(1..axes)) % axes;
    }
    let mut out = vec![shape];
    for k in 0..8u8 {
        out.push(InterpInputs {
            load_axis: true,
            axis: k,
            from: rng.gen(),
            share: rng.gen(),
            ..Default::default()
        });
    }
    out
}

/// The stream's source of inputs, clock by clock, from the model's state.
struct Stimulus {
    rng: rand::rngs::StdRng,
    axes: u8,
    /// Inputs queued for the next clocks (a load, then a start).
    queue: std::collections::VecDeque<InterpInputs>,
    /// The planner's segments still to be computed, and computations left on the current one.
    segments: Vec<Segment>,
    current: Option<(Segment, u32)>,
    /// The computation running: the rule's positions when checked.
    expect: Option<Vec<i128>>,
    got: Vec<Option<i128>>,
}

impl Stimulus {
    /// The next clock's inputs, given the model's outputs after the last clock.
    fn next(&mut self, busy: bool, report: &mut InterpReport) -> InterpInputs {
        if let Some(i) = self.queue.pop_front() {
            return i;
        }
        if busy {
            // Disturbances while busy: rare, and they end the rule check.
            let roll = self.rng.gen_range(0..100_000);
            let disturb = match roll {
                0..=19 => Some(InterpInputs {
                    start: true,
                    offset: self.rng.gen(),
                    ..Default::default()
                }),
                20..=29 => Some(InterpInputs {
                    load_axis: true,
                    axis: self.rng.gen_range(0..8),
                    from: self.rng.gen(),
                    share: self.rng.gen(),
                    ..Default::default()
                }),
                30..=34 => random_load(&mut self.rng, self.axes).first().copied(),
                35..=44 => Some(InterpInputs {
                    reset: true,
                    ..Default::default()
                }),
                _ => None,
            };
            if let Some(d) = disturb {
                let kind = if d.start {
                    0
                } else if d.load_axis {
                    1
                } else if d.load_shape {
                    2
                } else {
                    3
                };
                report.disturbances[kind] += 1;
                if !d.start {
                    self.expect = None;
                }
                if d.load_axis || d.load_shape {
                    // The segment is no longer the planner's: load a fresh one next.
                    self.current = None;
                }
                return d;
            }
            return InterpInputs::default();
        }
        if self.rng.gen_bool(0.001) {
            // A reset while idle changes nothing but the outputs it clears.
            report.disturbances[4] += 1;
            return InterpInputs {
                reset: true,
                ..Default::default()
            };
        }
        // Idle: the next computation, on the current segment or a new one.
        let cell = 1i128 << FRAC_BITS;
        match self.current.take() {
            Some((g, left)) if left > 0 => {
                let r = self.rng.gen_range(-cell..=g.length + cell);
                self.expect = Some(g.at(r));
                self.got = vec![None; usize::from(self.axes)];
                self.current = Some((g, left - 1));
                InterpInputs {
                    start: true,
                    offset: r,
                    ..Default::default()
                }
            }
            _ => {
                report.segments += 1;
                if self.rng.gen_bool(0.1) {
                    // Random bits, computed once at a random offset (no rule check).
                    report.random_segments += 1;
                    self.queue.extend(random_load(&mut self.rng, self.axes));
                    self.queue.push_back(InterpInputs {
                        start: true,
                        offset: self.rng.gen(),
                        ..Default::default()
                    });
                    self.expect = None;
                    return self.queue.pop_front().unwrap_or_default();
                }
                while self.segments.is_empty() {
                    if let Some(p) = random_path(&mut self.rng, usize::from(self.axes), 8) {
                        self.segments = p.segments;
                        self.segments.reverse();
                    }
                }
                let g = self.segments.pop().expect("refilled above");
                let loads = load_inputs(&g, self.axes).expect("the planner's segments fit");
                self.queue.extend(loads);
                self.current = Some((g, self.rng.gen_range(1..=4)));
                self.expect = None;
                self.queue.pop_front().unwrap_or_default()
            }
        }
    }

    /// Takes the model's outputs after a clock: collects the writes and checks a finished
    /// computation against the rule.
    fn observe(&mut self, o: &InterpOutputs, report: &mut InterpReport) {
        if o.out_write {
            report.writes += 1;
            if let Some(slot) = self.got.get_mut(usize::from(o.out_axis)) {
                *slot = Some(o.out_value);
            }
        }
        if o.done {
            report.computations += 1;
            if let Some(want) = self.expect.take() {
                report.checked += 1;
                let got: Vec<i128> = self.got.iter().map(|v| v.unwrap_or(i128::MIN)).collect();
                if got != want {
                    report.rule_errors += 1;
                }
            }
        }
    }
}

/// Clocks per batch.
const BATCH: usize = 1 << 10;

/// Runs the lockstep of `cfg` on the library `library` (built by
/// [`crate::build::build_interpolator`] for `cfg.axes` axes).
pub fn run(library: &FsPath, cfg: &InterpConfig) -> Result<InterpReport, SimError> {
    if let Some(f) = cfg.fault.filter(|f| f.clock >= cfg.clocks) {
        return Err(SimError::FaultNotReached {
            clock: f.clock,
            clocks: cfg.clocks,
        });
    }
    let mut fabric = Verilated::open(library, None, INTERP_TAG, IN_WORDS, OUT_WORDS)?;
    let mut model = Engine::new(cfg.axes);
    let mut stim = Stimulus {
        rng: rand::rngs::StdRng::seed_from_u64(cfg.seed),
        axes: cfg.axes,
        queue: Default::default(),
        segments: Vec::new(),
        current: None,
        expect: None,
        got: Vec::new(),
    };
    let mut report = InterpReport::default();
    let (mut ins, mut want, mut got) = (Vec::new(), Vec::new(), Vec::new());
    while report.clocks < cfg.clocks {
        let n = (cfg.clocks - report.clocks).min(BATCH as u64) as usize;
        ins.clear();
        want.clear();
        for _ in 0..n {
            let i = stim.next(model.outputs().busy, &mut report);
            model.clock(&i);
            stim.observe(&model.outputs(), &mut report);
            ins.extend_from_slice(&encode_inputs(&i));
            want.extend_from_slice(&encode_outputs(&model.outputs()));
        }
        fabric.run_each(&ins, &mut got);
        if let Some(f) = cfg.fault {
            f.apply(&OUT_SLOTS, OUT_WORDS, report.clocks, &mut got);
        }
        if got != want {
            report.mismatch = first_difference(
                &INTERP_OUTPUTS,
                &OUT_SLOTS,
                OUT_WORDS,
                report.clocks,
                &got,
                &want,
            );
            report.clocks += n as u64;
            return Ok(report);
        }
        report.clocks += n as u64;
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_planner_makes_paths_for_every_axis_count() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        for axes in 1..=8 {
            let made = (0..20)
                .filter_map(|_| random_path(&mut rng, axes, 8))
                .count();
            assert!(made >= 15, "{axes} axes: {made} of 20 paths prepared");
        }
    }
}
