//! The last payload bytes of a frame, shifted in one at a time (the last [`PAYLOAD_BYTES`],
//! the newest in bits 7:0, as `snapgen_model::io::frame_rx::FrameRxOutputs::payload`, so byte
//! `k` of an `n`-byte payload is bits `8(n-1-k) +: 8`), and the CRC the frame carried, taken
//! whole when its high byte arrives. The payload is complete as soon as its last byte is in,
//! two bytes before the frame is checked, as in the model: the executor registers fields of it
//! (a SWAP_AT's lead) on the clocks before it executes the frame. The longest command payload
//! (LOAD_SEGMENT) fits; a longer frame is refused by its length anyway. Written as Verilog (a
//! byte shift is a concatenation, which `#[hdl_gen]` cannot express) and modelled for
//! rust-hdl's simulator.

use rust_hdl::prelude::*;
use snapgen_spec::COMMANDS;

use crate::sim_bits::from_u128;

/// Payload bytes kept: the longest command payload.
pub const PAYLOAD_BYTES: usize = {
    let mut most = 0;
    let mut k = 0;
    while k < COMMANDS.len() {
        if COMMANDS[k].len as usize > most {
            most = COMMANDS[k].len as usize;
        }
        k += 1;
    }
    most
};
/// Their bits.
pub const PAYLOAD_BITS: usize = 8 * PAYLOAD_BYTES;

/// Payload shift register and received CRC.
#[derive(LogicBlock, Default)]
pub struct PayloadShift {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Shift `data` in (a payload byte).
    pub shift: Signal<In, Bit>,
    /// Take the CRC: `data` is its high byte, `crc_low` its low byte.
    pub take_crc: Signal<In, Bit>,
    /// The byte.
    pub data: Signal<In, Bits<8>>,
    /// The CRC's low byte, as received the byte before.
    pub crc_low: Signal<In, Bits<8>>,
    /// The payload bytes, newest in bits 7:0.
    pub bytes: Signal<Out, Bits<PAYLOAD_BITS>>,
    /// The CRC the last frame carried (its low byte came first).
    pub crc: Signal<Out, Bits<16>>,
    _held: [u8; PAYLOAD_BYTES],
    _crc: u16,
}

impl Logic for PayloadShift {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            if self.shift.val() {
                self._held.copy_within(0..PAYLOAD_BYTES - 1, 1);
                self._held[0] = self.data.val().to_u64() as u8;
            }
            if self.take_crc.val() {
                self._crc = u16::from_le_bytes([
                    self.crc_low.val().to_u64() as u8,
                    self.data.val().to_u64() as u8,
                ]);
            }
        }
        // _held[0] is the newest payload byte.
        let p = &self._held;
        let low = (0..16).fold(0u128, |v, k| v | (u128::from(p[k]) << (8 * k)));
        let mut b: Bits<PAYLOAD_BITS> = from_u128(low);
        for (k, &byte) in p.iter().enumerate().skip(16) {
            for bit in 0..8 {
                b = b.replace_bit(8 * k + bit, (byte >> bit) & 1 == 1);
            }
        }
        self.bytes.next = b;
        self.crc.next = u64::from(self._crc).into();
    }

    fn connect(&mut self) {
        self.bytes.connect();
        self.crc.connect();
    }

    fn hdl(&self) -> Verilog {
        let top = PAYLOAD_BITS - 1;
        Verilog::Custom(format!(
            "\
reg [{top}:0] held = {bits}'d0;             // the payload, newest byte in 7:0
reg [15:0] crc_held = 16'd0;
always @(posedge clock) begin
   if (shift) held <= {{held[{below}:0], data}};
   if (take_crc) crc_held <= {{data, crc_low}};
end
always @(*) begin
   bytes = held;
   crc = crc_held;
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
