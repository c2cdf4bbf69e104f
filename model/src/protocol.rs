//! The framed command and telemetry protocol spoken over the UART (docs/PROTOCOL.md).
//!
//! ```text
//! +------+-----+-----+-----+-------------+---------+
//! | 0xA5 | LEN | CMD | SEQ | PAYLOAD     | CRC16   |
//! +------+-----+-----+-----+-------------+---------+
//!    1      1     1     1    LEN bytes     2 (LE)
//! ```
//!
//! `CRC16` is CRC-16/CCITT-FALSE (polynomial 0x1021, initial value 0xFFFF, no reflection, no
//! final XOR; check value 0x29B1 for "123456789") over `LEN CMD SEQ PAYLOAD`, sent low byte
//! first. Multi-byte fields are little-endian. The same encoder and decoder serve the host,
//! the tests and the reference the fabric is compared with.

use crate::error::ProgramError;
use crate::format::Format;
use crate::program::Segment;

/// Start-of-frame byte.
pub const START: u8 = 0xA5;
/// Bytes around the payload: start, length, command, sequence, two CRC bytes.
pub const OVERHEAD: usize = 6;
/// Protocol version reported by `Ping`.
pub const PROTOCOL_VERSION: u8 = 1;
/// Bytes of the position register in a `POSITION` reply (112 bits).
pub const POSITION_BYTES: usize = 14;

/// CRC-16/CCITT-FALSE of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for &b in data {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// Command and reply codes.
pub mod code {
    /// Host → device: ping; replied with `VERSION`.
    pub const PING: u8 = 0x01;
    /// Load one segment into the standby program.
    pub const LOAD_SEGMENT: u8 = 0x02;
    /// Set the standby program's segment count (completes an upload).
    pub const COMMIT: u8 = 0x03;
    /// Start the standby program.
    pub const START: u8 = 0x04;
    /// Controlled stop: play the standby program now (a stop profile the host uploaded).
    pub const STOP: u8 = 0x05;
    /// Abort: v = a = j = 0 at once.
    pub const ABORT: u8 = 0x06;
    /// Read status; replied with `STATUS`.
    pub const READ_STATUS: u8 = 0x07;
    /// Set a configuration parameter.
    pub const CONFIGURE: u8 = 0x08;
    /// Read the full position register; replied with `POSITION`.
    pub const READ_POSITION: u8 = 0x09;
    /// Device → host: version (reply to `PING`).
    pub const VERSION: u8 = 0x41;
    /// Status (reply to `READ_STATUS`).
    pub const STATUS: u8 = 0x47;
    /// Position register (reply to `READ_POSITION`).
    pub const POSITION: u8 = 0x49;
    /// Acknowledge.
    pub const ACK: u8 = 0x7E;
    /// Reject with a reason.
    pub const NAK: u8 = 0x7F;
    /// Periodic telemetry (unsolicited, status layout).
    pub const TELEMETRY: u8 = 0x80;
}

/// Why a frame was rejected (the `NAK` reason byte).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Reason {
    /// CRC mismatch.
    BadCrc = 1,
    /// Length does not match the command.
    BadLength = 2,
    /// Unknown command code.
    UnknownCommand = 3,
    /// Not allowed while a program plays.
    Busy = 4,
    /// An argument is out of range.
    BadArgument = 5,
    /// Start without a committed program.
    NoProgram = 6,
    /// UART framing error or a frame cut short (inter-byte timeout).
    Framing = 7,
}

impl Reason {
    /// From the reason byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        Some(match b {
            1 => Reason::BadCrc,
            2 => Reason::BadLength,
            3 => Reason::UnknownCommand,
            4 => Reason::Busy,
            5 => Reason::BadArgument,
            6 => Reason::NoProgram,
            7 => Reason::Framing,
            _ => return None,
        })
    }
}

/// Configuration parameters (`CONFIGURE`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Param {
    /// Clocks per tick − 1.
    TickDivider = 1,
    /// PWM period in clocks.
    PwmPeriod = 2,
    /// Encoder glitch filter length in clocks.
    EncoderFilter = 3,
    /// Telemetry period in ticks (0: off).
    TelemetryPeriod = 4,
}

