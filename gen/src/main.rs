//! `snapgen`: plans jerk- and snap-limited moves for the snapgen motion core, and writes traces
//! and plots from the bit-accurate model.
//!
//! Exit codes: 0 success, 1 failure (I/O), 2 bad input (a usage error or a move that cannot be
//! planned; the message says what to change).

mod args;
mod board;
mod board_spec;
mod demo;
mod experiment;
mod fpga;
mod hw;
mod online;
mod plot;
mod report;
mod scenario;
mod send;
mod trace;
mod yosys;

use std::fs::File;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};
use snapgen_plan::{plan, Plan, PlanError};

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
    /// Write the motion core (snapgen_core.v) and the I/O top (snapgen_io.v, which instantiates
    /// snapgen_core) as Verilog, each with its lint waivers written in it.
    Verilog {
        /// Output directory.
        #[arg(long, default_value = "out/verilog")]
        out: PathBuf,
        #[command(flatten)]
        timing: TimingArgs,
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
        /// Share of the moves given a controlled stop at a random clock (each stopping tick
        /// takes the stop unit's decision, about 130 clocks).
        #[arg(long, default_value_t = snapgen_sim::moves::DEFAULT_STOP_SHARE)]
        stop_share: f64,
        /// Share of the other moves replanned on the way: 1 to 8 program swaps at random
        /// ticks, each planned online from the state at its tick (docs/PROTOCOL.md, SWAP_AT).
        #[arg(long, default_value_t = snapgen_sim::moves::DEFAULT_REPLAN_SHARE)]
        replan_share: f64,
        /// Share of the moves played instead as PLCopen event streams: 3 to 12 random
        /// MC_MoveAbsolute (every buffer mode), MC_MoveVelocity, MC_Halt and override changes
        /// at random ticks, each change planned and its swap led by the host axis's driver over
        /// the core's ports (docs/ONLINE.md).
        #[arg(long, default_value_t = snapgen_sim::moves::DEFAULT_STREAM_SHARE)]
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
    },
    /// Co-simulate the I/O top (UART command interface, motion core, encoder, PWM, limit
    /// switches, emergency stop) against the device model, every output on every clock, under
    /// random command streams; exit 1 on any mismatch (the waves around it are written).
    CosimIo {
        /// Clocks per session.
        #[arg(long, default_value_t = 1_000_000)]
        clocks: u64,
        /// Seed of session 0's stream (the others derive theirs from it).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Sessions, each its own Verilated I/O top, model and stream, on one thread per core.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=256))]
        sessions: u16,
        /// Where to write the waves around a mismatch.
        #[arg(long, default_value = "io-mismatch.vcd")]
        mismatch_vcd: PathBuf,
        /// Test hook: flip BIT of SIGNAL (a pin, or status.FIELD) at CLOCK in session 0's
        /// captured fabric outputs ("CLOCK:SIGNAL:BIT").
        #[arg(long, hide = true)]
        inject_fault: Option<String>,
    },
    /// Play a timed script of PLCopen commands (MC_MoveAbsolute with its buffer modes,
    /// MC_MoveVelocity, MC_Halt, the feed override) through the host axis on a board: every
    /// change planned from the exact state at a swap tick ahead of the link's latency and
    /// swapped in there; every state read checked bit for bit against the plan
    /// (docs/ONLINE.md).
    Online {
        /// The script (TOML, docs/ONLINE.md).
        #[arg(
            long,
            conflicts_with = "scenario",
            required_unless_present = "scenario"
        )]
        script: Option<PathBuf>,
        /// A built-in scenario instead of a script.
        #[arg(long, value_enum)]
        scenario: Option<scenario::Scenario>,
        /// The scenario's jerk (unit/s³) [seed002: 50000].
        #[arg(long, requires = "scenario")]
        jerk: Option<f64>,
        /// The virtual board: the device model, or the Verilated I/O top with the device model
        /// in lockstep (every output compared on every clock).
        #[arg(long, value_enum, default_value = "model", conflicts_with = "port")]
        board: online::BoardKind,
        /// A real board's serial port instead of a virtual board.
        #[arg(long)]
        port: Option<String>,
        /// Baud rate: the virtual board's UART (its design) or the port's.
        #[arg(long, default_value_t = 115_200)]
        baud: u32,
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
    },
    /// Plan a move and run it on a board over a serial port: read the board's identity, plan
    /// with its Ts and format from its exact registers, configure (read back), upload, start,
    /// follow, and check the end bit for bit.
    Send {
        /// Serial device (a real board's USB-UART, or the path `snapgen board --pty` prints).
        #[arg(long)]
        port: String,
        /// Baud rate.
        #[arg(long, default_value_t = 115_200)]
        baud: u32,
        /// Reply timeout per attempt, in milliseconds (above the board's 20 ms inter-byte
        /// timeout and a frame's airtime).
        #[arg(long, default_value_t = 300)]
        timeout_ms: u64,
        /// Retries after a lost reply or a corrupted frame.
        #[arg(long, default_value_t = 3)]
        retries: u32,
        /// Test hook: corrupt one bit of segment K's frame on every attempt.
        #[arg(long, hide = true)]
        corrupt_segment: Option<u8>,
        /// Controlled stop (STOP) this many milliseconds after the start: the board brings the
        /// axis to rest within the stop limits; the end is checked against the model's stop.
        #[arg(long)]
        stop_after_ms: Option<u64>,
        /// The stop's deceleration limit, units/s² [default: the move's peak acceleration].
        #[arg(long)]
        stop_decel: Option<f64>,
        /// The stop's jerk limit, units/s³ [default: the move's peak jerk].
        #[arg(long)]
        stop_jerk: Option<f64>,
        /// Reset an axis found in ErrorStop (after its cause is removed) before the move.
        #[arg(long)]
        reset: bool,
        /// The board's host watchdog, in milliseconds (written and read back): a moving axis
        /// that hears nothing from the host for this long stops by itself. 0 turns it off.
        #[arg(long, default_value_t = snapgen_spec::Param::WatchdogMs.spec().reset_value(0) as u32)]
        watchdog_ms: u32,
        /// The axis drives a motor: configure the board's controller for it (gains derived
        /// from the plant, docs/PLANT.md) and report the following error and the settling.
        /// `--motor` (or `--motor default`) for the default motor, `--motor FILE` for a plant
        /// file.
        #[arg(long, num_args = 0..=1, default_missing_value = "default")]
        motor: Option<PathBuf>,
        /// The settling band: the move has settled when |position − encoder| stays within this
        /// many output LSBs (encoder counts).
        #[arg(long, default_value_t = 2)]
        settle_lsb: u32,
        #[command(flatten)]
        servo: ServoArgs,
        #[command(flatten)]
        plan: PlanArgs,
    },
    /// Stop the axis from the host (MC_Stop; --halt: MC_Halt): the board brings it to rest by
    /// itself, within its stop limits; this waits for it and prints where it stands.
    Stop {
        /// Serial device.
        #[arg(long)]
        port: String,
        /// Baud rate.
        #[arg(long, default_value_t = 115_200)]
        baud: u32,
        /// HALT instead of STOP: the axis stays in its motion state until at rest.
        #[arg(long)]
        halt: bool,
        /// Reply timeout per attempt, in milliseconds.
        #[arg(long, default_value_t = 300)]
        timeout_ms: u64,
        /// Retries after a lost reply.
        #[arg(long, default_value_t = 3)]
        retries: u32,
    },
    /// A virtual board behind a pseudo-terminal: prints its path, then serves the protocol on
    /// the Verilated I/O top (or, with --model, on the device model) in real time until
    /// stopped. Default design: 1.5 MHz clock, 115 200 baud, Ts = 100 µs.
    Board {
        /// Open a pseudo-terminal (the only transport so far).
        #[arg(long, required = true)]
        pty: bool,
        /// Serve the device model instead of the Verilated fabric.
        #[arg(long)]
        model: bool,
        /// The virtual board's clock in Hz (it must run in real time: a few MHz at most).
        #[arg(long, default_value_t = board::VIRTUAL_CLOCK_HZ)]
        clock_hz: f64,
        /// UART baud rate (8N1).
        #[arg(long, default_value_t = snapgen_model::timing::DEFAULT_BAUD)]
        baud: u32,
        /// Tick period Ts after reset, in seconds (a whole number of clocks).
        #[arg(long, default_value_t = board::VIRTUAL_TS)]
        ts: f64,
        /// A simulated motor on the board's PWM and encoder instead of the ideal follower:
        /// `--motor` (or `--motor default`) for the default one, `--motor FILE` for a plant
        /// file (docs/PLANT.md).
        #[arg(long, num_args = 0..=1, default_missing_value = "default")]
        motor: Option<PathBuf>,
    },
    /// Write a board build: board top, I/O top, XDC, Vivado TCL and Makefile (--run runs it).
    Build {
        #[command(flatten)]
        board: BoardArgs,
        /// Output directory [default: out/BOARD].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run the build (needs Vivado, $VIVADO or on the PATH).
        #[arg(long)]
        run: bool,
        #[command(flatten)]
        timing: TimingArgs,
    },
    /// Synthesise the board top and the motion core with Yosys: resources, share of the device,
    /// logic-only timing; exit 1 if the motion core is over its budget.
    Synth {
        #[command(flatten)]
        board: BoardArgs,
        #[command(flatten)]
        timing: TimingArgs,
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
    /// Seed 001's experiment on the closed loop: Table 1's move as the S-curve, the 32 rad/s
    /// trapezoid and an order-4 profile of the same duration, and Table 3's return, on a
    /// simulated motor, with the controller in the fabric and at the seed's 5 ms host-loop
    /// rate; the figures beside the paper's, SVG plots, --json.
    Experiment {
        /// Which experiment.
        #[arg(value_enum)]
        which: ExperimentName,
        /// Where the loop runs: the Verilated I/O top with the device model in lockstep, the
        /// device model, or the fast model-only loop.
        #[arg(long, value_enum, default_value = "fabric")]
        board: experiment::Board,
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
        /// Directory for the SVG plots.
        #[arg(long, default_value = "out/seed001")]
        out: PathBuf,
        /// Only the S-curve and the trapezoid, watched 0.5 s after their end.
        #[arg(long)]
        short: bool,
        /// Leave out the 5 ms host-loop runs.
        #[arg(long)]
        no_host_loop: bool,
        /// The fabric clock (Hz).
        #[arg(long, default_value_t = experiment::EXPERIMENT_CLOCK_HZ)]
        clock_hz: f64,
        /// Tick period Ts (s).
        #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.ts)]
        ts: f64,
        /// The plant's integration step (µs).
        #[arg(long, default_value_t = 1.0)]
        step_us: f64,
        #[command(flatten)]
        motor: MotorArgs,
        #[command(flatten)]
        servo: ServoArgs,
    },
    /// The controller's gains for a motor (pole placement at a bandwidth and damping on the
    /// plant's model, docs/PLANT.md): in volts and radians, in PWM clocks and counts, and the
    /// integers CONFIGURE writes.
    Gains {
        #[command(flatten)]
        motor: MotorArgs,
        #[command(flatten)]
        servo: ServoArgs,
        /// The fabric clock (Hz).
        #[arg(long, default_value_t = experiment::EXPERIMENT_CLOCK_HZ)]
        clock_hz: f64,
        /// Tick period Ts (s).
        #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.ts)]
        ts: f64,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// The main job on built-in defaults: plan the seed 001 Table 1 and Table 3 moves and a
    /// seed 000 move, print the plans and write their plots; generate the Verilog, co-simulate
    /// the core and the I/O top against the model, synthesise with Yosys; run seed 001's
    /// experiment (short form) on the closed loop. Needs Verilator and Yosys
    /// (`./scripts/demo.sh` installs them).
    Demo {
        /// Directory for the plots.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
    },
}

/// Which experiment.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum ExperimentName {
    /// Seed 001, sections 3 and 4.
    Seed001,
}

