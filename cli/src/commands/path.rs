//! `snapgen path`: a G-code program of lines, arcs and helices, or seed 002's demonstration
//! as a path (`--scenario seed002`), played by the axis group on the bit-accurate model (X, Y,
//! Z): the path length through the PLCopen host axis, tangent blocks joined at speed, corners
//! stopped exactly, a feed override at given times (`--override K@MS`). Checked from the axes'
//! positions alone: on the path (lines 1 LSB on every axis, arcs 2) and within every axis's
//! limits on every tick (`snapgen_host::path`). Prints each block's outcome (`--json`: one
//! object); `--csv` writes the per-tick trace, `--svg` the path in the XY plane (XZ and YZ
//! too when Z moves) and each axis's velocity, acceleration and jerk. Exit 1 when the check fails, 2 for a program it cannot read
//! or play.
//!
//! `--board model|fabric` and `--port` run the path length on a board (its Ts read from it),
//! the host interpolating; `--board path-core` on the Verilated path core, the interpolator in
//! fabric and the axes read from its step lines. Not built yet (issue 22): corners with a
//! blend, the command interface that writes the path core's ring.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

use anyhow::Context;
use snapgen_host::driver::RunOptions;
use snapgen_host::gcode::{read_with, Block, DEFAULT_ARC_TOLERANCE_MM};
use snapgen_host::link::{FramedLink, Link, RetryPolicy};
use snapgen_host::online::PlayError as ScriptError;
use snapgen_host::path::board::{play_on_board_with, BoardError};
use snapgen_host::path::group::MAX_EVENT_MS;
use snapgen_host::path::group::STOP_MARGIN;
use snapgen_host::path::{play_events, verify, PathAction, PathEvent, PathLimits, Run};
use snapgen_host::serial::session_seq;
use snapgen_host::session::Session;
use snapgen_model::path::interp::Path;
use snapgen_model::{Format, FRAC_BITS};
use snapgen_plan::path::speed::Limits;
use snapgen_sim::board::VirtualBoard;
use snapgen_sim::host_link::board_link;
use snapgen_sim::path_board::{path_core_link, FabricView, PathCoreBoard};

use crate::args::BoardLinkArgs;
use crate::error::{failure, InputError};
use crate::scenario::seed002_path;

/// Play a G-code program (or seed 002's demonstration) along its path on the model.
#[derive(clap::Args)]
pub struct Args {
    /// The G-code program.
    #[arg(
        long,
        conflicts_with = "scenario",
        required_unless_present = "scenario"
    )]
    gcode: Option<PathBuf>,
    /// Seed 002's demonstration as a path: a 400 mm line and a tangent 100 mm arc (R 200 mm)
    /// entering at 300 mm, the set speed changed as in `snapgen online --scenario seed002`.
    #[arg(long, value_parser = ["seed002"])]
    scenario: Option<String>,
    /// The scenario's path jerk (mm/s³; the seed's 5000, 50000 or 500000).
    #[arg(long, requires = "scenario", default_value_t = 50_000.0)]
    jerk: f64,
    /// A feed override from a time: `K@MS` (K 0–2, MS milliseconds from the start);
    /// repeat for several.
    #[arg(long = "override", conflicts_with = "scenario", value_parser = parse_override)]
    overrides: Vec<(f64, f64)>,
    /// Each axis's velocity limit (mm/s; also the rapid's speed) [G-code: 50; seed002: 250].
    #[arg(long)]
    vmax: Option<f64>,
    /// Each axis's acceleration limit (mm/s²) [G-code: 1000; seed002: 5000].
    #[arg(long)]
    amax: Option<f64>,
    /// Each axis's jerk limit (mm/s³) [G-code: 100000; seed002: 2000000].
    #[arg(long)]
    jmax: Option<f64>,
    /// The tick (s) [1e-4; on a board, the board's, read from it; the path core board is
    /// built with this tick, 1e-4 by default].
    #[arg(long)]
    ts: Option<f64>,
    /// Run the path length on a virtual board: the device model, or the Verilated I/O top
    /// with the device model in lockstep (every output compared on every clock), the
    /// interpolator on the host; or the Verilated path core (issue 22: the chain on the path
    /// length driving the interpolator and a step/dir generator per axis in fabric) with its
    /// model in lockstep, the axes read from its step lines. Without it (or `--port`) the
    /// host axis plays its own timeline, each change at the tick it is due.
    #[arg(long, value_enum, conflicts_with_all = ["port", "uio"])]
    board: Option<PathBoard>,
    #[command(flatten)]
    link: BoardLinkArgs,
    /// The output grid (mm per LSB).
    #[arg(long, default_value_t = 1e-6)]
    lsb: f64,
    /// How much nearer to or farther from its centre an arc's end may be than its start (mm):
    /// within it the centre is corrected onto the chord's bisector (CAM output rounds both
    /// to its decimals); beyond it the block is refused.
    #[arg(long, default_value_t = DEFAULT_ARC_TOLERANCE_MM)]
    arc_tolerance: f64,
    /// Write the per-tick trace (tick, time, X, Y, Z in mm) to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draw the path in the XY plane (XZ and YZ too when Z moves) and each axis's velocity,
    /// acceleration and jerk against time into this SVG file.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Print one JSON object instead of the table: each block (line, kind, length, limits,
    /// ticks), the ticks and duration, each axis's peaks, and the check's outcome.
    #[arg(long)]
    json: bool,
}

