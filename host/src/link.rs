//! The host's one way to talk to a board: [`Link`] (a command in, its reply out, and the
//! host's clock), implemented once over any byte medium by [`FramedLink`] with the one retry
//! policy every host uses ([`RetryPolicy`]), over a [`Transport`] (a serial port, a virtual
//! board's UART, later a memory map).
//!
//! The policy (docs/PROTOCOL.md, "Retries"): every command gets a new sequence number (the
//! first chosen when the link opens); a lost reply sends the identical frame again (same
//! sequence, same CRC: the device answers a retry without executing it twice); a NAK with
//! sequence 0 (the device received a frame corrupted, or cut short) sends it again after the
//! device's inter-byte timeout has cleared; a NAK for this sequence is the board's answer,
//! returned as a reply (a LATE swap is planned again, a refused upload is the caller's to
//! report); replies to earlier attempts are dropped. TELEMETRY frames are kept aside.

use snapgen_model::format::Format;
use snapgen_spec::rules::{HOST_REPLY_TIMEOUT_S, HOST_RETRIES};
use snapgen_spec::wire::FRAME_TIMEOUT_S;

use crate::protocol::{Command, Decoded, Decoder, Reason, Reply, Status};

/// A board the host talks to.
pub trait Link {
    /// Sends `c` and returns the board's reply (a NAK for `c` is a reply; lost replies and
    /// corrupted frames are retried inside).
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError>;
    /// Frames are encoded for a board of this format from now on (after PING).
    fn set_format(&mut self, format: &Format);
    /// The last TELEMETRY received, once (those before it are dropped).
    fn take_telemetry(&mut self) -> Option<Status>;
    /// Every TELEMETRY received since the last call, in order (a recording: identification),
    /// up to [`TELEMETRY_KEPT`] of them.
    fn drain_telemetry(&mut self) -> Vec<Status>;
    /// The host's clock (s): wall time, or a virtual board's own time.
    fn now(&self) -> f64;
    /// Lets `seconds` pass (receiving meanwhile).
    fn wait(&mut self, seconds: f64);
    /// Seconds one byte takes on the wire (0 where there is no wire).
    fn byte_time(&self) -> f64;
}

/// TELEMETRY frames a link keeps between two reads (the oldest go first): 2^16, over four
/// minutes of frames every 4 ms.
pub const TELEMETRY_KEPT: usize = 1 << 16;

/// Why the link failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkError {
    /// The medium failed (the port closed, the simulation stopped).
    #[error("{0}")]
    Io(String),
    /// No reply.
    #[error("no reply to {command} after {tries} tries of {timeout_ms} ms: check the port, the baud rate and that the board is running")]
    Timeout {
        /// The command.
        command: String,
        /// Attempts made.
        tries: u32,
        /// Timeout per attempt.
        timeout_ms: u64,
    },
    /// Every attempt reached the board corrupted (NAK BAD_CRC or FRAMING, sequence 0).
    #[error("{command} reached the board corrupted on all {tries} tries (NAK {reason} with sequence 0): check the wiring and the baud rate")]
    Corrupted {
        /// The command.
        command: String,
        /// Attempts made.
        tries: u32,
        /// The last NAK's reason (BAD_CRC or FRAMING).
        reason: &'static str,
    },
}

/// How long a host waits for a reply and how often it sends a frame again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RetryPolicy {
    /// Reply timeout per attempt (s).
    pub timeout: f64,
    /// Attempts after the first.
    pub retries: u32,
    /// Pause before resending after a NAK with sequence 0 (s): longer than the device's
    /// inter-byte timeout, so a partial frame begun by a corrupted byte is gone.
    pub resend_gap: f64,
}

impl Default for RetryPolicy {
    fn default() -> Self {
        RetryPolicy {
            timeout: HOST_REPLY_TIMEOUT_S,
            retries: HOST_RETRIES,
            resend_gap: 2.5 * FRAME_TIMEOUT_S,
        }
    }
}

/// A byte medium to a board.
pub trait Transport {
    /// Sends bytes.
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError>;
    /// Appends what arrives to `out`, waiting at most `wait` seconds for a first byte.
    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError>;
    /// The host's clock (s).
    fn now(&self) -> f64;
    /// Lets `seconds` pass.
    fn sleep(&mut self, seconds: f64);
    /// Seconds per byte on the wire.
    fn byte_time(&self) -> f64;
}

/// A medium behind a pointer is the medium: `&mut T` (a session over a simulation the caller
/// keeps) and `Box<T>` (a host that picks its board at run time).
macro_rules! forward_transport {
    ($($ptr:ty),*) => {$(
        impl<T: Transport + ?Sized> Transport for $ptr {
            fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
                (**self).write(bytes)
            }
            fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
                (**self).read(wait, out)
            }
            fn now(&self) -> f64 {
                (**self).now()
            }
            fn sleep(&mut self, seconds: f64) {
                (**self).sleep(seconds)
            }
            fn byte_time(&self) -> f64 {
                (**self).byte_time()
            }
        }
    )*};
}
forward_transport!(&mut T, Box<T>);

