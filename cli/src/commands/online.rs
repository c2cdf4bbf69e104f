//! `snapgen online`: plays a timed script of PLCopen commands (MC_MoveAbsolute with its buffer
//! modes, MC_MoveVelocity, MC_Halt, the feed override) on a board through the host axis
//! (`snapgen_host::axis`): the device model or the Verilated I/O top (with the device model in
//! lockstep) at the design's clock and baud rate, or a real board on a serial port.
//!
//! The script is TOML (docs/ONLINE.md):
//!
//! ```toml
//! order = 3                  # 3 (jerk-limited) or 2 (trapezoid)
//! stop_deceleration = 3000   # the board's controlled stop (unit/s², unit/s³)
//! stop_jerk = 50000
//! [[event]]
//! at_ms = 0
//! kind = "move_absolute"
//! position = 400.0
//! velocity = 100.0
//! acceleration = 4000.0
//! deceleration = 3000.0
//! jerk = 50000.0
//! buffer_mode = "aborting"   # buffered, blending_low, blending_previous, blending_next, blending_high
//! [[event]]
//! at_ms = 500
//! override = 0.5             # the feed override, 0–2
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use serde::Serialize;
use snapgen_host::driver::{RunOptions, RunReport};
use snapgen_host::link::{FramedLink, Link, RetryPolicy};
use snapgen_host::online::{
    command_lines, override_lines, play as play_script, target_lsb, CommandLine, OverrideLine,
    PlayError, Script,
};
use snapgen_host::serial::session_seq;
use snapgen_host::session::Session;
use snapgen_model::device::Design;
use snapgen_model::{Trace, DEFAULT_FORMAT};
use snapgen_sim::axi_board::{axi_link, AxiBoard};
use snapgen_sim::board::VirtualBoard;
use snapgen_sim::host_link::board_link;

use crate::args::BoardLinkArgs;
use crate::error::{failure, InputError};
use crate::scenario::Scenario;

/// Play a timed script of PLCopen commands on a board.
#[derive(clap::Args)]
pub struct Args {
    /// The script (TOML, docs/ONLINE.md).
    #[arg(
        long,
        conflicts_with = "scenario",
        required_unless_present = "scenario"
    )]
    script: Option<PathBuf>,
    /// A built-in scenario instead of a script.
    #[arg(long, value_enum)]
    scenario: Option<Scenario>,
    /// The scenario's jerk (unit/s³) [seed002: 50000].
    #[arg(long, requires = "scenario")]
    jerk: Option<f64>,
    /// The virtual board: the device model, or the Verilated I/O top with the device model
    /// in lockstep (every output compared on every clock); behind its UART, or behind the
    /// AXI4-Lite slave (`axi-model`, `axi-fabric`: the host's UIO link on a simulated memory
    /// map, docs/AXI.md).
    #[arg(long, value_enum, default_value = "model", conflicts_with_all = ["port", "uio"])]
    board: BoardKind,
    #[command(flatten)]
    link: BoardLinkArgs,
    /// Write the per-tick integer trace (tick, x, v, a, j, position LSB).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Plot position, velocity, acceleration and jerk with the events marked.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Print one JSON object (commands and outcomes, replans, ticks, final and target
    /// position, final registers, mismatches) instead of the summary.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand: exit 1 if the fabric and the model disagree.
pub fn run(a: Args) -> anyhow::Result<()> {
    let (script, title) = match (a.script, a.scenario) {
        (Some(path), _) => {
            let title = format!("snapgen online {}", path.display());
            (read_script(&path).map_err(InputError::Script)?, title)
        }
        (None, Some(s)) => (
            s.script(a.jerk).map_err(InputError::Script)?,
            s.title(a.jerk),
        ),
        (None, None) => anyhow::bail!("give --script FILE or --scenario NAME"),
    };
    let target = Target {
        board: a.board,
        port: a.link.port,
        uio: a.link.uio,
        baud: a.link.baud,
    };
    let played = play(script, &target)?;
    if a.json {
        println!("{}", json(&played));
    } else {
        println!("{title}\n{}", describe(&played));
    }
    if let Some(path) = a.csv {
        write_csv(&played, &path)?;
    }
    if let Some(path) = a.svg {
        write_svg(&played, &title, &path)?;
    }
    if played.mismatches.unwrap_or(0) > 0 {
        return Err(anyhow::Error::new(crate::error::Mismatched));
    }
    Ok(())
}

/// Reads and checks a script file.
pub fn read_script(path: &Path) -> anyhow::Result<Script> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the script {}", path.display()))?;
    Script::from_toml(&text).with_context(|| path.display().to_string())
}

