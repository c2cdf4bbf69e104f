//! `snapgen synth`: the board top and the motion core synthesised with Yosys — resources,
//! share of the device, logic-only timing; exit 1 if the motion core is over its budget.

use crate::args::{BoardArgs, TimingArgs};

/// Synthesise with Yosys.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    board: BoardArgs,
    #[command(flatten)]
    timing: TimingArgs,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let b = a.board.load()?;
    let (t, d) = a
        .timing
        .resolve(Some(b.fabric_clock_hz()), b.input_polarity)?;
    let r = crate::fpga::synth(&b, &t, &d)?;
    print!("{}", r.table());
    let v = r.violations();
    if !v.is_empty() {
        anyhow::bail!("over budget: {}", v.join("; "));
    }
    println!("motion core within budget");
    Ok(())
}
