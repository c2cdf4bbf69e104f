//! `snapgen`: plans jerk- and snap-limited moves for the snapgen motion core, writes its
//! Verilog and the contract's files, co-simulates the fabric against the bit-accurate model,
//! and drives boards (real or virtual) as a host. Each subcommand lives in its own file under
//! `commands/`; the arguments several share are in `args`.
//!
//! Exit codes: 0 success, 1 failure (I/O, a board, a mismatch), 2 bad input (a usage error or
//! a move that cannot be planned; the message says what to change).

mod args;
mod board_spec;
mod commands;
mod ecp5;
mod error;
mod fpga;
mod report;
mod scenario;
mod svg;
mod xc7;
mod yosys;
mod zynq;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::*;
use error::InputError;

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
    Plan(plan::Args),
    /// Write the per-tick trace of a move from the bit-accurate model as CSV.
    Trace(trace::Args),
    /// Plot position, velocity, acceleration, jerk and snap of a move as SVG.
    Plot(plot::Args),
    /// Write the motion core (snapgen_core.v) and the I/O top (snapgen_io.v, which instantiates
    /// snapgen_core) as Verilog, each with its lint waivers written in it.
    Verilog(verilog::Args),
    /// Write the contract between host and board (codes, layouts, parameters, rules, ports)
    /// for your firmware and tools: a C header, a JSON description and the protocol's tables
    /// (--emit DIR), or bring docs/PROTOCOL.md's generated blocks up to date (--update-docs).
    Spec(spec::Args),
    /// Co-simulate random moves on the Verilated core against the model, clock by clock.
    Cosim(cosim::Args),
    /// Co-simulate the I/O top (UART command interface, motion core, encoder, PWM, limit
    /// switches, emergency stop) against the device model, every output on every clock, under
    /// random command streams; exit 1 on any mismatch (the waves around it are written).
    CosimIo(cosim_io::Args),
    /// Co-simulate the AXI4-Lite top (issue 23: the station behind an AXI4-Lite slave)
    /// against its model, every output on every clock, under random AXI traffic with random
    /// back-pressure, the handshake rules checked on the fabric's outputs; exit 1 on any
    /// mismatch or broken rule.
    CosimAxi(cosim_axi::Args),
    /// Co-simulate the path interpolator (issue 22: a distance into a line or arc becomes
    /// each axis's position) against its model, every output on every clock, under random
    /// segments from the path planner; exit 1 on any mismatch.
    CosimInterp(cosim_interp::Args),
    /// Co-simulate the path core (issue 22: the motion core on the path length driving a
    /// step/dir generator per axis through the path sequencer and the interpolator) against
    /// its model, every output on every clock, under random paths, moves and group stops;
    /// exit 1 on any mismatch or a drive's count that breaks the rule.
    CosimPathCore(cosim_path_core::Args),
    /// Play a timed script of PLCopen commands (MC_MoveAbsolute with its buffer modes,
    /// MC_MoveVelocity, MC_Halt, the feed override) through the host axis on a board: every
    /// change planned from the exact state at a swap tick ahead of the link's latency and
    /// swapped in there; every state read checked bit for bit against the plan
    /// (docs/ONLINE.md).
    Online(online::Args),
    /// Play a G-code program (G0-G3 lines, arcs and helices) along its path on the
    /// bit-accurate model, each block an exact stop, and check from the axes' positions that
    /// it stays on the path and every axis within its limits on every tick.
    Path(path::Args),
    /// Plan a move and run it on a board over a serial port: read the board's identity, plan
    /// with its Ts and format from its exact registers, configure (read back), upload, start,
    /// follow, and check the end bit for bit.
    Send(send::Args),
    /// Stop the axis from the host (MC_Stop; --halt: MC_Halt): the board brings it to rest by
    /// itself, within its stop limits; this waits for it and prints where it stands.
    Stop(stop::Args),
    /// A virtual board behind a pseudo-terminal: prints its path, then serves the protocol on
    /// the Verilated I/O top (or, with --model, on the device model) in real time until
    /// stopped. Default design: 1.5 MHz clock, 115 200 baud, Ts = 100 µs.
    Board(board::Args),
    /// Write a board build: board top, I/O top, XDC, Vivado TCL and Makefile (--run runs it).
    Build(build::Args),
    /// Synthesise the board top and the motion core with Yosys: resources, share of the device,
    /// logic-only timing; exit 1 if the motion core is over its budget.
    Synth(synth::Args),
    /// Print the fixed-point format: widths, range and resolution of every register.
    Format(format::Args),
    /// Seed 001's experiment on the closed loop: Table 1's move as the S-curve, the 32 rad/s
    /// trapezoid and an order-4 profile of the same duration, and Table 3's return, on a
    /// simulated motor, with the controller in the fabric and at the seed's 5 ms host-loop
    /// rate; the figures beside the paper's, SVG plots, --json.
    Experiment(experiment::Args),
    /// The controller's gains for a motor (pole placement at a bandwidth and damping on the
    /// plant's model, docs/PLANT.md): in volts and radians, in PWM clocks and counts, and the
    /// integers CONFIGURE writes.
    Gains(gains::Args),
    /// Identify the motor and its load on a board: a bounded excitation through the fabric's
    /// loop (following-error limit armed), recorded by TELEMETRY, fitted (speed per volt,
    /// time constant, Coulomb friction, the dead time's loss); writes a plant file and prints
    /// the gains for it. On --port/--uio, or the virtual board around --plant/--mismatch.
    Identify(identify::Args),
    /// The main job on built-in defaults: plan the seed 001 Table 1 and Table 3 moves and a
    /// seed 000 move, print the plans and write their plots; generate the Verilog, co-simulate
    /// the core and the I/O top against the model, synthesise with Yosys; run seed 001's
    /// experiment (short form) on the closed loop. Needs Verilator and Yosys
    /// (`./scripts/demo.sh` installs them).
    Demo(demo::Args),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Plan(a) => plan::run(a),
        Command::Path(a) => path::run(a),
        Command::Trace(a) => trace::run(a),
        Command::Plot(a) => plot::run(a),
        Command::Verilog(a) => verilog::run(a),
        Command::Spec(a) => spec::run(a),
        Command::Cosim(a) => cosim::run(a),
        Command::CosimIo(a) => cosim_io::run(a),
        Command::CosimAxi(a) => cosim_axi::run(a),
        Command::CosimInterp(a) => cosim_interp::run(a),
        Command::CosimPathCore(a) => cosim_path_core::run(a),
        Command::Online(a) => online::run(a),
        Command::Send(a) => send::run(a),
        Command::Stop(a) => stop::run(a),
        Command::Board(a) => board::run(a),
        Command::Build(a) => build::run(a),
        Command::Synth(a) => synth::run(a),
        Command::Format(a) => format::run(a),
        Command::Experiment(a) => experiment::run(a),
        Command::Gains(a) => gains::run(a),
        Command::Identify(a) => identify::run(a),
        Command::Demo(a) => demo::run(a),
    }
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
