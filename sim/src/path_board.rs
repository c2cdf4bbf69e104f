//! The path core as a board's core (`snapgen path --board path-core`, issue 22): the Verilated
//! path core ([`crate::path_core`]) in lockstep with its model, every output compared on every
//! clock, its motion core driven by the board's command executor (the model's, through
//! [`ExecutorLink`] as in the core's co-simulation), so the host's driver plays the group on
//! it as on any board.
//!
//! What is not built yet is the path's way in: the command interface that writes the ring.
//! [`PathCoreBoard::load_path`] writes it through the path core's ports, a word a clock, before
//! anything moves, and holds the drives disabled until two ticks have committed the path's
//! start; then every axis's drive follows (a step of the length given, every pulse time 1
//! clock).
//!
//! From the fabric's lines alone, as drives count them: on each of the chain's ticks, each
//! axis's steps since the drives were enabled, beside the fabric's path length register.
//! [`PathCoreBoard::fabric_view`] compares them with the rule (`Path::at`) at the register of
//! the tick before (the steppers commit a tick's axes on the next and the pulses follow within
//! a tick).

use std::collections::VecDeque;
use std::path::Path as FsPath;

use snapgen_model::path::core::PathCore;
use snapgen_model::path::interp::Path;
use snapgen_model::path::sequencer::{segment_writes, worst_clocks};
use snapgen_model::FRAC_BITS;
use snapgen_model::{CoreInputs, CoreModel, CoreOutputs, Format, PathCoreInputs, PathSeqInputs};
use snapgen_spec::widths::PATH_SLOTS;

use crate::cosim::{CoreSide, ExecutorLink};
use crate::drive_lines::{whole, DriveLines};
use crate::layout::{slot_named, Batch, PortMismatch, Slot};
use crate::path_core::{
    encode_inputs, encode_outputs, IN_WORDS, OUT_SLOTS, OUT_WORDS, PATH_CORE_OUTPUTS, PATH_CORE_TAG,
};
use crate::verilated::Verilated;
use crate::SimError;

/// Clocks the model runs before the fabric runs them in one call.
const BATCH: usize = 65_536;

/// Segments a tick of the board may cross: its tick is long enough for that many
/// ([`PathCoreBoard::tick_div`]).
pub const SEGMENTS_PER_TICK: u64 = 4;

/// What the fabric's lines say of the axes (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FabricView {
    /// Ticks whose counts were compared with the rule.
    pub ticks: u64,
    /// Of those, ticks on which an axis's count differed from the rule.
    pub differing: u64,
    /// The first difference, said.
    pub first: Option<String>,
    /// Steps counted on every axis.
    pub steps: u64,
    /// Each axis's whole position at the last tick, from its count (output LSBs: the
    /// position the drives were enabled at, and the steps times the step length).
    pub end: Vec<i64>,
    /// The step length (output LSBs).
    pub step: u16,
    /// The sequencer's `late` or `refused`, or an axis's `overrun`, at the end (said).
    pub flags: Option<String>,
}

/// The path core of a virtual board: fabric and model in lockstep (module documentation).
pub struct PathCoreBoard {
    axes: u8,
    fabric: Verilated,
    model: PathCore,
    batch: Batch,
    /// The executor's inputs of the last clock: the core takes them on the next, as a
    /// board's core takes the executor's registered outputs.
    pending: CoreInputs,
    /// Words of the ring still to write, one a clock.
    writes: VecDeque<PathSeqInputs>,
    /// The path core's inputs other than the motion core's: the drives' settings.
    drives: PathCoreInputs,
    /// The path given and the register's value where it starts.
    path: Option<(Path, i128)>,
    /// Ticks still to wait, once the ring is written, before the drives follow.
    settle: Option<u32>,
    /// The clock from which the drives follow, and each axis's whole position then.
    enabled: Option<u64>,
    anchor: Vec<i64>,
    /// Each axis's step length (output LSBs).
    step: u16,
    clock: u64,
    lines: DriveLines,
    counts: Vec<i64>,
    tick_slot: Slot,
    x_slot: Slot,
    /// On each of the chain's ticks once the drives follow: the fabric's register and each
    /// axis's steps counted.
    samples: Vec<(i128, Vec<i64>)>,
    last_words: Vec<u32>,
}

