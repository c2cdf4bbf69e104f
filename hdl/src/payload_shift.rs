//! The last 18 payload bytes of a frame, shifted in one at a time (the newest at the top), with
//! the command fields read from where each command's payload lands (docs/PROTOCOL.md):
//! LOAD_SEGMENT (18 bytes): index, ticks, snap; COMMIT (1 or 2 bytes): count and cruise
//! segment; CONFIGURE (5 bytes): param, value. The field wiring is byte concatenation, which `#[hdl_gen]` cannot express, so
//! this block writes its Verilog and models it for rust-hdl's simulator.

use rust_hdl::prelude::*;

use crate::{D_BITS, TICK_BITS};

/// Payload bytes kept.
pub const PAYLOAD_BYTES: usize = 18;

/// Payload shift register and field decoder.
#[derive(LogicBlock, Default)]
pub struct PayloadShift {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Shift `data` in.
    pub shift: Signal<In, Bit>,
    /// Payload byte.
    pub data: Signal<In, Bits<8>>,
    /// LOAD_SEGMENT index.
    pub seg_index: Signal<Out, Bits<8>>,
    /// LOAD_SEGMENT ticks.
    pub seg_ticks: Signal<Out, Bits<TICK_BITS>>,
    /// LOAD_SEGMENT snap.
    pub seg_snap: Signal<Out, Bits<D_BITS>>,
    /// COMMIT count (one-byte COMMIT) or cruise index (two-byte COMMIT): the last byte.
    pub commit_count: Signal<Out, Bits<8>>,
    /// COMMIT count of a two-byte COMMIT: the byte before the last.
    pub commit_first: Signal<Out, Bits<8>>,
    /// CONFIGURE parameter.
    pub cfg_param: Signal<Out, Bits<8>>,
    /// CONFIGURE value.
    pub cfg_value: Signal<Out, Bits<32>>,
    _bytes: Vec<u8>,
}

fn le(bytes: &[u8]) -> u128 {
    bytes
        .iter()
        .rev()
        .fold(0u128, |acc, &b| (acc << 8) | u128::from(b))
}

fn bits<const N: usize>(v: u128) -> Bits<N> {
    let mut b = Bits::<N>::default();
    for i in 0..N {
        if (v >> i) & 1 == 1 {
            b = b.replace_bit(i, true);
        }
    }
    b
}

impl Logic for PayloadShift {
    fn update(&mut self) {
        if self._bytes.len() != PAYLOAD_BYTES {
            self._bytes = vec![0; PAYLOAD_BYTES];
        }
        if self.clock.pos_edge() && self.shift.val() {
            self._bytes.remove(0);
            self._bytes.push(self.data.val().to_u64() as u8);
        }
        let p = &self._bytes;
        self.seg_index.next = bits(u128::from(p[0]));
        self.seg_ticks.next = bits(le(&p[1..5]));
        self.seg_snap.next = bits(le(&p[5..18]));
        self.commit_count.next = bits(u128::from(p[17]));
        self.commit_first.next = bits(u128::from(p[16]));
        self.cfg_param.next = bits(u128::from(p[13]));
        self.cfg_value.next = bits(le(&p[14..18]));
    }

    fn connect(&mut self) {
        self.seg_index.connect();
        self.seg_ticks.connect();
        self.seg_snap.connect();
        self.commit_count.connect();
        self.commit_first.connect();
        self.cfg_param.connect();
        self.cfg_value.connect();
    }

    fn hdl(&self) -> Verilog {
        let snap: Vec<String> = (5..18).rev().map(|k| format!("p[{k}]")).collect();
        Verilog::Custom(format!(
            "\
reg [7:0] p [0:17];
integer k;
initial begin
   for (k = 0; k < 18; k = k + 1) p[k] = 8'h00;
end
always @(posedge clock) begin
   if (shift) begin
      for (k = 0; k < 17; k = k + 1) p[k] <= p[k + 1];
      p[17] <= data;
   end
end
always @(*) begin
   seg_index = p[0];
   seg_ticks = {{p[4], p[3], p[2], p[1]}};
   seg_snap = {{{snap}}};
   commit_count = p[17];
   commit_first = p[16];
   cfg_param = p[13];
   cfg_value = {{p[17], p[16], p[15], p[14]}};
end
",
            snap = snap.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn payload_shift_is_synthesizable() {
        let mut uut = PayloadShift::default();
        uut.connect_all();
        let v = generate_verilog(&uut);
        yosys_validate("payload_shift", &v).unwrap();
        crate::synth_check::synth_xilinx("payload_shift", &v);
    }
}