/// The plant: a motor file, or the default one.
#[derive(clap::Args, Debug, Clone)]
struct MotorArgs {
    /// A plant file (TOML, docs/PLANT.md) [default: plant/motors/re40-148877.toml, built in].
    #[arg(long)]
    motor: Option<PathBuf>,
}

impl MotorArgs {
    fn load(&self) -> Result<snapgen_plant::PlantParams, InputError> {
        match &self.motor {
            Some(f) => snapgen_plant::PlantParams::from_file(f)
                .map_err(|e| InputError::Board(e.to_string())),
            None => Ok(snapgen_plant::PlantParams::default_plant()),
        }
    }
}

/// The controller's rate and design.
#[derive(clap::Args, Debug, Clone)]
struct ServoArgs {
    /// The controller's sample rate (Hz): SERVO_PERIOD = 1 / (rate · Ts) ticks.
    #[arg(long, default_value_t = 10_000.0)]
    loop_hz: f64,
    /// PWM frequency (Hz): PWM_PERIOD = clock / rate.
    #[arg(long, default_value_t = 20_000.0)]
    pwm_hz: f64,
    /// Closed-loop bandwidth (Hz), at most a twentieth of the sample rate.
    #[arg(long, default_value_t = snapgen_plant::gains::LoopDesign::default().bandwidth_hz)]
    bandwidth_hz: f64,
    /// Damping of the complex pole pair.
    #[arg(long, default_value_t = snapgen_plant::gains::LoopDesign::default().damping)]
    damping: f64,
    /// No velocity and acceleration feed-forward (the seed's controller had none).
    #[arg(long)]
    no_feed_forward: bool,
    /// Following-error limit (rad): beyond it the amplifier goes off (FOLLOWING_ERROR).
    #[arg(long, default_value_t = snapgen_plant::gains::LoopDesign::default().following_limit_rad)]
    following_limit_rad: f64,
}

