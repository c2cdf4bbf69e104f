//! The protocol's codecs on the host side (docs/PROTOCOL.md): a [`Command`] to its frame, a
//! frame to a [`Reply`], and the byte-at-a-time [`Decoder`] that finds frames in a stream.
//! Every code, length and layout comes from `snapgen_spec`; this module only turns them into
//! Rust values and back.

use snapgen_model::format::Format;
use snapgen_model::program::{Program, Segment};
pub use snapgen_spec::codes::{command_spec, reply_spec};
pub use snapgen_spec::fields::{
    AckPayload, CommitArgs, ConfigValue, Identity, LoadSegmentArgs, NakPayload, PowerArgs,
    ReadConfigArgs, StateReply, Status, SwapAtArgs,
};
pub use snapgen_spec::wire::{crc16, DEVICE_MAX_PAYLOAD, OVERHEAD, START};
pub use snapgen_spec::{code, flag, AxisState, ErrorId, Param, Reason};

/// A host command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// Ping.
    Ping,
    /// Load segment `index` of the standby program.
    LoadSegment {
        /// Segment index (0..max_segments).
        index: u8,
        /// The segment.
        segment: Segment,
    },
    /// Commit `count` segments as the standby program.
    Commit {
        /// Segment count.
        count: u8,
    },
    /// Start the standby program.
    Start,
    /// Controlled stop (MC_Stop).
    Stop,
    /// Controlled stop of the move (MC_Halt).
    Halt,
    /// Read status.
    ReadStatus,
    /// Configure.
    Configure {
        /// Parameter.
        param: Param,
        /// Value.
        value: i128,
    },
    /// Read the registers.
    ReadState,
    /// Read a parameter.
    ReadConfig {
        /// Parameter.
        param: Param,
    },
    /// Enable or disable the axis.
    Power {
        /// Enable.
        on: bool,
    },
    /// Clear an axis error.
    Reset,
    /// Arm a program swap: the standby program takes over from the registers at absolute
    /// tick `tick` (a value of the time base, `ticks` in STATE).
    SwapAt {
        /// The tick.
        tick: u64,
    },
}

/// A device reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reply {
    /// Identity.
    Identity(Identity),
    /// Acknowledge of command `cmd`.
    Ack {
        /// The acknowledged command.
        cmd: u8,
    },
    /// Rejection.
    Nak {
        /// The rejected command (0 if unknown).
        cmd: u8,
        /// Why.
        reason: Reason,
    },
    /// Status.
    Status(Status),
    /// Telemetry.
    Telemetry(Status),
    /// Registers.
    State(StateReply),
    /// A parameter's value.
    Config {
        /// The parameter.
        param: Param,
        /// Its value.
        value: i128,
    },
}

/// A frame: command code, sequence number, payload.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Command or reply code.
    pub cmd: u8,
    /// Sequence number (echoed in replies).
    pub seq: u8,
    /// Payload (≤ 255 bytes).
    pub payload: Vec<u8>,
}

impl Frame {
    /// The bytes on the wire.
    pub fn to_bytes(&self) -> Vec<u8> {
        snapgen_spec::wire::frame_bytes(self.cmd, self.seq, &self.payload)
    }
}

/// What the stream decoder found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Decoded {
    /// A frame whose CRC matches.
    Frame(Frame),
    /// A frame with a bad CRC (dropped; its command and sequence are untrusted).
    BadCrc,
}

/// Byte-at-a-time frame decoder: hunts for the start byte, reads the header and payload and
/// checks the CRC. Never panics; on a bad CRC it resynchronises on the next start byte after
/// the bad frame's first byte.
#[derive(Clone, Debug)]
pub struct Decoder {
    buf: Vec<u8>,
    max_payload: usize,
    rescan: bool,
}

impl Default for Decoder {
    fn default() -> Self {
        Decoder {
            buf: Vec::new(),
            max_payload: 255,
            rescan: true,
        }
    }
}

impl Decoder {
    /// A decoder waiting for a start byte, accepting any payload length.
    pub fn new() -> Self {
        Self::default()
    }

    /// A decoder that takes a start byte followed by a length above `max` as noise.
    pub fn with_max_payload(max: usize) -> Self {
        Decoder {
            buf: Vec::new(),
            max_payload: max,
            rescan: true,
        }
    }

    /// The device's decoder, as the fabric implements it: lengths above
    /// [`DEVICE_MAX_PAYLOAD`] are noise, and after a bad CRC it hunts for the next start byte
    /// among the bytes still to come (it keeps no bytes to rescan).
    pub fn device() -> Self {
        Decoder {
            buf: Vec::new(),
            max_payload: DEVICE_MAX_PAYLOAD,
            rescan: false,
        }
    }