impl PathCoreBoard {
    /// The path core of `axes` axes from `library` (built by
    /// [`crate::build::build_path_core`]), reset on its first clock, its chain in `format`.
    pub fn open(library: &FsPath, axes: u8, format: &Format) -> Result<Self, SimError> {
        let fabric = Verilated::open(library, None, PATH_CORE_TAG, IN_WORDS, OUT_WORDS)?;
        let model = PathCore::new(format, axes).map_err(|e| SimError::Config(e.to_string()))?;
        let slot = |name: &str| slot_named(&PATH_CORE_OUTPUTS, &OUT_SLOTS, name);
        let mut drives = PathCoreInputs {
            high_clocks: 1,
            low_clocks: 1,
            setup_clocks: 1,
            ..Default::default()
        };
        for k in 0..u32::from(axes) {
            drives.step_lsb |= 1u128 << (16 * k);
        }
        let mut b = PathCoreBoard {
            axes,
            fabric,
            model,
            batch: Batch::new(&PATH_CORE_OUTPUTS, &OUT_SLOTS, OUT_WORDS, None),
            pending: CoreInputs::default(),
            writes: VecDeque::new(),
            drives,
            path: None,
            settle: None,
            enabled: None,
            anchor: Vec::new(),
            step: 1,
            clock: 0,
            lines: DriveLines::of(&PATH_CORE_OUTPUTS, &OUT_SLOTS),
            counts: vec![0; usize::from(axes)],
            tick_slot: slot("tick"),
            x_slot: slot("x"),
            samples: Vec::new(),
            last_words: Vec::new(),
        };
        // The power-up reset: the chain at its home, the path empty.
        let reset = PathCoreInputs {
            reset: true,
            tick_div: Self::tick_div(axes),
            ..b.drives
        };
        b.model.clock(&reset);
        b.batch
            .push(&encode_inputs(&reset), &encode_outputs(&b.model.outputs()));
        b.clock = 1;
        b.flush().map_err(|m| {
            SimError::Config(format!("the fabric and the model differ at reset: {m}"))
        })?;
        Ok(b)
    }

    /// Clocks per tick minus one for a board of `axes` axes: room for a tick that crosses
    /// [`SEGMENTS_PER_TICK`] segments.
    pub fn tick_div(axes: u8) -> u32 {
        (worst_clocks(axes, SEGMENTS_PER_TICK).div_ceil(50) * 50) as u32 - 1
    }

    /// The step length (whole LSB, every axis) whose pulses follow an axis moving up to
    /// `lsb_per_tick` output LSBs a tick on a board of `axes` axes, with a reversal on every
    /// step and a margin of 2: a step every `2 + high + low + setup` = 5 clocks (the step/dir
    /// generator's safe rate at 1 clock each).
    pub fn step_for(axes: u8, lsb_per_tick: f64) -> Result<u16, String> {
        let steps_per_tick = f64::from(Self::tick_div(axes) + 1) / 5.0;
        let step = (2.0 * lsb_per_tick / steps_per_tick).ceil().max(1.0);
        if !(step.is_finite() && step <= f64::from(u16::MAX)) {
            return Err(format!(
                "an axis moving {lsb_per_tick:.0} LSB a tick needs steps of {step:.0} LSB, more than the drives' step length holds ({}): use a coarser grid (--lsb)",
                u16::MAX
            ));
        }
        Ok(step as u16)
    }

    /// Writes `path` into the ring, its start at the path length register's `start` (raw),
    /// and extends the path to its last segment (the ring's ports, a word a clock, from the
    /// next clock on); on the third tick after, the drives follow (two ticks commit the
    /// path's start), each axis stepping `step` LSB. Refused here: a path of more segments
    /// than the ring holds, one the interpolator cannot take, and one with a run of
    /// `SEGMENTS_PER_TICK − 1` segments shorter than `most_per_tick` (the path length a tick
    /// may advance at most, raw): a tick could cross more segments than the board's tick has
    /// room for.
    pub fn load_path(
        &mut self,
        path: &Path,
        start: i128,
        step: u16,
        most_per_tick: i128,
    ) -> Result<(), String> {
        let n = path.segments.len();
        if n == 0 {
            return Err("the path is empty".into());
        }
        let window = (SEGMENTS_PER_TICK - 1) as usize;
        for (k, run) in path.segments.windows(window).enumerate() {
            let length: i128 = run.iter().map(|g| g.length).sum();
            if length <= most_per_tick {
                return Err(format!(
                    "segments {k} to {} are {:.1} LSB long together, no more than the path may advance in a tick ({:.1} LSB): a tick could cross more than the {SEGMENTS_PER_TICK} segments this board's tick has room for: use a shorter tick (--ts), lower axis velocity limits (--vmax) or longer elements",
                    k + window - 1,
                    length as f64 / (1u128 << FRAC_BITS) as f64,
                    most_per_tick as f64 / (1u128 << FRAC_BITS) as f64
                ));
            }
        }
        if n > PATH_SLOTS as usize - 2 {
            return Err(format!(
                "the path has {n} segments; this board writes the ring once, before the run, and it holds {} (writing it as the ring makes room needs the command interface, not built yet)",
                PATH_SLOTS - 2
            ));
        }
        let mut at = start;
        for (k, g) in path.segments.iter().enumerate() {
            let words = segment_writes(k as u16, at, g, self.axes)
                .map_err(|e| format!("segment {k}: {e}"))?;
            self.writes.extend(words);
            at += g.length;
        }
        self.writes.push_back(PathSeqInputs {
            seg_index: n as u16 - 1,
            extend: true,
            ..Default::default()
        });
        self.path = Some((path.clone(), start));
        self.settle = Some(3);
        self.step = step.max(1);
        self.drives.step_lsb = 0;
        for k in 0..u32::from(self.axes) {
            self.drives.step_lsb |= u128::from(self.step) << (16 * k);
        }
        Ok(())
    }

