//! One byte of CRC-16/CCITT-FALSE, combinational: `crc_out` is `crc_in` updated with `data`
//! (`snapgen_spec::wire::crc16_step`, whose polynomial [`CRC_POLY`] is written into the
//! Verilog). Written as a Verilog function with a loop, which `#[hdl_gen]` cannot express; in
//! rust-hdl's simulator the block runs `crc16_step` itself. The reply transmitter calls the
//! same Verilog function ([`crc16_function`]).

use rust_hdl::prelude::*;
use snapgen_spec::wire::{crc16_step, CRC_POLY};

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
        Verilog::Custom(format!(
            "{}always @(*) crc_out = crc16_step(crc_in, data);\n",
            crc16_function()
        ))
    }
}

/// The Verilog function `crc16_step(crc, byte)`.
pub fn crc16_function() -> String {
    format!(
        "\
function automatic [15:0] crc16_step(input [15:0] c, input [7:0] b);
   integer i;
   reg [15:0] acc;
   begin
      acc = c ^ {{b, 8'h00}};
      for (i = 0; i < 8; i = i + 1)
         acc = acc[15] ? ((acc << 1) ^ 16'h{CRC_POLY:04x}) : (acc << 1);
      crc16_step = acc;
   end
endfunction
"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc16_step_is_synthesizable() {
        crate::synth_check::synth_block("crc16", Crc16Step::default());
    }
}
