//! `snapgen stop`: MC_Stop (or MC_Halt) from the host: the board brings the axis to rest by
//! itself within its stop limits; this waits for it and prints where it stands.

use snapgen_host::protocol::flag;
use snapgen_model::DEFAULT_FORMAT;

use crate::args::LinkArgs;
use crate::error::failure;

/// Stop the axis.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    link: LinkArgs,
    /// HALT instead of STOP: the axis stays in its motion state until at rest.
    #[arg(long)]
    halt: bool,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let mut session = a.link.open(DEFAULT_FORMAT.position_lsb).map_err(failure)?;
    let r = snapgen_host::send::stop_axis(&mut session, a.halt).map_err(failure)?;
    println!(
        "{} from {}: now {} at rest (x {:#x}, v = a = j = 0) after {} ticks{}",
        if a.halt { "HALT" } else { "STOP" },
        r.before.name(),
        r.status.axis().map_or("?", |s| s.name()),
        r.state.x,
        r.status.tick_count,
        if r.status.has(flag::STOP_OVER_LIMITS) {
            "; the stop left its limits on some tick (it began outside them; it landed exactly)"
        } else {
            ""
        }
    );
    Ok(())
}