    /// True when no partial frame is held.
    pub fn is_idle(&self) -> bool {
        self.buf.is_empty()
    }

    /// Drops a partial frame (after an inter-byte timeout or a UART framing error).
    pub fn reset(&mut self) -> bool {
        let had = !self.buf.is_empty();
        self.buf.clear();
        had
    }

    /// Feeds one byte; returns a decoded frame when one completes.
    pub fn push(&mut self, b: u8) -> Option<Decoded> {
        if self.buf.is_empty() && b != START {
            return None;
        }
        self.buf.push(b);
        if self.buf.len() == 2 && usize::from(b) > self.max_payload {
            // Not a frame start: rescan from the length byte.
            self.buf.clear();
            return self.push(b);
        }
        if self.buf.len() < 4 {
            return None;
        }
        let len = usize::from(self.buf[1]);
        if self.buf.len() < len + OVERHEAD {
            return None;
        }
        let n = len + 4;
        let got = u16::from_le_bytes([self.buf[n], self.buf[n + 1]]);
        if got == crc16(&self.buf[1..n]) {
            let f = Frame {
                cmd: self.buf[2],
                seq: self.buf[3],
                payload: self.buf[4..n].to_vec(),
            };
            self.buf.clear();
            Some(Decoded::Frame(f))
        } else {
            if !self.rescan {
                self.buf.clear();
                return Some(Decoded::BadCrc);
            }
            // Resynchronise: rescan what followed the bad frame's start byte.
            let rest: Vec<u8> = self.buf[1..].to_vec();
            self.buf.clear();
            for &r in &rest {
                if let Some(Decoded::Frame(f)) = self.push(r) {
                    return Some(Decoded::Frame(f));
                }
            }
            Some(Decoded::BadCrc)
        }
    }
}

/// A payload that does not fit its command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rejected {
    /// The command.
    pub cmd: u8,
    /// Why.
    pub reason: Reason,
}

impl Command {
    /// Its code.
    pub fn code(&self) -> u8 {
        match self {
            Command::Ping => code::PING,
            Command::LoadSegment { .. } => code::LOAD_SEGMENT,
            Command::Commit { .. } => code::COMMIT,
            Command::Start => code::START,
            Command::Stop => code::STOP,
            Command::Halt => code::HALT,
            Command::ReadStatus => code::READ_STATUS,
            Command::Configure { .. } => code::CONFIGURE,
            Command::ReadState => code::READ_STATE,
            Command::ReadConfig { .. } => code::READ_CONFIG,
            Command::Power { .. } => code::POWER,
            Command::Reset => code::RESET,
            Command::SwapAt { .. } => code::SWAP_AT,
        }
    }