/// A short name for messages: `LOAD_SEGMENT 3`, `CONFIGURE STOP_JERK 5`, `START`, …
pub fn command_name(c: &Command) -> String {
    match c {
        Command::LoadSegment { index, .. } => format!("LOAD_SEGMENT {index}"),
        Command::Commit { count } => format!("COMMIT {count}"),
        Command::Configure { param, value } => format!("CONFIGURE {} {value}", param.name()),
        Command::ReadConfig { param } => format!("READ_CONFIG {}", param.name()),
        Command::Power { on } => format!("POWER {}", u8::from(*on)),
        Command::SwapAt { tick } => format!("SWAP_AT {tick}"),
        c => c.name().to_string(),
    }
}

/// The framed protocol over a [`Transport`], with the [`RetryPolicy`].
pub struct FramedLink<T: Transport> {
    transport: T,
    decoder: Decoder,
    seq: u8,
    format: Format,
    policy: RetryPolicy,
    telemetry: std::collections::VecDeque<Status>,
    corrupt_segment: Option<u8>,
    buf: Vec<u8>,
}

impl<T: Transport> FramedLink<T> {
    /// A link over `transport`, numbering its commands from `first_seq` + 1 (a serial port's
    /// session picks it at random, so a new session is never taken for a retry of an old
    /// one's; a simulation picks a fixed one, so runs repeat).
    pub fn new(transport: T, policy: RetryPolicy, first_seq: u8) -> Self {
        FramedLink {
            transport,
            decoder: Decoder::new(),
            seq: first_seq,
            format: snapgen_model::DEFAULT_FORMAT,
            policy,
            telemetry: std::collections::VecDeque::new(),
            corrupt_segment: None,
            buf: Vec::new(),
        }
    }

    /// The medium.
    pub fn transport(&self) -> &T {
        &self.transport
    }

    /// The medium, the link given up.
    pub fn into_transport(self) -> T {
        self.transport
    }

    /// The medium, mutably (a virtual board's world: switches, injected faults).
    pub fn transport_mut(&mut self) -> &mut T {
        &mut self.transport
    }

    /// Test hook: every frame of LOAD_SEGMENT `index` goes out with one bit flipped (the
    /// device answers NAK BAD_CRC, the policy sends it again, corrupted again).
    pub fn corrupt_segment(&mut self, index: Option<u8>) {
        self.corrupt_segment = index;
    }

    /// Reads whatever arrives within `wait`: replies with their sequence numbers (telemetry
    /// kept aside).
    fn receive(&mut self, wait: f64) -> Result<Vec<(u8, Reply)>, LinkError> {
        self.buf.clear();
        self.transport.read(wait, &mut self.buf)?;
        let mut out = Vec::new();
        for &b in &self.buf {
            if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
                match Reply::from_frame(&f) {
                    Some(Reply::Telemetry(s)) => {
                        if self.telemetry.len() == TELEMETRY_KEPT {
                            self.telemetry.pop_front();
                        }
                        self.telemetry.push_back(s);
                    }
                    Some(r) => out.push((f.seq, r)),
                    None => {}
                }
            }
        }
        Ok(out)
    }
}

impl<T: Transport> Link for FramedLink<T> {
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError> {
        self.seq = self.seq.wrapping_add(1).max(1);
        let seq = self.seq;
        let mut bytes = c.to_frame(seq, &self.format).to_bytes();
        if matches!(c, Command::LoadSegment { index, .. } if Some(*index) == self.corrupt_segment) {
            let last = bytes.len() - 3;
            bytes[last] ^= 0x01;
        }
        let tries = self.policy.retries + 1;
        let mut corrupted: Option<Reason> = None;
        for _ in 0..tries {
            self.transport.write(&bytes)?;
            let deadline = self.transport.now() + self.policy.timeout;
            corrupted = None;
            'wait: while self.transport.now() < deadline {
                let left = deadline - self.transport.now();
                for (s, r) in self.receive(left)? {
                    match r {
                        Reply::Nak {
                            reason: reason @ (Reason::BadCrc | Reason::Framing),
                            ..
                        } if s == 0 => {
                            // Our frame arrived corrupted or cut: send it again once the
                            // device's inter-byte timeout has cleared any partial frame.
                            corrupted = Some(reason);
                            self.transport.sleep(self.policy.resend_gap);
                            break 'wait;
                        }
                        r if s == seq => return Ok(r),
                        _ => {} // a reply to an earlier attempt or command
                    }
                }
            }
        }
        let command = command_name(c);
        Err(if let Some(reason) = corrupted {
            LinkError::Corrupted {
                command,
                tries,
                reason: reason.name(),
            }
        } else {
            LinkError::Timeout {
                command,
                tries,
                timeout_ms: (self.policy.timeout * 1e3).round() as u64,
            }
        })
    }

    fn set_format(&mut self, format: &Format) {
        self.format = *format;
    }

    fn take_telemetry(&mut self) -> Option<Status> {
        let last = self.telemetry.pop_back();
        self.telemetry.clear();
        last
    }

    fn drain_telemetry(&mut self) -> Vec<Status> {
        self.telemetry.drain(..).collect()
    }

    fn now(&self) -> f64 {
        self.transport.now()
    }

    fn wait(&mut self, seconds: f64) {
        let until = self.transport.now() + seconds;
        while self.transport.now() < until {
            let left = until - self.transport.now();
            // Replies that come now are late ones to earlier commands: dropped; a failing
            // medium shows on the next command.
            if self.receive(left).is_err() {
                self.transport.sleep(left);
                break;
            }
        }
    }

    fn byte_time(&self) -> f64 {
        self.transport.byte_time()
    }
}
