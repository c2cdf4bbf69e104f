//! The status block (docs/PROTOCOL.md, "Status block"): the STATUS/TELEMETRY payload, byte 0
//! in bits 7:0. [`StatusBlock`] has one input per field of the contract's layout
//! (`with_status_fields!`, each `8 × bytes` wide) and [`FlagsWord`] one input per flag
//! (`with_flags!`, named as the signal that sets it), so the fabric's status block is laid out
//! by the same lists as the model's and the host's. Both are combinational concatenations; the
//! reply transmitter sends the block, and the I/O top also brings it out for co-simulation,
//! where every field is compared with the device model on every clock.

use rust_hdl::prelude::*;
use snapgen_spec::fields::STATUS_FIELDS;
use snapgen_spec::FLAGS;

/// Bits of the status block.
pub const STATUS_BITS: usize = snapgen_spec::STATUS_BITS;
/// Bits of the flags word.
pub const FLAG_BITS: usize = 8 * snapgen_spec::fields::field(&STATUS_FIELDS, "flags").bytes;

macro_rules! status_block {
    ( $( $field:ident : $ty:ty = $bytes:expr, $sign:ident, $meaning:literal; )* ) => {
        /// The status block: one input per field.
        #[derive(LogicBlock, Default)]
        pub struct StatusBlock {
            $( #[doc = $meaning] pub $field: Signal<In, Bits<{ 8 * ($bytes) }>>, )*
            /// The block, byte 0 in bits 7:0.
            pub status: Signal<Out, Bits<STATUS_BITS>>,
        }
    };
}

snapgen_spec::with_status_fields!(status_block! {});

macro_rules! flags_word {
    ( $( $name:ident = $bit:literal, $port:ident, $meaning:literal; )* ) => {
        /// The flags word: one input per flag.
        #[derive(LogicBlock, Default)]
        pub struct FlagsWord {
            $( #[doc = $meaning] pub $port: Signal<In, Bit>, )*
            /// The word, flag `k` in bit `k`.
            pub flags: Signal<Out, Bits<FLAG_BITS>>,
        }
    };
}

snapgen_spec::with_flags!(flags_word! {});

impl Logic for StatusBlock {
    fn update(&mut self) {}

    fn connect(&mut self) {
        self.status.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(status_verilog())
    }
}

impl Logic for FlagsWord {
    fn update(&mut self) {}

    fn connect(&mut self) {
        self.flags.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(flags_verilog())
    }
}

/// The status block's Verilog: the fields, last first. rust-hdl's own simulator does not run
/// it (its output stays 0 there); Verilator runs it against the model in the I/O top.
pub fn status_verilog() -> String {
    let parts: Vec<&str> = STATUS_FIELDS.iter().rev().map(|f| f.name).collect();
    format!(
        "// The fields, last first (snapgen_spec::fields::STATUS_FIELDS).\nalways @(*) status = {{{}}};\n",
        parts.join(", ")
    )
}

/// The flags word's Verilog: each flag's input at its bit (snapgen_spec::FLAGS), 0 elsewhere.
pub fn flags_verilog() -> String {
    let mut bits = vec!["1'b0".to_string(); FLAG_BITS];
    for f in FLAGS {
        bits[f.bit as usize] = f.port.to_string();
    }
    bits.reverse();
    format!(
        "// Flag k at bit k (snapgen_spec::FLAGS).\nalways @(*) flags = {{{}}};\n",
        bits.join(", ")
    )
}

const _: () = assert!(STATUS_BITS == 240 && FLAGS.len() <= FLAG_BITS);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_block_is_synthesizable() {
        crate::synth_check::synth_block("status_block", StatusBlock::default());
        crate::synth_check::synth_block("flags_word", FlagsWord::default());
    }

    #[test]
    fn the_flags_are_at_their_bits() {
        let v = flags_verilog();
        // 16 bits, bit 15 first: two unused, then swap_pending (13) … playing (0).
        assert!(
            v.contains("{1'b0, 1'b0, swap_pending, servo_overrun,"),
            "{v}"
        );
        assert!(v.ends_with("stopping, cut, done, playing};\n"), "{v}");
    }
}