impl ServoArgs {
    fn design(&self) -> snapgen_plant::gains::LoopDesign {
        snapgen_plant::gains::LoopDesign {
            bandwidth_hz: self.bandwidth_hz,
            damping: self.damping,
            feed_forward: !self.no_feed_forward,
            following_limit_rad: self.following_limit_rad,
            ..Default::default()
        }
    }

    /// The loop's timing at `clock_hz` and `ts`, checked.
    fn timing(
        &self,
        clock_hz: f64,
        ts: f64,
    ) -> Result<snapgen_plant::gains::LoopTiming, InputError> {
        let bad = |m: String| Err(InputError::Board(m));
        if !(ts.is_finite() && ts > 0.0) {
            return bad(format!("--ts {ts}: give a positive tick period in seconds"));
        }
        let ticks = (1.0 / (self.loop_hz * ts)).round();
        if !(self.loop_hz.is_finite() && self.loop_hz > 0.0 && (1.0..=65535.0).contains(&ticks)) {
            return bad(format!(
                "--loop-hz {}: at Ts {ts} s that is {ticks} ticks per sample; give a rate of 1 to 65 535 ticks",
                self.loop_hz
            ));
        }
        let clocks = (clock_hz / self.pwm_hz).round();
        if !(self.pwm_hz.is_finite() && self.pwm_hz > 0.0 && (2.0..=32767.0).contains(&clocks)) {
            return bad(format!(
                "--pwm-hz {}: at {clock_hz} Hz that is {clocks} clocks per period; give a rate with 2 to 32 767",
                self.pwm_hz
            ));
        }
        Ok(snapgen_plant::gains::LoopTiming {
            ts,
            servo_period: ticks as u16,
            pwm_period: clocks as u16,
        })
    }
}

