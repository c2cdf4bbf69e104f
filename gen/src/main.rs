//! `snapgen`: plans jerk- and snap-limited moves for the snapgen motion core, and writes traces
//! and plots from the bit-accurate model.
//!
//! Exit codes: 0 success, 1 failure (I/O), 2 bad input (a usage error or a move that cannot be
//! planned; the message says what to change).

mod args;
mod board;
mod demo;
mod fpga;
mod hw;
mod plot;
mod report;
mod send;
mod trace;
mod yosys;

use std::fs::File;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};
use snapgen_model::{plan, Plan, PlanError};

use args::{ArgError, PlanArgs};
use report::PlanReport;

/// Plans jerk- and snap-limited point-to-point moves for an FPGA motion core.
#[derive(Parser)]
#[command(name = "snapgen", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Plan a move and print it (human-readable, or one JSON object with --json).
    Plan {
        #[command(flatten)]
        plan: PlanArgs,
        /// Print one JSON object instead of the summary.
        #[arg(long)]
        json: bool,
    },
    /// Write the per-tick trace of a move from the bit-accurate model as CSV.
    Trace {
        #[command(flatten)]
        plan: PlanArgs,
        /// Output CSV file.
        #[arg(long)]
        csv: PathBuf,
        /// Write every N-th tick only (the last tick is always written).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
    },
    /// Plot position, velocity, acceleration, jerk and snap of a move as SVG.
    Plot {
        #[command(flatten)]
        plan: PlanArgs,
        /// Output SVG file.
        #[arg(long)]
        svg: PathBuf,
    },
    /// Write the motion core's Verilog (top.v) and its Verilator waivers (verilator.vlt).
    Verilog {
        /// Output directory.
        #[arg(long, default_value = "out/verilog")]
        out: PathBuf,
    },
    /// Co-simulate random moves on the Verilated core against the model, clock by clock.
    Cosim {
        /// Moves to play.
        #[arg(long, default_value_t = 100)]
        moves: usize,
        /// Seed of the random move stream.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Planners: 2, 3, 4 or mixed.
        #[arg(long, default_value = "mixed")]
        order: snapgen_sim::moves::OrderMix,
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
    },
    /// Plan a move and run it on a board over a serial port: upload, start, follow, check.
    Send {
        /// Serial device (a real board's USB-UART, or the path `snapgen board --pty` prints).
        #[arg(long)]
        port: String,
        /// Baud rate.
        #[arg(long, default_value_t = 115_200)]
        baud: u32,
        /// Reply timeout per attempt, in milliseconds.
        #[arg(long, default_value_t = 300)]
        timeout_ms: u64,
        /// Retries after a lost reply or a corrupted frame.
        #[arg(long, default_value_t = 3)]
        retries: u32,
        /// Test hook: corrupt one bit of segment K's frame on every attempt.
        #[arg(long, hide = true)]
        corrupt_segment: Option<u8>,
        /// Controlled stop this many milliseconds after the start: the cruise is cut short and
        /// the move decelerates as planned, ending short of the target.
        #[arg(long)]
        stop_after_ms: Option<u64>,
        #[command(flatten)]
        plan: PlanArgs,
    },
    /// A virtual board behind a pseudo-terminal: prints its path, then serves the protocol on
    /// the Verilated I/O top (or, with --model, on the device model) until stopped.
    Board {
        /// Open a pseudo-terminal (the only transport so far).
        #[arg(long, required = true)]
        pty: bool,
        /// Serve the device model instead of the Verilated fabric.
        #[arg(long)]
        model: bool,
        /// Simulated fabric clocks per second of wall time (Ts stays 10 µs of wall time).
        #[arg(long)]
        clocks_per_second: Option<u64>,
    },
    /// Write a board build: board top, I/O top, XDC, Vivado TCL and Makefile (--run runs it).
    Build {
        /// Board name.
        #[arg(long, default_value = "zybo-z7-10")]
        board: String,
        /// Output directory.
        #[arg(long, default_value = "out/zybo-z7-10")]
        out: PathBuf,
        /// Run the build (needs Vivado, $VIVADO or on the PATH).
        #[arg(long)]
        run: bool,
    },
    /// Synthesise the board top and the motion core with Yosys: resources, share of the device,
    /// logic-only timing; exit 1 if the motion core is over its budget.
    Synth {
        /// Board name.
        #[arg(long, default_value = "zybo-z7-10")]
        board: String,
    },
    /// Print the fixed-point format: widths, range and resolution of every register.
    Format {
        /// Tick period Ts (s).
        #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.ts, allow_hyphen_values = true)]
        ts: f64,
        /// Output position LSB (units).
        #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.position_lsb, allow_hyphen_values = true)]
        lsb: f64,
    },
    /// The main job on built-in defaults: plan the seed 001 Table 1 and Table 3 moves and a
    /// seed 000 move, print the plans, write their plots.
    Demo {
        /// Directory for the plots.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
    },
}

