//! `snapgen format`: the fixed-point format's widths, range and resolution.

use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plan::PlanError;

use crate::error::InputError;

/// Print the fixed-point format.
#[derive(clap::Args)]
pub struct Args {
    /// Tick period Ts (s).
    #[arg(long, default_value_t = DEFAULT_FORMAT.ts, allow_hyphen_values = true)]
    ts: f64,
    /// Output position LSB (units).
    #[arg(long, default_value_t = DEFAULT_FORMAT.position_lsb, allow_hyphen_values = true)]
    lsb: f64,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let f = Format {
        ts: a.ts,
        position_lsb: a.lsb,
        ..DEFAULT_FORMAT
    };
    f.validate()
        .map_err(PlanError::from)
        .map_err(InputError::from)?;
    print!("{}", crate::report::format_table(&f));
    Ok(())
}