/// The fabric's clock, UART baud rate and tick period (docs/HDL.md, "Timing").
#[derive(clap::Args, Debug, Clone)]
struct TimingArgs {
    /// Fabric clock frequency in Hz [default: the board's oscillator, or 125e6].
    #[arg(long)]
    clock_hz: Option<f64>,
    /// UART baud rate (8N1).
    #[arg(long, default_value_t = snapgen_model::timing::DEFAULT_BAUD)]
    baud: u32,
    /// Tick period Ts after reset, in seconds (a whole number of clocks).
    #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.ts)]
    ts: f64,
}

impl TimingArgs {
    /// The timing, with the clock of `board` unless `--clock-hz` says otherwise; checked.
    fn resolve(
        &self,
        board_clock_hz: Option<u64>,
        input_polarity: u8,
    ) -> Result<(snapgen_model::timing::Timing, snapgen_model::device::Design), InputError> {
        let clock_hz = match self.clock_hz {
            Some(f) if !(f.is_finite() && f >= 1.0 && f.fract() == 0.0 && f < 1e12) => {
                return Err(InputError::Board(format!(
                    "--clock-hz {f}: give a whole number of Hz, e.g. 125e6"
                )))
            }
            Some(f) => f as u64,
            None => board_clock_hz.unwrap_or(snapgen_model::timing::DEFAULT_CLOCK_HZ),
        };
        let t = snapgen_model::timing::Timing {
            clock_hz,
            baud: self.baud,
            ts: self.ts,
        };
        let mut d = snapgen_model::device::Design::from_timing(&snapgen_model::DEFAULT_FORMAT, &t)
            .map_err(|e| InputError::Board(e.to_string()))?;
        d.input_polarity = input_polarity;
        Ok((t, snapgen_hdl::verilog::io_design(&d)))
    }
}

