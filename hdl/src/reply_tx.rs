//! Reply transmitter: on `request` it takes the reply kind, command, sequence and reason,
//! snapshots the payload from the packer, and writes the frame — start byte, length, code,
//! sequence, payload, CRC-16 low then high — into the transmit FIFO one byte per clock while it
//! is not full. One request waits while a reply is being written; a telemetry request is taken
//! only when nothing else waits.

use rust_hdl::prelude::*;

use crate::crc16::Crc16Step;
use crate::reply_packer::{ReplyPacker, PAYLOAD_BITS};
use crate::X_BITS;

/// The transmitter.
#[derive(LogicBlock)]
pub struct ReplyTx {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Pulse: send a reply.
    pub request: Signal<In, Bit>,
    /// Reply kind.
    pub kind: Signal<In, Bits<3>>,
    /// Command acknowledged or rejected.
    pub cmd: Signal<In, Bits<8>>,
    /// Sequence number.
    pub seq: Signal<In, Bits<8>>,
    /// NAK reason.
    pub reason: Signal<In, Bits<8>>,
    /// Pulse: send telemetry when free.
    pub telemetry: Signal<In, Bit>,
    /// Status: state bits.
    pub state: Signal<In, Bits<8>>,
    /// Status: error flags.
    pub errors: Signal<In, Bits<8>>,
    /// Status: ticks.
    pub tick_count: Signal<In, Bits<32>>,
    /// Status: position.
    pub position: Signal<In, Bits<32>>,
    /// Status: velocity.
    pub velocity: Signal<In, Bits<32>>,
    /// Status: encoder.
    pub encoder: Signal<In, Bits<32>>,
    /// Status: bad CRC frames.
    pub bad_crc: Signal<In, Bits<16>>,
    /// Status: bad frames.
    pub bad_frames: Signal<In, Bits<16>>,
    /// Position register.
    pub x: Signal<In, Bits<X_BITS>>,
    /// Transmit FIFO is full.
    pub fifo_full: Signal<In, Bit>,
    /// Pulse: write `fifo_data`.
    pub fifo_write: Signal<Out, Bit>,
    /// Byte to write.
    pub fifo_data: Signal<Out, Bits<8>>,
    /// A reply is being written.
    pub busy: Signal<Out, Bit>,
    packer: ReplyPacker,
    step: Crc16Step,
    active: DFF<Bit>,
    index: DFF<Bits<8>>,
    len: DFF<Bits<8>>,
    code: DFF<Bits<8>>,
    seq_reg: DFF<Bits<8>>,
    payload: DFF<Bits<PAYLOAD_BITS>>,
    crc: DFF<Bits<16>>,
    pending: DFF<Bit>,
    p_kind: DFF<Bits<3>>,
    p_cmd: DFF<Bits<8>>,
    p_seq: DFF<Bits<8>>,
    p_reason: DFF<Bits<8>>,
    tel_pending: DFF<Bit>,
    sel_kind: Signal<Local, Bits<3>>,
    sel_cmd: Signal<Local, Bits<8>>,
    sel_reason: Signal<Local, Bits<8>>,
    sel_seq: Signal<Local, Bits<8>>,
    launch: Signal<Local, Bit>,
    out_byte: Signal<Local, Bits<8>>,
    start_byte: Constant<Bits<8>>,
    one: Constant<Bits<8>>,
    four: Constant<Bits<8>>,
    five: Constant<Bits<8>>,
    zero8: Constant<Bits<8>>,
    crc_init: Constant<Bits<16>>,
    tel_kind: Constant<Bits<3>>,
}

impl Default for ReplyTx {
    fn default() -> Self {
        ReplyTx {
            clock: Default::default(),
            reset: Default::default(),
            request: Default::default(),
            kind: Default::default(),
            cmd: Default::default(),
            seq: Default::default(),
            reason: Default::default(),
            telemetry: Default::default(),
            state: Default::default(),
            errors: Default::default(),
            tick_count: Default::default(),
            position: Default::default(),
            velocity: Default::default(),
            encoder: Default::default(),
            bad_crc: Default::default(),
            bad_frames: Default::default(),
            x: Default::default(),
            fifo_full: Default::default(),
            fifo_write: Default::default(),
            fifo_data: Default::default(),
            busy: Default::default(),
            packer: Default::default(),
            step: Default::default(),
            active: Default::default(),
            index: Default::default(),
            len: Default::default(),
            code: Default::default(),
            seq_reg: Default::default(),
            payload: Default::default(),
            crc: Default::default(),
            pending: Default::default(),
            p_kind: Default::default(),
            p_cmd: Default::default(),
            p_seq: Default::default(),
            p_reason: Default::default(),
            tel_pending: Default::default(),
            sel_kind: Default::default(),
            sel_cmd: Default::default(),
            sel_reason: Default::default(),
            sel_seq: Default::default(),
            launch: Default::default(),
            out_byte: Default::default(),
            start_byte: Constant::new(0xA5.into()),
            one: Constant::new(1.into()),
            four: Constant::new(4.into()),
            five: Constant::new(5.into()),
            zero8: Constant::new(0.into()),
            crc_init: Constant::new(0xFFFF.into()),
            tel_kind: Constant::new(5.into()),
        }
    }
}

