//! rust-hdl description of the snapgen motion core.
//!
//! One block per file: [`tick_divider`] (trajectory tick from the fabric clock),
//! [`program_memory`] (two banks of segments, written while the other plays), [`sequencer`]
//! (plays a program, one snap value per tick), [`chain`] (the four accumulators) and
//! [`core`] (all of them wired together, the top level that `snapgen verilog` writes).
//!
//! Widths and port lists come from the contract (`snapgen_spec`): the blocks whose ports cross
//! a boundary (the motion core, the I/O top) declare them with [`block_with_ports!`] from the
//! spec's lists, so there is no second copy of a port or a width. rust-hdl needs widths as
//! const generics, so the generator supports the spec's register widths only; `Ts` and the
//! position LSB do not change the hardware (the tick divider is an input).
//!
//! rust-hdl 0.46 workarounds used here (each is also noted where it is applied):
//! * `#[hdl_gen]` drops Rust's operator precedence: every mixed expression is parenthesised.
//! * Signed types are avoided (its simulator overflows the stack on `signed_bit_cast` of the
//!   most negative value, and the casts lint with WIDTH warnings): registers are `Bits`
//!   holding two's complement, addition is the same for both, and the one sign extension
//!   (velocity into position) is an explicit mux on the sign bit.
//! * Its simulator is slow past 32 bits: the blocks' own tests are short; long runs use
//!   Verilator (`snapgen-sim`).

pub mod axi_top;
pub mod byte_fifo;
pub mod chain;
pub mod core;
pub mod crc16;
pub mod defaults;
pub mod emit;
pub mod executor;
pub mod frame_rx;
pub mod input_filter;
pub mod interpolator;
pub mod io_top;
pub mod netlist;
pub mod path_core;
pub mod path_sequencer;
pub mod path_steppers;
pub mod payload_shift;
pub mod program_memory;
pub mod protocol_v;
pub mod pwm;
pub mod quadrature;
pub mod reply_queue;
pub mod reply_tx;
pub mod sequencer;
pub mod servo;
pub mod sign_extend;
pub mod sim_bits;
pub mod station;
pub mod status_block;
pub mod step_dir;
pub mod stop_unit;
pub mod swap_timer;
pub mod template;
pub mod tick_divider;
pub mod uart_rx;
pub mod uart_tx;
pub mod verilog;

use snapgen_spec::widths;

/// Position register width.
pub const X_BITS: usize = widths::X_BITS as usize;
/// Velocity register width.
pub const V_BITS: usize = widths::V_BITS as usize;
/// Acceleration register width.
pub const A_BITS: usize = widths::A_BITS as usize;
/// Jerk register width.
pub const J_BITS: usize = widths::J_BITS as usize;
/// Snap (segment value) width.
pub const D_BITS: usize = widths::D_BITS as usize;
/// Segment tick count and tick counter width.
pub const TICK_BITS: usize = widths::TICK_BITS as usize;
/// Fractional bits of the position register below the output LSB.
pub const FRAC: usize = widths::FRAC_BITS as usize;
/// Width of the whole-LSB position output (`x >> FRAC`, truncated).
pub const POSITION_BITS: usize = widths::POSITION_BITS as usize;
/// Segment address within a bank: `max_segments` = 2^ADDR_BITS.
pub const ADDR_BITS: usize = widths::ADDR_BITS as usize;
/// Segment index and count width (holds 0..=2^ADDR_BITS).
pub const INDEX_BITS: usize = widths::INDEX_BITS as usize;
/// Memory address: bank bit and segment address.
pub const MEM_ADDR_BITS: usize = ADDR_BITS + 1;

/// A port's rust-hdl type from its kind and width in a `snapgen_spec` port list.
macro_rules! hdl_type {
    (bit, $b:expr) => {
        Bit
    };
    (bits, $b:expr) => {
        Bits<{ ($b) as usize }>
    };
}
pub(crate) use hdl_type;

