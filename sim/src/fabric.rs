//! The Verilated motion core: its port tables and word layout (from the spec's port list),
//! and its instance, loaded through [`crate::verilated`].

use std::path::Path;

use snapgen_model::{CoreInputs, CoreOutputs};

use crate::layout::{harness_header, pack, Port, PortValue, Slot};
pub use crate::verilated::VcdWindow;
use crate::verilated::{abi, Verilated};
use crate::SimError;

/// The core's port tables, encoders and decoders, from the spec's port list: one slot per
/// port in list order (the harness's word order), one `put` per port with a constant slot
/// (straight-line code), one field of [`CoreInputs`]/[`CoreOutputs`] per port.
macro_rules! core_layout {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        /// The core's inputs, in the harness's word order (the wrapper registers each of them).
        pub const CORE_INPUTS: [Port; [$($(stringify!($i)),*),*].len()] =
            [$($( Port { name: stringify!($i), bits: $ib }, )*)*];

        /// The core's outputs, in [`crate::cosim::Register`] order.
        pub const CORE_OUTPUTS: [Port; [$($(stringify!($o)),*),*].len()] =
            [$($( Port { name: stringify!($o), bits: $ob }, )*)*];

        /// Each output's raw bits in [`CoreOutputs`], by register.
        pub(crate) const OUTPUT_BITS: [fn(&CoreOutputs) -> u128; CORE_OUTPUTS.len()] =
            [$($( |o: &CoreOutputs| PortValue::to_word(o.$o), )*)*];

        /// The inputs in the harness's word layout.
        #[inline(always)]
        pub fn encode_inputs(i: &CoreInputs) -> [u32; IN_WORDS] {
            let mut w = [0u32; IN_WORDS];
            let mut k = 0;
            $($( IN_SLOTS[k].put(&mut w, PortValue::to_word(i.$i)); k += 1; )*)*
            debug_assert_eq!(k, IN_SLOTS.len());
            w
        }

        /// Encodes outputs in the harness's word layout (the inverse of [`decode`]): what the
        /// co-simulation compares the fabric's words with, on every clock.
        #[inline(always)]
        pub fn encode(o: &CoreOutputs) -> [u32; OUT_WORDS] {
            let mut w = [0u32; OUT_WORDS];
            let mut k = 0;
            $($( OUT_SLOTS[k].put(&mut w, PortValue::to_word(o.$o)); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            w
        }

        /// Decodes one clock's output words.
        pub fn decode(w: &[u32]) -> CoreOutputs {
            let mut k = 0;
            $($( let $o = PortValue::from_word(OUT_SLOTS[k].get(w), $ob); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            CoreOutputs { $($( $o, )*)* }
        }
    };
}

snapgen_spec::with_motion_core_ports!(core_layout! {});

const IN_LAYOUT: ([Slot; CORE_INPUTS.len()], usize) = pack(&CORE_INPUTS);
const OUT_LAYOUT: ([Slot; CORE_OUTPUTS.len()], usize) = pack(&CORE_OUTPUTS);
/// Where each input is in the input words.
pub const IN_SLOTS: [Slot; CORE_INPUTS.len()] = IN_LAYOUT.0;
/// Where each output is in a clock's output words.
pub const OUT_SLOTS: [Slot; CORE_OUTPUTS.len()] = OUT_LAYOUT.0;
/// Input words per `set` call.
pub const IN_WORDS: usize = IN_LAYOUT.1;
/// Output words per clock.
pub const OUT_WORDS: usize = OUT_LAYOUT.1;

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
