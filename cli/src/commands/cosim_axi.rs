//! `snapgen cosim-axi`: the AXI4-Lite top (`snapgen_axi.v`: the station behind an AXI4-Lite
//! slave, issue 23) against its model, every output on every clock, under random AXI traffic
//! with random VALID delays and READY back-pressure; the AXI4-Lite handshake rules checked on
//! the fabric's own outputs.

use std::time::Instant;

use snapgen_sim::axi::AXI_OUTPUTS;
use snapgen_sim::axi_cosim::{self, AxiCosimConfig};
use snapgen_sim::layout::PortFault;

use crate::args::TimingArgs;
use crate::error::{split_fault, InputError, Mismatched};

/// Co-simulate the AXI4-Lite top against its model.
#[derive(clap::Args)]
pub struct Args {
    /// Clocks to run.
    #[arg(long, default_value_t = 2_000_000)]
    clocks: u64,
    /// Seed of the host.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[command(flatten)]
    timing: TimingArgs,
    /// Test hook: flip BIT of OUTPUT at CLOCK in the fabric's outputs ("CLOCK:OUTPUT:BIT").
    #[arg(long, hide = true)]
    inject_fault: Option<String>,
}

/// Runs the subcommand: exit 1 on a mismatch or a broken AXI rule.
pub fn run(a: Args) -> anyhow::Result<()> {
    let fault = a.inject_fault.map(|s| parse_fault(&s)).transpose()?;
    let (_, design) = a.timing.resolve(None, 0)?;
    let cfg = AxiCosimConfig {
        clocks: a.clocks,
        seed: a.seed,
        fault,
    };
    let t = Instant::now();
    let r = axi_cosim::run(&design, &cfg)?;
    let secs = t.elapsed().as_secs_f64();
    println!(
        "AXI4-Lite co-simulation: {} clocks compared, {} writes and {} reads answered ({} SLVERR), {} frames written, {} reply frames read ({} bytes), {} moves uploaded ({} STARTs and {} swaps acknowledged), {} snapshots, interrupt causes seen {:#x}, irq high {} clocks; {} mismatches; {:.2} M clocks/s",
        r.clocks,
        r.writes,
        r.reads,
        r.slave_errors,
        r.frames_sent,
        r.replies,
        r.reply_bytes,
        r.moves_sent,
        r.starts_acked,
        r.swaps_armed,
        r.snapshots,
        r.irq_seen,
        r.irq_clocks,
        u32::from(r.mismatch.is_some()),
        r.clocks as f64 / secs / 1e6
    );
    println!(
        "AXI4-Lite handshake rules: {}",
        r.violation.as_deref().unwrap_or("none broken")
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
    }
    if !r.passed() {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn parse_fault(s: &str) -> Result<PortFault, InputError> {
    let (clock, name, bit) = split_fault::<String>(s)?;
    let port = AXI_OUTPUTS
        .iter()
        .position(|p| p.name == name)
        .ok_or_else(|| InputError::Fault(s.to_string()))?;
    Ok(PortFault { clock, port, bit })
}
