//! The AXI4-Lite top (`snapgen_axi.v` with the station of `snapgen_io.v`) against its model
//! (`snapgen_model::io::axi::AxiDevice`) on every clock: every output port — the AXI channels,
//! the interrupt, the pins and the whole status block — compared bit for bit, under random AXI
//! traffic with random VALID delays and READY back-pressure ([`master`]) from a random host
//! ([`host`]: frames of every kind through COMMAND and REPLY, moves, snapshots, interrupts,
//! accesses anywhere in and past the map, switches pressed). Beside the lockstep, [`checker`]
//! checks the AXI4-Lite handshake rules on the fabric's own outputs.

use snapgen_model::device::Design;
use snapgen_model::io::axi::AxiDevice;
use snapgen_model::ports::{AxiInputs, AxiOutputs};

use crate::axi::{encode_inputs, encode_outputs, AXI_OUTPUTS, OUT_SLOTS, OUT_WORDS};
use crate::layout::{slot_named, Batch, PortFault, PortMismatch};
use crate::SimError;

pub mod checker;
mod host;
pub mod master;

pub use checker::{AxiChecker, AxiViolation};

/// Clocks per batch: the host and the model run a batch ahead, then the fabric runs it.
const BATCH: usize = 1 << 12;

/// A run's settings.
#[derive(Clone, Copy, Debug)]
pub struct AxiCosimConfig {
    /// Clocks to run.
    pub clocks: u64,
    /// Seed of the host.
    pub seed: u64,
    /// Test hook: flip a bit of an output of the fabric's (`port` indexes
    /// [`crate::axi::AXI_OUTPUTS`]).
    pub fault: Option<PortFault>,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AxiCosimReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Writes and reads answered.
    pub writes: u64,
    /// See [`AxiCosimReport::writes`].
    pub reads: u64,
    /// Answers with SLVERR.
    pub slave_errors: u64,
    /// Frames written (good ones; damaged ones are not counted).
    pub frames_sent: u64,
    /// Moves uploaded.
    pub moves_sent: u64,
    /// Reply bytes read and reply frames decoded from them.
    pub reply_bytes: u64,
    /// See [`AxiCosimReport::reply_bytes`].
    pub replies: u64,
    /// Entries into ErrorStop by error identifier, ascending.
    pub errors: Vec<(u8, u64)>,
    /// NAKs by reason code, ascending.
    pub naks: Vec<(u8, u64)>,
    /// STARTs and SWAP_ATs acknowledged.
    pub starts_acked: u64,
    /// See [`AxiCosimReport::starts_acked`].
    pub swaps_armed: u64,
    /// Snapshots taken and read.
    pub snapshots: u64,
    /// Clocks with the reset pin high.
    pub resets: u64,
    /// Every IRQ_STATUS bit seen set by a read.
    pub irq_seen: u32,
    /// Clocks with `irq` high.
    pub irq_clocks: u64,
    /// The first difference between fabric and model, if any.
    pub mismatch: Option<PortMismatch>,
    /// The first broken AXI rule (or host-level check), if any.
    pub violation: Option<String>,
}

impl AxiCosimReport {
    /// No mismatch and no broken rule.
    pub fn passed(&self) -> bool {
        self.mismatch.is_none() && self.violation.is_none()
    }
}

/// The AXI outputs of a clock's output words (what the checker reads of the fabric).
struct Bus {
    slots: [crate::layout::Slot; 9],
}

impl Bus {
    const NAMES: [&'static str; 9] = [
        "s_axi_awready",
        "s_axi_wready",
        "s_axi_bvalid",
        "s_axi_bresp",
        "s_axi_arready",
        "s_axi_rvalid",
        "s_axi_rdata",
        "s_axi_rresp",
        "irq",
    ];

    fn new() -> Self {
        Bus {
            slots: Self::NAMES.map(|n| slot_named(&AXI_OUTPUTS, &OUT_SLOTS, n)),
        }
    }

    fn decode(&self, w: &[u32]) -> AxiOutputs {
        let g = |k: usize| self.slots[k].get(w);
        AxiOutputs {
            s_axi_awready: g(0) == 1,
            s_axi_wready: g(1) == 1,
            s_axi_bvalid: g(2) == 1,
            s_axi_bresp: g(3) as u8,
            s_axi_arready: g(4) == 1,
            s_axi_rvalid: g(5) == 1,
            s_axi_rdata: g(6) as u32,
            s_axi_rresp: g(7) as u8,
            irq: g(8) == 1,
            ..Default::default()
        }
    }
}

/// Runs the lockstep for `design`'s AXI top.
pub fn run(design: &Design, cfg: &AxiCosimConfig) -> Result<AxiCosimReport, SimError> {
    let verilog = snapgen_hdl::axi_top::axi_sources_text(design);
    run_verilog(design, &verilog, cfg)
}

