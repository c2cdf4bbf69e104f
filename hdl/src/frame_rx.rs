//! Frame receiver (docs/PROTOCOL.md), as `snapgen_host::protocol::Decoder::device()`:
//! hunts for the start byte 0xA5, takes a length above 32 as noise (a 0xA5 there starts a new
//! frame), checks the CRC-16 over length, command, sequence and payload, and pulses `frame` or
//! `bad_crc` one clock after the last CRC byte. A frame cut short by an inter-byte gap of
//! `timeout` clocks, or by a UART framing error, is dropped with a `dropped` pulse.

use rust_hdl::prelude::*;
use snapgen_spec::wire::{CRC_INIT, DEVICE_MAX_PAYLOAD, START};

use crate::crc16::Crc16Step;
use crate::payload_shift::PayloadShift;
pub use crate::payload_shift::{PAYLOAD_BITS, PAYLOAD_BYTES};

/// The receiver.
#[derive(LogicBlock)]
pub struct FrameRx {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Received byte.
    pub data: Signal<In, Bits<8>>,
    /// `data` is valid on this clock.
    pub valid: Signal<In, Bit>,
    /// UART framing error on this clock.
    pub line_error: Signal<In, Bit>,
    /// Inter-byte timeout in clocks.
    pub timeout: Signal<In, Bits<32>>,
    /// Pulse: a frame with a good CRC.
    pub frame: Signal<Out, Bit>,
    /// Pulse: a frame with a bad CRC.
    pub bad_crc: Signal<Out, Bit>,
    /// Pulse: a partial frame was dropped.
    pub dropped: Signal<Out, Bit>,
    /// Command of the last frame.
    pub cmd: Signal<Out, Bits<8>>,
    /// Sequence number of the last frame.
    pub seq: Signal<Out, Bits<8>>,
    /// Payload length of the last frame.
    pub len: Signal<Out, Bits<8>>,
    /// The last payload bytes, the newest in bits 7:0 (byte `k` of an `n`-byte payload is
    /// bits `8(n-1-k) +: 8`).
    pub payload: Signal<Out, Bits<PAYLOAD_BITS>>,
    /// The CRC the last frame carried.
    pub crc: Signal<Out, Bits<16>>,
    step: Crc16Step,
    payload_bytes: PayloadShift,
    state: DFF<Bits<3>>,
    crc_acc: DFF<Bits<16>>,
    crc_lo: DFF<Bits<8>>,
    left: DFF<Bits<8>>,
    cmd_reg: DFF<Bits<8>>,
    seq_reg: DFF<Bits<8>>,
    len_reg: DFF<Bits<8>>,
    idle: DFF<Bits<32>>,
    frame_reg: DFF<Bit>,
    bad_reg: DFF<Bit>,
    dropped_reg: DFF<Bit>,
    hunt: Constant<Bits<3>>,
    s_len: Constant<Bits<3>>,
    s_cmd: Constant<Bits<3>>,
    s_seq: Constant<Bits<3>>,
    s_pay: Constant<Bits<3>>,
    s_crcl: Constant<Bits<3>>,
    s_crch: Constant<Bits<3>>,
    start_byte: Constant<Bits<8>>,
    max_len: Constant<Bits<8>>,
    byte_zero: Constant<Bits<8>>,
    byte_one: Constant<Bits<8>>,
    crc_init: Constant<Bits<16>>,
    idle_zero: Constant<Bits<32>>,
    idle_one: Constant<Bits<32>>,
}

impl Default for FrameRx {
    fn default() -> Self {
        FrameRx {
            clock: Default::default(),
            reset: Default::default(),
            data: Default::default(),
            valid: Default::default(),
            line_error: Default::default(),
            timeout: Default::default(),
            frame: Default::default(),
            bad_crc: Default::default(),
            dropped: Default::default(),
            cmd: Default::default(),
            seq: Default::default(),
            len: Default::default(),
            payload: Default::default(),
            crc: Default::default(),
            step: Default::default(),
            payload_bytes: Default::default(),
            state: Default::default(),
            crc_acc: Default::default(),
            crc_lo: Default::default(),
            left: Default::default(),
            cmd_reg: Default::default(),
            seq_reg: Default::default(),
            len_reg: Default::default(),
            idle: Default::default(),
            frame_reg: Default::default(),
            bad_reg: Default::default(),
            dropped_reg: Default::default(),
            hunt: Constant::new(0.into()),
            s_len: Constant::new(1.into()),
            s_cmd: Constant::new(2.into()),
            s_seq: Constant::new(3.into()),
            s_pay: Constant::new(4.into()),
            s_crcl: Constant::new(5.into()),
            s_crch: Constant::new(6.into()),
            start_byte: Constant::new(u64::from(START).into()),
            max_len: Constant::new((DEVICE_MAX_PAYLOAD as u64).into()),
            byte_zero: Constant::new(0.into()),
            byte_one: Constant::new(1.into()),
            crc_init: Constant::new(u64::from(CRC_INIT).into()),
            idle_zero: Constant::new(0.into()),
            idle_one: Constant::new(1.into()),
        }
    }
}