impl Param {
    /// From the parameter byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        Some(match b {
            1 => Param::TickDivider,
            2 => Param::PwmPeriod,
            3 => Param::EncoderFilter,
            4 => Param::TelemetryPeriod,
            _ => return None,
        })
    }
}

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
        /// The cruise segment, which a controlled stop cuts short (sent as a second payload
        /// byte; `None` sends a one-byte COMMIT).
        cruise: Option<u8>,
    },
    /// Start the standby program.
    Start,
    /// Controlled stop: end the cruise now (or when it is reached) and decelerate as planned.
    Stop,
    /// Abort.
    Abort,
    /// Read status.
    ReadStatus,
    /// Configure.
    Configure {
        /// Parameter.
        param: Param,
        /// Value.
        value: u32,
    },
    /// Read the position register.
    ReadPosition,
}

/// Device state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Status {
    /// Bit 0 busy, bit 1 done, bit 2 aborted, bit 3 fault.
    pub state: u8,
    /// Error flags (bit 0 encoder error seen, bit 1 UART framing error seen).
    pub errors: u8,
    /// Ticks since the start of the move.
    pub tick_count: u32,
    /// Position in output LSBs (`x >> 80`, 32 bits).
    pub position: i32,
    /// Velocity, raw, top 32 bits of the velocity register (`v >> (v_bits − 32)`).
    pub velocity: i32,
    /// Encoder count.
    pub encoder: i32,
    /// Frames dropped for a bad CRC.
    pub bad_crc: u16,
    /// Frames dropped for a bad length or unknown command.
    pub bad_frames: u16,
}

/// A device reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reply {
    /// Version.
    Version {
        /// Protocol version.
        protocol: u8,
        /// Segments per program.
        max_segments: u8,
        /// Snap bytes per segment.
        snap_bytes: u8,
    },
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
    /// The position register (raw, `x_bits` wide, sign-extended).
    Position {
        /// Raw position register.
        x: i128,
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
        assert!(self.payload.len() <= 255, "payload longer than 255 bytes");
        let mut v = Vec::with_capacity(self.payload.len() + OVERHEAD);
        v.push(START);
        v.push(self.payload.len() as u8);
        v.push(self.cmd);
        v.push(self.seq);
        v.extend_from_slice(&self.payload);
        let crc = crc16(&v[1..]);
        v.extend_from_slice(&crc.to_le_bytes());
        v
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

/// The longest payload a device accepts: a longer `LEN` cannot start a frame, so its start byte
/// is taken as noise at once (a corrupted frame's payload byte 0xA5 then cannot swallow the
/// frames that follow for long).
pub const DEVICE_MAX_PAYLOAD: usize = 32;

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

fn le32(p: &[u8]) -> u32 {
    u32::from_le_bytes([p[0], p[1], p[2], p[3]])
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
            Command::Abort => code::ABORT,
            Command::ReadStatus => code::READ_STATUS,
            Command::Configure { .. } => code::CONFIGURE,
            Command::ReadPosition => code::READ_POSITION,
        }
    }

    /// The frame carrying this command.
    pub fn to_frame(&self, seq: u8, format: &Format) -> Frame {
        let payload = match *self {
            Command::LoadSegment { index, segment } => {
                let nb = crate::program::Program::snap_bytes(format);
                let mut p = vec![index];
                p.extend_from_slice(&segment.ticks.to_le_bytes());
                p.extend_from_slice(&segment.snap.to_le_bytes()[..nb]);
                p
            }
            Command::Commit { count, cruise } => match cruise {
                Some(c) => vec![count, c],
                None => vec![count],
            },
            Command::Configure { param, value } => {
                let mut p = vec![param as u8];
                p.extend_from_slice(&value.to_le_bytes());
                p
            }
            _ => vec![],
        };
        Frame {
            cmd: self.code(),
            seq,
            payload,
        }
    }

    /// Parses a frame with a good CRC into a command, or says why it is rejected.
    pub fn from_frame(f: &Frame, format: &Format) -> Result<Command, Rejected> {
        let reject = |reason| Rejected { cmd: f.cmd, reason };
        let p = &f.payload;
        let need = |n: usize| {
            if p.len() == n {
                Ok(())
            } else {
                Err(reject(Reason::BadLength))
            }
        };
        Ok(match f.cmd {
            code::PING => {
                need(0)?;
                Command::Ping
            }
            code::LOAD_SEGMENT => {
                let nb = crate::program::Program::snap_bytes(format);
                need(1 + 4 + nb)?;
                let index = p[0];
                if usize::from(index) >= format.max_segments {
                    return Err(reject(Reason::BadArgument));
                }
                let ticks = le32(&p[1..5]);
                let mut wide = [0u8; 16];
                wide[..nb].copy_from_slice(&p[5..5 + nb]);
                if p[4 + nb] & 0x80 != 0 {
                    wide[nb..].fill(0xff);
                }
                let segment = Segment {
                    ticks,
                    snap: i128::from_le_bytes(wide),
                };
                let check = crate::program::Program {
                    segments: vec![segment],
                };
                check.validate(format).map_err(|e| match e {
                    ProgramError::ZeroTicks { .. }
                    | ProgramError::TicksTooLarge { .. }
                    | ProgramError::SnapTooLarge { .. } => reject(Reason::BadArgument),
                    _ => reject(Reason::BadArgument),
                })?;
                Command::LoadSegment { index, segment }
            }
            code::COMMIT => {
                if p.len() != 1 && p.len() != 2 {
                    return Err(reject(Reason::BadLength));
                }
                if usize::from(p[0]) > format.max_segments {
                    return Err(reject(Reason::BadArgument));
                }
                let cruise = p.get(1).copied();
                if cruise.is_some_and(|c| usize::from(c) >= format.max_segments && c != 0xFF) {
                    return Err(reject(Reason::BadArgument));
                }
                Command::Commit {
                    count: p[0],
                    cruise,
                }
            }
            code::START => {
                need(0)?;
                Command::Start
            }
            code::STOP => {
                need(0)?;
                Command::Stop
            }
            code::ABORT => {
                need(0)?;
                Command::Abort
            }
            code::READ_STATUS => {
                need(0)?;
                Command::ReadStatus
            }
            code::READ_POSITION => {
                need(0)?;
                Command::ReadPosition
            }
            code::CONFIGURE => {
                need(5)?;
                let param = Param::from_byte(p[0]).ok_or(reject(Reason::BadArgument))?;
                Command::Configure {
                    param,
                    value: le32(&p[1..5]),
                }
            }
            _ => return Err(reject(Reason::UnknownCommand)),
        })
    }
}

