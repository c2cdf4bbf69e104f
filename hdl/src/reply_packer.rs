//! The code, length and payload of a reply (docs/PROTOCOL.md), from its kind and the live
//! status: byte concatenation, written as Verilog (`#[hdl_gen]` has no concatenation) and
//! modelled for rust-hdl's simulator. Payload byte 0 is bits 7:0.

use rust_hdl::prelude::*;

use crate::X_BITS;

/// Reply kinds.
pub mod kind {
    /// VERSION.
    pub const VERSION: u64 = 0;
    /// ACK.
    pub const ACK: u64 = 1;
    /// NAK.
    pub const NAK: u64 = 2;
    /// STATUS.
    pub const STATUS: u64 = 3;
    /// POSITION.
    pub const POSITION: u64 = 4;
    /// TELEMETRY.
    pub const TELEMETRY: u64 = 5;
}

/// Payload bits (22 bytes, the longest reply).
pub const PAYLOAD_BITS: usize = 176;

/// The packer.
#[derive(LogicBlock, Default)]
pub struct ReplyPacker {
    /// Reply kind (see [`kind`]).
    pub kind: Signal<In, Bits<3>>,
    /// Command acknowledged or rejected.
    pub cmd: Signal<In, Bits<8>>,
    /// NAK reason.
    pub reason: Signal<In, Bits<8>>,
    /// Status: state bits.
    pub state: Signal<In, Bits<8>>,
    /// Status: error flags.
    pub errors: Signal<In, Bits<8>>,
    /// Status: ticks.
    pub tick_count: Signal<In, Bits<32>>,
    /// Status: position (output LSBs).
    pub position: Signal<In, Bits<32>>,
    /// Status: velocity (top 32 bits).
    pub velocity: Signal<In, Bits<32>>,
    /// Status: encoder count.
    pub encoder: Signal<In, Bits<32>>,
    /// Status: bad CRC frames.
    pub bad_crc: Signal<In, Bits<16>>,
    /// Status: bad frames.
    pub bad_frames: Signal<In, Bits<16>>,
    /// Position register.
    pub x: Signal<In, Bits<X_BITS>>,
    /// Reply code.
    pub code: Signal<Out, Bits<8>>,
    /// Payload length.
    pub len: Signal<Out, Bits<8>>,
    /// Payload.
    pub payload: Signal<Out, Bits<PAYLOAD_BITS>>,
}

fn bits<const N: usize>(bytes: &[u8]) -> Bits<N> {
    let mut b = Bits::<N>::default();
    for (k, byte) in bytes.iter().enumerate() {
        for i in 0..8 {
            if k * 8 + i < N && (byte >> i) & 1 == 1 {
                b = b.replace_bit(k * 8 + i, true);
            }
        }
    }
    b
}

impl ReplyPacker {
    fn status_bytes(&self) -> Vec<u8> {
        let u = |b: u64, n: usize| b.to_le_bytes()[..n].to_vec();
        let mut p = vec![
            self.state.val().to_u64() as u8,
            self.errors.val().to_u64() as u8,
        ];
        p.extend(u(self.tick_count.val().to_u64(), 4));
        p.extend(u(self.position.val().to_u64(), 4));
        p.extend(u(self.velocity.val().to_u64(), 4));
        p.extend(u(self.encoder.val().to_u64(), 4));
        p.extend(u(self.bad_crc.val().to_u64(), 2));
        p.extend(u(self.bad_frames.val().to_u64(), 2));
        p
    }
}

impl Logic for ReplyPacker {
    fn update(&mut self) {
        let cmd = self.cmd.val().to_u64() as u8;
        let (code, payload): (u8, Vec<u8>) = match self.kind.val().to_u64() {
            kind::VERSION => (0x41, vec![1, 32, 13]),
            kind::ACK => (0x7E, vec![cmd]),
            kind::NAK => (0x7F, vec![cmd, self.reason.val().to_u64() as u8]),
            kind::STATUS => (0x47, self.status_bytes()),
            kind::POSITION => (0x49, self.x.val().to_u128().to_le_bytes()[..14].to_vec()),
            _ => (0x80, self.status_bytes()),
        };
        self.code.next = u64::from(code).into();
        self.len.next = (payload.len() as u64).into();
        self.payload.next = bits(&payload);
    }

    fn connect(&mut self) {
        self.code.connect();
        self.len.connect();
        self.payload.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(
            "\
wire [175:0] status_block = {bad_frames, bad_crc, encoder, velocity, position, tick_count, errors, state};
always @(*) begin
   case (kind)
      3'd0: begin code = 8'h41; len = 8'd3; payload = {152'd0, 8'd13, 8'd32, 8'd1}; end
      3'd1: begin code = 8'h7E; len = 8'd1; payload = {168'd0, cmd}; end
      3'd2: begin code = 8'h7F; len = 8'd2; payload = {160'd0, reason, cmd}; end
      3'd3: begin code = 8'h47; len = 8'd22; payload = status_block; end
      3'd4: begin code = 8'h49; len = 8'd14; payload = {64'd0, x}; end
      default: begin code = 8'h80; len = 8'd22; payload = status_block; end
   endcase
end
"
            .into(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_packer_is_synthesizable() {
        let mut uut = ReplyPacker::default();
        uut.connect_all();
        let v = generate_verilog(&uut);
        yosys_validate("reply_packer", &v).unwrap();
        crate::synth_check::synth_xilinx("reply_packer", &v);
    }
}