impl Logic for ReplyTx {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            active,
            index,
            len,
            code,
            seq_reg,
            payload,
            crc,
            pending,
            p_kind,
            p_cmd,
            p_seq,
            p_reason,
            tel_pending
        );
        // What starts next when idle: a waiting request, else a new one, else telemetry.
        self.launch.next = false;
        self.sel_kind.next = self.kind.val();
        self.sel_cmd.next = self.cmd.val();
        self.sel_reason.next = self.reason.val();
        self.sel_seq.next = self.seq.val();
        if !self.active.q.val() {
            if self.pending.q.val() {
                self.launch.next = true;
                self.sel_kind.next = self.p_kind.q.val();
                self.sel_cmd.next = self.p_cmd.q.val();
                self.sel_reason.next = self.p_reason.q.val();
                self.sel_seq.next = self.p_seq.q.val();
            } else if self.request.val() {
                self.launch.next = true;
            } else if self.tel_pending.q.val() | self.telemetry.val() {
                self.launch.next = true;
                self.sel_kind.next = self.tel_kind.val();
                self.sel_seq.next = self.zero8.val();
            }
        }
        self.packer.kind.next = self.sel_kind.val();
        self.packer.cmd.next = self.sel_cmd.val();
        self.packer.reason.next = self.sel_reason.val();
        self.packer.state.next = self.state.val();
        self.packer.errors.next = self.errors.val();
        self.packer.tick_count.next = self.tick_count.val();
        self.packer.position.next = self.position.val();
        self.packer.velocity.next = self.velocity.val();
        self.packer.encoder.next = self.encoder.val();
        self.packer.bad_crc.next = self.bad_crc.val();
        self.packer.bad_frames.next = self.bad_frames.val();
        self.packer.x.next = self.x.val();
        // The byte at `index`: start, length, code, sequence, payload, CRC low, CRC high.
        if self.index.q.val() == self.zero8.val() {
            self.out_byte.next = self.start_byte.val();
        } else if self.index.q.val() == self.one.val() {
            self.out_byte.next = self.len.q.val();
        } else if self.index.q.val() == (self.one.val() + self.one.val()) {
            self.out_byte.next = self.code.q.val();
        } else if self.index.q.val() == (self.four.val() - self.one.val()) {
            self.out_byte.next = self.seq_reg.q.val();
        } else if self.index.q.val() < (self.len.q.val() + self.four.val()) {
            self.out_byte.next = self.payload.q.val().get_bits::<8>(0);
        } else if self.index.q.val() == (self.len.q.val() + self.four.val()) {
            self.out_byte.next = self.crc.q.val().get_bits::<8>(0);
        } else {
            self.out_byte.next = self.crc.q.val().get_bits::<8>(8);
        }
        self.step.crc_in.next = self.crc.q.val();
        self.step.data.next = self.out_byte.val();
        self.fifo_write.next = false;
        self.fifo_data.next = self.out_byte.val();
        if self.reset.val() {
            self.active.d.next = false;
            self.pending.d.next = false;
            self.tel_pending.d.next = false;
        } else {
            if self.launch.val() {
                self.active.d.next = true;
                self.index.d.next = self.zero8.val();
                self.len.d.next = self.packer.len.val();
                self.code.d.next = self.packer.code.val();
                self.seq_reg.d.next = self.sel_seq.val();
                self.payload.d.next = self.packer.payload.val();
                self.crc.d.next = self.crc_init.val();
                if self.pending.q.val() {
                    self.pending.d.next = false;
                } else if !self.request.val() {
                    self.tel_pending.d.next = false;
                }
            }
            // A request that cannot start now waits (one deep).
            if self.request.val() & (self.active.q.val() | self.pending.q.val()) {
                self.pending.d.next = true;
                self.p_kind.d.next = self.kind.val();
                self.p_cmd.d.next = self.cmd.val();
                self.p_seq.d.next = self.seq.val();
                self.p_reason.d.next = self.reason.val();
            }
            if self.telemetry.val()
                & !(self.launch.val() & (self.sel_kind.val() == self.tel_kind.val()))
            {
                self.tel_pending.d.next = true;
            }
            if self.active.q.val() & !self.fifo_full.val() {
                self.fifo_write.next = true;
                self.index.d.next = self.index.q.val() + self.one.val();
                if (self.index.q.val() > self.zero8.val())
                    & (self.index.q.val() < (self.len.q.val() + self.four.val()))
                {
                    self.crc.d.next = self.step.crc_out.val();
                }
                if (self.index.q.val() >= self.four.val())
                    & (self.index.q.val() < (self.len.q.val() + self.four.val()))
                {
                    self.payload.d.next = self.payload.q.val() >> 8;
                }
                if self.index.q.val() == (self.len.q.val() + self.five.val()) {
                    self.active.d.next = false;
                }
            }
        }
        self.busy.next = self.active.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_tx_is_synthesizable() {
        let mut uut = ReplyTx::default();
        uut.connect_all();
        let v = crate::verilog::direct_clocks(&generate_verilog(&uut));
        yosys_validate("reply_tx", &v).unwrap();
        crate::synth_check::synth_xilinx("reply_tx", &v);
    }
}
