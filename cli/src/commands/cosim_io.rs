//! `snapgen cosim-io`: the Verilated I/O top against the device model under random command
//! streams, every output on every clock.

use std::path::PathBuf;

use snapgen_sim::io_cosim::{self, IoCosimConfig, IoFault};

use crate::error::{split_fault, InputError, Mismatched};

/// Co-simulate the I/O top against the device model.
#[derive(clap::Args)]
pub struct Args {
    /// Clocks per session.
    #[arg(long, default_value_t = 1_000_000)]
    clocks: u64,
    /// Seed of session 0's stream (the others derive theirs from it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Sessions, each its own Verilated I/O top, model and stream, on one thread per core.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=256))]
    sessions: u16,
    /// Where to write the waves around a mismatch.
    #[arg(long, default_value = "io-mismatch.vcd")]
    mismatch_vcd: PathBuf,
    /// Test hook: flip BIT of SIGNAL (a pin, or status.FIELD) at CLOCK in session 0's
    /// captured fabric outputs ("CLOCK:SIGNAL:BIT").
    #[arg(long, hide = true)]
    inject_fault: Option<String>,
}

/// Runs the subcommand: exit 1 on a mismatch (the waves around it are written).
pub fn run(a: Args) -> anyhow::Result<()> {
    let mut cfg = IoCosimConfig::new(a.clocks, a.seed, usize::from(a.sessions));
    cfg.mismatch_vcd = a.mismatch_vcd;
    cfg.fault = a.inject_fault.map(|s| parse_fault(&s)).transpose()?;
    let design = io_cosim::cosim_design();
    let r = io_cosim::run(&design, &cfg)?;
    println!("I/O co-simulation: {}", io_cosim::describe(&r));
    println!(
        "{} mismatches; {:.2} M clocks/s ({:.2} s, {} sessions)",
        u32::from(r.mismatch.is_some()),
        r.clocks_per_second() / 1e6,
        r.seconds,
        a.sessions
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
        if let Some(v) = &r.vcd {
            println!("waves: {}", v.display());
        }
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn parse_fault(s: &str) -> Result<IoFault, InputError> {
    let (clock, signal, bit) = split_fault(s)?;
    Ok(IoFault { clock, signal, bit })
}
