//! The path interpolator (issue 22): a distance into the loaded path segment becomes every
//! axis's position, one axis after the other, through one shared serial multiplier and a
//! CORDIC (the rule: `snapgen_model::path::interp`; the reference, register for register:
//! `snapgen_model::path::engine`, whose documentation gives the clocks a computation takes).
//!
//! Its ports are the spec's `with_interpolator_ports!` list. The number of axes (1 to
//! [`MAX_AXES`]) is chosen at generation; the per-axis memories are [`MAX_AXES`] words deep
//! whatever it is, so an axis adds [`SHARE_BITS`]` + 2` clocks to a computation and no
//! arithmetic. Its timing (the wide sums split over two clocks) and routed Fmax:
//! docs/PATH.md.
//!
//! rust-hdl 0.46 has no signed shifts, memories with run-time indices inside a clocked
//! process or functions, so this block writes its own Verilog (`hdl/verilog/interpolator.v`);
//! for rust-hdl's simulator it runs the model's engine. The Verilog is what is checked:
//! Verilator co-simulation against the engine on every clock (`snapgen_sim::interp`).
//!
//! The path sequencer (`crate::path_sequencer`) loads its segments and starts it on each tick;
//! neither is yet part of a generated design: the N-axis core around them is still to be
//! built.

use rust_hdl::prelude::*;
use snapgen_model::path::cordic::{constants, ITERATIONS};
use snapgen_model::path::engine::{Engine, CORDIC_BITS, HI_BITS, LO_BITS, SPLIT, T_BITS};
use snapgen_model::{InterpInputs, InterpOutputs};
use snapgen_spec::widths::{MAX_AXES, RATE_BITS, RATE_FRAC, SHARE_BITS, SHARE_FRAC};

use crate::block_with_ports;
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/interpolator.v");

/// Module prefix of the interpolator's own Verilog (`snapgen_interpolator.v`).
pub const INTERPOLATOR_PREFIX: &str = "snapgen_interpolator";

snapgen_spec::with_interpolator_ports!(block_with_ports! {
    /// The path interpolator for a design of `axes` axes.
    pub struct Interpolator(axes: u8) {
        _axes: u8 = axes,
        _sim: Engine = Engine::new(axes),
    }
});

impl Interpolator {
    /// The interpolator of a design of `axes` axes (1 to [`MAX_AXES`]).
    pub fn new(axes: u8) -> Self {
        Interpolator::build(axes)
    }
}

snapgen_spec::with_interpolator_ports!(
    model_ports! { Interpolator, InterpInputs, InterpOutputs, |b| interpolator_body(b._axes); }
);

/// The arctangent ROM: one `case` entry per CORDIC step.
fn atan_cases() -> String {
    let c = constants();
    let mut s = String::new();
    for (i, a) in c.atan.iter().enumerate() {
        s.push_str(&format!("   6'd{i}: atan = {CORDIC_BITS}'d{a};\n"));
    }
    s.push_str(&format!("   default: atan = {CORDIC_BITS}'d0;\n"));
    s
}

/// The block's body for `axes` axes (the template filled, its widths in front).
fn interpolator_body(axes: u8) -> String {
    assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
    let holes = Holes::new()
        .value("AXES", axes)
        .value("AXES_TOP", axes - 1)
        .value("LAST_STEP", ITERATIONS - 1)
        .value("SHARE_LAST", SHARE_BITS / 2 - 1)
        .value("RATE_LAST", RATE_BITS / 2 - 1)
        .value("CORDIC_BITS", CORDIC_BITS)
        .value("GAIN", constants().gain)
        .block("atan_cases", atan_cases());
    let body =
        fill("interpolator.v", TEMPLATE, &holes).expect("the interpolator's template is filled");
    let params = crate::protocol_v::localparams_with(&[
        ("SHARE_BITS", SHARE_BITS),
        ("SHARE_FRAC", SHARE_FRAC),
        ("RATE_BITS", RATE_BITS),
        ("RATE_FRAC", RATE_FRAC),
        ("HI_BITS", HI_BITS),
        ("LO_BITS", LO_BITS),
        ("CORDIC_BITS", CORDIC_BITS),
        ("T_BITS", T_BITS),
        ("SPLIT", SPLIT),
    ]);
    crate::protocol_v::with_localparams(&params, &body)
}

/// The interpolator's Verilog for `axes` axes: `snapgen_interpolator.v`, top module
/// `snapgen_interpolator`.
pub fn interpolator_verilog(axes: u8) -> String {
    let header = [
        format!(
            "snapgen path interpolator for {axes} axes: a distance into a line or arc segment becomes each axis's position."
        ),
        "Reference: snapgen_model::path::engine, register for register.".to_string(),
    ];
    let mut uut = Interpolator::new(axes);
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), INTERPOLATOR_PREFIX, &header, &[])
        .expect("the interpolator's names are checked by its tests")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolator_is_synthesizable() {
        // One axis and eight: an axis costs memory words, not logic (printed for the docs).
        for axes in [1, 8] {
            let stat = crate::synth_check::synth_block("interpolator", Interpolator::new(axes));
            eprintln!("{axes} axes:\n{stat}");
        }
    }
}
