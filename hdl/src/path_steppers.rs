//! The path steppers (issue 22): the N-axis output stage of a path design for stepper drives:
//! the path sequencer and the interpolator it drives, each axis's position registers
//! (committed together on a tick) and a step/dir generator per axis (the reference, register
//! for register: `snapgen_model::path::steppers`). Its ports are the spec's
//! `with_path_steppers_ports!`.
//!
//! The Verilog (`hdl/verilog/path_steppers.v`) instantiates the three blocks of their own files
//! (`snapgen_path_sequencer.v`, `snapgen_interpolator.v`, `snapgen_step_dir.v`;
//! [`path_steppers_sources`] gives all four), and its wires and instances are written from
//! the spec's port lists, so a port renamed in one block's list cannot leave the stage
//! miswired. For rust-hdl's simulator it runs the model. The Verilog is what is checked:
//! Verilator co-simulation against the model on every clock (`snapgen_sim::path_steppers`).
//!
//! The path core (`crate::path_core`) drives it from the motion core's chain; the command
//! interface that writes the ring is still to be built around both.

use rust_hdl::prelude::*;
use snapgen_model::path::steppers::PathSteppers as Model;
use snapgen_model::{PathSteppersInputs, PathSteppersOutputs};
use snapgen_spec::ports::{Dir, Port, INTERPOLATOR, PATH_SEQUENCER, STEP_DIR};
use snapgen_spec::widths::{AXIS_BITS, FRAC_BITS, MAX_AXES, POSITION_BITS, STEP_TIMER_BITS};

use crate::block_with_ports;
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/path_steppers.v");

/// Module prefix of the stage's own Verilog (`snapgen_path_steppers.v`).
pub const PATH_STEPPERS_PREFIX: &str = "snapgen_path_steppers";

snapgen_spec::with_path_steppers_ports!(block_with_ports! {
    /// The path steppers for a design of `axes` axes.
    pub struct PathSteppersBlock(axes: u8) {
        _axes: u8 = axes,
        _sim: Model = Model::new(axes).expect("1 to MAX_AXES axes"),
    }
});

impl PathSteppersBlock {
    /// The stage of a design of `axes` axes (1 to [`MAX_AXES`]).
    pub fn new(axes: u8) -> Self {
        assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
        PathSteppersBlock::build(axes)
    }
}

snapgen_spec::with_path_steppers_ports!(
    model_ports! { PathSteppersBlock, PathSteppersInputs, PathSteppersOutputs, |b| path_steppers_body(b._axes); }
);

/// `wire [W-1:0] name;` (or a single wire).
pub(crate) fn wire(name: &str, bits: u32) -> String {
    if bits == 1 {
        format!("wire {name};")
    } else {
        format!("wire [{}:0] {name};", bits - 1)
    }
}

/// An instance of `module` named `name` whose port `p` is connected to `net(p)`.
pub(crate) fn instance(
    module: &str,
    name: &str,
    ports: &[Port],
    net: impl Fn(&Port) -> String,
) -> String {
    let conns: Vec<String> = std::iter::once(".clock(clock)".to_string())
        .chain(ports.iter().map(|p| format!(".{}({})", p.name, net(p))))
        .collect();
    format!("{module} {name}(\n   {}\n);", conns.join(",\n   "))
}

/// The interpolator's ports that the sequencer drives or reads (by name).
fn between(p: &Port) -> bool {
    PATH_SEQUENCER
        .section("interpolator")
        .any(|q| q.name == p.name)
}

