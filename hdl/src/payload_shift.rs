//! The last bytes of a frame, shifted in one at a time: its payload (the last
//! [`PAYLOAD_BYTES`], the newest in bits 7:0, as
//! `snapgen_model::io::frame_rx::FrameRxOutputs::payload`, so byte `k` of an `n`-byte payload
//! is bits `8(n-1-k) +: 8`) followed by its two CRC bytes. The longest command payload
//! (LOAD_SEGMENT) fits; a longer frame is refused by its length anyway. Written as Verilog (a
//! byte shift is a concatenation, which `#[hdl_gen]` cannot express) and modelled for
//! rust-hdl's simulator.

use rust_hdl::prelude::*;
use snapgen_model::protocol::COMMANDS;

use crate::sim_bits::from_u128;

/// Payload bytes kept: the longest command payload.
pub const PAYLOAD_BYTES: usize = 18;
/// Their bits.
pub const PAYLOAD_BITS: usize = 8 * PAYLOAD_BYTES;
/// Bytes held: the payload and the CRC.
const HELD: usize = PAYLOAD_BYTES + 2;

const _: () = {
    let mut k = 0;
    while k < COMMANDS.len() {
        assert!(COMMANDS[k].len as usize <= PAYLOAD_BYTES);
        k += 1;
    }
};

/// Payload and CRC shift register.
#[derive(LogicBlock, Default)]
pub struct PayloadShift {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Shift `data` in (a payload or CRC byte).
    pub shift: Signal<In, Bit>,
    /// The byte.
    pub data: Signal<In, Bits<8>>,
    /// The payload bytes, newest in bits 7:0 (valid once the CRC bytes are in).
    pub bytes: Signal<Out, Bits<PAYLOAD_BITS>>,
    /// The CRC the frame carried (its low byte came first).
    pub crc: Signal<Out, Bits<16>>,
    _held: [u8; HELD],
}

impl Logic for PayloadShift {
    fn update(&mut self) {
        if self.clock.pos_edge() && self.shift.val() {
            self._held.copy_within(0..HELD - 1, 1);
            self._held[0] = self.data.val().to_u64() as u8;
        }
        // _held[0] is the CRC's high byte, _held[1] its low byte, _held[2..] the payload.
        let p = &self._held[2..];
        let low = (0..16).fold(0u128, |v, k| v | (u128::from(p[k]) << (8 * k)));
        let mut b: Bits<PAYLOAD_BITS> = from_u128(low);
        for (k, &byte) in p.iter().enumerate().skip(16) {
            for bit in 0..8 {
                b = b.replace_bit(8 * k + bit, (byte >> bit) & 1 == 1);
            }
        }
        self.bytes.next = b;
        self.crc.next = u64::from(u16::from_le_bytes([self._held[1], self._held[0]])).into();
    }

    fn connect(&mut self) {
        self.bytes.connect();
        self.crc.connect();
    }

    fn hdl(&self) -> Verilog {
        let top = 8 * HELD - 1;
        Verilog::Custom(format!(
            "\
reg [{top}:0] held = {bits}'d0;             // payload, then CRC low, CRC high (in 7:0)
always @(posedge clock) begin
   if (shift) held <= {{held[{below}:0], data}};
end
always @(*) begin
   bytes = held[{top}:16];
   crc = {{held[7:0], held[15:8]}};
end
",
            bits = top + 1,
            below = top - 8,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn payload_shift_is_synthesizable() {
        crate::synth_check::synth_block("payload_shift", PayloadShift::default());
    }
}
