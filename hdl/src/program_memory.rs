//! Program memory: two banks of `2^ADDR_BITS` segments (tick count and snap), one written
//! while the other plays (double buffering). Synchronous write, asynchronous read — Yosys maps
//! it to distributed LUT RAM on the 7 series — so the sequencer can fetch the next segment in
//! the same clock and play one-tick segments back to back.
//!
//! Two reads: any segment of a bank (the next one of the program playing), from the memory, and
//! segment 0 of a bank (the first of the program a start or a swap takes), from registers that
//! keep a copy of each bank's segment 0 (written with it; as a second port of the same memory
//! a synthesiser merged the two reads into one behind an address multiplexer). Both come from
//! registers' addresses; the sequencer chooses between the two entries after the reads, so
//! the swap's decision on a tick is not in front of the memory.
//!
//! rust-hdl has no asynchronous-read memory, so this block writes its Verilog by hand (as
//! rust-hdl's own `RAM` does) and models the same behaviour for rust-hdl's simulator.

use rust_hdl::prelude::*;

use crate::{ADDR_BITS, D_BITS, MEM_ADDR_BITS, TICK_BITS};

/// Two-bank segment memory.
#[derive(LogicBlock, Default)]
pub struct ProgramMemory {
    /// Fabric clock (write side).
    pub clock: Signal<In, Clock>,
    /// Write strobe.
    pub write_enable: Signal<In, Bit>,
    /// Bank to write.
    pub write_bank: Signal<In, Bit>,
    /// Segment address to write.
    pub write_address: Signal<In, Bits<ADDR_BITS>>,
    /// Segment tick count to write.
    pub write_ticks: Signal<In, Bits<TICK_BITS>>,
    /// Segment snap to write.
    pub write_snap: Signal<In, Bits<D_BITS>>,
    /// Bank to read.
    pub read_bank: Signal<In, Bit>,
    /// Segment address to read (asynchronous).
    pub read_address: Signal<In, Bits<ADDR_BITS>>,
    /// Tick count at `read_address`.
    pub read_ticks: Signal<Out, Bits<TICK_BITS>>,
    /// Snap at `read_address`.
    pub read_snap: Signal<Out, Bits<D_BITS>>,
    /// Bank whose segment 0 the second port reads.
    pub first_bank: Signal<In, Bit>,
    /// Tick count of segment 0 of `first_bank`.
    pub first_ticks: Signal<Out, Bits<TICK_BITS>>,
    /// Snap of segment 0 of `first_bank`.
    pub first_snap: Signal<Out, Bits<D_BITS>>,
    _sim_ticks: Vec<Bits<TICK_BITS>>,
    _sim_snap: Vec<Bits<D_BITS>>,
}

impl Logic for ProgramMemory {
    fn update(&mut self) {
        if self._sim_ticks.is_empty() {
            self._sim_ticks = vec![Bits::default(); 1 << MEM_ADDR_BITS];
            self._sim_snap = vec![Bits::default(); 1 << MEM_ADDR_BITS];
        }
        if self.clock.pos_edge() && self.write_enable.val() {
            let a = self.write_address.val().index()
                + (usize::from(self.write_bank.val()) << ADDR_BITS);
            self._sim_ticks[a] = self.write_ticks.val();
            self._sim_snap[a] = self.write_snap.val();
        }
        let r = self.read_address.val().index() + (usize::from(self.read_bank.val()) << ADDR_BITS);
        self.read_ticks.next = self._sim_ticks[r];
        self.read_snap.next = self._sim_snap[r];
        let f = usize::from(self.first_bank.val()) << ADDR_BITS;
        self.first_ticks.next = self._sim_ticks[f];
        self.first_snap.next = self._sim_snap[f];
    }

    fn connect(&mut self) {
        self.read_ticks.connect();
        self.read_snap.connect();
        self.first_ticks.connect();
        self.first_snap.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "\
// Segment memory: {depth} entries, bank bit on top of the address.
reg [{tmsb}:0] ticks_mem [0:{last}];
reg [{dmsb}:0] snap_mem [0:{last}];
integer i;
initial begin
   for (i = 0; i <= {last}; i = i + 1) begin
      ticks_mem[i] = {tick_bits}'d0;
      snap_mem[i] = {d_bits}'d0;
   end
end
// Segment 0 of each bank, also in registers.
reg [{tmsb}:0] first_ticks0 = {tick_bits}'d0, first_ticks1 = {tick_bits}'d0;
reg [{dmsb}:0] first_snap0 = {d_bits}'d0, first_snap1 = {d_bits}'d0;
always @(posedge clock) begin
   if (write_enable) begin
      ticks_mem[{{write_bank, write_address}}] <= write_ticks;
      snap_mem[{{write_bank, write_address}}] <= write_snap;
      if (write_address == {addr_bits}'d0) begin
         if (write_bank) begin
            first_ticks1 <= write_ticks;
            first_snap1 <= write_snap;
         end else begin
            first_ticks0 <= write_ticks;
            first_snap0 <= write_snap;
         end
      end
   end
end
always @(*) begin
   read_ticks = ticks_mem[{{read_bank, read_address}}];
   read_snap = snap_mem[{{read_bank, read_address}}];
   first_ticks = first_bank ? first_ticks1 : first_ticks0;
   first_snap = first_bank ? first_snap1 : first_snap0;
end
",
            depth = 1 << MEM_ADDR_BITS,
            last = (1 << MEM_ADDR_BITS) - 1,
            tmsb = TICK_BITS - 1,
            dmsb = D_BITS - 1,
            tick_bits = TICK_BITS,
            d_bits = D_BITS,
            addr_bits = ADDR_BITS,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn program_memory_is_synthesizable() {
        let stat = crate::synth_check::synth_block_to(
            "program_memory",
            ProgramMemory::default(),
            crate::synth_check::Depth::Xilinx,
        );
        // Asynchronous read: distributed (LUT) RAM, no block RAM.
        assert!(stat.contains("RAM64M") && !stat.contains("RAMB"), "{stat}");
    }
}