/// Which board.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BoardKind {
    /// The device model.
    Model,
    /// The Verilated I/O top, the device model in lockstep (every output compared).
    Fabric,
    /// The AXI4-Lite top's model, through the host's UIO link on a simulated memory map.
    AxiModel,
    /// The Verilated AXI4-Lite top, its model in lockstep, through the UIO link.
    AxiFabric,
}

/// Where to run.
pub struct Target {
    /// A virtual board, or None with `port`.
    pub board: BoardKind,
    /// A serial port.
    pub port: Option<String>,
    /// A UIO device.
    pub uio: Option<PathBuf>,
    /// Baud rate (the virtual board's design, or the port's).
    pub baud: u32,
}

/// The result of a run, with what the board was.
pub struct Played {
    /// The run.
    pub report: RunReport,
    /// The script.
    pub script: Script,
    /// Fabric against model: clocks that differed (None: no fabric in the run).
    pub mismatches: Option<u64>,
    /// The first of them, described.
    pub first_mismatch: Option<String>,
    /// Board clocks simulated (virtual boards).
    pub clocks: Option<u64>,
}

/// Plays `script` on the board behind `link` with the link's run options `run`: a session
/// (PING, the board's format), the stop limits, the axis powered, the run. The stop-limit rule's warnings go to stderr.
fn play_on<L: Link>(link: L, script: &Script, run: RunOptions) -> anyhow::Result<(RunReport, L)> {
    let mut session = Session::open(link, DEFAULT_FORMAT.position_lsb).map_err(failure)?;
    let (report, _, warnings) = play_script(&mut session, &script.events, &script.options(run))
        .map_err(|e| match e {
            PlayError::Setup(f) => failure(f),
            e => anyhow::Error::new(e),
        })?;
    for w in warnings {
        eprintln!("warning: {w}");
    }
    Ok((report, session.link))
}

/// Plays `script` on `target`.
pub fn play(script: Script, target: &Target) -> anyhow::Result<Played> {
    if let Some((t, run)) =
        crate::args::direct_link(target.port.as_deref(), target.uio.as_deref(), target.baud)
            .map_err(failure)?
    {
        let link = FramedLink::new(t, RetryPolicy::default(), session_seq());
        let (report, _) = play_on(link, &script, run)?;
        return Ok(Played {
            report,
            script,
            mismatches: None,
            first_mismatch: None,
            clocks: None,
        });
    }
    let design = design(target.baud)?;
    if matches!(target.board, BoardKind::AxiModel | BoardKind::AxiFabric) {
        let board = match target.board {
            BoardKind::AxiFabric => AxiBoard::lockstep(&design)?,
            _ => AxiBoard::model(&design),
        };
        let (report, link) = play_on(axi_link(board)?, &script, RunOptions::memory_mapped())?;
        let b = link.transport().registers();
        return Ok(Played {
            report,
            script,
            mismatches: (target.board == BoardKind::AxiFabric).then(|| b.mismatches()),
            first_mismatch: b.first_mismatch().map(|m| m.to_string()),
            clocks: Some(b.clocks()),
        });
    }
    let board = match target.board {
        BoardKind::Fabric => VirtualBoard::lockstep(&design)?,
        _ => VirtualBoard::model(&design),
    };
    let (report, link) = play_on(board_link(board), &script, RunOptions::default())?;
    let b = link.transport().board();
    let fabric = target.board == BoardKind::Fabric;
    Ok(Played {
        report,
        script,
        mismatches: fabric.then(|| b.mismatches()),
        first_mismatch: b.first_mismatch().map(|m| format!("{m:?}")),
        clocks: Some(b.clocks()),
    })
}

/// The virtual board's design: the default clock and Ts, at `baud`.
pub fn design(baud: u32) -> anyhow::Result<Design> {
    snapgen_sim::board::virtual_design(baud).with_context(|| format!("a board at {baud} baud"))
}

/// The registers, as decimal strings (they exceed 64 bits).
#[derive(Serialize)]
struct Raw {
    x: String,
    v: String,
    a: String,
    j: String,
}

