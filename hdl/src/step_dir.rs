//! The step/dir generator (issue 22): a stepper drive's step and direction lines from an
//! axis's whole-LSB position, with the pulse width, the space between pulses and the
//! direction's setup time set in clocks (the reference, register for register, and the
//! rules: `snapgen_model::io::step_dir`). Its ports are the spec's `with_step_dir_ports!`.
//!
//! Written as a Verilog template (`hdl/verilog/step_dir.v`: wrapping comparisons read as
//! signs of differences, which rust-hdl's `Bits` would hide); for rust-hdl's simulator it runs
//! the model. The Verilog is what is checked: Verilator co-simulation against the model on
//! every clock (`snapgen_sim::step_dir`). Not yet part of a generated design.

use rust_hdl::prelude::*;
use snapgen_model::io::step_dir::StepDir;
use snapgen_model::{StepDirInputs, StepDirOutputs};

use crate::block_with_ports;
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/step_dir.v");

/// Module prefix of the generator's own Verilog (`snapgen_step_dir.v`).
pub const STEP_DIR_PREFIX: &str = "snapgen_step_dir";

snapgen_spec::with_step_dir_ports!(block_with_ports! {
    /// The step/dir generator of one axis.
    pub struct StepDirGenerator() {
        _sim: StepDir = StepDir::new(),
    }
});

impl Default for StepDirGenerator {
    fn default() -> Self {
        StepDirGenerator::build()
    }
}

snapgen_spec::with_step_dir_ports!(
    model_ports! { StepDirGenerator, StepDirInputs, StepDirOutputs, |_| step_dir_body(); }
);

/// The generator's body (the template filled, its widths in front).
fn step_dir_body() -> String {
    let body =
        fill("step_dir.v", TEMPLATE, &Holes::new()).expect("the step/dir template has no holes");
    crate::protocol_v::with_localparams(
        &crate::protocol_v::localparams_with(&[
            ("STEP_TIMER_BITS", snapgen_spec::widths::STEP_TIMER_BITS),
            ("POSITION_BITS", snapgen_spec::widths::POSITION_BITS),
        ]),
        &body,
    )
}

/// The generator's Verilog: `snapgen_step_dir.v`, top module `snapgen_step_dir`.
pub fn step_dir_verilog() -> String {
    let header = [
        "snapgen step/dir generator: a stepper drive's step and direction lines from an axis's position."
            .to_string(),
        "Reference: snapgen_model::io::step_dir, register for register.".to_string(),
    ];
    let mut uut = StepDirGenerator::default();
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), STEP_DIR_PREFIX, &header, &[])
        .expect("the generator's names are checked by its tests")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_dir_is_synthesizable() {
        let stat = crate::synth_check::synth_block("step_dir", StepDirGenerator::default());
        eprintln!("{stat}");
    }
}
