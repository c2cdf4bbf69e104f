//! `snapgen send`: plans a move from the device's exact position, uploads it, starts it, follows
//! it by telemetry, and checks where it ended.
//!
//! Every command waits for its reply; a lost reply is retried with the same sequence number
//! (the device answers a retry without executing it twice); a frame the device received
//! corrupted (NAK BAD_CRC) is sent again. Any other NAK, or no reply after the retries, ends
//! the run with an error — and `START` is only sent after every segment and the commit were
//! acknowledged.

use std::io::{IsTerminal, Read, Write};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use serialport::SerialPort;
use snapgen_model::protocol::{
    Command, Decoded, Decoder, Param, Reason, Reply, Status, PROTOCOL_VERSION,
};
use snapgen_model::{plan_from, ChainState, Format, MoveRequest, Plan, Program};

/// Pause before resending: longer than a device's inter-byte timeout (20 ms), so a partial
/// frame left by a corrupted one is dropped before the retry arrives.
const RESEND_GAP: Duration = Duration::from_millis(50);

/// What can go wrong talking to a board.
#[derive(Debug, thiserror::Error)]
pub enum SendError {
    /// The port would not open.
    #[error("cannot open {port}: {source}")]
    Open {
        /// Port path.
        port: String,
        /// Why.
        source: serialport::Error,
    },
    /// Reading or writing failed.
    #[error("serial I/O on {port}: {source}")]
    Io {
        /// Port path.
        port: String,
        /// Why.
        source: std::io::Error,
    },
    /// The device rejected a command.
    #[error("the device rejected {command}: {reason:?}")]
    Nak {
        /// The command.
        command: String,
        /// Its reason.
        reason: Reason,
    },
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
    /// An unexpected reply.
    #[error("unexpected reply to {command}: {reply:?}")]
    Unexpected {
        /// The command.
        command: String,
        /// The reply.
        reply: Reply,
    },
    /// The device speaks another protocol or format.
    #[error("device reports protocol {protocol}, {max_segments} segments, {snap_bytes} snap bytes; this host speaks protocol {PROTOCOL_VERSION} with {want_segments} and {want_bytes}")]
    Version {
        /// Device protocol.
        protocol: u8,
        /// Device program depth.
        max_segments: u8,
        /// Device snap bytes.
        snap_bytes: u8,
        /// Ours.
        want_segments: usize,
        /// Ours.
        want_bytes: usize,
    },
    /// The device is moving.
    #[error("the device is busy with a move: wait for it or abort it")]
    Busy,
    /// The move was aborted on the device.
    #[error("the move was aborted on the device at tick {0}")]
    Aborted(u32),
    /// No progress.
    #[error("no telemetry or status progress for {0:?}: the board stopped answering")]
    Stalled(Duration),
    /// The device ended somewhere else than planned.
    #[error("the device ended at position register {got:#x}, the plan said {want:#x}")]
    WrongEnd {
        /// Device register.
        got: i128,
        /// Planned register.
        want: i128,
    },
}

/// Link settings.
#[derive(Clone, Debug)]
pub struct SendOptions {
    /// Serial device path.
    pub port: String,
    /// Baud rate.
    pub baud: u32,
    /// Reply timeout per attempt.
    pub timeout: Duration,
    /// Retries after the first attempt.
    pub retries: u32,
    /// Test hook: corrupt one bit of this segment's frame on every attempt.
    pub corrupt_segment: Option<u8>,
    /// Send a controlled stop this long after the start.
    pub stop_after: Option<Duration>,
}

/// The outcome of a move.
#[derive(Clone, Debug)]
pub struct SendReport {
    /// The plan that was run.
    pub plan: Plan,
    /// Final status.
    pub status: Status,
    /// Final position register.
    #[allow(dead_code)]
    pub x: i128,
}

/// A short name for messages: `LOAD_SEGMENT 3`, `START`, …
fn command_name(c: &Command) -> String {
    match c {
        Command::Ping => "PING".into(),
        Command::LoadSegment { index, .. } => format!("LOAD_SEGMENT {index}"),
        Command::Commit { count, .. } => format!("COMMIT {count}"),
        Command::Start => "START".into(),
        Command::Stop => "STOP".into(),
        Command::Abort => "ABORT".into(),
        Command::ReadStatus => "READ_STATUS".into(),
        Command::Configure { param, value } => format!("CONFIGURE {param:?} {value}"),
        Command::ReadPosition => "READ_POSITION".into(),
    }
}

