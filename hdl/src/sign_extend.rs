//! Sign extension of the velocity into the position's width, as a tiny hand-written module:
//! `{{(X_BITS-V_BITS){v[msb]}}, v}`. rust-hdl's `bit_cast` zero-extends with a mask that
//! Verilator flags as a WIDTH mismatch, and its `Signed` casts have simulator bugs (see the
//! crate docs), so this block writes its own Verilog and models it for rust-hdl's simulator.

use rust_hdl::prelude::*;

use crate::{V_BITS, X_BITS};

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_extend_is_synthesizable() {
        let mut uut = SignExtend::default();
        uut.connect_all();
        let v = generate_verilog(&uut);
        yosys_validate("sign_extend", &v).unwrap();
        crate::synth_check::synth_xilinx("sign_extend", &v);
    }
}
