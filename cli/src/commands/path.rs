//! `snapgen path`: a G-code program of lines, arcs and helices played along its path on the
//! bit-accurate model (X, Y, Z), each block an exact stop, and checked from the axes'
//! positions alone: on the path (lines 1 LSB on every axis, arcs 2) and within every axis's
//! limits on every tick (`snapgen_host::path`). Prints each block's outcome (`--json`: one
//! object); `--csv` writes the per-tick trace, `--svg` the path in the XY plane and each axis's
//! velocity, acceleration and jerk. Exit 1 when the check fails, 2 for a program it cannot read or play.
//!
//! Not built yet (issue 22): tangent blocks joined at speed, the feed override, corners with
//! a blend, the N-axis fabric, `--board fabric` and `--port`; the picture does not draw the
//! measured deviation.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

use anyhow::Context;
use snapgen_host::gcode::read;
use snapgen_host::path::{play, verify};
use snapgen_model::{Format, FRAC_BITS};
use snapgen_plan::path::speed::Limits;

use crate::error::InputError;

/// Play a G-code program along its path on the model.
#[derive(clap::Args)]
pub struct Args {
    /// The G-code program.
    #[arg(long)]
    gcode: PathBuf,
    /// Each axis's velocity limit (mm/s; also the rapid's speed).
    #[arg(long, default_value_t = 50.0)]
    vmax: f64,
    /// Each axis's acceleration limit (mm/s²).
    #[arg(long, default_value_t = 1000.0)]
    amax: f64,
    /// Each axis's jerk limit (mm/s³).
    #[arg(long, default_value_t = 100_000.0)]
    jmax: f64,
    /// The tick (s).
    #[arg(long, default_value_t = 1e-4)]
    ts: f64,
    /// The output grid (mm per LSB).
    #[arg(long, default_value_t = 1e-6)]
    lsb: f64,
    /// Write the per-tick trace (tick, time, X, Y, Z in mm) to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draw the path in the XY plane and each axis's velocity, acceleration and jerk against
    /// time into this SVG file.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Print one JSON object instead of the table: each block (line, kind, length, limits,
    /// ticks), the ticks and duration, each axis's peaks, and the check's outcome.
    #[arg(long)]
    json: bool,
}

/// The path left its program or an axis its limits (exit 1; the report is printed).
#[derive(Debug, thiserror::Error)]
#[error("the played path failed its check")]
pub struct CheckFailed;

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    for (flag, v) in [
        ("--vmax", a.vmax),
        ("--amax", a.amax),
        ("--jmax", a.jmax),
        ("--ts", a.ts),
        ("--lsb", a.lsb),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(InputError::Board(format!("{flag} {v}: give a positive number")).into());
        }
    }
    let src = std::fs::read_to_string(&a.gcode)
        .with_context(|| format!("cannot read {}", a.gcode.display()))?;
    let blocks =
        read(&src, a.lsb).map_err(|e| InputError::Board(format!("{}: {e}", a.gcode.display())))?;
    let format = Format {
        ts: a.ts,
        position_lsb: a.lsb,
        ..snapgen_model::DEFAULT_FORMAT
    };
    let axis = Limits {
        velocity: a.vmax,
        acceleration: a.amax,
        jerk: a.jmax,
    };
    let axes = [axis; 3];
    let run = play(&blocks, &axes, &format)
        .map_err(|e| InputError::Board(format!("{}: {e}", a.gcode.display())))?;
    let ticks = run.trace.len() as u64 - 1;
    if let Some(path) = &a.csv {
        write_csv(&run.trace, &format, path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &a.svg {
        let title = format!("{}", a.gcode.display());
        crate::svg::write_path_svg(&run.trace, &format, &title, path)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    let c = verify(&run, &blocks, &axes, &format);
    let passed = c.deviation.is_none() && c.exceeded.is_none();
    if a.json {
        let blocks: Vec<serde_json::Value> = run
            .blocks
            .iter()
            .map(|b| {
                serde_json::json!({
                    "line": b.line,
                    "kind": b.kind,
                    "length_mm": b.length,
                    "velocity": b.limits.velocity,
                    "acceleration": b.limits.acceleration,
                    "jerk": b.limits.jerk,
                    "ticks": b.ticks,
                })
            })
            .collect();
        let peaks: Vec<serde_json::Value> = ["X", "Y", "Z"]
            .iter()
            .zip(&c.peaks)
            .map(|(n, [v, aa, j])| {
                serde_json::json!({"axis": n, "velocity": v, "acceleration": aa, "jerk": j})
            })
            .collect();
        let v = serde_json::json!({
            "blocks": blocks,
            "ticks": ticks,
            "duration_s": ticks as f64 * a.ts,
            "peaks": peaks,
            "checked": passed,
            "deviation": c.deviation.as_ref().map(|d| format!("{d:?}")),
            "exceeded": c.exceeded.as_ref().map(|e| format!("{e:?}")),
        });
        println!("{v}");
    } else {
        println!("line  kind    length mm   v mm/s   a mm/s²   j mm/s³     ticks");
        for b in &run.blocks {
            println!(
                "{:>4}  {:<6} {:>10.4} {:>8.3} {:>9.1} {:>9.0} {:>9}",
                b.line,
                b.kind,
                b.length,
                b.limits.velocity,
                b.limits.acceleration,
                b.limits.jerk,
                b.ticks
            );
        }
        println!(
            "{} blocks, {ticks} ticks ({:.3} s)",
            run.blocks.len(),
            ticks as f64 * a.ts
        );
        for (name, [v, aa, j]) in ["X", "Y", "Z"].iter().zip(&c.peaks) {
            println!("{name}: peaks {v:.3} mm/s, {aa:.1} mm/s², {j:.0} mm/s³");
        }
        if passed {
            println!("checked from the positions: on the path (lines 1 LSB, arcs 2) and within every axis's limits on every tick");
        }
        if let Some(d) = &c.deviation {
            println!("OFF THE PATH: {d:?}");
        }
        if let Some(e) = &c.exceeded {
            println!("OVER A LIMIT: {e:?}");
        }
    }
    if passed {
        Ok(())
    } else {
        Err(CheckFailed.into())
    }
}

fn write_csv(trace: &[Vec<i128>], f: &Format, path: &PathBuf) -> std::io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "tick,time_s,x_mm,y_mm,z_mm")?;
    let mm = |x: i128| {
        (x - (1i128 << (FRAC_BITS - 1))) as f64 / 2f64.powi(FRAC_BITS as i32) * f.position_lsb
    };
    for (k, p) in trace.iter().enumerate() {
        writeln!(
            w,
            "{k},{:.9},{:.9},{:.9},{:.9}",
            k as f64 * f.ts,
            mm(p[0]),
            mm(p[1]),
            mm(p[2])
        )?;
    }
    w.flush()
}
