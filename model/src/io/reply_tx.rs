//! The fabric's reply transmitter (`snapgen_hdl::reply_tx::ReplyTx`), clock by clock. When idle
//! it takes the next queued reply, or else a pending telemetry frame, and writes the frame —
//! start byte, length, code, sequence, payload, CRC low then high — into the transmit FIFO one
//! byte per clock while the FIFO is not full. Frames are never interleaved; telemetry waits
//! while a reply is queued. The payload is read from the live values [`PAYLOAD_DELAY`] clocks
//! after the reply starts (docs/PROTOCOL.md: a reply reports the device as it is when it
//! starts), a CONFIG reply's value a clock before that (the executor registers the parameter
//! the reply names): in the fabric the reads are pipelined so that the design closes routed
//! timing, and the frame's payload bytes come later than that anyway.

use snapgen_spec::fields::{AckPayload, ConfigValue, Identity, NakPayload, StateReply, Status};
use snapgen_spec::wire::{crc16_step, CRC_INIT, START};
use snapgen_spec::{code, flag, Param};

use crate::io::executor::{Config, ReplyDesc, ReplyKind};

/// What the payloads are read from: the live values of a clock (a reply reads its payload
/// [`PAYLOAD_DELAY`] clocks after it starts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Live {
    /// The status block.
    pub status: Status,
    /// The registers and their tick.
    pub state: StateReply,
    /// The configuration.
    pub config: Config,
    /// The design's constant identity (its tick divider and stop limits are taken from
    /// `config`).
    pub identity: Identity,
}

impl Live {
    /// The code and payload of the reply `d` stands for.
    pub fn reply(&self, d: &ReplyDesc) -> (u8, Vec<u8>) {
        match d.kind {
            ReplyKind::Identity => (
                code::IDENTITY,
                Identity {
                    tick_divider: self.config.tick_divider,
                    stop_jerk: self.config.stop_jerk,
                    stop_accel: self.config.stop_accel,
                    ..self.identity
                }
                .to_payload(),
            ),
            ReplyKind::Ack => (code::ACK, AckPayload { cmd: d.cmd }.to_payload()),
            ReplyKind::Nak => (
                code::NAK,
                NakPayload {
                    cmd: d.cmd,
                    reason: d.aux,
                }
                .to_payload(),
            ),
            ReplyKind::Status => (code::STATUS, self.status.to_payload()),
            ReplyKind::State => (code::STATE, self.state.to_payload()),
            ReplyKind::Config => {
                let param = Param::from_byte(d.aux).expect("the executor checked it");
                (
                    code::CONFIG,
                    ConfigValue {
                        param: d.aux,
                        value: self.config.get(param),
                    }
                    .to_payload(),
                )
            }
            ReplyKind::Telemetry => (code::TELEMETRY, self.status.to_payload()),
        }
    }
}

/// Clocks from a reply's start to the clock whose live values its payload reads (a CONFIG
/// reply's value: the clock before).
pub const PAYLOAD_DELAY: u8 = 2;

/// Inputs of one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReplyTxInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// The reply queue's head.
    pub head: Option<ReplyDesc>,
    /// Pulse: send telemetry.
    pub telemetry: bool,
    /// The transmit FIFO is full.
    pub fifo_full: bool,
}

/// What the transmitter does this clock (combinational from its state and inputs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReplyTxOutputs {
    /// Take the queue's head now.
    pub pop: bool,
    /// Write `fifo_data` into the transmit FIFO now.
    pub fifo_write: bool,
    /// The byte.
    pub fifo_data: u8,
}

/// The transmitter.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReplyTx {
    active: bool,
    index: u8,
    len: u8,
    code: u8,
    seq: u8,
    payload: Vec<u8>,
    crc: u16,
    telemetry_pending: bool,
    /// The reply being written.
    desc: ReplyDesc,
    /// Clocks until its payload is read (0: read).
    load: u8,
}

impl ReplyTx {
    /// Idle.
    pub fn new() -> Self {
        Self::default()
    }

    /// True while a frame is being written.
    pub fn busy(&self) -> bool {
        self.active
    }

    /// The byte at the current index.
    fn byte(&self) -> u8 {
        let (k, n) = (self.index, self.len);
        match k {
            0 => START,
            1 => n,
            2 => self.code,
            3 => self.seq,
            _ if k < n + 4 => self.payload[usize::from(k - 4)],
            _ if k == n + 4 => self.crc as u8,
            _ => (self.crc >> 8) as u8,
        }
    }

