//! The path sequencer (issue 22): the ring of path segments the host writes ahead of the
//! motion and, on each tick, the choice of the segment the path length lies in, the
//! interpolator's load and its start (the reference, register for register, and the rules:
//! `snapgen_model::path::sequencer`). Its ports are the spec's `with_path_sequencer_ports!`;
//! its `interpolator` outputs are the interpolator's inputs of the same names.
//!
//! rust-hdl 0.46 has no memories with run-time indices inside a clocked process and no signed
//! comparisons, so this block writes its own Verilog (`hdl/verilog/path_sequencer.v`; its ring
//! is block RAM); for rust-hdl's simulator it runs the model. The Verilog is what is checked:
//! Verilator co-simulation against the model on every clock (`snapgen_sim::path_seq`).
//!
//! Not yet part of a generated design: the N-axis core around it is still to be built.

use rust_hdl::prelude::*;
use snapgen_model::path::sequencer::{PathSequencer as Model, SPLIT};
use snapgen_model::{PathSeqInputs, PathSeqOutputs};
use snapgen_spec::widths::{
    AXIS_BITS, FRAC_BITS, MAX_AXES, PATH_INDEX_BITS, PATH_SLOTS, PATH_SLOT_BITS, RATE_BITS,
    SHARE_BITS, TURN_BITS,
};

use crate::block_with_ports;
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/path_sequencer.v");

/// Module prefix of the sequencer's own Verilog (`snapgen_path_sequencer.v`).
pub const PATH_SEQUENCER_PREFIX: &str = "snapgen_path_sequencer";

snapgen_spec::with_path_sequencer_ports!(block_with_ports! {
    /// The path sequencer for a design of `axes` axes.
    pub struct PathSequencerBlock(axes: u8) {
        _axes: u8 = axes,
        _sim: Model = Model::new(axes).expect("1 to MAX_AXES axes"),
    }
});

impl PathSequencerBlock {
    /// The sequencer of a design of `axes` axes (1 to [`MAX_AXES`]).
    pub fn new(axes: u8) -> Self {
        assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
        PathSequencerBlock::build(axes)
    }
}

snapgen_spec::with_path_sequencer_ports!(
    model_ports! { PathSequencerBlock, PathSeqInputs, PathSeqOutputs, |b| path_sequencer_body(b._axes); }
);

/// The block's body for `axes` axes (the template filled, its widths in front).
fn path_sequencer_body(axes: u8) -> String {
    assert!((1..=MAX_AXES as u8).contains(&axes), "1 to {MAX_AXES} axes");
    let holes = Holes::new()
        .value("AXIS_BITS", AXIS_BITS)
        .value("AXES_TOP", axes - 1)
        .value(
            "AXIS_EXISTS",
            if u32::from(axes) == MAX_AXES {
                "1'b1"
            } else {
                "seg_axis <= AXES_TOP"
            },
        );
    let body = fill("path_sequencer.v", TEMPLATE, &holes)
        .expect("the path sequencer's template is filled");
    let params = crate::protocol_v::localparams_with(&[
        ("FRAC_BITS", FRAC_BITS),
        ("AXIS_BITS", AXIS_BITS),
        ("SHARE_BITS", SHARE_BITS),
        ("TURN_BITS", TURN_BITS),
        ("RATE_BITS", RATE_BITS),
        ("PATH_INDEX_BITS", PATH_INDEX_BITS),
        ("PATH_SLOT_BITS", PATH_SLOT_BITS),
        ("PATH_SLOTS", PATH_SLOTS),
        ("MAX_AXES", MAX_AXES),
        ("SPLIT", SPLIT),
    ]);
    crate::protocol_v::with_localparams(&params, &body)
}

/// The sequencer's Verilog for `axes` axes: `snapgen_path_sequencer.v`, top module
/// `snapgen_path_sequencer`.
pub fn path_sequencer_verilog(axes: u8) -> String {
    let header = [
        format!(
            "snapgen path sequencer for {axes} axes: the ring of path segments, the segment of each tick's path length, the interpolator's load and start."
        ),
        "Reference: snapgen_model::path::sequencer, register for register.".to_string(),
    ];
    let mut uut = PathSequencerBlock::new(axes);
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), PATH_SEQUENCER_PREFIX, &header, &[])
        .expect("the sequencer's names are checked by its tests")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_sequencer_is_synthesizable() {
        for axes in [1, 8] {
            let stat =
                crate::synth_check::synth_block("path_sequencer", PathSequencerBlock::new(axes));
            eprintln!("{axes} axes:\n{stat}");
        }
    }
}
