//! Fabric and model in lockstep, compared on every clock.
//!
//! Each batch runs the model first: clock by clock, with the inputs a source gives for each
//! clock from the model's outputs before it (a constant, or a board's executor clocked
//! beside the core), encoding every clock's outputs in the harness's word layout (not when the
//! model runs alone, the benchmark's reference), until the inputs change or the batch is full. The fabric then runs the same clocks with those inputs
//! (one call into the Verilated library) and its words are compared with the model's in one
//! slice comparison; only a difference is looked at register by register. A fault (tests)
//! flips a bit of the fabric's words at its clock.

use snapgen_model::{CoreInputs, CoreModel, CoreOutputs, Format};

use super::{Fault, Mismatch, Register};
use crate::fabric::{encode_outputs, Fabric, OUT_WORDS};

/// Clocks per batch: the model's and the fabric's words of a batch (76 bytes a clock each)
/// stay in the L1/L2 cache between being written and compared.
pub const BATCH: u64 = 1 << 9;

/// Where a clock's inputs come from: held for the whole call, or given clock by clock.
enum Source<'s> {
    Held(CoreInputs),
    Each(&'s mut dyn FnMut(&CoreOutputs) -> CoreInputs),
}

/// The model's side of the lockstep.
pub struct ModelSide {
    /// The core model.
    pub model: CoreModel,
    /// Inputs of the previous clock: the fabric's wrapper registers every input, so the core
    /// sees them one clock late, and so does the model.
    pub pending: CoreInputs,
    /// The chain steps with a program or a stop on the next clock.
    ticking: bool,
}

impl ModelSide {
    /// A model in its power-up state.
    pub fn new(format: &Format) -> Self {
        ModelSide {
            model: CoreModel::new(format),
            pending: CoreInputs::default(),
            ticking: false,
        }
    }

    /// One clock with inputs `i`: the outputs after it, and whether the chain stepped on it
    /// with a program playing (a tick of the program).
    #[inline(always)]
    pub fn clock(&mut self, i: &CoreInputs) -> (CoreOutputs, bool) {
        let ticked = self.ticking;
        self.model.edge(&self.pending);
        let m = self.model.outputs();
        self.ticking = m.tick && (m.busy || m.stopping);
        self.pending = *i;
        (m, ticked)
    }
}

/// The two sides in lockstep.
pub struct Lockstep {
    /// The Verilated core (None: the model alone, the benchmark's reference).
    pub fabric: Option<Fabric>,
    /// The model.
    pub side: ModelSide,
    /// Clocks run.
    pub clock: u64,
    /// Ticks run (clocks on which the chain stepped with a program or a stop).
    pub ticks: u64,
    /// The move being played (for reports).
    pub move_index: usize,
    /// The session (for reports).
    pub session: usize,
    fault: Option<Fault>,
    /// The fabric's words of a batch.
    got: Vec<u32>,
    /// The model's words of a batch.
    want: Vec<u32>,
    /// Inputs a source gave for the clock after a batch, kept for the next one (a source may
    /// clock a board: it is asked once per clock).
    carry: Option<CoreInputs>,
}

impl Lockstep {
    /// A lockstep of `fabric` (or the model alone) with a model in its power-up state.
    pub fn new(
        fabric: Option<Fabric>,
        format: &Format,
        fault: Option<Fault>,
        session: usize,
    ) -> Self {
        Lockstep {
            fabric,
            side: ModelSide::new(format),
            clock: 0,
            ticks: 0,
            move_index: 0,
            session,
            fault,
            got: Vec::new(),
            want: Vec::new(),
            carry: None,
        }
    }

    /// `n` clocks with inputs `i` on both sides, compared.
    pub fn drive(&mut self, i: &CoreInputs, n: u64) -> Result<(), Mismatch> {
        self.clocks(n, Source::Held(*i))
    }

    /// `n` clocks, each with the inputs `source` gives from the model's outputs before it,
    /// compared (see the module documentation).
    pub fn run(
        &mut self,
        n: u64,
        source: &mut dyn FnMut(&CoreOutputs) -> CoreInputs,
    ) -> Result<(), Mismatch> {
        self.clocks(n, Source::Each(source))
    }

    fn clocks(&mut self, n: u64, mut source: Source<'_>) -> Result<(), Mismatch> {
        let mut left = n;
        while left > 0 {
            let cap = left.min(BATCH) as usize;
            let inputs = match (self.carry.take(), &mut source) {
                (Some(i), _) => i,
                (None, Source::Held(i)) => *i,
                (None, Source::Each(f)) => f(&self.side.model.outputs()),
            };
            let recorded = self.fabric.is_some();
            let (k, ticked) = self.model_run(&inputs, cap, &mut source, recorded);
            if let Some(fab) = self.fabric.as_mut() {
                // The fabric, the same clocks.
                fab.set(&inputs);
                fab.run(k, &mut self.got);
                if let Some(fl) = self.fault {
                    if fl.clock >= self.clock && fl.clock < self.clock + k as u64 {
                        let at = (fl.clock - self.clock) as usize * OUT_WORDS;
                        fl.register.flip(&mut self.got[at..at + OUT_WORDS], fl.bit);
                    }
                }
                if self.got[..k * OUT_WORDS] != self.want[..] {
                    return Err(self.locate(k));
                }
            }
            self.ticks += ticked;
            self.clock += k as u64;
            left -= k as u64;
        }
        Ok(())
    }

    /// The model's clocks of a batch: with `inputs`, up to `cap` clocks or until the source
    /// gives other inputs (kept for the next batch); with `record`, each clock's outputs
    /// encoded into `want`. Returns the clocks run and the ticks among them.
    #[inline(always)]
    fn model_run(
        &mut self,
        inputs: &CoreInputs,
        cap: usize,
        source: &mut Source<'_>,
        record: bool,
    ) -> (usize, u64) {
        self.want.clear();
        let (mut k, mut ticked) = (0, 0u64);
        loop {
            let (m, t) = self.side.clock(inputs);
            if record {
                self.want.extend_from_slice(&encode_outputs(&m));
            } else {
                std::hint::black_box(m);
            }
            ticked += u64::from(t);
            k += 1;
            if k == cap {
                return (k, ticked);
            }
            if let Source::Each(f) = source {
                let next = f(&self.side.model.outputs());
                if next != *inputs {
                    self.carry = Some(next);
                    return (k, ticked);
                }
            }
        }
    }

    /// The first clock and register of a batch of `k` clocks where the words differ.
    fn locate(&self, k: usize) -> Mismatch {
        for c in 0..k {
            let got = &self.got[c * OUT_WORDS..(c + 1) * OUT_WORDS];
            let want = &self.want[c * OUT_WORDS..(c + 1) * OUT_WORDS];
            if got != want {
                // Every bit of every word belongs to a register (tested): one differs.
                let register = Register::all()
                    .find(|r| r.bits_in(got) != r.bits_in(want))
                    .expect("a differing word lies in a register");
                return Mismatch {
                    session: self.session,
                    clock: self.clock + c as u64,
                    move_index: self.move_index,
                    register,
                    expected: register.bits_in(want),
                    actual: register.bits_in(got),
                    bits: register.bits(),
                };
            }
        }
        unreachable!("the batch's words differ somewhere")
    }
}