/// The virtual boards `snapgen path` runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PathBoard {
    /// The device model.
    Model,
    /// The Verilated I/O top, the device model in lockstep (every output compared).
    Fabric,
    /// The Verilated path core (the chain, the ring of segments, the interpolator, a
    /// step/dir generator per axis), its model in lockstep; its command executor the
    /// model's, the ring written through its ports before the run.
    PathCore,
}

/// The path left its program or an axis its limits (exit 1; the report is printed).
#[derive(Debug, thiserror::Error)]
#[error("the played path failed its check")]
pub struct CheckFailed;

/// `K@MS` as (K, MS).
fn parse_override(s: &str) -> Result<(f64, f64), String> {
    let bad = || {
        format!("{s}: give K@MS, a factor 0–2 and a time of 0–{MAX_EVENT_MS} ms (e.g. 0.5@1200)")
    };
    let (k, ms) = s.split_once('@').ok_or_else(bad)?;
    let (k, ms): (f64, f64) = (
        k.trim().parse().map_err(|_| bad())?,
        ms.trim().parse().map_err(|_| bad())?,
    );
    if !((0.0..=2.0).contains(&k) && (0.0..=MAX_EVENT_MS).contains(&ms)) {
        return Err(bad());
    }
    Ok((k, ms))
}

