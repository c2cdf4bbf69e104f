//! One byte of CRC-16/CCITT-FALSE (polynomial 0x1021), combinational: `crc_out` is `crc_in`
//! updated with `data` (`snapgen_model::protocol::crc16` one byte at a time). Written as a
//! Verilog function with a loop, which `#[hdl_gen]` cannot express; modelled in Rust for
//! rust-hdl's simulator.

use rust_hdl::prelude::*;

/// CRC-16/CCITT-FALSE byte step.
#[derive(LogicBlock, Default)]
pub struct Crc16Step {
    /// CRC so far.
    pub crc_in: Signal<In, Bits<16>>,
    /// Next byte.
    pub data: Signal<In, Bits<8>>,
    /// CRC after the byte.
    pub crc_out: Signal<Out, Bits<16>>,
}

/// The same step in Rust.
pub fn crc16_step(crc: u16, b: u8) -> u16 {
    let mut x = crc ^ (u16::from(b) << 8);
    for _ in 0..8 {
        x = if x & 0x8000 != 0 {
            (x << 1) ^ 0x1021
        } else {
            x << 1
        };
    }
    x
}

impl Logic for Crc16Step {
    fn update(&mut self) {
        let c = crc16_step(
            self.crc_in.val().to_u64() as u16,
            self.data.val().to_u64() as u8,
        );
        self.crc_out.next = u64::from(c).into();
    }

    fn connect(&mut self) {
        self.crc_out.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(
            "\
function [15:0] crc16_step;
   input [15:0] c;
   input [7:0] b;
   integer i;
   reg [15:0] acc;
   begin
      acc = c ^ {b, 8'h00};
      for (i = 0; i < 8; i = i + 1)
         acc = acc[15] ? ((acc << 1) ^ 16'h1021) : (acc << 1);
      crc16_step = acc;
   end
endfunction
always @(*) crc_out = crc16_step(crc_in, data);
"
            .into(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc16_step_matches_the_model() {
        let mut c = 0xFFFF;
        for &b in b"123456789" {
            c = crc16_step(c, b);
        }
        assert_eq!(c, snapgen_model::protocol::crc16(b"123456789"));
    }

    #[test]
    fn crc16_step_is_synthesizable() {
        let mut uut = Crc16Step::default();
        uut.connect_all();
        let v = generate_verilog(&uut);
        yosys_validate("crc16", &v).unwrap();
        crate::synth_check::synth_xilinx("crc16", &v);
    }
}
