//! The reply queue: [`REPLY_QUEUE`] reply descriptors (kind, command, sequence, reason or
//! parameter), first in first out, between the executor and the reply transmitter (the
//! reference is `snapgen_model::io::executor::ReplyQueue`). On a clock it pops the head if
//! asked, then takes a push unless it was full before the clock; the executor does not push
//! while it is full (it drops the frame and flags it).
//!
//! Written as Verilog (a memory with one write port and an asynchronous read of the head,
//! LUT-RAM on the 7 series); the model runs in rust-hdl's simulator.

use rust_hdl::prelude::*;
use snapgen_model::io::executor::{ReplyDesc, ReplyKind};
use snapgen_model::io::reply_queue::ReplyQueue as QueueModel;
use snapgen_spec::rules::REPLY_QUEUE;

use crate::protocol_v::KIND_BITS;

const _: () = assert!(REPLY_QUEUE == 16, "the Verilog's pointers are 4 bits");

/// The queue.
#[derive(LogicBlock, Default)]
pub struct ReplyQueue {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset (empties it).
    pub reset: Signal<In, Bit>,
    /// Push a descriptor.
    pub push: Signal<In, Bit>,
    /// Its kind.
    pub push_kind: Signal<In, Bits<3>>,
    /// The command it answers.
    pub push_cmd: Signal<In, Bits<8>>,
    /// Its sequence number.
    pub push_seq: Signal<In, Bits<8>>,
    /// The NAK reason or CONFIG parameter.
    pub push_aux: Signal<In, Bits<8>>,
    /// Pop the head.
    pub pop: Signal<In, Bit>,
    /// A head is there.
    pub head_valid: Signal<Out, Bit>,
    /// Its kind.
    pub head_kind: Signal<Out, Bits<3>>,
    /// Its command.
    pub head_cmd: Signal<Out, Bits<8>>,
    /// Its sequence number.
    pub head_seq: Signal<Out, Bits<8>>,
    /// Its reason or parameter.
    pub head_aux: Signal<Out, Bits<8>>,
    /// Full.
    pub full: Signal<Out, Bit>,
    _model: QueueModel,
}

impl Logic for ReplyQueue {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let push = self.push.val().then(|| ReplyDesc {
                kind: ReplyKind::from_bits(self.push_kind.val().to_u64() as u8),
                cmd: self.push_cmd.val().to_u64() as u8,
                seq: self.push_seq.val().to_u64() as u8,
                aux: self.push_aux.val().to_u64() as u8,
            });
            self._model.clock(self.reset.val(), push, self.pop.val());
        }
        let head = self._model.head();
        let h = head.unwrap_or_default();
        self.head_valid.next = head.is_some();
        self.head_kind.next = (h.kind as u64).into();
        self.head_cmd.next = u64::from(h.cmd).into();
        self.head_seq.next = u64::from(h.seq).into();
        self.head_aux.next = u64::from(h.aux).into();
        self.full.next = self._model.full();
    }

    fn connect(&mut self) {
        self.head_valid.connect();
        self.head_kind.connect();
        self.head_cmd.connect();
        self.head_seq.connect();
        self.head_aux.connect();
        self.full.connect();
    }

    fn hdl(&self) -> Verilog {
        let w = KIND_BITS + 24;
        Verilog::Custom(format!(
            "\
// Entry: {{kind, cmd, seq, aux}}.
reg [{top}:0] entries [0:15];
integer init_k;
initial for (init_k = 0; init_k < 16; init_k = init_k + 1) entries[init_k] = {bits}'d0;
reg [3:0] head_q = 4'd0;
reg [3:0] tail_q = 4'd0;
reg [4:0] count_q = 5'd0;
wire was_full = count_q == 5'd16;
wire take = pop && (count_q != 5'd0);
wire put = push && !was_full;
always @(posedge clock) begin
   if (!reset && put) entries[tail_q] <= {{push_kind, push_cmd, push_seq, push_aux}};
end
always @(posedge clock) begin
   if (reset) begin
      head_q <= 4'd0;
      tail_q <= 4'd0;
      count_q <= 5'd0;
   end else begin
      if (take) head_q <= head_q + 4'd1;
      if (put) tail_q <= tail_q + 4'd1;
      count_q <= count_q + {{4'd0, put}} - {{4'd0, take}};
   end
end
wire [{top}:0] head_entry = entries[head_q];
always @(*) begin
   head_valid = count_q != 5'd0;
   {{head_kind, head_cmd, head_seq, head_aux}} = head_entry;
   full = was_full;
end
",
            top = w - 1,
            bits = w
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_queue_is_synthesizable() {
        crate::synth_check::synth_block("reply_queue", ReplyQueue::default());
    }
}