/// `--json`'s object.
#[derive(Serialize)]
struct Json {
    commands: Vec<CommandLine>,
    overrides: Vec<OverrideLine>,
    refused_overrides: Vec<(usize, &'static str)>,
    replans: usize,
    extension_swaps: u32,
    ticks: u64,
    ts: f64,
    final_lsb: i128,
    target_lsb: Option<i128>,
    final_raw: Raw,
    state_checks: u64,
    mismatches: Option<u64>,
    clocks: Option<u64>,
}

/// The `--json` object.
pub fn json(p: &Played) -> String {
    let r = &p.report;
    let f = r.axis.settings.format;
    let j = Json {
        commands: command_lines(r, &p.script.events),
        overrides: override_lines(r, &p.script.events),
        refused_overrides: r
            .refused_overrides
            .iter()
            .map(|(e, id)| (*e, id.name()))
            .collect(),
        replans: r.swaps.len(),
        extension_swaps: r.extensions,
        ticks: r.last.ticks - r.start_tick,
        ts: f.ts,
        final_lsb: f.output_lsb(r.last.x),
        target_lsb: target_lsb(r),
        final_raw: Raw {
            x: r.last.x.to_string(),
            v: r.last.v.to_string(),
            a: r.last.a.to_string(),
            j: r.last.j.to_string(),
        },
        state_checks: r.checks,
        mismatches: p.mismatches,
        clocks: p.clocks,
    };
    serde_json::to_string_pretty(&j).expect("plain data serialises")
}

/// The human summary.
pub fn describe(p: &Played) -> String {
    let r = &p.report;
    let f = r.axis.settings.format;
    let mut s = String::new();
    for c in command_lines(r, &p.script.events) {
        s += &format!(
            "  event {:>2} at {:>8.1} ms  {:<16} {:<15}{}{}{}\n",
            c.event,
            c.at_ms,
            c.command,
            c.outcome,
            c.latency_ms
                .map_or(String::new(), |l| format!(" latency {l:.2} ms")),
            match (c.error_id, &c.error) {
                (Some(id), Some(m)) => format!(" ErrorID {id}: {m}"),
                _ => String::new(),
            },
            c.note.map_or(String::new(), |n| format!(" ({n})")),
        );
    }
    for o in override_lines(r, &p.script.events) {
        s += &format!(
            "  event {:>2} at {:>8.1} ms  override {:<7} {}\n",
            o.event,
            o.at_ms,
            format!("{:.0} %", o.factor * 100.0),
            match (o.error_id, o.latency_ms) {
                (Some(id), _) => format!("refused: {id}: {}", o.error.as_deref().unwrap_or("")),
                (None, Some(l)) => format!("latency {l:.2} ms"),
                (None, None) => "nothing to change".into(),
            }
        );
    }
    s += &format!(
        "  {} replans ({} more swaps to upload long programs), {} ticks ({:.3} s), {} board states checked bit for bit against the plan\n",
        r.swaps.len(),
        r.extensions,
        r.last.ticks - r.start_tick,
        (r.last.ticks - r.start_tick) as f64 * f.ts,
        r.checks
    );
    s += &format!(
        "  final position {} LSB{}, registers x={} v={} a={} j={}",
        f.output_lsb(r.last.x),
        target_lsb(r).map_or(String::new(), |t| format!(" (target {t})")),
        r.last.x,
        r.last.v,
        r.last.a,
        r.last.j
    );
    if let Some(m) = p.mismatches {
        s += &format!("\n  fabric against model: {m} mismatches");
        if let Some(first) = &p.first_mismatch {
            s += &format!(" (first: {first})");
        }
    }
    s
}

/// Writes the per-tick integer trace: tick, x, v, a, j (raw), output LSB.
pub fn write_csv(p: &Played, path: &PathBuf) -> anyhow::Result<()> {
    let r = &p.report;
    let f = r.axis.settings.format;
    let t = &r.axis.timeline;
    let program = t.played(r.last.ticks);
    let mut w = std::io::BufWriter::new(
        std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?,
    );
    writeln!(w, "tick,x,v,a,j,position_lsb")?;
    let (t0, s0) = t.origin;
    for k in Trace::new(&program, s0, f.widths) {
        let s = k.state;
        writeln!(
            w,
            "{},{},{},{},{},{}",
            t0 + k.tick,
            s.x,
            s.v,
            s.a,
            s.j,
            f.output_lsb(s.x)
        )?;
    }
    Ok(())
}

/// Plots position, velocity, acceleration and jerk with the events marked.
pub fn write_svg(p: &Played, title: &str, path: &Path) -> anyhow::Result<()> {
    let r = &p.report;
    let f = r.axis.settings.format;
    let t = &r.axis.timeline;
    let program = t.played(r.last.ticks);
    let offset = (r.start_tick - t.origin.0) as f64 * f.ts;
    let events: Vec<f64> = p
        .script
        .events
        .iter()
        .map(|e| offset + e.at_ms * 1e-3)
        .collect();
    crate::svg::write_program_svg(&program, t.origin.1, &f, title, &events, path)
        .map_err(|e| anyhow::anyhow!("cannot draw {}: {e}", path.display()))
}
