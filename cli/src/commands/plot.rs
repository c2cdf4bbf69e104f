//! `snapgen plot`: position, velocity, acceleration, jerk and snap of a move as SVG.

use std::path::PathBuf;

use crate::args::PlanArgs;

/// Plot a move as SVG.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    plan: PlanArgs,
    /// Output SVG file.
    #[arg(long)]
    svg: PathBuf,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.plan.plan()?;
    let title = format!(
        "order {} move of {} units, {} ticks of {} s",
        p.order(),
        p.request.distance,
        p.ticks_total(),
        p.format.ts
    );
    crate::svg::write_svg(&p, &title, &a.svg)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", a.svg.display()))?;
    eprintln!("wrote {}", a.svg.display());
    Ok(())
}
