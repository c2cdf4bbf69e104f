//! `snapgen cosim-interp`: the Verilated path interpolator against its model, every output on
//! every clock, under random segments from the host's path planner (issue 22).

use std::time::Instant;

use snapgen_sim::build::build_interpolator;
use snapgen_sim::interp::{self, InterpConfig, PortFault, INTERP_OUTPUTS};

use crate::error::{split_fault, InputError, Mismatched};

/// Co-simulate the path interpolator against its model.
#[derive(clap::Args)]
pub struct Args {
    /// Axes of the design (1 to 8).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(1..=8))]
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

/// Runs the subcommand: exit 1 on a mismatch or a computation that breaks the rule.
pub fn run(a: Args) -> anyhow::Result<()> {
    let fault = a.inject_fault.map(|s| parse_fault(&s)).transpose()?;
    let built = build_interpolator(a.axes, false)?;
    let cfg = InterpConfig {
        axes: a.axes,
        clocks: a.clocks,
        seed: a.seed,
        fault,
    };
    let t = Instant::now();
    let r = interp::run(&built.library, &cfg)?;
    let secs = t.elapsed().as_secs_f64();
    println!(
        "interpolator co-simulation, {} axes: {} clocks compared, {} segments, {} computations ({} writes), {} mismatches; {:.2} M clocks/s",
        a.axes,
        r.clocks,
        r.segments,
        r.computations,
        r.writes,
        u32::from(r.mismatch.is_some()),
        r.clocks as f64 / secs / 1e6
    );
    println!(
        "against the rule (Segment::at): {} computations of planner's segments checked, {} wrong",
        r.checked, r.rule_errors
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
    }
    if r.mismatch.is_some() || r.rule_errors > 0 {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn parse_fault(s: &str) -> Result<PortFault, InputError> {
    let (clock, name, bit) = split_fault::<String>(s)?;
    let port = INTERP_OUTPUTS
        .iter()
        .position(|p| p.name == name)
        .ok_or_else(|| InputError::Fault(s.to_string()))?;
    Ok(PortFault { clock, port, bit })
}