impl Status {
    /// Payload bytes of a status.
    pub const BYTES: usize = 22;

    fn to_payload(self) -> Vec<u8> {
        let mut p = vec![self.state, self.errors];
        p.extend_from_slice(&self.tick_count.to_le_bytes());
        p.extend_from_slice(&self.position.to_le_bytes());
        p.extend_from_slice(&self.velocity.to_le_bytes());
        p.extend_from_slice(&self.encoder.to_le_bytes());
        p.extend_from_slice(&self.bad_crc.to_le_bytes());
        p.extend_from_slice(&self.bad_frames.to_le_bytes());
        p
    }

    fn from_payload(p: &[u8]) -> Option<Self> {
        if p.len() != Self::BYTES {
            return None;
        }
        let i32at = |k: usize| le32(&p[k..k + 4]) as i32;
        Some(Status {
            state: p[0],
            errors: p[1],
            tick_count: le32(&p[2..6]),
            position: i32at(6),
            velocity: i32at(10),
            encoder: i32at(14),
            bad_crc: u16::from_le_bytes([p[18], p[19]]),
            bad_frames: u16::from_le_bytes([p[20], p[21]]),
        })
    }
}

impl Reply {
    /// The frame carrying this reply.
    pub fn to_frame(&self, seq: u8) -> Frame {
        let (cmd, payload) = match *self {
            Reply::Version {
                protocol,
                max_segments,
                snap_bytes,
            } => (code::VERSION, vec![protocol, max_segments, snap_bytes]),
            Reply::Ack { cmd } => (code::ACK, vec![cmd]),
            Reply::Nak { cmd, reason } => (code::NAK, vec![cmd, reason as u8]),
            Reply::Status(s) => (code::STATUS, s.to_payload()),
            Reply::Telemetry(s) => (code::TELEMETRY, s.to_payload()),
            Reply::Position { x } => (code::POSITION, x.to_le_bytes()[..POSITION_BYTES].to_vec()),
        };
        Frame { cmd, seq, payload }
    }