/// Runs the lockstep with the AXI design's sources `verilog` (the generator's, or a
/// deliberately altered copy: the tests show an altered line is found).
pub fn run_verilog(
    design: &Design,
    verilog: &str,
    cfg: &AxiCosimConfig,
) -> Result<AxiCosimReport, SimError> {
    let built = crate::build::build_axi(verilog, false)?;
    let mut fabric = crate::axi::open(&built.library, None)?;
    let mut model = AxiDevice::new(design);
    let mut host = host::Host::new(cfg.seed, *design);
    let mut batch = Batch::new(&AXI_OUTPUTS, &OUT_SLOTS, OUT_WORDS, cfg.fault);
    let bus = Bus::new();
    let mut checker = AxiChecker::new();
    // The fabric's AXI outputs before the batch's first clock, and the batch's inputs.
    let mut fabric_before = model.outputs();
    let mut inputs: Vec<AxiInputs> = Vec::with_capacity(BATCH);
    let mut clock = 0;
    while clock < cfg.clocks {
        let before = model.outputs();
        let i = host.inputs(&model);
        let after = model.clock(&i);
        host.observe(&i, &before, &after);
        batch.push(&encode_inputs(&i), &encode_outputs(&after));
        inputs.push(i);
        clock += 1;
        if batch.len() == BATCH || clock == cfg.clocks {
            let mismatch = batch.run(&mut fabric);
            for (i, w) in inputs.iter().zip(batch.got()) {
                let got = bus.decode(w);
                if let Err(v) = checker.clock(i, &fabric_before, &got) {
                    host.report.violation.get_or_insert(v.to_string());
                }
                fabric_before = got;
            }
            inputs.clear();
            host.report.clocks = batch.first + batch.len() as u64;
            if let Some(m) = mismatch {
                host.report.mismatch = Some(m);
                break;
            }
            if host.report.violation.is_some() {
                break;
            }
            batch.next();
        }
    }
    Ok(host.report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A real trace of the model under the random host: (inputs, outputs before, after).
    fn trace(clocks: usize) -> Vec<(AxiInputs, AxiOutputs, AxiOutputs)> {
        let d = crate::io_cosim::cosim_design();
        let mut model = AxiDevice::new(&d);
        let mut host = host::Host::new(3, d);
        (0..clocks)
            .map(|_| {
                let before = model.outputs();
                let i = host.inputs(&model);
                let after = model.clock(&i);
                host.observe(&i, &before, &after);
                (i, before, after)
            })
            .collect()
    }

    fn check(t: &[(AxiInputs, AxiOutputs, AxiOutputs)]) -> Result<(), AxiViolation> {
        let mut c = AxiChecker::new();
        t.iter().try_for_each(|(i, o, a)| c.clock(i, o, a))
    }

    /// The first clock `k` (after the reset) where `f(t[k])` holds.
    fn find(
        t: &[(AxiInputs, AxiOutputs, AxiOutputs)],
        f: impl Fn(&(AxiInputs, AxiOutputs, AxiOutputs)) -> bool,
    ) -> usize {
        (20..t.len())
            .find(|&k| f(&t[k]))
            .expect("the trace has such a clock")
    }

    #[test]
    fn the_checker_passes_the_model_and_fails_each_injected_violation() {
        let t = trace(60_000);
        assert_eq!(check(&t), Ok(()));
        let rule = |t: &[_]| check(t).map_err(|v| v.rule).unwrap_err();
        // The slave drops RVALID (or changes RDATA) while the master is not ready.
        let k = find(&t, |(i, o, _)| o.s_axi_rvalid && !i.s_axi_rready);
        let mut bad = t.clone();
        bad[k + 1].1.s_axi_rvalid = false;
        assert!(rule(&bad).starts_with("RVALID dropped"));
        let mut bad = t.clone();
        bad[k + 1].1.s_axi_rdata ^= 1;
        assert!(rule(&bad).starts_with("RVALID dropped"));
        // Likewise BVALID and BRESP.
        let k = find(&t, |(i, o, _)| o.s_axi_bvalid && !i.s_axi_bready);
        let mut bad = t.clone();
        bad[k + 1].1.s_axi_bresp ^= 2;
        assert!(rule(&bad).starts_with("BVALID dropped"));
        // A response nobody asked for.
        let k = find(&t, |(_, o, _)| {
            !o.s_axi_bvalid && o.s_axi_awready && o.s_axi_wready
        });
        let mut bad = t.clone();
        bad[k].1.s_axi_bvalid = true;
        assert!(rule(&bad).starts_with("BVALID without"));
        let k = find(&t, |(i, o, _)| !o.s_axi_rvalid && !i.s_axi_arvalid);
        let mut bad = t.clone();
        bad[k].1.s_axi_rvalid = true;
        assert!(rule(&bad).starts_with("RVALID without"));
        // The master changes an address it has not handed over.
        let k = find(&t, |(i, o, _)| i.s_axi_awvalid && !o.s_axi_awready);
        let mut bad = t.clone();
        bad[k + 1].0.s_axi_awaddr ^= 4;
        assert!(rule(&bad).starts_with("AWVALID dropped"));
        let k = find(&t, |(i, o, _)| i.s_axi_arvalid && !o.s_axi_arready);
        let mut bad = t.clone();
        bad[k + 1].0.s_axi_arvalid = false;
        assert!(rule(&bad).starts_with("ARVALID dropped"));
        // A valid response out of a reset clock.
        let k = t.iter().position(|(i, _, _)| i.reset).unwrap();
        let mut bad = t.clone();
        bad[k].2.s_axi_rvalid = true;
        assert!(rule(&bad).contains("reset"));
    }
}
