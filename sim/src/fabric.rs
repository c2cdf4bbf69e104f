//! The Verilated motion core: its port tables and word layout (from the spec's port list),
//! and its instance, loaded through [`crate::verilated`].

use std::path::Path;

use snapgen_model::{CoreInputs, CoreOutputs};

use crate::layout::{harness_header, port_layout, PortValue};
pub use crate::verilated::VcdWindow;
use crate::verilated::{abi, Verilated};
use crate::SimError;

snapgen_spec::with_motion_core_ports!(port_layout! {
    CORE_INPUTS, CORE_OUTPUTS, CoreInputs, CoreOutputs;
});

/// What the comparison reads of the core's outputs besides the layout: each output's raw bits
/// in [`CoreOutputs`] by register, and a clock's output words decoded.
macro_rules! core_outputs {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        /// Each output's raw bits in [`CoreOutputs`], by register ([`crate::cosim::Register`]
        /// order: the table's).
        pub(crate) const OUTPUT_BITS: [fn(&CoreOutputs) -> u128; CORE_OUTPUTS.len()] =
            [$($( |o: &CoreOutputs| PortValue::to_word(o.$o), )*)*];

        /// Decodes one clock's output words (the inverse of [`encode_outputs`]).
        pub fn decode(w: &[u32]) -> CoreOutputs {
            let mut k = 0;
            $($( let $o = PortValue::from_word(OUT_SLOTS[k].get(w), $ob); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            CoreOutputs { $($( $o, )*)* }
        }
    };
}

snapgen_spec::with_motion_core_ports!(core_outputs! {});

/// The core harness's generated header (`snapgen_layout.h`): the inputs at rest are the
/// core's defaults.
pub fn core_layout_header() -> String {
    harness_header(
        &CORE_INPUTS,
        &CORE_OUTPUTS,
        abi(CORE_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&CoreInputs::default()),
    )
}

/// The motion core's tag in the harness's ABI word.
const CORE_TAG: u32 = 1;

/// One instance of the Verilated core (behind its input registers, [`crate::wrapper`]).
pub struct Fabric(Verilated);

impl Fabric {
    /// Loads `library` and creates one core; with `vcd`, the library must be a trace build.
    pub fn open(library: &Path, vcd: Option<&VcdWindow>) -> Result<Self, SimError> {
        Verilated::open(library, vcd, CORE_TAG, IN_WORDS, OUT_WORDS).map(Fabric)
    }

    /// Applies inputs (held until the next call).
    pub fn set(&mut self, i: &CoreInputs) {
        self.0.set(&encode_inputs(i));
    }

    /// Runs `n` clocks; `out` receives `n * OUT_WORDS` words.
    pub fn run(&mut self, n: usize, out: &mut Vec<u32>) {
        self.0.run(n, out);
    }
}