/// Which board: a built-in one by name, or a user's description.
#[derive(clap::Args, Debug, Clone)]
struct BoardArgs {
    /// Built-in board name.
    #[arg(long, default_value = "zybo-z7-10", conflicts_with = "board_file")]
    board: String,
    /// A board description of your own (TOML, schema in docs/BOARDS.md).
    #[arg(long)]
    board_file: Option<PathBuf>,
}

impl BoardArgs {
    fn load(&self) -> Result<board_spec::Board, InputError> {
        match &self.board_file {
            Some(f) => board_spec::from_file(f),
            None => board_spec::builtin(&self.board),
        }
        .map_err(|e| InputError::Board(e.to_string()))
    }
}

/// Errors that are the user's to fix (exit 2).
#[derive(Debug, thiserror::Error)]
enum InputError {
    #[error(transparent)]
    Args(#[from] ArgError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    #[error("--inject-fault {0:?}: use CLOCK:NAME:BIT, e.g. 1000:x:3 (cosim) or 1000:status.flags:3 (cosim-io)")]
    Fault(String),
    #[error("{0}")]
    Board(String),
    #[error(transparent)]
    Host(snapgen_host::session::InputError),
    #[error("{0:#}")]
    Script(anyhow::Error),
}

/// A host failure: the user's input (exit 2) or the link and the board (exit 1).
fn failure(f: snapgen_host::session::Failure) -> anyhow::Error {
    match f {
        snapgen_host::session::Failure::Input(e) => InputError::Host(e).into(),
        snapgen_host::session::Failure::Host(e) => e.into(),
    }
}

/// The co-simulation found a difference (exit 1; the report is already printed).
#[derive(Debug, thiserror::Error)]
#[error("the fabric and the model disagree")]
struct Mismatched;

/// `CLOCK:NAME:BIT`, the form of both co-simulations' `--inject-fault`.
fn split_fault<T: std::str::FromStr>(s: &str) -> Result<(u64, T, u32), InputError> {
    let bad = || InputError::Fault(s.to_string());
    let mut it = s.split(':');
    let (Some(c), Some(name), Some(b), None) = (it.next(), it.next(), it.next(), it.next()) else {
        return Err(bad());
    };
    Ok((
        c.parse().map_err(|_| bad())?,
        name.parse().map_err(|_| bad())?,
        b.parse().map_err(|_| bad())?,
    ))
}

fn parse_fault(s: &str) -> Result<snapgen_sim::cosim::Fault, InputError> {
    let (clock, register, bit) = split_fault(s)?;
    Ok(snapgen_sim::cosim::Fault {
        clock,
        register,
        bit,
    })
}

fn parse_io_fault(s: &str) -> Result<snapgen_sim::io_cosim::IoFault, InputError> {
    let (clock, signal, bit) = split_fault(s)?;
    Ok(snapgen_sim::io_cosim::IoFault { clock, signal, bit })
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
        Command::Verilog { out, timing } => {
            let (t, d) = timing.resolve(None, 0)?;
            let files = hw::write_verilog(&out, &d)?;
            println!(
                "wrote {} and {} (clock {} Hz, {} baud = {} clocks per bit ({} baud), Ts {} s = {} clocks, design hash {:#010x})",
                files.core.display(),
                files.io_top.display(),
                t.clock_hz,
                t.baud,
                d.dividers.uart_divisor,
                d.baud,
                t.ts,
                u64::from(d.dividers.tick_div) + 1,
                d.design_hash
            );
        }
        Command::Cosim {
            moves,
            seed,
            order,
            stop_share,
            replan_share,
            stream_share,
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
            cfg.stop_share = stop_share;
            cfg.replan_share = replan_share;
            cfg.stream_share = stream_share;
            cfg.vcd = vcd;
            cfg.mismatch_vcd = mismatch_vcd;
            cfg.fault = inject_fault.map(|s| parse_fault(&s)).transpose()?;
            let r = hw::cosim(&cfg, bench)?;
            if r.mismatch.is_some()
                || r.planner_disagreements > 0
                || r.swap_faults() > 0
                || r.streams_diverged > 0
            {
                return Err(anyhow::Error::new(Mismatched));
            }
        }
        Command::CosimIo {
            clocks,
            seed,
            sessions,
            mismatch_vcd,
            inject_fault,
        } => {
            let mut cfg =
                snapgen_sim::io_cosim::IoCosimConfig::new(clocks, seed, usize::from(sessions));
            cfg.mismatch_vcd = mismatch_vcd;
            cfg.fault = inject_fault.map(|s| parse_io_fault(&s)).transpose()?;
            let design = snapgen_sim::io_cosim::cosim_design();
            let r = snapgen_sim::io_cosim::run(&design, &cfg)?;
            println!("I/O co-simulation: {}", snapgen_sim::io_cosim::describe(&r));
            println!(
                "{} mismatches; {:.2} M clocks/s ({:.2} s, {} sessions)",
                u32::from(r.mismatch.is_some()),
                r.clocks_per_second() / 1e6,
                r.seconds,
                sessions
            );
            if let Some(m) = &r.mismatch {
                println!("{m}");
                if let Some(v) = &r.vcd {
                    println!("waves: {}", v.display());
                }
                return Err(anyhow::Error::new(Mismatched));
            }
        }
        Command::Online {
            script,
            scenario,
            jerk,
            board,
            port,
            baud,
            csv,
            svg,
            json,
        } => {
            let (script, title) = match (script, scenario) {
                (Some(path), _) => {
                    let title = format!("snapgen online {}", path.display());
                    (
                        online::Script::read(&path).map_err(InputError::Script)?,
                        title,
                    )
                }
                (None, Some(s)) => (s.script(jerk).map_err(InputError::Script)?, s.title(jerk)),
                (None, None) => anyhow::bail!("give --script FILE or --scenario NAME"),
            };
            let target = online::Target { board, port, baud };
            let played = online::play(script, &target)?;
            if json {
                println!("{}", online::json(&played));
            } else {
                println!("{title}\n{}", online::describe(&played));
            }
            if let Some(path) = csv {
                online::write_csv(&played, &path)?;
            }
            if let Some(path) = svg {
                online::write_svg(&played, &title, &path)?;
            }
            if played.mismatches.unwrap_or(0) > 0 {
                anyhow::bail!("the fabric and the model disagree");
            }
        }
        Command::Send {
            port,
            baud,
            timeout_ms,
            retries,
            corrupt_segment,
            stop_after_ms,
            stop_decel,
            stop_jerk,
            reset,
            watchdog_ms,
            motor,
            settle_lsb,
            servo,
            plan,
        } => {
            let request = plan.request()?;
            let motor = match motor {
                None => None,
                Some(f) if f.as_os_str() == "default" => {
                    Some(snapgen_plant::PlantParams::default_plant())
                }
                Some(f) => Some(
                    snapgen_plant::PlantParams::from_file(&f)
                        .map_err(|e| InputError::Board(e.to_string()))?,
                ),
            };
            let lsb = plan.lsb.unwrap_or_else(|| {
                motor
                    .as_ref()
                    .map_or(snapgen_model::DEFAULT_FORMAT.position_lsb, |m| {
                        m.physical().rad_per_count()
                    })
            });
            let policy = snapgen_host::link::RetryPolicy {
                timeout: timeout_ms as f64 / 1e3,
                retries,
                ..Default::default()
            };
            let mut session = send::open(&port, baud, policy, lsb).map_err(failure)?;
            session.link.corrupt_segment(corrupt_segment);
            snapgen_host::send::check_ts(&session, plan.ts).map_err(InputError::Host)?;
            let servo = match motor {
                Some(m) => Some(
                    send::servo_setup(
                        &session,
                        &send::MotorOptions {
                            plant: m,
                            design: servo.design(),
                            loop_hz: servo.loop_hz,
                            pwm_hz: servo.pwm_hz,
                        },
                    )
                    .map_err(InputError::Host)?,
                ),
                None => None,
            };
            let opts = snapgen_host::send::SendOptions {
                ts: plan.ts,
                stop_decel,
                stop_jerk,
                reset,
                watchdog_ms,
                servo,
                settle_lsb,
                stop_after: stop_after_ms.map(|ms| ms as f64 / 1e3),
            };
            let r =
                snapgen_host::send::send_move(&mut session, &request, &opts, &mut send::Bar::new())
                    .map_err(failure)?;
            print!("{}", send::describe(&r, &session.identity));
        }
        Command::Stop {
            port,
            baud,
            halt,
            timeout_ms,
            retries,
        } => {
            let policy = snapgen_host::link::RetryPolicy {
                timeout: timeout_ms as f64 / 1e3,
                retries,
                ..Default::default()
            };
            let mut session = send::open(
                &port,
                baud,
                policy,
                snapgen_model::DEFAULT_FORMAT.position_lsb,
            )
            .map_err(failure)?;
            let r = snapgen_host::send::stop_axis(&mut session, halt).map_err(failure)?;
            println!(
                "{} from {}: now {} at rest (x {:#x}, v = a = j = 0) after {} ticks{}",
                if halt { "HALT" } else { "STOP" },
                r.before.name(),
                r.status.axis().map_or("?", |a| a.name()),
                r.state.x,
                r.status.tick_count,
                if r.status.has(snapgen_host::protocol::flag::STOP_OVER_LIMITS) {
                    "; the stop left its limits on some tick (it began outside them; it landed exactly)"
                } else {
                    ""
                }
            );
        }
        Command::Board {
            pty: _,
            model,
            clock_hz,
            baud,
            ts,
            motor,
        } => {
            let timing = TimingArgs {
                clock_hz: Some(clock_hz),
                baud,
                ts,
            };
            let (_, design) = timing.resolve(None, 0)?;
            let motor = match motor {
                None => None,
                Some(f) if f.as_os_str() == "default" => {
                    Some(snapgen_plant::PlantParams::default_plant())
                }
                Some(f) => Some(
                    snapgen_plant::PlantParams::from_file(&f)
                        .map_err(|e| InputError::Board(e.to_string()))?,
                ),
            };
            board::run(board::BoardOptions {
                design,
                fabric: !model,
                motor,
            })?
        }
        Command::Build {
            board,
            out,
            run,
            timing,
        } => {
            let b = board.load()?;
            let (t, d) = timing.resolve(Some(b.clock.frequency_hz), b.input_polarity)?;
            let out = out.unwrap_or_else(|| PathBuf::from("out").join(&b.name));
            let plan = fpga::build_plan(&b, &t, &d);
            for f in plan.write(&out)? {
                println!("wrote {}", f.display());
            }
            if run {
                plan.run(&out)?;
            } else {
                println!("run it with: make -C {} (needs Vivado)", out.display());
            }
        }
        Command::Synth { board, timing } => {
            let b = board.load()?;
            let (t, d) = timing.resolve(Some(b.clock.frequency_hz), b.input_polarity)?;
            let r = fpga::synth(&b, &t, &d)?;
            print!("{}", r.table());
            let v = r.violations();
            if !v.is_empty() {
                anyhow::bail!("over budget: {}", v.join("; "));
            }
            println!("motion core within budget");
        }
        Command::Experiment {
            which: ExperimentName::Seed001,
            board,
            json,
            out,
            short,
            no_host_loop,
            clock_hz,
            ts,
            step_us,
            motor,
            servo,
        } => {
            let plant = motor.load()?;
            let t = servo.timing(clock_hz, ts)?;
            if !(step_us.is_finite() && step_us > 0.0) {
                return Err(InputError::Board(format!(
                    "--step-us {step_us}: give a positive step in µs"
                ))
                .into());
            }
            let o = experiment::Options {
                board,
                plant,
                clock_hz,
                ts,
                pwm_hz: clock_hz / f64::from(t.pwm_period),
                loop_hz: 1.0 / (f64::from(t.servo_period) * ts),
                design: servo.design(),
                host_loop: !no_host_loop,
                short,
                step_s: step_us * 1e-6,
                out: Some(out),
            };
            let r = experiment::run(&o)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                print!("{}", experiment::table(&r));
            }
            if r.mismatches.is_some_and(|m| m > 0) {
                return Err(anyhow::Error::new(Mismatched));
            }
        }
        Command::Gains {
            motor,
            servo,
            clock_hz,
            ts,
            json,
        } => {
            let plant = motor.load()?;
            let t = servo.timing(clock_hz, ts)?;
            let g = snapgen_plant::gains::derive(&plant.physical(), &servo.design(), &t)
                .map_err(|e| InputError::Board(e.to_string()))?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&experiment::gains_json(&plant, &t, &g))?
                );
            } else {
                print!("{}", experiment::gains_text(&plant, &t, &g));
            }
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
