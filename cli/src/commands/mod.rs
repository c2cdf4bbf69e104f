//! One file per subcommand: its arguments (`Args`) and what it does (`run`).

pub mod board;
pub mod build;
pub mod cosim;
pub mod cosim_axi;
pub mod cosim_interp;
pub mod cosim_io;
pub mod cosim_path_core;
pub mod demo;
pub mod experiment;
pub mod format;
pub mod gains;
pub mod identify;
pub mod online;
pub mod path;
pub mod plan;
pub mod plot;
pub mod send;
pub mod spec;
pub mod stop;
pub mod synth;
pub mod trace;
pub mod verilog;