struct Link {
    port: Box<dyn SerialPort>,
    name: String,
    decoder: Decoder,
    seq: u8,
    format: Format,
    opts: SendOptions,
    telemetry: Option<(Instant, Status)>,
}

impl Link {
    fn io(&self, source: std::io::Error) -> SendError {
        SendError::Io {
            port: self.name.clone(),
            source,
        }
    }

    /// Reads whatever arrives within `wait`; returns replies (telemetry is kept aside).
    fn read_replies(&mut self, wait: Duration) -> Result<Vec<(u8, Reply)>, SendError> {
        let deadline = Instant::now() + wait;
        let mut out = Vec::new();
        let mut buf = [0u8; 512];
        while Instant::now() < deadline && out.is_empty() {
            match self.port.read(&mut buf) {
                Ok(n) => {
                    for &b in &buf[..n] {
                        if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
                            match Reply::from_frame(&f) {
                                Some(Reply::Telemetry(s)) => {
                                    self.telemetry = Some((Instant::now(), s));
                                }
                                Some(r) => out.push((f.seq, r)),
                                None => {}
                            }
                        }
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => return Err(self.io(e)),
            }
        }
        Ok(out)
    }

    /// Sends a command and returns its reply (retrying as the module documentation says).
    fn transact(&mut self, c: Command, corrupt: bool) -> Result<Reply, SendError> {
        self.seq = self.seq.wrapping_add(1).max(1);
        let seq = self.seq;
        let mut bytes = c.to_frame(seq, &self.format).to_bytes();
        if corrupt {
            let last = bytes.len() - 3;
            bytes[last] ^= 0x01;
        }
        let name = command_name(&c);
        let tries = self.opts.retries + 1;
        let mut last_nak = None;
        for _ in 0..tries {
            self.port.write_all(&bytes).map_err(|e| self.io(e))?;
            self.port.flush().map_err(|e| self.io(e))?;
            let deadline = Instant::now() + self.opts.timeout;
            'wait: while Instant::now() < deadline {
                for (s, r) in self.read_replies(deadline - Instant::now())? {
                    match r {
                        Reply::Nak {
                            reason: Reason::BadCrc,
                            ..
                        } if s == 0 => {
                            // Our frame arrived corrupted: send it again, after the device's
                            // inter-byte timeout has cleared any partial frame.
                            last_nak = Some(Reason::BadCrc);
                            std::thread::sleep(RESEND_GAP);
                            break 'wait;
                        }
                        Reply::Nak { reason, .. } if s == seq => {
                            return Err(SendError::Nak {
                                command: name,
                                reason,
                            })
                        }
                        r if s == seq => return Ok(r),
                        _ => {} // a stale reply to an earlier attempt
                    }
                }
            }
        }
        Err(match last_nak {
            Some(reason) => SendError::Nak {
                command: name,
                reason,
            },
            None => SendError::Timeout {
                command: name,
                tries,
                timeout_ms: self.opts.timeout.as_millis() as u64,
            },
        })
    }

    fn expect_ack(&mut self, c: Command, corrupt: bool) -> Result<(), SendError> {
        match self.transact(c, corrupt)? {
            Reply::Ack { cmd } if cmd == c.code() => Ok(()),
            r => Err(SendError::Unexpected {
                command: command_name(&c),
                reply: r,
            }),
        }
    }

    fn status(&mut self) -> Result<Status, SendError> {
        match self.transact(Command::ReadStatus, false)? {
            Reply::Status(s) => Ok(s),
            r => Err(SendError::Unexpected {
                command: "ReadStatus".into(),
                reply: r,
            }),
        }
    }

    fn position(&mut self) -> Result<i128, SendError> {
        match self.transact(Command::ReadPosition, false)? {
            Reply::Position { x } => Ok(x),
            r => Err(SendError::Unexpected {
                command: "ReadPosition".into(),
                reply: r,
            }),
        }
    }
}

