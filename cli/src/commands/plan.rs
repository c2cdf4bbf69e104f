//! `snapgen plan`: a move planned and printed (a summary, or one JSON object).

use crate::args::PlanArgs;
use crate::report::PlanReport;

/// Plan a move and print it.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    plan: PlanArgs,
    /// Print one JSON object instead of the summary.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.plan.plan()?;
    let r = PlanReport::new(&p);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", r.human());
    }
    Ok(())
}