    /// Each axis's whole position by the rule at the register `x`.
    fn rule(&self, x: i128) -> Vec<i64> {
        let (path, start) = self.path.as_ref().expect("a path");
        path.at(x - start)
            .expect("a segment")
            .iter()
            .map(|&p| whole(p))
            .collect()
    }

    /// Runs the gathered clocks on the fabric, compares them and reads the lines.
    fn flush(&mut self) -> Result<(), PortMismatch> {
        if self.batch.is_empty() {
            return Ok(());
        }
        if let Some(m) = self.batch.run(&mut self.fabric) {
            return Err(m);
        }
        let first = self.batch.first;
        // (Clocks from 0 here: `enabled` is the clock whose inputs enabled the drives.)
        for (c, g) in self.batch.got().enumerate() {
            let clock = first + c as u64;
            let follows = self.enabled.is_some_and(|e| clock >= e);
            if follows {
                self.lines.clock(g, &mut self.counts);
                if self.tick_slot.get(g) == 1 {
                    let raw = self.x_slot.get(g) as i128;
                    let shift = 128 - self.x_slot.bits;
                    let x = (raw << shift) >> shift;
                    self.samples.push((x, self.counts.clone()));
                }
            }
        }
        if let Some(g) = self.batch.got().last() {
            self.last_words = g.to_vec();
        }
        self.batch.next();
        Ok(())
    }

    /// The fabric's axes against the rule, from the lines (module documentation).
    pub fn fabric_view(&self) -> FabricView {
        let mut v = FabricView {
            steps: self.lines.steps,
            ..Default::default()
        };
        if self.path.is_none() || self.samples.is_empty() {
            return v;
        }
        for w in self.samples.windows(2) {
            let ((x_before, _), (_, counts)) = (&w[0], &w[1]);
            let rule = self.rule(*x_before);
            v.ticks += 1;
            let step = i64::from(self.step);
            let due = |k: usize| (rule[k] - self.anchor[k]).div_euclid(step);
            let wrong = (0..usize::from(self.axes)).find(|&k| counts[k] != due(k));
            if let Some(k) = wrong {
                v.differing += 1;
                v.first.get_or_insert(format!(
                    "axis {k}: {} steps of {step} LSB on its line since the drives were enabled, the rule {} at the register {x_before:#x}",
                    counts[k],
                    due(k)
                ));
            }
        }
        let (_, last) = self.samples.last().expect("a sample");
        v.step = self.step;
        v.end = last
            .iter()
            .zip(&self.anchor)
            .map(|(c, a)| a + c * i64::from(self.step))
            .collect();
        if !self.last_words.is_empty() {
            let f = self.lines.flags(&self.last_words);
            if f.late || f.refused || f.overrun != 0 {
                v.flags = Some(format!(
                    "late {}, refused {}, overrun {:#010b}",
                    f.late, f.refused, f.overrun
                ));
            }
        }
        v
    }

    /// Axes of the design.
    pub fn axes(&self) -> u8 {
        self.axes
    }
}

impl CoreSide for PathCoreBoard {
    type Mismatch = PortMismatch;

    fn run(
        &mut self,
        n: u64,
        source: &mut dyn FnMut(&CoreOutputs) -> CoreInputs,
    ) -> Result<(), PortMismatch> {
        for _ in 0..n {
            let before = self.model.core.outputs();
            let now = source(&before);
            let core = std::mem::replace(&mut self.pending, now);
            let mut i = PathCore::with_core(&core, &self.drives);
            if let Some(w) = self.writes.pop_front() {
                i = PathCore::host_inputs(&w, &i);
            } else if let (Some(left), true) = (self.settle, before.tick) {
                // The ring is in: two ticks commit the path's start, then, on the third, the
                // drives follow from where the rule puts the axes (the chain at rest).
                self.settle = (left > 1).then(|| left - 1);
                if left == 1 {
                    // Where each generator anchors its grid: its axis's committed position
                    // (whole LSB), whatever the chain does meanwhile.
                    self.anchor = (0..usize::from(self.axes))
                        .map(|k| i64::from(self.model.steppers.whole(k) as i32))
                        .collect();
                    self.drives.enable = ((1u16 << self.axes) - 1) as u8;
                    i.enable = self.drives.enable;
                    self.enabled = Some(self.clock);
                }
            }
            self.model.clock(&i);
            self.batch
                .push(&encode_inputs(&i), &encode_outputs(&self.model.outputs()));
            self.clock += 1;
            if self.batch.len() >= BATCH {
                self.flush()?;
            }
        }
        self.flush()
    }

    fn core(&self) -> &CoreModel {
        &self.model.core
    }

    fn clocks(&self) -> u64 {
        self.clock
    }
}

/// The host's link to `board` through the board's command executor, at `baud`, its chain in
/// `format`.
pub fn path_core_link<'b>(
    board: &'b mut PathCoreBoard,
    format: &Format,
    baud: f64,
) -> ExecutorLink<'b, PathCoreBoard> {
    let tick_div = PathCoreBoard::tick_div(board.axes());
    ExecutorLink::new(board, format, tick_div, baud)
}
