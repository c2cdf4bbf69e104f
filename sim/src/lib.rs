//! Verilator co-simulation: the generated Verilog of the motion core, built by Verilator into a
//! shared library with a small C harness (`harness/harness.cpp`), runs clock by clock beside
//! the clock-accurate model (`snapgen_model::CoreModel`); every output is compared on every
//! clock.
//!
//! * [`wrapper`] puts a register on every input of the core, so Verilator evaluates its logic
//!   once per clock instead of twice (co-simulation only).
//! * [`build`] runs Verilator (cached by a hash of everything that goes into the build).
//! * [`fabric`] loads the library and drives it.
//! * [`cosim`] runs both in lockstep and reports the first mismatch.
//! * [`moves`] makes the random move streams `snapgen cosim` plays.
//! * [`io`] loads the Verilated I/O top; [`io_cosim`] runs it in lockstep with the device
//!   model under random command streams; [`board`] is the virtual board on it.
//! * [`axi`] loads the Verilated AXI4-Lite top; [`axi_cosim`] runs it in lockstep with its
//!   model under random AXI traffic, the handshake rules checked; [`axi_board`] is the virtual
//!   board behind its registers that the host's UIO link drives.
//! * [`interp`] runs the path interpolator in lockstep with its model, [`path_seq`] the path
//!   sequencer, [`step_dir`] the step/dir generator, [`path_steppers`] the N-axis stage made
//!   of them (issue 22).

pub mod axi;
pub mod axi_board;
pub mod axi_cosim;
pub mod board;
pub mod build;
pub mod closed_loop;
pub mod cosim;
pub mod drive_lines;
pub mod fabric;
pub mod host_link;
pub mod interp;
pub mod io;
pub mod io_cosim;
pub mod layout;
pub mod moves;
pub mod path_board;
pub mod path_core;
pub mod path_seq;
pub mod path_steppers;
pub mod step_dir;
pub mod vcd;
pub mod verilated;
pub mod wrapper;

use std::path::PathBuf;

/// Errors of the co-simulation tool chain.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A tool is not installed.
    #[error("{tool} was not found: {hint}")]
    ToolMissing {
        /// The tool.
        tool: &'static str,
        /// How to get it.
        hint: &'static str,
    },
    /// A tool ran and failed.
    #[error("{tool} failed (exit {code:?}); its output is in {log}")]
    ToolFailed {
        /// The tool.
        tool: &'static str,
        /// Exit code.
        code: Option<i32>,
        /// Log file.
        log: PathBuf,
    },
    /// File system trouble.
    #[error("{what} {path}: {source}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// Where.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A deliberate fault (test hook) was asked for at a clock its session never reached.
    #[error(
        "the fault at clock {clock} was never injected: session 0 ran only {clocks} clocks; \
         pick an earlier clock or a longer run (more moves, more clocks, fewer sessions)"
    )]
    FaultNotReached {
        /// The clock asked for.
        clock: u64,
        /// Clocks session 0 ran.
        clocks: u64,
    },
    /// A run's settings are not possible (see the message).
    #[error("{0}")]
    Config(String),
    /// The built library does not load or does not match this harness.
    #[error("cannot load the co-simulation library {path}: {reason}")]
    Load {
        /// Library path.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}
