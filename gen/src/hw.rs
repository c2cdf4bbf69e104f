//! `snapgen verilog` and `snapgen cosim`.

use std::path::{Path, PathBuf};

use std::io::IsTerminal;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use snapgen_model::device::Design;
use snapgen_sim::cosim::{self, CosimConfig, CosimReport};

/// Files `snapgen verilog` writes.
pub struct VerilogFiles {
    /// The motion core (`snapgen_core.v`).
    pub core: PathBuf,
    /// The I/O top (`snapgen_io.v`: UART command interface, position controller, encoder, PWM, around `snapgen_core`).
    pub io_top: PathBuf,
}

/// Writes the motion core's Verilog (`snapgen_core.v`) and the I/O top of `design`
/// (`snapgen_io.v`, which instantiates `snapgen_core`). Each file carries its own lint
/// waivers; the I/O top needs both.
pub fn write_verilog(out: &Path, design: &Design) -> anyhow::Result<VerilogFiles> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let core = out.join(format!("{}.v", snapgen_hdl::verilog::CORE_PREFIX));
    let io_top = out.join(format!("{}.v", snapgen_hdl::verilog::IO_PREFIX));
    std::fs::write(&io_top, snapgen_hdl::verilog::io_top_verilog(design))
        .with_context(|| format!("cannot write {}", io_top.display()))?;
    std::fs::write(&core, snapgen_hdl::verilog::motion_core_verilog())
        .with_context(|| format!("cannot write {}", core.display()))?;
    Ok(VerilogFiles { core, io_top })
}

/// A bar of `moves` moves on stderr when it is a terminal (hidden otherwise).
fn move_bar(moves: usize) -> ProgressBar {
    if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(moves as u64);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} moves {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    }
}

/// Runs a co-simulation and prints its report; returns it.
pub fn cosim(cfg: &CosimConfig, bench: bool) -> anyhow::Result<CosimReport> {
    let verilog = snapgen_hdl::verilog::motion_core_verilog();
    let bar = move_bar(cfg.moves);
    let r = cosim::run_observed(&verilog, cfg, &|| bar.inc(1))?;
    bar.finish_and_clear();
    println!(
        "co-simulation: {} moves ({} aborted midway, {} with a controlled stop, {} skipped), {} ticks in {} clocks compared, {} mismatches{}",
        r.moves,
        r.aborted,
        r.stopped,
        r.skipped,
        r.ticks,
        r.clocks,
        u32::from(r.mismatch.is_some()),
        if r.cached_build { " (cached Verilator build)" } else { "" }
    );
    println!(
        "throughput: {:.1} M ticks/s, {:.1} M clocks/s ({:.3} s, {})",
        r.ticks_per_second() / 1e6,
        r.clocks as f64 / r.seconds.max(1e-9) / 1e6,
        r.seconds,
        count(r.threads, "thread")
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
    }
    println!(
        "replans: {} program swaps played ({} drawn too long; refused by the online planner: {}), {} late swaps refused by the core, {} armed swaps cancelled by a stop{}",
        r.replans,
        r.replans_too_long,
        tally(&r.replans_refused),
        r.late_swaps - r.late_swaps_taken,
        r.swaps_cancelled,
        if r.swap_faults() > 0 {
            format!(
                "; {} late swaps armed and {} timely swaps not armed (must be 0)",
                r.late_swaps_taken, r.swaps_not_armed
            )
        } else {
            String::new()
        }
    );
    if r.streams > 0 {
        println!(
            "PLCopen event streams: {} played, {} commands, {} program swaps ({} of them uploading the rest of a long change); commands in Error: {}; {} ended moving (stopped with STOP){}{}",
            r.streams,
            r.stream_commands,
            r.stream_swaps,
            r.stream_extensions,
            tally(&r.stream_errors),
            r.streams_stopped,
            if r.streams_diverged > 0 {
                format!(
                    "; {} diverged from the host's prediction (must be 0): {}",
                    r.streams_diverged,
                    r.divergences.join("; ")
                )
            } else {
                String::new()
            },
            if r.streams_failed.is_empty() {
                String::new()
            } else {
                format!("; runs that failed: {}", tally(&r.streams_failed))
            }
        );
    }
    if r.planner_disagreements > 0 {
        println!(
            "{} moves ended where the planner did not predict",
            r.planner_disagreements
        );
    }
    if let Some(v) = &r.vcd {
        println!("waves: {}", v.display());
    }
    if bench && r.mismatch.is_none() {
        print_bench(&verilog, cfg, &r)?;
    }
    Ok(r)
}

/// `n kind, …` of a tally, or `none`.
fn tally(t: &std::collections::BTreeMap<String, usize>) -> String {
    if t.is_empty() {
        "none".to_string()
    } else {
        t.iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Timed runs of the benchmark: the co-simulation and the model alone, each [`BENCH_RUNS`]
/// times over the same moves.
const BENCH_RUNS: usize = 5;

/// Repeats the co-simulation and the model-only run and prints medians and bests: one run is
/// at the mercy of whatever else the machine does (seen here: ±20 % between runs).
fn print_bench(verilog: &str, cfg: &CosimConfig, first: &CosimReport) -> anyhow::Result<()> {
    let quiet = cfg.clone();
    let mut cosim_tps = vec![first.ticks_per_second()];
    for _ in 1..BENCH_RUNS {
        let again = cosim::run(verilog, &quiet)?;
        if let Some(m) = again.mismatch {
            anyhow::bail!("a repeated benchmark run mismatched: {m}");
        }
        cosim_tps.push(again.ticks_per_second());
    }
    let model_tps: Vec<f64> = (0..BENCH_RUNS)
        .map(|_| cosim::run_model_only(&quiet).ticks_per_second())
        .collect();
    let threads = first.threads.max(1) as f64;
    let (c_med, c_best) = (median(&cosim_tps), max(&cosim_tps));
    let (m_med, m_best) = (median(&model_tps), max(&model_tps));
    println!(
        "bench, co-simulation, {BENCH_RUNS} runs: median {:.1}, best {:.1} M ticks/s ({} on {}; {:.1} M ticks/s per thread, median)",
        c_med / 1e6,
        c_best / 1e6,
        count(cfg.sessions().len(), "session"),
        count(first.threads, "thread"),
        c_med / threads / 1e6
    );
    println!(
        "bench, model alone (one thread, same moves), {BENCH_RUNS} runs: median {:.1}, best {:.1} M ticks/s",
        m_med / 1e6,
        m_best / 1e6
    );
    println!(
        "bench, co-sim / model throughput ratio (medians): {:.3} all threads, {:.3} per thread",
        c_med / m_med,
        c_med / threads / m_med
    );
    Ok(())
}

/// "1 thread", "2 threads".
fn count(n: usize, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}

fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn max(xs: &[f64]) -> f64 {
    xs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}
