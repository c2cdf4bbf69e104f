//! `snapgen build`: a board build — board top, I/O top, motion core, XDC, Vivado TCL and
//! Makefile — written for a board (`--run` runs it with Vivado).

use std::path::PathBuf;

use crate::args::{BoardArgs, TimingArgs};

/// Write a board build.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    board: BoardArgs,
    /// Output directory [default: out/BOARD].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run the build (needs Vivado, $VIVADO or on the PATH).
    #[arg(long)]
    run: bool,
    #[command(flatten)]
    timing: TimingArgs,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let b = a.board.load()?;
    let (t, d) = a
        .timing
        .resolve(Some(b.clock.frequency_hz), b.input_polarity)?;
    let out = a.out.unwrap_or_else(|| PathBuf::from("out").join(&b.name));
    let plan = crate::fpga::build_plan(&b, &t, &d);
    for f in plan.write(&out)? {
        println!("wrote {}", f.display());
    }
    if a.run {
        plan.run(&out)?;
    } else {
        println!("run it with: make -C {} (needs Vivado)", out.display());
    }
    Ok(())
}
