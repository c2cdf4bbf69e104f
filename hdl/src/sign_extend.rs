//! Sign extension of the velocity into the position's width, as a tiny hand-written module:
//! `{{(X_BITS-V_BITS){v[msb]}}, v}`. rust-hdl's `bit_cast` zero-extends with a mask that
//! Verilator flags as a WIDTH mismatch, and its `Signed` casts have simulator bugs (see the
//! crate docs), so this block writes its own Verilog and models it for rust-hdl's simulator.

use rust_hdl::prelude::*;

use crate::{FRAC, POSITION_BITS, V_BITS, X_BITS};

const _: () = assert!(FRAC + POSITION_BITS == X_BITS);

/// `out = sign_extend(inp)`.
#[derive(LogicBlock, Default)]
pub struct SignExtend {
    /// Two's complement input.
    pub inp: Signal<In, Bits<V_BITS>>,
    /// The same value, `X_BITS` wide.
    pub out: Signal<Out, Bits<X_BITS>>,
}

impl Logic for SignExtend {
    fn update(&mut self) {
        let v = self.inp.val();
        let mut out = bit_cast::<X_BITS, V_BITS>(v);
        if v.get_bit(V_BITS - 1) {
            for i in V_BITS..X_BITS {
                out = out.replace_bit(i, true);
            }
        }
        self.out.next = out;
    }

    fn connect(&mut self) {
        self.out.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "always @(*) out = {{{{{ext}{{inp[{msb}]}}}}, inp}};\n",
            ext = X_BITS - V_BITS,
            msb = V_BITS - 1
        ))
    }
}

/// The centre of an output cell: `{cell, 1'b1, 0…}` — the position register at rest on the
/// 32-bit output LSB `cell` (what the chain loads when the reference takes the encoder's
/// position). A tiny hand-written module for the same reasons as [`SignExtend`].
#[derive(LogicBlock, Default)]
pub struct CellCentre {
    /// The cell (output LSBs, 32 bits; `cell` is a Verilog keyword).
    pub position: Signal<In, Bits<POSITION_BITS>>,
    /// The position register.
    pub out: Signal<Out, Bits<X_BITS>>,
}

impl Logic for CellCentre {
    fn update(&mut self) {
        let mut out = Bits::<X_BITS>::default().replace_bit(FRAC - 1, true);
        for k in 0..POSITION_BITS {
            out = out.replace_bit(FRAC + k, self.position.val().get_bit(k));
        }
        self.out.next = out;
    }

    fn connect(&mut self) {
        self.out.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "always @(*) out = {{position, 1'b1, {}'d0}};\n",
            FRAC - 1
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_extend_is_synthesizable() {
        crate::synth_check::synth_block("sign_extend", SignExtend::default());
    }

    #[test]
    fn cell_centre_is_synthesizable() {
        crate::synth_check::synth_block("cell_centre", CellCentre::default());
    }
}