    /// What it does this clock, before the edge.
    pub fn outputs(&self, i: &ReplyTxInputs) -> ReplyTxOutputs {
        ReplyTxOutputs {
            pop: !i.reset && !self.active && i.head.is_some(),
            fifo_write: !i.reset && self.active && !i.fifo_full,
            fifo_data: self.byte(),
        }
    }

    /// One clock, with the live values of this clock.
    pub fn clock(&mut self, i: &ReplyTxInputs, live: &Live) -> ReplyTxOutputs {
        let out = self.outputs(i);
        if i.reset {
            *self = ReplyTx::new();
            return out;
        }
        // The payload of the reply started PAYLOAD_DELAY clocks ago (before this clock's start).
        // A CONFIG reply's payload (its parameter and the value the executor registers) a clock
        // before every other reply's.
        let config = self.desc.kind == ReplyKind::Config;
        match self.load {
            PAYLOAD_DELAY if config => self.payload = live.reply(&self.desc).1,
            1 if !config => self.payload = live.reply(&self.desc).1,
            _ => {}
        }
        self.load = self.load.saturating_sub(1);
        let mut launched_telemetry = false;
        if !self.active {
            let d = match i.head {
                Some(d) => Some(d),
                None if self.telemetry_pending || i.telemetry => {
                    launched_telemetry = true;
                    Some(ReplyDesc {
                        kind: ReplyKind::Telemetry,
                        ..Default::default()
                    })
                }
                None => None,
            };
            if let Some(d) = d {
                // The code and length now; the payload PAYLOAD_DELAY clocks later (its first
                // byte, frame byte 4, is written 5 clocks after the start at the earliest).
                let (code, payload) = live.reply(&d);
                self.active = true;
                self.index = 0;
                self.len = payload.len() as u8;
                self.code = code;
                self.seq = d.seq;
                self.crc = CRC_INIT;
                self.desc = d;
                self.load = PAYLOAD_DELAY;
            }
        } else if out.fifo_write {
            let (k, n) = (self.index, self.len);
            if k >= 1 && k < n + 4 {
                self.crc = crc16_step(self.crc, out.fifo_data);
            }
            self.index += 1;
            if k == n + 5 {
                self.active = false;
            }
        }
        if launched_telemetry {
            self.telemetry_pending = false;
        }
        if i.telemetry && !launched_telemetry {
            self.telemetry_pending = true;
        }
        out
    }
}

/// The status block of the I/O top, from the registered values of its blocks.
#[derive(Clone, Copy, Debug)]
pub struct StatusInputs<'a> {
    /// The executor's outputs.
    pub exec: &'a crate::io::executor::ExecutorOutputs,
    /// The core's outputs.
    pub core: &'a crate::CoreOutputs,
    /// Velocity register width.
    pub v_bits: u32,
    /// The encoder count.
    pub encoder: i64,
    /// An illegal encoder transition was seen.
    pub encoder_error: bool,
    /// Limit and emergency-stop inputs (filtered, polarity applied).
    pub limit_pos: bool,
    /// Negative limit.
    pub limit_neg: bool,
    /// Emergency stop.
    pub estop: bool,
    /// The controller's outputs.
    pub servo: &'a crate::io::servo::ServoOutputs,
}

/// The status block.
pub fn status(s: &StatusInputs) -> Status {
    let (e, c) = (s.exec, s.core);
    let mut flags = 0u16;
    for (on, bit) in [
        (c.busy, flag::PLAYING),
        (c.done, flag::DONE),
        (c.aborted, flag::CUT),
        (c.stopping, flag::STOPPING),
        (c.stop_over, flag::STOP_OVER_LIMITS),
        (e.amplifier, flag::AMPLIFIER),
        (s.limit_pos, flag::LIMIT_POSITIVE),
        (s.limit_neg, flag::LIMIT_NEGATIVE),
        (s.estop, flag::EMERGENCY_STOP),
        (s.encoder_error, flag::ENCODER_ERROR),
        (e.uart_error, flag::UART_ERROR),
        (e.reply_overflow, flag::REPLY_OVERFLOW),
        (e.servo_overrun, flag::SERVO_OVERRUN),
        (c.swap_pending, flag::SWAP_PENDING),
    ] {
        if on {
            flags |= bit;
        }
    }
    Status {
        state: e.state as u8,
        error: e.error as u8,
        flags,
        tick_count: c.tick_count,
        position: c.position as i32,
        velocity: (c.v >> (s.v_bits - 32)) as i32,
        encoder: s.encoder as i32,
        bad_crc: e.bad_crc,
        bad_frames: e.bad_frames,
        following_peak: s.servo.peak,
        duty: s.servo.duty,
    }
}