/// Errors before anything is sent: the move cannot be planned.
#[derive(Debug, thiserror::Error)]
pub enum SendFailure {
    /// The plan failed (exit 2).
    #[error(transparent)]
    Plan(#[from] snapgen_model::PlanError),
    /// The link failed (exit 1).
    #[error(transparent)]
    Link(#[from] SendError),
}

/// Plans, uploads, starts and follows one move.
pub fn send(
    request: &MoveRequest,
    format: &Format,
    opts: &SendOptions,
) -> Result<SendReport, SendFailure> {
    let port = serialport::new(&opts.port, opts.baud)
        .timeout(Duration::from_millis(10))
        .open()
        .map_err(|source| SendError::Open {
            port: opts.port.clone(),
            source,
        })?;
    let mut link = Link {
        port,
        name: opts.port.clone(),
        decoder: Decoder::new(),
        seq: 0,
        format: *format,
        opts: opts.clone(),
        telemetry: None,
    };
    match link.transact(Command::Ping, false)? {
        Reply::Version {
            protocol,
            max_segments,
            snap_bytes,
        } if protocol == PROTOCOL_VERSION
            && usize::from(max_segments) == format.max_segments
            && usize::from(snap_bytes) == Program::snap_bytes(format) => {}
        Reply::Version {
            protocol,
            max_segments,
            snap_bytes,
        } => {
            return Err(SendError::Version {
                protocol,
                max_segments,
                snap_bytes,
                want_segments: format.max_segments,
                want_bytes: Program::snap_bytes(format),
            }
            .into())
        }
        r => {
            return Err(SendError::Unexpected {
                command: "Ping".into(),
                reply: r,
            }
            .into())
        }
    }
    if link.status()?.state & 1 != 0 {
        return Err(SendError::Busy.into());
    }
    let x0 = link.position()?;
    let plan = plan_from(request, format, ChainState::at_rest(x0))?;
    let ticks = plan.ticks_total();
    link.expect_ack(
        Command::Configure {
            param: Param::TelemetryPeriod,
            value: (ticks / 50).clamp(1, u64::from(u32::MAX)) as u32,
        },
        false,
    )?;
    for (k, s) in plan.program.segments.iter().enumerate() {
        link.expect_ack(
            Command::LoadSegment {
                index: k as u8,
                segment: *s,
            },
            opts.corrupt_segment == Some(k as u8),
        )?;
    }
    link.expect_ack(
        Command::Commit {
            count: plan.program.segments.len() as u8,
            cruise: plan.cruise_segment.map(|c| c as u8),
        },
        false,
    )?;
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(ticks);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} ticks {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    link.expect_ack(Command::Start, false)?;
    let started = Instant::now();
    let mut stop_sent = false;
    let stall = Duration::from_secs(5);
    let mut last_progress = (Instant::now(), u32::MAX);
    let status = loop {
        let _ = link.read_replies(Duration::from_millis(20))?;
        if let Some(after) = opts.stop_after {
            if !stop_sent && started.elapsed() >= after {
                link.expect_ack(Command::Stop, false)?;
                stop_sent = true;
            }
        }
        let s = match link.telemetry.take() {
            Some((_, s)) => s,
            None => link.status()?,
        };
        bar.set_position(u64::from(s.tick_count));
        if s.state & 4 != 0 {
            bar.finish_and_clear();
            return Err(SendError::Aborted(s.tick_count).into());
        }
        if s.state & 1 == 0 && s.state & 2 != 0 {
            break s;
        }
        if s.tick_count != last_progress.1 {
            last_progress = (Instant::now(), s.tick_count);
        } else if last_progress.0.elapsed() > stall {
            bar.finish_and_clear();
            return Err(SendError::Stalled(stall).into());
        }
    };
    bar.finish_and_clear();
    link.expect_ack(
        Command::Configure {
            param: Param::TelemetryPeriod,
            value: 0,
        },
        false,
    )?;
    let x = link.position()?;
    // Let the encoder settle on the final position (a real axis follows the reference with a
    // lag), for up to a second.
    let settle = Instant::now();
    let mut last = link.status()?;
    while last.encoder != last.position && settle.elapsed() < Duration::from_secs(1) {
        std::thread::sleep(Duration::from_millis(20));
        last = link.status()?;
    }
    let status = Status {
        tick_count: status.tick_count,
        ..last
    };
    let want = plan.end_after(u64::from(status.tick_count));
    if x != want.x {
        return Err(SendError::WrongEnd {
            got: x,
            want: want.x,
        }
        .into());
    }
    Ok(SendReport { plan, status, x })
}