/// Runs the subcommand with `args` as its command line would give them (the demo's part).
pub fn run_args(args: &[&str]) -> anyhow::Result<()> {
    #[derive(clap::Parser)]
    struct Line {
        #[command(flatten)]
        args: Args,
    }
    let line = <Line as clap::Parser>::try_parse_from(
        std::iter::once("path").chain(args.iter().copied()),
    )?;
    run(line.args)
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let scenario = a.scenario.is_some();
    let default = if scenario {
        seed002_path::AXES
    } else {
        Limits {
            velocity: 50.0,
            acceleration: 1000.0,
            jerk: 100_000.0,
        }
    };
    let axis = Limits {
        velocity: a.vmax.unwrap_or(default.velocity),
        acceleration: a.amax.unwrap_or(default.acceleration),
        jerk: a.jmax.unwrap_or(default.jerk),
    };
    for (flag, v) in [
        ("--vmax", axis.velocity),
        ("--amax", axis.acceleration),
        ("--jmax", axis.jerk),
        ("--ts", a.ts.unwrap_or(1e-4)),
        ("--lsb", a.lsb),
        ("--jerk", a.jerk),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(InputError::Board(format!("{flag} {v}: give a positive number")).into());
        }
    }
    let on_board = a.board.is_some() || a.link.port.is_some() || a.link.uio.is_some();
    if on_board && a.ts.is_some() && a.board != Some(PathBoard::PathCore) {
        return Err(InputError::Board(
            "--ts: a board's tick is read from the board; leave --ts out".into(),
        )
        .into());
    }
    let format = Format {
        ts: a.ts.unwrap_or(1e-4),
        position_lsb: a.lsb,
        ..snapgen_model::DEFAULT_FORMAT
    };
    let axes = [axis; 3];
    let (name, blocks, own, events) = match &a.gcode {
        Some(file) => {
            let src = std::fs::read_to_string(file)
                .with_context(|| format!("cannot read {}", file.display()))?;
            let blocks = read_with(&src, a.lsb, a.arc_tolerance)
                .map_err(|e| InputError::Board(format!("{}: {e}", file.display())))?;
            let mut events: Vec<PathEvent> = a
                .overrides
                .iter()
                .map(|&(k, at_ms)| PathEvent {
                    at_ms,
                    at_length: None,
                    action: PathAction::Override(k),
                })
                .collect();
            if let Some(last) = blocks.len().checked_sub(1) {
                events.push(PathEvent {
                    at_ms: 0.0,
                    at_length: None,
                    action: PathAction::Enter(last),
                });
            }
            events.sort_by(|x, y| x.at_ms.total_cmp(&y.at_ms));
            (file.display().to_string(), blocks, None, events)
        }
        None => {
            let (blocks, own, events) =
                seed002_path::path(a.jerk, a.lsb).map_err(InputError::Script)?;
            let name = format!(
                "seed 002 as a path: 400 mm line, tangent 100 mm arc (R 200 mm) entering at 300 mm, jerk {} mm/s³",
                a.jerk
            );
            (name, blocks, Some(own), events)
        }
    };
    let (run, format, mismatches) = if on_board {
        board_run(&a, &blocks, &axes, own, &events)
            .map_err(|e| e.context(format!("{name} on the board")))?
    } else {
        let run = play_events(&blocks, &axes, own, &format, &events)
            .map_err(|e| InputError::Board(format!("{name}: {e}")))?;
        (run, format, None)
    };
    let ticks = run.trace.len() as u64 - 1;
    if let Some(path) = &a.csv {
        write_csv(&run.trace, &format, path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    let c = verify(&run, &blocks, &axes, &format);
    if let Some(path) = &a.svg {
        crate::svg::write_path_svg(&run.trace, &c.distance, &format, &name, path)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    let farthest = c.distance.iter().copied().fold(0.0f64, f64::max);
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
                    "entry": b.entry,
                    "outcome": b.outcome.name(),
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
            "events": events_json(&events, &run),
            "ts": format.ts,
            "max_distance_lsb": farthest,
            "mismatches": mismatches,
            "ticks": ticks,
            "duration_s": ticks as f64 * format.ts,
            "peaks": peaks,
            "checked": passed,
            "deviation": c.deviation.as_ref().map(|d| format!("{d:?}")),
            "exceeded": c.exceeded.as_ref().map(|e| format!("{e:?}")),
            "board_stop": run.stop.map(|s| serde_json::json!({
                "deceleration": s.deceleration,
                "jerk": s.jerk,
            })),
        });
        println!("{v}");
    } else {
        println!("{name}");
        println!(
            "line  kind    length mm   v mm/s   a mm/s²   j mm/s³  entry mm/s     ticks  outcome"
        );
        for b in &run.blocks {
            println!(
                "{:>4}  {:<6} {:>10.4} {:>8.3} {:>9.1} {:>9.0} {:>11.3} {:>9}  {}",
                b.line,
                b.kind,
                b.length,
                b.limits.velocity,
                b.limits.acceleration,
                b.limits.jerk,
                b.entry,
                b.ticks,
                b.outcome.name()
            );
        }
        for e in events_json(&events, &run) {
            println!("  event {e}");
        }
        println!(
            "{} blocks, {ticks} ticks ({:.3} s)",
            run.blocks.len(),
            ticks as f64 * format.ts
        );
        if let Some(s) = run.stop {
            println!(
                "the board's controlled stop (a group stop on the path): {:.1} mm/s², {:.0} mm/s³, within every axis on every element; every move within {:.0} % of them",
                s.deceleration,
                s.jerk,
                100.0 * (1.0 - STOP_MARGIN)
            );
        }
        println!("farthest from the programmed path: {farthest:.3e} LSB");
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
    if let Some(m) = mismatches {
        if !a.json {
            println!("fabric against the model: {m} clocks differed");
        }
        if m > 0 {
            return Err(anyhow::Error::new(crate::error::Mismatched));
        }
    }
    if passed {
        Ok(())
    } else {
        Err(CheckFailed.into())
    }
}

/// Each event: what, when it was due, the tick it was taken on, a refusal.
fn events_json(events: &[PathEvent], run: &Run) -> Vec<serde_json::Value> {
    events
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let what = match e.action {
                PathAction::Enter(k) => format!("block {} enters", k + 1),
                PathAction::Override(k) => format!("override {:.0} %", k * 100.0),
            };
            serde_json::json!({
                "event": what,
                "at_ms": e.at_ms,
                "at_length_mm": e.at_length,
                "tick": run.taken.get(i).copied().flatten(),
                "refused": run.refused.iter().find(|(k, _)| *k == i).map(|(_, r)| r.to_string()),
            })
        })
        .collect()
}

