//! The Verilated step/dir generator (`snapgen_step_dir`) in lockstep with its model
//! (`snapgen_model::io::step_dir::StepDir`): every output compared on every clock, and the
//! fabric's step and direction lines checked on their own as a drive would see them.
//!
//! The stream: runs of a random configuration (1–20 LSB per step, pulse, space and setup of
//! 1–20 clocks, now and then 0), each disabled for 100 clocks (the grid anchored), then a
//! random smooth motion of the position with reversals, then still; a fifth of the runs faster
//! than the pulse train allows (1.3–2 times), the others within the rate that is safe with a
//! reversal on every step; now and then a reset. The drive's view (from the fabric's lines
//! alone): every pulse high for exactly its clocks and low at least its clocks, the direction
//! unchanged from `setup` clocks before a rising edge after it changed to the end of the
//! pulse's low time, and at the end of every run within the limit, once the position has been
//! still, the steps counted on the rising edges equal `⌊(position − anchor) / step⌋`.

use std::path::Path as FsPath;

use rand::{Rng, SeedableRng};
use snapgen_model::io::step_dir::{max_steps_per_second, safe_steps_per_second, StepDir};
use snapgen_model::{StepDirInputs, StepDirOutputs};

use crate::layout::{first_difference, harness_header, port_layout};
pub use crate::layout::{PortFault, PortMismatch};
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_step_dir_ports!(port_layout! {
    STEP_DIR_INPUTS, STEP_DIR_OUTPUTS, StepDirInputs, StepDirOutputs;
});

/// The generator's tag in the harness's ABI word.
const STEP_DIR_TAG: u32 = 4;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn step_dir_layout_header() -> String {
    harness_header(
        &STEP_DIR_INPUTS,
        &STEP_DIR_OUTPUTS,
        abi(STEP_DIR_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&StepDirInputs::default()),
    )
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StepDirReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Runs (configurations) played.
    pub runs: u64,
    /// Pulses on the fabric's step line.
    pub pulses: u64,
    /// Runs within the limit whose final step count was checked against the grid.
    pub checked: u64,
    /// Runs over the limit.
    pub over: u64,
    /// Of those, how many raised `overrun`.
    pub flagged: u64,
    /// Runs within the limit that raised `overrun` (must be 0).
    pub false_overruns: u64,
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
    /// What the drive's view found wrong, first only.
    pub violation: Option<String>,
}

/// The drive's view of the lines, clock by clock (see the module documentation).
#[derive(Default)]
struct Drive {
    /// The lines on the last clock.
    last: (bool, bool),
    /// Clocks the step line has been high (in a pulse).
    high_for: u64,
    /// Clocks since the last pulse ended (None before the first).
    low_for: Option<u64>,
    /// Clocks the direction line has been stable.
    dir_for: u64,
    /// The direction changed since the last pulse.
    turned: bool,
    /// Clocks after a rising edge in which the direction must not change.
    hold_left: u64,
    /// Steps counted on the rising edges, signed by the direction line.
    counted: i64,
    /// Rising edges seen.
    pulses: u64,
}

impl Drive {
    /// Takes one clock of the fabric's lines, with the run's timing; a broken promise says so.
    fn clock(&mut self, step: bool, dir: bool, i: &StepDirInputs) -> Result<(), String> {
        let at_least = |x: u16| u64::from(x.max(1));
        let (was_step, was_dir) = self.last;
        self.last = (step, dir);
        if dir != was_dir {
            if self.hold_left > 0 {
                return Err("the direction changed during a pulse or its low time".into());
            }
            self.dir_for = 0;
            self.turned = true;
        }
        self.dir_for += 1;
        self.hold_left = self.hold_left.saturating_sub(1);
        if step && !was_step {
            if let Some(low) = self.low_for.filter(|&l| l < at_least(i.low_clocks)) {
                return Err(format!("a pulse after only {low} clocks low"));
            }
            if self.turned && self.dir_for <= at_least(i.setup_clocks) {
                return Err(format!(
                    "a rising edge {} clocks after a change of direction",
                    self.dir_for - 1
                ));
            }
            self.turned = false;
            self.counted += if dir { 1 } else { -1 };
            self.pulses += 1;
            self.high_for = 0;
            self.hold_left = at_least(i.high_clocks) + at_least(i.low_clocks);
        }
        if !step && was_step {
            if self.high_for != at_least(i.high_clocks) {
                return Err(format!("a pulse {} clocks high", self.high_for));
            }
            self.low_for = Some(0);
        }
        if step {
            self.high_for += 1;
        } else if let Some(l) = self.low_for.as_mut() {
            *l += 1;
        }
        Ok(())
    }
}

