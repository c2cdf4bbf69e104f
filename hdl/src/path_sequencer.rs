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
use snapgen_model::PathSeqInputs;
use snapgen_spec::widths::{
    AXIS_BITS, FRAC_BITS, MAX_AXES, PATH_INDEX_BITS, PATH_SLOTS, PATH_SLOT_BITS, RATE_BITS,
    SHARE_BITS, TURN_BITS,
};

use crate::block_with_ports;
use crate::sim_bits::{from_i128, to_i128, to_u128};
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

impl Logic for PathSequencerBlock {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let i = PathSeqInputs {
                reset: self.reset.val(),
                seg_index: self.seg_index.val().to_u64() as u16,
                write_span: self.write_span.val(),
                seg_start: to_i128(self.seg_start.val()),
                seg_length: to_i128(self.seg_length.val()),
                write_shape: self.write_shape.val(),
                seg_arc: self.seg_arc.val(),
                seg_ccw: self.seg_ccw.val(),
                seg_plane_first: self.seg_plane_first.val().to_u64() as u8,
                seg_plane_second: self.seg_plane_second.val().to_u64() as u8,
                seg_centre_first: to_i128(self.seg_centre_first.val()),
                seg_centre_second: to_i128(self.seg_centre_second.val()),
                seg_radius: to_i128(self.seg_radius.val()),
                seg_growth: to_i128(self.seg_growth.val()),
                seg_start_angle: self.seg_start_angle.val().to_u64(),
                seg_rate: to_u128(self.seg_rate.val()) as i128,
                write_axis: self.write_axis.val(),
                seg_axis: self.seg_axis.val().to_u64() as u8,
                seg_from: to_i128(self.seg_from.val()),
                seg_share: to_i128(self.seg_share.val()),
                extend: self.extend.val(),
                tick: self.tick.val(),
                s: to_i128(self.s.val()),
                done: self.done.val(),
            };
            self._sim.clock(&i);
        }
        let o = self._sim.outputs();
        self.load_shape.next = o.load_shape;
        self.arc.next = o.arc;
        self.ccw.next = o.ccw;
        self.plane_first.next = u64::from(o.plane_first).into();
        self.plane_second.next = u64::from(o.plane_second).into();
        self.centre_first.next = from_i128(o.centre_first);
        self.centre_second.next = from_i128(o.centre_second);
        self.radius.next = from_i128(o.radius);
        self.growth.next = from_i128(o.growth);
        self.start_angle.next = o.start_angle.into();
        self.rate.next = from_i128(o.rate);
        self.load_axis.next = o.load_axis;
        self.axis.next = u64::from(o.axis).into();
        self.from.next = from_i128(o.from);
        self.share.next = from_i128(o.share);
        self.start.next = o.start;
        self.offset.next = from_i128(o.offset);
        self.commit.next = o.commit;
        self.segment.next = u64::from(o.segment).into();
        self.running.next = o.running;
        self.empty.next = o.empty;
        self.late.next = o.late;
        self.refused.next = o.refused;
    }

    fn connect(&mut self) {
        self.load_shape.connect();
        self.arc.connect();
        self.ccw.connect();
        self.plane_first.connect();
        self.plane_second.connect();
        self.centre_first.connect();
        self.centre_second.connect();
        self.radius.connect();
        self.growth.connect();
        self.start_angle.connect();
        self.rate.connect();
        self.load_axis.connect();
        self.axis.connect();
        self.from.connect();
        self.share.connect();
        self.start.connect();
        self.offset.connect();
        self.commit.connect();
        self.segment.connect();
        self.running.connect();
        self.empty.connect();
        self.late.connect();
        self.refused.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(path_sequencer_body(self._axes))
    }
}

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