    /// Parses a frame with a good CRC into a reply.
    pub fn from_frame(f: &Frame) -> Option<Reply> {
        let p = &f.payload;
        Some(match (f.cmd, p.len()) {
            (code::VERSION, 3) => Reply::Version {
                protocol: p[0],
                max_segments: p[1],
                snap_bytes: p[2],
            },
            (code::ACK, 1) => Reply::Ack { cmd: p[0] },
            (code::NAK, 2) => Reply::Nak {
                cmd: p[0],
                reason: Reason::from_byte(p[1])?,
            },
            (code::STATUS, _) => Reply::Status(Status::from_payload(p)?),
            (code::TELEMETRY, _) => Reply::Telemetry(Status::from_payload(p)?),
            (code::POSITION, POSITION_BYTES) => {
                let mut wide = [0u8; 16];
                wide[..POSITION_BYTES].copy_from_slice(p);
                if p[POSITION_BYTES - 1] & 0x80 != 0 {
                    wide[POSITION_BYTES..].fill(0xff);
                }
                Reply::Position {
                    x: i128::from_le_bytes(wide),
                }
            }
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;

    fn hex(b: &[u8]) -> String {
        b.iter()
            .map(|x| format!("{x:02X}"))
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn crc_check_value() {
        assert_eq!(crc16(b"123456789"), 0x29B1);
    }

    /// The worked examples of docs/PROTOCOL.md, byte for byte (computed by an independent
    /// Python implementation of CRC-16/CCITT-FALSE).
    #[test]
    fn documented_examples() {
        let f = DEFAULT_FORMAT;
        assert_eq!(
            hex(&Command::Ping.to_frame(0x01, &f).to_bytes()),
            "A5 00 01 01 8C EF"
        );
        let seg = Command::LoadSegment {
            index: 2,
            segment: Segment {
                ticks: 5000,
                snap: -12_089_258_196_146,
            },
        };
        assert_eq!(
            hex(&seg.to_frame(0x07, &f).to_bytes()),
            "A5 12 02 07 02 88 13 00 00 4E 43 0F 40 01 F5 FF FF FF FF FF FF FF 15 3C"
        );
        assert_eq!(
            hex(&Command::Commit {
                count: 15,
                cruise: None
            }
            .to_frame(0x08, &f)
            .to_bytes()),
            "A5 01 03 08 0F 62 D3"
        );
        assert_eq!(
            hex(&Command::Commit {
                count: 15,
                cruise: Some(7)
            }
            .to_frame(0x08, &f)
            .to_bytes()),
            "A5 02 03 08 0F 07 2B 07"
        );
        assert_eq!(
            hex(&Reply::Ack { cmd: code::STOP }.to_frame(0x0C).to_bytes()),
            "A5 01 7E 0C 05 B5 24"
        );
        assert_eq!(
            hex(&Command::Start.to_frame(0x09, &f).to_bytes()),
            "A5 00 04 09 71 91"
        );
        assert_eq!(
            hex(&Reply::Ack { cmd: code::START }.to_frame(0x09).to_bytes()),
            "A5 01 7E 09 04 61 CB"
        );
        assert_eq!(
            hex(&Reply::Nak {
                cmd: code::START,
                reason: Reason::NoProgram
            }
            .to_frame(0x09)
            .to_bytes()),
            "A5 02 7F 09 04 06 87 F1"
        );
        assert_eq!(
            hex(&Command::Configure {
                param: Param::TickDivider,
                value: 1249
            }
            .to_frame(0x0A, &f)
            .to_bytes()),
            "A5 05 08 0A 01 E1 04 00 00 E0 E8"
        );
        assert_eq!(
            hex(&Command::Stop.to_frame(0x0C, &f).to_bytes()),
            "A5 00 05 0C E5 F2"
        );
        assert_eq!(
            hex(&Command::Abort.to_frame(0x0D, &f).to_bytes()),
            "A5 00 06 0D 97 B7"
        );
        assert_eq!(
            hex(&Command::ReadStatus.to_frame(0x0B, &f).to_bytes()),
            "A5 00 07 0B 60 E4"
        );
        assert_eq!(
            hex(&Reply::Version {
                protocol: 1,
                max_segments: 32,
                snap_bytes: 13
            }
            .to_frame(0x01)
            .to_bytes()),
            "A5 03 41 01 01 20 0D 06 ED"
        );
        let status = Status {
            state: 0b0010,
            errors: 0,
            tick_count: 85_000,
            position: 500_000,
            velocity: 0,
            encoder: 500_000,
            bad_crc: 0,
            bad_frames: 1,
        };
        assert_eq!(
            hex(&Reply::Status(status).to_frame(0x0B).to_bytes()),
            "A5 16 47 0B 02 00 08 4C 01 00 20 A1 07 00 00 00 00 00 20 A1 07 00 00 00 01 00 2D 10"
        );
        let telemetry = Status {
            state: 0b0001,
            errors: 0,
            tick_count: 40_000,
            position: 235_702,
            velocity: 123_456,
            encoder: 235_700,
            bad_crc: 0,
            bad_frames: 0,
        };
        assert_eq!(
            hex(&Reply::Telemetry(telemetry).to_frame(0x00).to_bytes()),
            "A5 16 80 00 01 00 40 9C 00 00 B6 98 03 00 40 E2 01 00 B4 98 03 00 00 00 00 00 A0 85"
        );
        assert_eq!(
            hex(&Command::ReadPosition.to_frame(0x0E, &f).to_bytes()),
            "A5 00 09 0E CA 97"
        );
        assert_eq!(
            hex(&Reply::Position {
                x: (500_000i128 << 80) + (1i128 << 79)
            }
            .to_frame(0x0E)
            .to_bytes()),
            "A5 0E 49 0E 00 00 00 00 00 00 00 00 00 80 20 A1 07 00 B2 E0"
        );
        assert_eq!(
            hex(&Reply::Ack {
                cmd: code::LOAD_SEGMENT
            }
            .to_frame(0x07)
            .to_bytes()),
            "A5 01 7E 07 02 A8 88"
        );
        assert_eq!(
            hex(&Reply::Nak {
                cmd: 0,
                reason: Reason::BadCrc
            }
            .to_frame(0x00)
            .to_bytes()),
            "A5 02 7F 00 00 01 35 D3"
        );
    }

    #[test]
    fn commands_round_trip() {
        let f = DEFAULT_FORMAT;
        for c in [
            Command::Ping,
            Command::LoadSegment {
                index: 31,
                segment: Segment {
                    ticks: u32::MAX,
                    snap: -(1i128 << 103),
                },
            },
            Command::Commit {
                count: 32,
                cruise: None,
            },
            Command::Commit {
                count: 15,
                cruise: Some(7),
            },
            Command::Start,
            Command::Stop,
            Command::Abort,
            Command::ReadStatus,
            Command::Configure {
                param: Param::TelemetryPeriod,
                value: 100,
            },
            Command::ReadPosition,
        ] {
            let bytes = c.to_frame(200, &f).to_bytes();
            let mut d = Decoder::new();
            let mut got = None;
            for b in bytes {
                if let Some(x) = d.push(b) {
                    got = Some(x);
                }
            }
            let Some(Decoded::Frame(fr)) = got else {
                panic!("{c:?} did not decode")
            };
            assert_eq!(fr.seq, 200);
            assert_eq!(Command::from_frame(&fr, &f), Ok(c));
        }
    }

    #[test]
    fn replies_round_trip() {
        let s = Status {
            state: 0b0101,
            errors: 2,
            tick_count: 123_456,
            position: -5_000_000,
            velocity: 77,
            encoder: -4,
            bad_crc: 3,
            bad_frames: 9,
        };
        for r in [
            Reply::Version {
                protocol: PROTOCOL_VERSION,
                max_segments: 32,
                snap_bytes: 13,
            },
            Reply::Ack { cmd: 4 },
            Reply::Nak {
                cmd: 9,
                reason: Reason::UnknownCommand,
            },
            Reply::Status(s),
            Reply::Telemetry(s),
            Reply::Position {
                x: -(1i128 << 100) + 7,
            },
            Reply::Position {
                x: (1i128 << 110) - 1,
            },
        ] {
            let f = r.to_frame(3);
            assert_eq!(Reply::from_frame(&f), Some(r));
        }
    }

    #[test]
    fn bad_arguments_are_rejected_with_a_reason() {
        let f = DEFAULT_FORMAT;
        let fr = |cmd, payload: Vec<u8>| Frame {
            cmd,
            seq: 0,
            payload,
        };
        assert_eq!(
            Command::from_frame(&fr(0x55, vec![]), &f)
                .unwrap_err()
                .reason,
            Reason::UnknownCommand
        );
        assert_eq!(
            Command::from_frame(&fr(code::START, vec![1]), &f)
                .unwrap_err()
                .reason,
            Reason::BadLength
        );
        assert_eq!(
            Command::from_frame(&fr(code::COMMIT, vec![33]), &f)
                .unwrap_err()
                .reason,
            Reason::BadArgument
        );
        // A zero-tick segment.
        let mut p = vec![0u8; 18];
        p[0] = 1;
        assert_eq!(
            Command::from_frame(&fr(code::LOAD_SEGMENT, p), &f)
                .unwrap_err()
                .reason,
            Reason::BadArgument
        );
    }
}