/// Runs `clocks` clocks of the stream from `seed` on the library `library` (built by
/// [`crate::build::build_step_dir`]); `fault` (a test hook) flips a bit of one of the
/// fabric's outputs (`port` indexes [`STEP_DIR_OUTPUTS`]).
pub fn run(
    library: &FsPath,
    clocks: u64,
    seed: u64,
    fault: Option<PortFault>,
) -> Result<StepDirReport, SimError> {
    let mut fabric = Verilated::open(library, None, STEP_DIR_TAG, IN_WORDS, OUT_WORDS)?;
    let slot = |name: &str| {
        STEP_DIR_OUTPUTS
            .iter()
            .position(|p| p.name == name)
            .map(|k| OUT_SLOTS[k])
            .expect("the spec's step/dir outputs")
    };
    let (step_slot, dir_slot) = (slot("step"), slot("dir"));
    let mut model = StepDir::new();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut r = StepDirReport::default();
    let (mut ins, mut want, mut got) = (Vec::new(), Vec::new(), Vec::new());
    while r.clocks < clocks {
        // One run: a configuration and a motion, in clocks.
        let pick = |rng: &mut rand::rngs::StdRng| -> u16 {
            if rng.gen_bool(0.05) {
                0
            } else {
                rng.gen_range(1..=20)
            }
        };
        let mut i = StepDirInputs {
            step_lsb: pick(&mut rng),
            high_clocks: pick(&mut rng),
            low_clocks: pick(&mut rng),
            setup_clocks: pick(&mut rng),
            enable: false,
            position: rng.gen(),
            ..Default::default()
        };
        let k = f64::from(i.step_lsb.max(1));
        // In LSB per clock: the train's limit (a speed over it, up to twice it), or the rate
        // that is safe with a reversal on every step (a speed within it).
        let over = rng.gen_bool(0.2);
        let vmax = if over {
            max_steps_per_second(1.0, i.high_clocks, i.low_clocks) * k * rng.gen_range(1.3..2.0)
        } else {
            safe_steps_per_second(1.0, i.high_clocks, i.low_clocks, i.setup_clocks)
                * k
                * rng.gen_range(0.05..1.0)
        };
        let length = rng.gen_range(2_000..20_000u64);
        let anchor = i.position;
        let mut x = 0.0f64;
        let mut v = 0.0f64;
        let mut target = rng.gen_range(-200.0..200.0) * k;
        // Disabled long enough for a pulse of the run before to end and the grid to be
        // anchored; the motion, then still.
        let (quiet, still) = (100u64, 3_000u64);
        ins.clear();
        let mut lines_in = Vec::new();
        for c in 0..quiet + length + still {
            i.enable = c >= quiet;
            if c >= quiet && c < quiet + length {
                // A smooth motion toward moving targets, within vmax.
                if rng.gen_bool(0.001) {
                    target = rng.gen_range(-200.0..200.0) * k;
                }
                let dv = ((target - x) * 0.01).clamp(-vmax, vmax) - v;
                v += dv.clamp(-vmax * 0.01, vmax * 0.01);
                x += v;
            }
            i.position = anchor.wrapping_add(x.floor() as i64 as u32);
            i.reset = c >= quiet && rng.gen_bool(0.00005);
            ins.extend_from_slice(&encode_inputs(&i));
            lines_in.push(i);
        }
        // Both sides, the run's clocks.
        want.clear();
        for i in &lines_in {
            model.clock(i);
            want.extend_from_slice(&encode_outputs(&model.outputs()));
        }
        fabric.run_each(&ins, &mut got);
        if let Some(f) = fault {
            f.apply(&OUT_SLOTS, OUT_WORDS, r.clocks, &mut got);
        }
        if got != want {
            let m = first_difference(
                &STEP_DIR_OUTPUTS,
                &OUT_SLOTS,
                OUT_WORDS,
                r.clocks,
                &got,
                &want,
            );
            if let Some(m) = m {
                r.clocks = m.clock + 1;
                r.mismatch = Some(m);
                return Ok(r);
            }
        }
        // The drive's view of the fabric's own lines.
        let mut reset_seen = false;
        let mut drive = Drive::default();
        for (c, (i, g)) in lines_in.iter().zip(got.chunks(OUT_WORDS)).enumerate() {
            let (o, d) = (step_slot.get(g) == 1, dir_slot.get(g) == 1);
            if i.reset || !i.enable {
                reset_seen |= i.reset && i.enable;
                r.pulses += drive.pulses;
                drive = Drive {
                    last: (o, d),
                    ..Drive::default()
                };
                continue;
            }
            if let Err(e) = drive.clock(o, d, i) {
                r.violation
                    .get_or_insert(format!("clock {}: {e}", r.clocks + c as u64));
            }
        }
        r.pulses += drive.pulses;
        let last = lines_in.last().expect("a run has clocks");
        let out = model.outputs();
        if over {
            r.over += 1;
            r.flagged += u64::from(out.overrun);
        } else if out.overrun {
            r.false_overruns += 1;
        } else if !reset_seen {
            let grid = (i64::from(last.position.wrapping_sub(anchor) as i32))
                .div_euclid(i64::from(last.step_lsb.max(1)));
            r.checked += 1;
            if drive.counted != grid || i64::from(out.steps as i32) != grid {
                r.violation.get_or_insert(format!(
                    "run {}: {} steps counted on the line, {} reported, the grid says {grid}",
                    r.runs, drive.counted, out.steps as i32
                ));
            }
        }
        r.runs += 1;
        r.clocks += lines_in.len() as u64;
    }
    Ok(r)
}