    /// Its name, as in docs/PROTOCOL.md.
    pub fn name(&self) -> &'static str {
        command_spec(self.code()).map_or("?", |c| c.name)
    }

    /// The frame carrying this command (a segment's snap in the bytes `format` gives it).
    pub fn to_frame(&self, seq: u8, format: &Format) -> Frame {
        let payload = match *self {
            Command::LoadSegment { index, segment } => {
                let mut p = LoadSegmentArgs {
                    index,
                    ticks: segment.ticks,
                    snap: segment.snap,
                }
                .to_payload();
                // A format with narrower snaps sends fewer bytes of it (the identity's
                // `snap_bytes`); the fabric's is the layout's.
                p.truncate(
                    p.len() - snapgen_spec::widths::WIDE_BYTES + Program::snap_bytes(format),
                );
                p
            }
            Command::Commit { count } => CommitArgs { count }.to_payload(),
            Command::Configure { param, value } => ConfigValue {
                param: param as u8,
                value,
            }
            .to_payload(),
            Command::ReadConfig { param } => ReadConfigArgs { param: param as u8 }.to_payload(),
            Command::Power { on } => PowerArgs { on: u8::from(on) }.to_payload(),
            Command::SwapAt { tick } => SwapAtArgs { tick }.to_payload(),
            Command::Ping
            | Command::Start
            | Command::Stop
            | Command::Halt
            | Command::ReadStatus
            | Command::ReadState
            | Command::Reset => vec![],
        };
        Frame {
            cmd: self.code(),
            seq,
            payload,
        }
    }

    /// Parses a frame with a good CRC into a command, or says why the device refuses it for
    /// its length or its arguments.
    pub fn from_frame(f: &Frame, format: &Format) -> Result<Command, Rejected> {
        let reject = |reason| Rejected { cmd: f.cmd, reason };
        let spec = command_spec(f.cmd).ok_or(reject(Reason::UnknownCommand))?;
        let p = &f.payload;
        if p.len() != usize::from(spec.len) {
            return Err(reject(Reason::BadLength));
        }
        let bad = || reject(Reason::BadArgument);
        Ok(match f.cmd {
            code::PING => Command::Ping,
            code::LOAD_SEGMENT => {
                let a = LoadSegmentArgs::from_payload(p).ok_or(bad())?;
                let segment = Segment {
                    ticks: a.ticks,
                    snap: a.snap,
                };
                let check = Program {
                    segments: vec![segment],
                };
                if usize::from(a.index) >= format.max_segments || check.validate(format).is_err() {
                    return Err(bad());
                }
                Command::LoadSegment {
                    index: a.index,
                    segment,
                }
            }
            code::COMMIT => {
                let a = CommitArgs::from_payload(p).ok_or(bad())?;
                if usize::from(a.count) > format.max_segments {
                    return Err(bad());
                }
                Command::Commit { count: a.count }
            }
            code::START => Command::Start,
            code::STOP => Command::Stop,
            code::HALT => Command::Halt,
            code::READ_STATUS => Command::ReadStatus,
            code::READ_STATE => Command::ReadState,
            code::RESET => Command::Reset,
            code::CONFIGURE => {
                let a = ConfigValue::from_payload(p).ok_or(bad())?;
                let param = Param::from_byte(a.param).ok_or(bad())?;
                if a.value < 0 || a.value > param.max() {
                    return Err(bad());
                }
                Command::Configure {
                    param,
                    value: a.value,
                }
            }
            code::READ_CONFIG => Command::ReadConfig {
                param: Param::from_byte(ReadConfigArgs::from_payload(p).ok_or(bad())?.param)
                    .ok_or(bad())?,
            },
            code::POWER => {
                let a = PowerArgs::from_payload(p).ok_or(bad())?;
                if a.on > 1 {
                    return Err(bad());
                }
                Command::Power { on: a.on == 1 }
            }
            code::SWAP_AT => Command::SwapAt {
                tick: SwapAtArgs::from_payload(p).ok_or(bad())?.tick,
            },
            _ => unreachable!("command_spec knows every code handled here"),
        })
    }
}

impl Reply {
    /// The frame carrying this reply.
    pub fn to_frame(&self, seq: u8) -> Frame {
        let (cmd, payload) = match *self {
            Reply::Identity(i) => (code::IDENTITY, i.to_payload()),
            Reply::Ack { cmd } => (code::ACK, AckPayload { cmd }.to_payload()),
            Reply::Nak { cmd, reason } => (
                code::NAK,
                NakPayload {
                    cmd,
                    reason: reason as u8,
                }
                .to_payload(),
            ),
            Reply::Status(s) => (code::STATUS, s.to_payload()),
            Reply::Telemetry(s) => (code::TELEMETRY, s.to_payload()),
            Reply::State(s) => (code::STATE, s.to_payload()),
            Reply::Config { param, value } => (
                code::CONFIG,
                ConfigValue {
                    param: param as u8,
                    value,
                }
                .to_payload(),
            ),
        };
        Frame { cmd, seq, payload }
    }

    /// Parses a frame with a good CRC into a reply (`None`: not a reply this host knows, or a
    /// payload of the wrong length).
    pub fn from_frame(f: &Frame) -> Option<Reply> {
        let p = &f.payload;
        Some(match f.cmd {
            code::IDENTITY => Reply::Identity(Identity::from_payload(p)?),
            code::ACK => Reply::Ack {
                cmd: AckPayload::from_payload(p)?.cmd,
            },
            code::NAK => {
                let n = NakPayload::from_payload(p)?;
                Reply::Nak {
                    cmd: n.cmd,
                    reason: Reason::from_byte(n.reason)?,
                }
            }
            code::STATUS => Reply::Status(Status::from_payload(p)?),
            code::TELEMETRY => Reply::Telemetry(Status::from_payload(p)?),
            code::STATE => Reply::State(StateReply::from_payload(p)?),
            code::CONFIG => {
                let c = ConfigValue::from_payload(p)?;
                Reply::Config {
                    param: Param::from_byte(c.param)?,
                    value: c.value,
                }
            }
            _ => return None,
        })
    }
}
