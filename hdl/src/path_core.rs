//! The path core (issue 22): the motion core (`snapgen_core`), whose chain integrates the path
//! length `s`, driving the path steppers (`snapgen_path_steppers`) on each of its ticks (the
//! reference, register for register: `snapgen_model::path::core`). Its ports are the spec's
//! `with_path_core_ports!`: the core's and the steppers' (but the steppers' `tick` and `s`).
//!
//! The Verilog (`hdl/verilog/path_core.v`) instantiates the two blocks of their own files
//! ([`path_core_sources`] gives all six: the core's, the steppers' four, its own); its wires
//! and instances are written from the spec's port lists. For rust-hdl's simulator it runs the
//! model. The Verilog is what is checked: Verilator co-simulation against the model on every
//! clock (`snapgen_sim::path_core`).
//!
//! Not yet part of a board's design: the command interface that writes the ring and the
//! drives' settings is still to be built around it.

use rust_hdl::prelude::*;
use snapgen_model::path::core::PathCore as Model;
use snapgen_model::{PathCoreInputs, PathCoreOutputs, DEFAULT_FORMAT};
use snapgen_spec::ports::{Dir, PATH_CORE, PATH_STEPPERS};
use snapgen_spec::widths::MAX_AXES;

use crate::block_with_ports;
use crate::path_steppers::{instance, wire};
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/path_core.v");

/// Module prefix of the path core's own Verilog (`snapgen_path_core.v`).
pub const PATH_CORE_PREFIX: &str = "snapgen_path_core";

snapgen_spec::with_path_core_ports!(block_with_ports! {
    /// The path core for a design of `axes` axes.
    pub struct PathCoreBlock(axes: u8) {
        _axes: u8 = axes,
        _sim: Model = Model::new(&DEFAULT_FORMAT, axes).expect("1 to MAX_AXES axes"),
    }
});

impl PathCoreBlock {
    /// The path core of a design of `axes` axes (1 to [`MAX_AXES`]).
    pub fn new(axes: u8) -> Self {
        assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
        PathCoreBlock::build(axes)
    }
}

snapgen_spec::with_path_core_ports!(
    model_ports! { PathCoreBlock, PathCoreInputs, PathCoreOutputs, |_| path_core_body(); }
);

/// A port of the steppers that the core drives inside the path core.
fn driven_inside(name: &str) -> bool {
    matches!(name, "tick" | "s")
}

/// The block's body (the template filled): the same for any number of axes, which the
/// steppers' file carries.
fn path_core_body() -> String {
    let core = snapgen_spec::ports::MOTION_CORE;
    // The blocks' outputs, as wires: the core's c_*, the steppers' p_*.
    let mut wires: Vec<String> = core
        .ports
        .iter()
        .filter(|p| p.dir == Dir::Out)
        .map(|p| wire(&format!("c_{}", p.name), p.bits))
        .collect();
    wires.extend(
        PATH_STEPPERS
            .ports
            .iter()
            .filter(|p| p.dir == Dir::Out)
            .map(|p| wire(&format!("p_{}", p.name), p.bits)),
    );
    let core_instance = instance(core_module(), "core", core.ports, |p| match p.dir {
        Dir::Out => format!("c_{}", p.name),
        Dir::In => p.name.to_string(),
    });
    let steppers = instance(
        crate::path_steppers::PATH_STEPPERS_PREFIX,
        "steppers",
        PATH_STEPPERS.ports,
        |p| match (p.dir, p.name) {
            (Dir::Out, _) => format!("p_{}", p.name),
            (Dir::In, "tick") => "tick_q".into(),
            (Dir::In, "s") => "c_x".into(),
            (Dir::In, name) => name.to_string(),
        },
    );
    // Each output from the block that has it (the spec's test: the lists do not overlap).
    let outputs: Vec<String> = PATH_CORE
        .ports
        .iter()
        .filter(|p| p.dir == Dir::Out)
        .map(|p| {
            let from = if core.port(p.name).is_some() {
                "c"
            } else {
                "p"
            };
            format!("{} = {from}_{};", p.name, p.name)
        })
        .collect();
    debug_assert!(PATH_STEPPERS
        .ports
        .iter()
        .filter(|p| p.dir == Dir::In && !driven_inside(p.name))
        .all(|p| PATH_CORE.port(p.name).is_some()));
    let holes = Holes::new()
        .block("wires", wires.join("\n"))
        .block("core", core_instance)
        .block("steppers", steppers)
        .block("outputs", outputs.join("\n"));
    fill("path_core.v", TEMPLATE, &holes).expect("the path core's template is filled")
}

/// The motion core's module name.
fn core_module() -> &'static str {
    crate::verilog::CORE_PREFIX
}

/// The path core's own Verilog for `axes` axes: `snapgen_path_core.v`, top module
/// `snapgen_path_core` (read with the blocks' files: [`path_core_sources`]).
pub fn path_core_verilog(axes: u8) -> String {
    let header = [
        format!(
            "snapgen path core for {axes} axes: the motion core on the path length, driving the path steppers on each of its ticks."
        ),
        "Instantiates snapgen_core and snapgen_path_steppers (their own files).".to_string(),
        "Reference: snapgen_model::path::core, register for register.".to_string(),
    ];
    let mut uut = PathCoreBlock::new(axes);
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), PATH_CORE_PREFIX, &header, &[])
        .expect("the path core's names are checked by its tests")
}

/// Every source file of the path core for `axes` axes: the motion core's, the path steppers'
/// four, and its own.
pub fn path_core_sources(axes: u8) -> Vec<(String, String)> {
    let mut v = vec![(
        format!("{}.v", crate::verilog::CORE_PREFIX),
        crate::verilog::motion_core_verilog(),
    )];
    v.extend(crate::path_steppers::path_steppers_sources(axes));
    v.push((format!("{PATH_CORE_PREFIX}.v"), path_core_verilog(axes)));
    v
}

/// The path core's sources as one text (what a simulator or a synthesis run reads).
pub fn path_core_sources_text(axes: u8) -> String {
    path_core_sources(axes)
        .into_iter()
        .map(|(_, v)| v)
        .collect()
}