/// The path run on a board (`--board`, `--port`): the run, the board's format, and for the
/// Verilated fabric the clocks on which it differed from the model.
fn board_run(
    a: &Args,
    blocks: &[Block],
    axes: &[Limits],
    own: Option<PathLimits>,
    events: &[PathEvent],
) -> anyhow::Result<(Run, Format, Option<u64>)> {
    if let Some((t, run)) = a.link.direct().map_err(crate::error::failure)? {
        let link = FramedLink::new(t, RetryPolicy::default(), session_seq());
        let (run, format, _) = session_run(
            link,
            run,
            a.lsb,
            blocks,
            axes,
            own,
            events,
            |_, _, _| Ok(()),
        )?;
        return Ok((run, format, None));
    }
    let design = crate::commands::online::design(a.link.baud)?;
    if a.board == Some(PathBoard::PathCore) {
        let axes_n = axes.len() as u8;
        let format = Format {
            ts: a.ts.unwrap_or(1e-4),
            ..design.format
        };
        // The step length that follows the fastest axis (its velocity limit), and the most
        // the path length may advance in a tick (every axis at its limit at once).
        let fastest = axes.iter().map(|l| l.velocity).fold(0.0, f64::max);
        let step = PathCoreBoard::step_for(axes_n, fastest / a.lsb * format.ts)
            .map_err(InputError::Board)?;
        let path_speed: f64 = axes.iter().map(|l| l.velocity.powi(2)).sum::<f64>().sqrt();
        let most_per_tick =
            (path_speed / a.lsb * format.ts * 2f64.powi(FRAC_BITS as i32)).ceil() as i128;
        let built = snapgen_sim::build::build_path_core(axes_n, false)?;
        let mut board = PathCoreBoard::open(&built.library, axes_n, &format)?;
        let link = path_core_link(&mut board, &format, f64::from(a.link.baud));
        let (run, format, _) = session_run(
            link,
            RunOptions::default(),
            a.lsb,
            blocks,
            axes,
            own,
            events,
            |s, path, start| {
                s.link
                    .lockstep()
                    .load_path(path, start, step, most_per_tick)
            },
        )?;
        let view = board.fabric_view();
        report_view(&view, &run, a.json);
        if view.differing > 0 || view.flags.is_some() || view.ticks == 0 {
            return Err(CheckFailed.into());
        }
        return Ok((run, format, Some(0)));
    }
    let fabric = a.board == Some(PathBoard::Fabric);
    let board = if fabric {
        VirtualBoard::lockstep(&design)?
    } else {
        VirtualBoard::model(&design)
    };
    let (run, format, link) = session_run(
        board_link(board),
        RunOptions::default(),
        a.lsb,
        blocks,
        axes,
        own,
        events,
        |_, _, _| Ok(()),
    )?;
    let b = link.transport().board();
    if let Some(m) = b.first_mismatch() {
        eprintln!("first mismatch: {m:?}");
    }
    Ok((run, format, fabric.then(|| b.mismatches())))
}

/// The path core's axes as its step lines show them (see `snapgen_sim::path_board`).
fn report_view(v: &FabricView, run: &Run, json: bool) {
    let out = |line: String| {
        if json {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    };
    out(format!(
        "path core in fabric: {} ticks, every axis's steps ({} LSB each) on its line against the rule at the fabric's path length a tick before: {} differ; {} steps",
        v.ticks, v.step, v.differing, v.steps
    ));
    let host: Vec<i64> = run.end_cells().iter().map(|&c| c as i64).collect();
    out(format!(
        "  axes at the end from the step lines: {:?} LSB (the host's rule: {:?})",
        v.end, host
    ));
    if let Some(f) = &v.first {
        out(format!("  first difference: {f}"));
    }
    if let Some(f) = &v.flags {
        out(format!("  FLAGS: {f}"));
    }
}

/// A session on `link` (the board's format read, the axis at rest), the path played on it
/// with the host's run options `run`; `load` gives the board the path before anything moves
/// (a board with the path core).
#[allow(clippy::too_many_arguments)]
fn session_run<L: Link>(
    link: L,
    run: RunOptions,
    lsb: f64,
    blocks: &[Block],
    axes: &[Limits],
    own: Option<PathLimits>,
    events: &[PathEvent],
    load: impl FnOnce(&mut Session<L>, &Path, i128) -> Result<(), String>,
) -> anyhow::Result<(Run, Format, L)> {
    let mut session = Session::open(link, lsb).map_err(failure)?;
    let (run, _, warnings) = play_on_board_with(&mut session, blocks, axes, own, events, run, load)
        .map_err(|e| match e {
            BoardError::Path(p) => InputError::Board(p.to_string()).into(),
            BoardError::Load(why) => {
                InputError::Board(format!("giving the board the path: {why}")).into()
            }
            BoardError::Board(ScriptError::Setup(f)) => failure(f),
            e => anyhow::Error::new(e),
        })?;
    for w in warnings {
        eprintln!("warning: {w}");
    }
    Ok((run, session.format, session.link))
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