impl Logic for FrameRx {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, payload_bytes);
        dff_setup!(
            self,
            clock,
            state,
            crc_acc,
            crc_lo,
            left,
            cmd_reg,
            seq_reg,
            len_reg,
            idle,
            frame_reg,
            bad_reg,
            dropped_reg
        );
        self.step.crc_in.next = self.crc_acc.q.val();
        self.step.data.next = self.data.val();
        self.payload_bytes.data.next = self.data.val();
        // Payload bytes are kept as they arrive, the CRC when its high byte does (for the
        // executor's retry rule).
        self.payload_bytes.shift.next =
            self.valid.val() & (self.state.q.val() == self.s_pay.val()) & !self.reset.val();
        self.payload_bytes.take_crc.next = self.valid.val()
            & (self.state.q.val() == self.s_crch.val())
            & !self.reset.val()
            & !self.line_error.val();
        self.payload_bytes.crc_low.next = self.crc_lo.q.val();
        self.frame_reg.d.next = false;
        self.bad_reg.d.next = false;
        self.dropped_reg.d.next = false;
        if self.reset.val() {
            self.state.d.next = self.hunt.val();
            self.idle.d.next = self.idle_zero.val();
        } else if self.line_error.val() {
            if self.state.q.val() != self.hunt.val() {
                self.dropped_reg.d.next = true;
            }
            self.state.d.next = self.hunt.val();
            self.idle.d.next = self.idle_zero.val();
        } else if self.valid.val() {
            self.idle.d.next = self.idle_zero.val();
            if self.state.q.val() == self.hunt.val() {
                if self.data.val() == self.start_byte.val() {
                    self.state.d.next = self.s_len.val();
                    self.crc_acc.d.next = self.crc_init.val();
                }
            } else if self.state.q.val() == self.s_len.val() {
                if self.data.val() > self.max_len.val() {
                    // Not a frame: a 0xA5 here starts one.
                    if self.data.val() != self.start_byte.val() {
                        self.state.d.next = self.hunt.val();
                    }
                    self.crc_acc.d.next = self.crc_init.val();
                } else {
                    self.len_reg.d.next = self.data.val();
                    self.crc_acc.d.next = self.step.crc_out.val();
                    self.state.d.next = self.s_cmd.val();
                }
            } else if self.state.q.val() == self.s_cmd.val() {
                self.cmd_reg.d.next = self.data.val();
                self.crc_acc.d.next = self.step.crc_out.val();
                self.state.d.next = self.s_seq.val();
            } else if self.state.q.val() == self.s_seq.val() {
                self.seq_reg.d.next = self.data.val();
                self.crc_acc.d.next = self.step.crc_out.val();
                self.left.d.next = self.len_reg.q.val();
                if self.len_reg.q.val() == self.byte_zero.val() {
                    self.state.d.next = self.s_crcl.val();
                } else {
                    self.state.d.next = self.s_pay.val();
                }
            } else if self.state.q.val() == self.s_pay.val() {
                self.crc_acc.d.next = self.step.crc_out.val();
                self.left.d.next = self.left.q.val() - self.byte_one.val();
                if self.left.q.val() == self.byte_one.val() {
                    self.state.d.next = self.s_crcl.val();
                }
            } else if self.state.q.val() == self.s_crcl.val() {
                self.crc_lo.d.next = self.data.val();
                self.state.d.next = self.s_crch.val();
            } else {
                // The CRC as received: low byte stored, high byte now.
                if (self.data.val() == self.crc_acc.q.val().get_bits::<8>(8))
                    & (self.crc_lo.q.val() == self.crc_acc.q.val().get_bits::<8>(0))
                {
                    self.frame_reg.d.next = true;
                } else {
                    self.bad_reg.d.next = true;
                }
                self.state.d.next = self.hunt.val();
            }
        } else if self.state.q.val() != self.hunt.val() {
            if self.idle.q.val() >= self.timeout.val() {
                self.state.d.next = self.hunt.val();
                self.dropped_reg.d.next = true;
                self.idle.d.next = self.idle_zero.val();
            } else {
                self.idle.d.next = self.idle.q.val() + self.idle_one.val();
            }
        }
        self.frame.next = self.frame_reg.q.val();
        self.bad_crc.next = self.bad_reg.q.val();
        self.dropped.next = self.dropped_reg.q.val();
        self.cmd.next = self.cmd_reg.q.val();
        self.seq.next = self.seq_reg.q.val();
        self.len.next = self.len_reg.q.val();
        self.payload.next = self.payload_bytes.bytes.val();
        self.crc.next = self.payload_bytes.crc.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_rx_is_synthesizable() {
        crate::synth_check::synth_block("frame_rx", FrameRx::default());
    }
}
