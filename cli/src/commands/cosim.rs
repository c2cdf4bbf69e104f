//! `snapgen cosim`: random moves on the Verilated motion core against the model, every
//! output on every clock; its report, and with `--bench` the throughputs it is measured by.

use std::io::IsTerminal;
use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use snapgen_sim::cosim::{self, CosimConfig, CosimReport, Fault};
use snapgen_sim::moves::{
    OrderMix, DEFAULT_REPLAN_SHARE, DEFAULT_STOP_SHARE, DEFAULT_STREAM_SHARE,
};

use crate::error::{split_fault, InputError, Mismatched};

/// Co-simulate random moves on the Verilated core against the model.
#[derive(clap::Args)]
pub struct Args {
    /// Moves to play.
    #[arg(long, default_value_t = 100)]
    moves: usize,
    /// Seed of the random move stream.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Planners: 2, 3, 4 or mixed.
    #[arg(long, default_value = "mixed")]
    order: OrderMix,
    /// Share of the moves given a controlled stop at a random clock (each stopping tick
    /// takes the stop unit's decision, about 140 clocks).
    #[arg(long, default_value_t = DEFAULT_STOP_SHARE)]
    stop_share: f64,
    /// Share of the other moves replanned on the way: 1 to 8 program swaps at random
    /// ticks, each planned online from the state at its tick (docs/PROTOCOL.md, SWAP_AT).
    #[arg(long, default_value_t = DEFAULT_REPLAN_SHARE)]
    replan_share: f64,
    /// Share of the moves played instead as PLCopen event streams: 3 to 12 random
    /// MC_MoveAbsolute (every buffer mode), MC_MoveVelocity, MC_Halt and override changes
    /// at random ticks, played by the host's own code through the board's command executor
    /// beside the core (docs/ONLINE.md).
    #[arg(long, default_value_t = DEFAULT_STREAM_SHARE)]
    stream_share: f64,
    /// Dump the whole run's waves to this VCD file.
    #[arg(long)]
    vcd: Option<PathBuf>,
    /// Where to write the waves around a mismatch.
    #[arg(long, default_value = "cosim-mismatch.vcd")]
    mismatch_vcd: PathBuf,
    /// Benchmark: repeat the run and the model alone 5 times each and print throughputs
    /// (median, best) and the co-sim/model ratio.
    #[arg(long, conflicts_with = "vcd")]
    bench: bool,
    /// Sessions: each its own Verilated core, model and sub-stream of moves; they run on
    /// one thread per core. The moves played depend on it [default: 16].
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=256))]
    sessions: Option<u16>,
    /// Test hook: flip BIT of REGISTER at CLOCK in the captured fabric stream
    /// ("CLOCK:REGISTER:BIT"), to show that a one-bit difference is reported.
    #[arg(long, hide = true)]
    inject_fault: Option<String>,
}

/// Runs the subcommand: exit 1 on any mismatch, planner disagreement, swap fault or
/// diverged stream.
pub fn run(a: Args) -> anyhow::Result<()> {
    let mut cfg = CosimConfig::new(a.moves, a.seed);
    if let Some(n) = a.sessions {
        cfg.session_count = usize::from(n);
    }
    cfg.mix = a.order;
    cfg.stop_share = a.stop_share;
    cfg.replan_share = a.replan_share;
    cfg.stream_share = a.stream_share;
    cfg.vcd = a.vcd;
    cfg.mismatch_vcd = a.mismatch_vcd;
    cfg.fault = a.inject_fault.map(|s| parse_fault(&s)).transpose()?;
    let r = cosim(&cfg, a.bench)?;
    if r.mismatch.is_some()
        || r.stops_not_at_rest > 0
        || r.planner_disagreements > 0
        || r.swap_faults() > 0
        || r.streams_diverged > 0
    {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn parse_fault(s: &str) -> Result<Fault, InputError> {
    let (clock, register, bit) = split_fault(s)?;
    Ok(Fault {
        clock,
        register,
        bit,
    })
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
        "controlled stops: {} ({} began outside their limits and landed within the bound, {} aborted on the way, {} timed out){}",
        r.stopped,
        r.stops_over,
        r.stops_aborted,
        r.stops_timed_out,
        if r.stops_not_at_rest > 0 {
            format!("; {} did not end at rest (must be 0)", r.stops_not_at_rest)
        } else {
            String::new()
        }
    );
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