/// A rust-hdl block whose ports are a `snapgen_spec` port list (called through
/// `with_motion_core_ports!` or `with_io_top_ports!`): the struct, with the ports first, each
/// with its list's doc line, then `$children`; and `fn build($args) -> Self`, which makes each
/// child from its expression (which may use the arguments).
macro_rules! block_with_ports {
    (
        $(#[$meta:meta])*
        pub struct $name:ident ( $( $arg:ident : $aty:ty ),* ) {
            $( $(#[$cm:meta])* $child:ident : $cty:ty = $init:expr ),* $(,)?
        }
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        $(#[$meta])*
        #[derive(LogicBlock)]
        pub struct $name {
            #[doc = $cdoc]
            pub clock: Signal<In, Clock>,
            $( $( #[doc = $idoc] pub $i: Signal<In, $crate::hdl_type!($ik, $ib)>, )* )*
            $( $( #[doc = $odoc] pub $o: Signal<Out, $crate::hdl_type!($ok, $ob)>, )* )*
            $( $(#[$cm])* $child: $cty, )*
        }

        impl $name {
            /// The block, every port at its default, every child made from its expression.
            fn build($( $arg: $aty ),*) -> Self {
                $name {
                    clock: Default::default(),
                    $( $( $i: Default::default(), )* )*
                    $( $( $o: Default::default(), )* )*
                    $( $child: $init, )*
                }
            }
        }
    };
}
pub(crate) use block_with_ports;

const _: () = {
    assert!(
        V_BITS == A_BITS && A_BITS == J_BITS && J_BITS == D_BITS,
        "the generator supports equal v, a, j, d widths (sign extension is only into x)"
    );
    assert!(X_BITS > V_BITS && X_BITS <= 127 && X_BITS >= FRAC + POSITION_BITS);
};

/// Test support: each block's check by Yosys (rust-hdl's `yosys_validate` only parses).
/// Every block is also synthesised in full for the 7 series inside the designs that hold it
/// (`snapgen synth`, its test in `cli/tests/fpga.rs`, which fails on a latch) and for the ECP5
/// (`scripts/route.sh`); here each is checked on its own, so that a latch or an unsynthesisable
/// construct is found in the block that has it: Yosys's coarse synthesis (elaboration,
/// processes to cells, memories, no technology mapping), or the full `synth_xilinx` where a
/// test asks what the block maps to.
#[cfg(test)]
pub(crate) mod synth_check {
    use std::process::Command;

    use rust_hdl::prelude::Block;

    /// How far Yosys goes.
    #[derive(Clone, Copy)]
    pub enum Depth {
        /// Elaboration and coarse synthesis (`synth -run begin:fine`): processes become
        /// registers, multiplexers and latches, memories are found; no LUT mapping.
        Coarse,
        /// `synth_xilinx` for the 7 series, flattened.
        Xilinx,
    }

    /// Generates `uut`'s Verilog as `snapgen_NAME` (as [`crate::emit::emit`] finishes every
    /// design) and checks it with Yosys to `Coarse` depth; panics on a Yosys error or on any
    /// latch. Returns the `stat` text.
    pub fn synth_block<U: Block>(name: &str, uut: U) -> String {
        synth_block_to(name, uut, Depth::Coarse)
    }

    /// [`synth_block`] to the given depth.
    pub fn synth_block_to<U: Block>(name: &str, uut: U, depth: Depth) -> String {
        let top = format!("snapgen_{name}");
        let mut waivers = crate::verilog::SEQUENCER_HINTS.to_vec();
        match name {
            "io_top" => waivers = crate::verilog::io_top_waivers(),
            "motion_core" => waivers = crate::verilog::core_waivers(),
            "swap_timer" => waivers.push(crate::verilog::SWAP_TIMER_WAIVER),
            _ => {}
        }
        let verilog = crate::emit::block_verilog(uut, &top, &waivers)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        synth_verilog(&top, &verilog, depth).unwrap_or_else(|e| panic!("{name}: {e}"))
    }

    /// Yosys on `verilog` (top module `top`) to `depth`: the `stat` text, or why not (a Yosys
    /// error, a latch, no statistics).
    pub fn synth_verilog(top: &str, verilog: &str, depth: Depth) -> Result<String, String> {
        let dir = std::env::temp_dir().join(format!("snapgen-synth-{}-{top}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(format!("{top}.v"));
        std::fs::write(&file, verilog).unwrap();
        let synth = match depth {
            Depth::Coarse => format!("synth -top {top} -flatten -run begin:fine"),
            Depth::Xilinx => format!("synth_xilinx -family xc7 -top {top} -flatten -noiopad"),
        };
        let out = Command::new("yosys")
            .args(["-q", "-p"])
            .arg(format!(
                "read_verilog {}; hierarchy -check -top {top}; {synth}; tee -q -o /dev/stdout stat",
                file.display()
            ))
            .output()
            .expect("yosys is installed by the test command (scripts/test.sh)");
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        let _ = std::fs::remove_dir_all(&dir);
        if !out.status.success() {
            return Err(format!(
                "yosys failed: {}",
                String::from_utf8_lossy(&out.stderr)
            ));
        }
        // Latches: the 7 series' cells, Yosys's fine cells and its coarse ones.
        for latch in ["LDCE", "LDPE", "$_DLATCH", "$dlatch", "$adlatch"] {
            if text.contains(latch) {
                return Err(format!("synthesised with a latch ({latch}):\n{text}"));
            }
        }
        if !text.contains("Number of cells") {
            return Err(format!("no statistics:\n{text}"));
        }
        Ok(text)
    }

    #[test]
    fn a_latch_is_found_at_either_depth() {
        let latch = "module snapgen_latch(input wire en, input wire d, output reg q);\n\
                     always @* if (en) q = d;\nendmodule\n";
        let flop = latch
            .replace("always @* if (en)", "always @(posedge en)")
            .replace("q = d", "q <= d");
        for depth in [Depth::Coarse, Depth::Xilinx] {
            let e = synth_verilog("snapgen_latch", latch, depth).unwrap_err();
            assert!(e.contains("latch"), "{e}");
            synth_verilog("snapgen_latch", &flop, depth).unwrap();
        }
    }
}
