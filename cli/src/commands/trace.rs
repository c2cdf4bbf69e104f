//! `snapgen trace`: the per-tick trace of a plan from the bit-accurate model, as CSV.
//!
//! Columns: `tick,time_s,segment,x,v,a,j,d,x_raw,v_raw,a_raw,j_raw,d_raw`. Physical columns are
//! in units, units/s, …, units/s⁴ (`x` from the centre of the start cell); raw columns are the
//! registers as the fabric holds them. Row `k` is the state after `k` ticks; `d` is the snap
//! applied on the tick before it (0 on row 0).

use std::fs::File;
use std::io::{self, Write};
use std::path::PathBuf;

use anyhow::Context;
use snapgen_model::{Quantity, Trace};
use snapgen_plan::Plan;

use crate::args::PlanArgs;

/// Write the per-tick trace of a move as CSV.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    plan: PlanArgs,
    /// Output CSV file.
    #[arg(long)]
    csv: PathBuf,
    /// Write every N-th tick only (the last tick is always written).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.plan.plan()?;
    let file =
        File::create(&a.csv).with_context(|| format!("cannot create {}", a.csv.display()))?;
    let rows = write_csv(&p, a.every, file)
        .with_context(|| format!("cannot write {}", a.csv.display()))?;
    eprintln!("wrote {rows} rows to {}", a.csv.display());
    Ok(())
}

/// Writes the trace of `plan`, every `every`-th tick plus the last one.
pub fn write_csv<W: Write>(plan: &Plan, every: u64, out: W) -> io::Result<u64> {
    let f = plan.format;
    let mut w = io::BufWriter::new(out);
    writeln!(
        w,
        "tick,time_s,segment,x,v,a,j,d,x_raw,v_raw,a_raw,j_raw,d_raw"
    )?;
    let x0 = f.position_physical(plan.start.x);
    let last = plan.ticks_total();
    let mut rows = 0u64;
    for t in Trace::new(&plan.program, plan.start, f.widths) {
        if t.tick % every != 0 && t.tick != last {
            continue;
        }
        let s = t.state;
        writeln!(
            w,
            "{},{:.9},{},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{},{},{},{},{}",
            t.tick,
            t.tick as f64 * f.ts,
            t.segment,
            f.position_physical(s.x) - x0,
            f.to_physical(Quantity::Velocity, s.v),
            f.to_physical(Quantity::Acceleration, s.a),
            f.to_physical(Quantity::Jerk, s.j),
            f.to_physical(Quantity::Snap, t.d),
            s.x,
            s.v,
            s.a,
            s.j,
            t.d
        )?;
        rows += 1;
    }
    w.flush()?;
    Ok(rows)
}