/// Errors that are the user's to fix (exit 2).
#[derive(Debug, thiserror::Error)]
enum InputError {
    #[error(transparent)]
    Args(#[from] ArgError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    #[error("--inject-fault {0:?}: use CLOCK:REGISTER:BIT, e.g. 1000:x:3")]
    Fault(String),
    #[error("{0}")]
    Board(String),
}

/// The co-simulation found a difference (exit 1; the report is already printed).
#[derive(Debug, thiserror::Error)]
#[error("the fabric and the model disagree")]
struct Mismatched;

fn parse_fault(s: &str) -> Result<snapgen_sim::cosim::Fault, InputError> {
    let bad = || InputError::Fault(s.to_string());
    let mut it = s.split(':');
    let (Some(c), Some(r), Some(b), None) = (it.next(), it.next(), it.next(), it.next()) else {
        return Err(bad());
    };
    Ok(snapgen_sim::cosim::Fault {
        clock: c.parse().map_err(|_| bad())?,
        register: r.parse().map_err(|_| bad())?,
        bit: b.parse().map_err(|_| bad())?,
    })
}

fn make_plan(a: &PlanArgs) -> Result<Plan, InputError> {
    let request = a.request()?;
    Ok(plan(&request, &a.format())?)
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Plan { plan, json } => {
            let p = make_plan(&plan)?;
            let r = PlanReport::new(&p);
            if json {
                println!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                print!("{}", r.human());
            }
        }
        Command::Trace { plan, csv, every } => {
            let p = make_plan(&plan)?;
            let file =
                File::create(&csv).with_context(|| format!("cannot create {}", csv.display()))?;
            let rows = trace::write_csv(&p, every, file)
                .with_context(|| format!("cannot write {}", csv.display()))?;
            eprintln!("wrote {rows} rows to {}", csv.display());
        }
        Command::Plot { plan, svg } => {
            let p = make_plan(&plan)?;
            let title = format!(
                "order {} move of {} units, {} ticks of {} s",
                p.order(),
                p.request.distance,
                p.ticks_total(),
                p.format.ts
            );
            plot::write_svg(&p, &title, &svg)
                .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", svg.display()))?;
            eprintln!("wrote {}", svg.display());
        }
        Command::Format { ts, lsb } => {
            let f = snapgen_model::Format {
                ts,
                position_lsb: lsb,
                ..snapgen_model::DEFAULT_FORMAT
            };
            f.validate()
                .map_err(PlanError::from)
                .map_err(InputError::from)?;
            print!("{}", report::format_table(&f));
        }
        Command::Verilog { out } => {
            let files = hw::write_verilog(&out)?;
            println!(
                "wrote {}, {} and {}",
                files.verilog.display(),
                files.io_top.display(),
                files.waivers.display()
            );
        }
        Command::Cosim {
            moves,
            seed,
            order,
            vcd,
            mismatch_vcd,
            bench,
            sessions,
            inject_fault,
        } => {
            let mut cfg = snapgen_sim::cosim::CosimConfig::new(moves, seed);
            if let Some(n) = sessions {
                cfg.session_count = usize::from(n);
            }
            cfg.mix = order;
            cfg.vcd = vcd;
            cfg.mismatch_vcd = mismatch_vcd;
            cfg.fault = inject_fault.map(|s| parse_fault(&s)).transpose()?;
            let r = hw::cosim(&cfg, bench)?;
            if r.mismatch.is_some() || r.planner_disagreements > 0 {
                return Err(anyhow::Error::new(Mismatched));
            }
        }
        Command::Send {
            port,
            baud,
            timeout_ms,
            retries,
            corrupt_segment,
            stop_after_ms,
            plan,
        } => {
            let request = plan.request()?;
            let format = plan.format();
            let opts = send::SendOptions {
                port,
                baud,
                timeout: std::time::Duration::from_millis(timeout_ms),
                retries,
                corrupt_segment,
                stop_after: stop_after_ms.map(std::time::Duration::from_millis),
            };
            let r = match send::send(&request, &format, &opts) {
                Ok(r) => r,
                Err(send::SendFailure::Plan(e)) => return Err(InputError::from(e).into()),
                Err(send::SendFailure::Link(e)) => return Err(e.into()),
            };
            println!(
                "moved {} units{} in {} ticks: now at {} LSB = {:.*} units, encoder {} counts; the position register matches the plan bit for bit",
                r.plan.request.distance,
                if u64::from(r.status.tick_count) < r.plan.ticks_total() {
                    " (controlled stop: cruise cut short)"
                } else {
                    ""
                },
                r.status.tick_count,
                r.status.position,
                (-format.position_lsb.log10()).ceil().max(0.0) as usize,
                f64::from(r.status.position) * format.position_lsb,
                r.status.encoder
            );
        }
        Command::Board {
            pty: _,
            model,
            clocks_per_second,
        } => board::run(board::BoardOptions {
            clocks_per_second: clocks_per_second.unwrap_or(if model { 100_000 } else { 1_000_000 }),
            fabric: !model,
        })?,
        Command::Build { board, out, run } => {
            let b = fpga::board(&board).map_err(|e| InputError::Board(e.to_string()))?;
            let plan = fpga::build_plan(&b);
            for f in plan.write(&out)? {
                println!("wrote {}", f.display());
            }
            if run {
                plan.run(&out)?;
            } else {
                println!("run it with: make -C {} (needs Vivado)", out.display());
            }
        }
        Command::Synth { board } => {
            let b = fpga::board(&board).map_err(|e| InputError::Board(e.to_string()))?;
            let r = fpga::synth(&b)?;
            print!("{}", r.table());
            let v = r.violations();
            if !v.is_empty() {
                anyhow::bail!("over budget: {}", v.join("; "));
            }
            println!("motion core within budget");
        }
        Command::Demo { out } => demo::run(&out)?,
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
