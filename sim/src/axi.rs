//! The Verilated AXI4-Lite top (`snapgen_axi`: the station behind the AXI4-Lite slave),
//! loaded through [`crate::verilated`]: its word layout and harness header from the spec's
//! port list, and its tag. Co-simulated against `snapgen_model::io::axi::AxiDevice` on every
//! clock by [`crate::axi_cosim`]; the virtual AXI board of the host's UIO link runs it.

use std::path::Path;

use snapgen_model::ports::{AxiInputs, AxiOutputs, IoInputs};

use crate::layout::{harness_header, port_layout};
use crate::verilated::{abi, VcdWindow, Verilated};
use crate::SimError;

snapgen_spec::with_axi_top_ports!(port_layout! {
    AXI_INPUTS, AXI_OUTPUTS, AxiInputs, AxiOutputs;
});

/// The AXI top's tag in the harness's ABI word.
const AXI_TAG: u32 = 8;

/// The harness's generated header (`snapgen_layout.h`): every input at rest is 0.
pub fn axi_layout_header() -> String {
    harness_header(
        &AXI_INPUTS,
        &AXI_OUTPUTS,
        abi(AXI_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&AxiInputs::default()),
    )
}

/// The AXI top's inputs for a clock: the machine's pins `pins` (a [`snapgen_model::peer::Peer`]'s,
/// whose UART line is not used) and the bus `bus` (its other fields ignored).
pub fn with_pins(pins: &IoInputs, bus: AxiInputs) -> AxiInputs {
    AxiInputs {
        reset: pins.reset,
        estop: pins.estop,
        enc_a: pins.enc_a,
        enc_b: pins.enc_b,
        enc_i: pins.enc_i,
        limit_pos: pins.limit_pos,
        limit_neg: pins.limit_neg,
        ..bus
    }
}

/// Opens the library `library` (built by [`crate::build::build_axi`]) as one AXI top; with
/// `vcd`, the library must be a trace build.
pub fn open(library: &Path, vcd: Option<&VcdWindow>) -> Result<Verilated, SimError> {
    Verilated::open(library, vcd, AXI_TAG, IN_WORDS, OUT_WORDS)
}