/// The block's body for `axes` axes (the template filled, its widths in front).
fn path_steppers_body(axes: u8) -> String {
    assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
    // The wires: between the sequencer and the interpolator (ip_*, named as the
    // interpolator's ports), the interpolator's other outputs, the sequencer's commit and status.
    // (Its `busy` stays unconnected: the sequencer waits for `done`.)
    let mut wires: Vec<String> = INTERPOLATOR
        .ports
        .iter()
        .filter(|p| p.name != "reset" && p.name != "busy")
        .map(|p| wire(&format!("ip_{}", p.name), p.bits))
        .collect();
    wires.extend(
        PATH_SEQUENCER
            .ports
            .iter()
            .filter(|p| p.dir == Dir::Out && (p.section == "axes" || p.section == "status"))
            .map(|p| match p.section {
                "axes" => wire(p.name, p.bits),
                _ => wire(&format!("seq_{}", p.name), p.bits),
            }),
    );
    let sequencer = instance(
        "snapgen_path_sequencer",
        "sequencer",
        PATH_SEQUENCER.ports,
        |p| match (p.dir, p.section) {
            (_, "interpolator") => format!("ip_{}", p.name),
            (Dir::Out, "status") => format!("seq_{}", p.name),
            _ => p.name.to_string(),
        },
    );
    let interpolator = instance(
        "snapgen_interpolator",
        "interpolator",
        INTERPOLATOR.ports,
        |p| match p.name {
            "reset" => "reset".into(),
            "busy" => String::new(),
            _ => {
                debug_assert!(between(p) || p.dir == Dir::Out);
                format!("ip_{}", p.name)
            }
        },
    );
    let drive = instance("snapgen_step_dir", "drive", STEP_DIR.ports, |p| {
        match p.name {
            "step_lsb" => format!("step_lsb[{STEP_TIMER_BITS}*gk +: {STEP_TIMER_BITS}]"),
            "enable" => "enable[gk]".into(),
            "position" => format!("position_x[{FRAC_BITS} +: {POSITION_BITS}]"),
            "step" | "dir" | "due" => format!("{}_k", p.name),
            // Unused: the steps count and the generator's own overrun (see the template).
            _ if p.dir == Dir::Out => String::new(),
            name => name.to_string(),
        }
    });
    let drive = format!(
        "/* verilator lint_off PINCONNECTEMPTY */ // its steps count and own overrun are not used\n{drive}\n/* verilator lint_on PINCONNECTEMPTY */"
    );
    let interpolator = format!(
        "/* verilator lint_off PINCONNECTEMPTY */ // busy: the sequencer waits for done\n{interpolator}\n/* verilator lint_on PINCONNECTEMPTY */"
    );
    let pad = |v: &str| {
        if u32::from(axes) == MAX_AXES {
            v.to_string()
        } else {
            format!("{{{{{}{{1'b0}}}}, {v}}}", MAX_AXES - u32::from(axes))
        }
    };
    let mut outputs: Vec<String> = PATH_SEQUENCER
        .section("status")
        .map(|p| format!("{} = seq_{};", p.name, p.name))
        .collect();
    outputs.push(format!("step = {};", pad("step_w")));
    outputs.push(format!("dir = {};", pad("dir_w")));
    outputs.push(format!("overrun = {};", pad("behind_w")));
    // The settings of axes the design lacks (Verilator ignores a signal named unused_*).
    let unused = if u32::from(axes) == MAX_AXES {
        "// (every axis's settings are used)".to_string()
    } else {
        format!(
            "wire unused_settings = &{{1'b0, step_lsb[{}:{}], enable[{}:{axes}], 1'b0}};",
            STEP_TIMER_BITS * MAX_AXES - 1,
            STEP_TIMER_BITS * u32::from(axes),
            MAX_AXES - 1
        )
    };
    let holes = Holes::new()
        .value("AXES", axes)
        .block("unused", unused)
        .block("wires", wires.join("\n"))
        .block("sequencer", sequencer)
        .block("interpolator", interpolator)
        .block("drive", drive)
        .block("outputs", outputs.join("\n"));
    let body =
        fill("path_steppers.v", TEMPLATE, &holes).expect("the path steppers' template is filled");
    let params = crate::protocol_v::localparams_with(&[
        ("FRAC_BITS", FRAC_BITS),
        ("AXIS_BITS", AXIS_BITS),
        ("POSITION_BITS", POSITION_BITS),
    ]);
    crate::protocol_v::with_localparams(&params, &body)
}

/// The stage's own Verilog for `axes` axes: `snapgen_path_steppers.v`, top module
/// `snapgen_path_steppers` (read with the blocks' files: [`path_steppers_sources`]).
pub fn path_steppers_verilog(axes: u8) -> String {
    let header = [
        format!(
            "snapgen path steppers for {axes} axes: the path sequencer, the interpolator, each axis's position and a step/dir generator per axis."
        ),
        "Instantiates snapgen_path_sequencer, snapgen_interpolator and snapgen_step_dir (their own files).".to_string(),
        "Reference: snapgen_model::path::steppers, register for register.".to_string(),
    ];
    let mut uut = PathSteppersBlock::new(axes);
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), PATH_STEPPERS_PREFIX, &header, &[])
        .expect("the stage's names are checked by its tests")
}

/// Every source file of the stage for `axes` axes: the sequencer's, the interpolator's, the
/// step/dir generator's and the stage's own.
pub fn path_steppers_sources(axes: u8) -> [(String, String); 4] {
    [
        (
            format!("{}.v", crate::path_sequencer::PATH_SEQUENCER_PREFIX),
            crate::path_sequencer::path_sequencer_verilog(axes),
        ),
        (
            format!("{}.v", crate::interpolator::INTERPOLATOR_PREFIX),
            crate::interpolator::interpolator_verilog(axes),
        ),
        (
            format!("{}.v", crate::step_dir::STEP_DIR_PREFIX),
            crate::step_dir::step_dir_verilog(),
        ),
        (
            format!("{PATH_STEPPERS_PREFIX}.v"),
            path_steppers_verilog(axes),
        ),
    ]
}

/// The stage's sources as one text (what a simulator or a synthesis run reads).
pub fn path_steppers_sources_text(axes: u8) -> String {
    path_steppers_sources(axes).map(|(_, v)| v).concat()
}
