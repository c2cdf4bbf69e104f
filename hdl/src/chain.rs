//! The snap integrator chain: four accumulators that update together on every tick, each from
//! the previous tick's values (seed 000 eqs 72–75 with `Ts` folded into the shared-LSB
//! scaling, see `snapgen_model::format`):
//!
//! ```text
//! j <= j + d;   a <= a + j;   v <= v + a;   x <= x + sext(v)
//! ```
//!
//! Registers hold two's complement in `Bits` (addition is the same for signed and unsigned);
//! every adder wraps at its width exactly as `snapgen_model::ChainState::step`.

use rust_hdl::prelude::*;

use crate::sign_extend::SignExtend;
use crate::{A_BITS, D_BITS, FRAC, J_BITS, V_BITS, X_BITS};

/// The four accumulators.
#[derive(LogicBlock)]
pub struct SnapChain {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset: position to the centre of output cell 0, the rest to 0.
    pub reset: Signal<In, Bit>,
    /// Tick enable: integrate on this clock.
    pub tick: Signal<In, Bit>,
    /// Zero velocity, acceleration and jerk now (abort); the position holds.
    pub halt: Signal<In, Bit>,
    /// Load `load_x` into the position and zero the rest (after `reset` and `halt`).
    pub load: Signal<In, Bit>,
    /// The position to load.
    pub load_x: Signal<In, Bits<X_BITS>>,
    /// Snap input, raw two's complement.
    pub snap: Signal<In, Bits<D_BITS>>,
    /// Position, raw (`FRAC` fractional bits below the output LSB).
    pub x: Signal<Out, Bits<X_BITS>>,
    /// Velocity, raw.
    pub v: Signal<Out, Bits<V_BITS>>,
    /// Acceleration, raw.
    pub a: Signal<Out, Bits<A_BITS>>,
    /// Jerk, raw.
    pub j: Signal<Out, Bits<J_BITS>>,
    x_reg: DFF<Bits<X_BITS>>,
    v_reg: DFF<Bits<V_BITS>>,
    a_reg: DFF<Bits<A_BITS>>,
    j_reg: DFF<Bits<J_BITS>>,
    v_ext: SignExtend,
    home: Constant<Bits<X_BITS>>,
    zero: Constant<Bits<V_BITS>>,
}

impl Default for SnapChain {
    fn default() -> Self {
        SnapChain {
            clock: Default::default(),
            reset: Default::default(),
            tick: Default::default(),
            halt: Default::default(),
            load: Default::default(),
            load_x: Default::default(),
            snap: Default::default(),
            x: Default::default(),
            v: Default::default(),
            a: Default::default(),
            j: Default::default(),
            x_reg: Default::default(),
            v_reg: Default::default(),
            a_reg: Default::default(),
            j_reg: Default::default(),
            v_ext: Default::default(),
            // The centre of output cell 0: half an output LSB.
            home: Constant::new(Bits::<X_BITS>::default().replace_bit(FRAC - 1, true)),
            zero: Constant::new(Bits::default()),
        }
    }
}

impl Logic for SnapChain {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, x_reg, v_reg, a_reg, j_reg);
        // rust-hdl workaround: literals like `0.into()` are emitted as 32-bit constants
        // (Verilator WIDTH warnings); sized `Constant`s are used instead.
        self.v_ext.inp.next = self.v_reg.q.val();
        if self.reset.val() {
            self.x_reg.d.next = self.home.val();
            self.v_reg.d.next = self.zero.val();
            self.a_reg.d.next = self.zero.val();
            self.j_reg.d.next = self.zero.val();
        } else if self.halt.val() {
            self.v_reg.d.next = self.zero.val();
            self.a_reg.d.next = self.zero.val();
            self.j_reg.d.next = self.zero.val();
        } else if self.load.val() {
            self.x_reg.d.next = self.load_x.val();
            self.v_reg.d.next = self.zero.val();
            self.a_reg.d.next = self.zero.val();
            self.j_reg.d.next = self.zero.val();
        } else if self.tick.val() {
            // Eqs 72–75: all four from the previous tick's values.
            self.j_reg.d.next = self.j_reg.q.val() + self.snap.val();
            self.a_reg.d.next = self.a_reg.q.val() + self.j_reg.q.val();
            self.v_reg.d.next = self.v_reg.q.val() + self.a_reg.q.val();
            self.x_reg.d.next = self.x_reg.q.val() + self.v_ext.out.val();
        }
        self.x.next = self.x_reg.q.val();
        self.v.next = self.v_reg.q.val();
        self.a.next = self.a_reg.q.val();
        self.j.next = self.j_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snap_chain_is_synthesizable() {
        crate::synth_check::synth_block("snap_chain", SnapChain::default());
    }
}
