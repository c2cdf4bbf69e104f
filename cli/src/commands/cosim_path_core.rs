//! `snapgen cosim-path-core`: the Verilated path core (the motion core on the path length
//! driving the path steppers) against its model, every output on every clock, under random
//! paths, moves, feed overrides and group stops; each axis's steps counted on its lines against the rule
//! (issue 22).

use std::time::Instant;

use snapgen_sim::build::build_path_core;
use snapgen_sim::path_core::{self, PathCoreConfig, PortFault, PATH_CORE_OUTPUTS};

use crate::error::{split_fault, InputError, Mismatched};

/// Co-simulate the path core against its model.
#[derive(clap::Args)]
pub struct Args {
    /// Axes of the design (1 to 8).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u8).range(1..=8))]
    axes: u8,
    /// Clocks to run.
    #[arg(long, default_value_t = 10_000_000)]
    clocks: u64,
    /// Seed of the stream.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Test hook: flip BIT of OUTPUT at CLOCK in the fabric's outputs ("CLOCK:OUTPUT:BIT").
    #[arg(long, hide = true)]
    inject_fault: Option<String>,
}

/// Runs the subcommand: exit 1 on a mismatch or a drive's count that breaks the rule.
pub fn run(a: Args) -> anyhow::Result<()> {
    let fault = a.inject_fault.map(|s| parse_fault(&s)).transpose()?;
    let built = build_path_core(a.axes, false)?;
    let cfg = PathCoreConfig {
        axes: a.axes,
        clocks: a.clocks,
        seed: a.seed,
        fault,
    };
    let t = Instant::now();
    let r = path_core::run(&built.library, &cfg)?;
    let secs = t.elapsed().as_secs_f64();
    println!(
        "path core co-simulation, {} axes: {} clocks compared ({} ticks), {} runs ({} group stops, {} feed overrides swapped in, {} aborts), {} mismatches; {:.2} M clocks/s",
        a.axes,
        r.clocks,
        r.ticks,
        r.runs,
        r.stops,
        r.swaps,
        r.aborts,
        u32::from(r.mismatch.is_some()),
        r.clocks as f64 / secs / 1e6
    );
    println!(
        "the drives' view: {} steps on the lines, {} runs within the rate checked against the rule, {}",
        r.steps,
        r.checked,
        r.violation.as_deref().unwrap_or("no violation")
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
    }
    if r.mismatch.is_some() || r.violation.is_some() {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn parse_fault(s: &str) -> Result<PortFault, InputError> {
    let (clock, name, bit) = split_fault::<String>(s)?;
    let port = PATH_CORE_OUTPUTS
        .iter()
        .position(|p| p.name == name)
        .ok_or_else(|| InputError::Fault(s.to_string()))?;
    Ok(PortFault { clock, port, bit })
}
