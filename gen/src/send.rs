//! `snapgen send`: asks the board what it is, plans a move from its exact registers with its
//! Ts and format, uploads it, starts it, follows it, and checks where it ended, bit for bit.
//!
//! Before anything moves: `PING` gives the board's identity (protocol, clock, tick divider,
//! register widths, program depth, design hash); a board that speaks another protocol, or a
//! format this host cannot plan for, or a `--ts` other than the board's, is refused (exit 2).
//! The stop limits (`STOP_JERK`, `STOP_ACCEL`: the move's own peaks, or `--stop-decel` and
//! `--stop-jerk`), the host watchdog and the telemetry period are written and read back; the
//! axis is powered on if it is disabled. During the move the host reads the status every
//! [`POLL`] (which also keeps the board's watchdog fed).
//!
//! A session begins with `PING`, which clears the board's retry memory, and numbers its
//! commands from a random sequence number, so that no command of a new session is taken for a
//! retry of an earlier one's.
//!
//! Every command waits for its reply; a lost reply is retried with the same sequence number
//! (the device answers a retry without executing it twice); a frame the device received
//! corrupted (NAK BAD_CRC) is sent again. Any other NAK, or no reply after the retries, ends
//! the run with an error — and `START` is only sent after every segment and the commit were
//! acknowledged.
//!
//! The end is checked against the model: a move that ran to its end must stand exactly on
//! the planned register at rest; a move cut by `--stop-after-ms` must end where the
//! controlled stop taken on one of its ticks ends ([`snapgen_model::stop::explain`]).

use std::io::{IsTerminal, Read, Write};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use serialport::SerialPort;
use snapgen_host::protocol::{
    AxisState, Command, Decoded, Decoder, ErrorId, Identity, Param, Reason, Reply, StateReply,
    Status,
};
use snapgen_model::format::Quantity;
use snapgen_model::stop::{StopFound, StopLimits};
use snapgen_model::{ChainState, Format, Program, FRAC_BITS};
use snapgen_plan::{plan_from, MoveRequest, Plan};
use snapgen_spec::wire::PROTOCOL_VERSION;

/// Pause before resending: longer than a device's inter-byte timeout (20 ms), so a partial
/// frame left by a corrupted one is dropped before the retry arrives.
const RESEND_GAP: Duration = Duration::from_millis(50);
/// How often the host reads the status while a move runs (well inside the watchdog's
/// default 1000 ms).
pub const POLL: Duration = Duration::from_millis(100);
/// No progress for this long ends the run (or the wait for a stop).
const STALL: Duration = Duration::from_secs(5);

/// What can go wrong talking to a board (exit 1).
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
    #[error("the device rejected {command}: {} ({})", reason.name(), reason_hint(*reason))]
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
        reply: Box<Reply>,
    },
    /// A configuration write did not read back.
    #[error("wrote {value} to {}, read back {read}: the board did not keep it", param.name())]
    ReadBack {
        /// The parameter.
        param: Param,
        /// Written.
        value: i128,
        /// Read back.
        read: i128,
    },
    /// The axis is not at rest in Standstill or Disabled.
    #[error("the axis is {} (v {v}, a {a}, j {j} raw): wait for it to stop, or stop it", state.name())]
    NotIdle {
        /// Its state.
        state: AxisState,
        /// Velocity.
        v: i128,
        /// Acceleration.
        a: i128,
        /// Jerk.
        j: i128,
    },
    /// The axis is in ErrorStop.
    #[error("the axis is in ErrorStop ({}): remove the cause, then run again with --reset", error.name())]
    AxisError {
        /// Why.
        error: ErrorId,
    },
    /// The axis stopped itself during the move.
    #[error("the axis stopped itself at tick {tick}: {} (now {})", error.name(), state.name())]
    Stopped {
        /// Why.
        error: ErrorId,
        /// Its state now.
        state: AxisState,
        /// Ticks since the start.
        tick: u32,
    },
    /// No progress.
    #[error("no telemetry or status progress for {0:?}: the axis is not moving toward its end (is the board's clock running?)")]
    Stalled(Duration),
    /// The device ended somewhere else than planned.
    #[error(
        "the device ended at x {got:#x} (v {v}, a {a}, j {j}), the plan said x {want:#x} at rest"
    )]
    WrongEnd {
        /// Device register.
        got: i128,
        /// Planned register.
        want: i128,
        /// Velocity.
        v: i128,
        /// Acceleration.
        a: i128,
        /// Jerk.
        j: i128,
    },
    /// After a stop, no stop taken on any tick of the move explains where the device is.
    #[error("after the stop the device stands at x {x:#x} after {ticks} ticks: no controlled stop taken on ticks {from}..={ticks} of the move ends there")]
    StopUnexplained {
        /// Device register.
        x: i128,
        /// Its tick count.
        ticks: u32,
        /// First candidate tick.
        from: u32,
    },
}

/// What the user can do about a NAK.
fn reason_hint(r: Reason) -> &'static str {
    match r {
        Reason::NotEnabled => "the axis is disabled",
        Reason::AxisError => "the axis is in ErrorStop: clear the cause and reset it",
        Reason::NotConfigured => "the stop limits are not set",
        Reason::Busy => "the axis is moving",
        Reason::Stopping => "the axis is stopping",
        Reason::BadArgument => "an argument is out of range",
        Reason::Limit => "the move heads into an active limit switch: move away from it",
        Reason::NotDisabled => "that parameter is set only while the axis is disabled",
        _ => "see docs/PROTOCOL.md",
    }
}

/// Errors that are the user's to fix (exit 2): nothing was moved.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The plan failed.
    #[error(transparent)]
    Plan(#[from] snapgen_plan::PlanError),
    /// The board speaks another protocol.
    #[error("the board speaks protocol {device}, this snapgen speaks {PROTOCOL_VERSION}: use a matching snapgen, or rebuild the board's design with this one")]
    Protocol {
        /// Its version.
        device: u8,
    },
    /// The board's format is one this host cannot plan for.
    #[error("the board's format ({what}) is not one this snapgen plans for: rebuild the board's design with this snapgen")]
    Format {
        /// What differs.
        what: String,
    },
    /// `--ts` is not the board's Ts.
    #[error("--ts {asked} s, but the board ticks every {board} s (tick divider {div} at {clock} Hz): drop --ts to plan with the board's Ts")]
    Ts {
        /// Asked for.
        asked: f64,
        /// The board's.
        board: f64,
        /// Its tick divider.
        div: u32,
        /// Its clock.
        clock: u32,
    },
    /// A stop limit that is not a positive number.
    #[error("{flag} {value}: give a positive number (units/s² or units/s³)")]
    StopLimit {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
    },
    /// A stop limit the board's register cannot hold at its Ts.
    #[error("{flag} {value} is {raw:.3e} raw at the board's Ts, above the register's 2^103 − 1: give a smaller limit")]
    StopLimitRange {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
        /// Raw.
        raw: f64,
    },
    /// `--ts` is not a positive number of seconds.
    #[error("--ts {0}: give a positive number of seconds (or drop it: the board's Ts is used)")]
    BadTs(f64),
    /// The controller cannot be configured as asked.
    #[error("the controller for this board: {0}")]
    Servo(String),
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
    /// The Ts the user asked for (refused unless it is the board's).
    pub ts: Option<f64>,
    /// Output position LSB (units): a host-side scale, not a board property.
    pub position_lsb: f64,
    /// The stop's deceleration limit (units/s²) [default: the move's peak acceleration].
    pub stop_decel: Option<f64>,
    /// The stop's jerk limit (units/s³) [default: the move's peak jerk].
    pub stop_jerk: Option<f64>,
    /// Reset an axis found in ErrorStop before the move.
    pub reset: bool,
    /// The board's host watchdog (ms; 0: off).
    pub watchdog_ms: u32,
    /// The axis drives this motor: the controller is configured for it.
    pub servo: Option<ServoOptions>,
    /// Settled: |position − encoder| within this many LSBs.
    pub settle_lsb: u32,
}

/// The motor the axis drives, and how to control it.
#[derive(Clone, Debug)]
pub struct ServoOptions {
    /// The plant.
    pub plant: snapgen_plant::PlantParams,
    /// Bandwidth, damping, feed-forward, following limit.
    pub design: snapgen_plant::gains::LoopDesign,
    /// Sample rate (Hz).
    pub loop_hz: f64,
    /// PWM frequency (Hz).
    pub pwm_hz: f64,
}

/// How the motor followed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Following {
    /// The largest |following error| at a controller sample during the move (LSBs).
    pub peak_lsb: f64,
    /// Position − encoder when the reference came to rest (LSBs).
    pub at_end_lsb: i64,
    /// Seconds from then until |position − encoder| stayed within the band (host-measured, to
    /// the poll); `None` if not within the wait.
    pub settle_s: Option<f64>,
    /// The band (LSBs).
    pub band_lsb: u32,
}

/// The outcome of a move.
#[derive(Clone, Debug)]
pub struct SendReport {
    /// The board.
    pub identity: Identity,
    /// The plan that was run.
    pub plan: Plan,
    /// The stop limits used (raw).
    pub stop_limits: StopLimits,
    /// Final status.
    pub status: Status,
    /// Final registers.
    pub state: StateReply,
    /// The controlled stop that cut the move, if one did.
    pub stop: Option<StopFound>,
    /// With a motor: how it followed.
    pub following: Option<Following>,
}

/// A short name for messages: `LOAD_SEGMENT 3`, `START`, …
fn command_name(c: &Command) -> String {
    match c {
        Command::LoadSegment { index, .. } => format!("LOAD_SEGMENT {index}"),
        Command::Commit { count } => format!("COMMIT {count}"),
        Command::Configure { param, value } => format!("CONFIGURE {} {value}", param.name()),
        Command::ReadConfig { param } => format!("READ_CONFIG {}", param.name()),
        Command::Power { on } => format!("POWER {}", u8::from(*on)),
        c => c.name().to_string(),
    }
}

/// A random first sequence number for a session (from the clock and the process id), so
/// that a session's commands are not taken for retries of an earlier session's even by a
/// board that did not see this session's PING.
fn session_seq() -> u8 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let h = snapgen_model::device::fnv1a32(
        &[nanos.to_le_bytes(), std::process::id().to_le_bytes()].concat(),
    );
    (h ^ (h >> 8) ^ (h >> 16) ^ (h >> 24)) as u8
}

/// A connection to a board.
pub struct Link {
    port: Box<dyn SerialPort>,
    name: String,
    decoder: Decoder,
    seq: u8,
    format: Format,
    timeout: Duration,
    retries: u32,
    telemetry: Option<Status>,
}

impl Link {
    /// Opens `port` at `baud`.
    pub fn open(port: &str, baud: u32, timeout: Duration, retries: u32) -> Result<Self, SendError> {
        let p = serialport::new(port, baud)
            .timeout(Duration::from_millis(10))
            .open()
            .map_err(|source| SendError::Open {
                port: port.to_string(),
                source,
            })?;
        Ok(Link {
            port: p,
            name: port.to_string(),
            decoder: Decoder::new(),
            seq: session_seq(),
            format: snapgen_model::DEFAULT_FORMAT,
            timeout,
            retries,
            telemetry: None,
        })
    }

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
                                Some(Reply::Telemetry(s)) => self.telemetry = Some(s),
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
    pub fn transact(&mut self, c: Command, corrupt: bool) -> Result<Reply, SendError> {
        self.seq = self.seq.wrapping_add(1).max(1);
        let seq = self.seq;
        let mut bytes = c.to_frame(seq, &self.format).to_bytes();
        if corrupt {
            let last = bytes.len() - 3;
            bytes[last] ^= 0x01;
        }
        let name = command_name(&c);
        let tries = self.retries + 1;
        let mut last_nak = None;
        for _ in 0..tries {
            self.port.write_all(&bytes).map_err(|e| self.io(e))?;
            self.port.flush().map_err(|e| self.io(e))?;
            let deadline = Instant::now() + self.timeout;
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
                timeout_ms: self.timeout.as_millis() as u64,
            },
        })
    }

    fn unexpected(c: &Command, reply: Reply) -> SendError {
        SendError::Unexpected {
            command: command_name(c),
            reply: Box::new(reply),
        }
    }

    /// Sends a command that is answered with an ACK.
    pub fn expect_ack(&mut self, c: Command, corrupt: bool) -> Result<(), SendError> {
        match self.transact(c, corrupt)? {
            Reply::Ack { cmd } if cmd == c.code() => Ok(()),
            r => Err(Self::unexpected(&c, r)),
        }
    }

    /// The board's identity.
    pub fn identity(&mut self) -> Result<Identity, SendError> {
        match self.transact(Command::Ping, false)? {
            Reply::Identity(i) => Ok(i),
            r => Err(Self::unexpected(&Command::Ping, r)),
        }
    }

    /// The status block.
    pub fn status(&mut self) -> Result<Status, SendError> {
        match self.transact(Command::ReadStatus, false)? {
            Reply::Status(s) => Ok(s),
            r => Err(Self::unexpected(&Command::ReadStatus, r)),
        }
    }

    /// The chain's registers and their tick.
    pub fn state(&mut self) -> Result<StateReply, SendError> {
        match self.transact(Command::ReadState, false)? {
            Reply::State(s) => Ok(s),
            r => Err(Self::unexpected(&Command::ReadState, r)),
        }
    }

    /// Writes a parameter and reads it back.
    pub fn configure(&mut self, param: Param, value: i128) -> Result<(), SendError> {
        self.expect_ack(Command::Configure { param, value }, false)?;
        match self.read_config(param)? {
            v if v == value => Ok(()),
            read => Err(SendError::ReadBack { param, value, read }),
        }
    }

    /// A parameter's value.
    pub fn read_config(&mut self, param: Param) -> Result<i128, SendError> {
        let c = Command::ReadConfig { param };
        match self.transact(c, false)? {
            Reply::Config { param: p, value } if p == param => Ok(value),
            r => Err(Self::unexpected(&c, r)),
        }
    }

    /// Writes both stop limits (read back) in an order the board accepts while enabled: every
    /// intermediate pair keeps `0 < STOP_JERK ≤ STOP_ACCEL`.
    pub fn set_stop_limits(&mut self, limits: StopLimits) -> Result<(), SendError> {
        let accel_now = self.read_config(Param::StopAccel)?;
        if limits.jerk <= accel_now {
            self.configure(Param::StopJerk, limits.jerk)?;
            self.configure(Param::StopAccel, limits.accel)
        } else {
            self.configure(Param::StopAccel, limits.accel)?;
            self.configure(Param::StopJerk, limits.jerk)
        }
    }
}

/// Why the run failed.
#[derive(Debug, thiserror::Error)]
pub enum SendFailure {
    /// The user's to fix (exit 2): nothing moved.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The link or the board (exit 1).
    #[error(transparent)]
    Link(#[from] SendError),
}

impl From<snapgen_plan::PlanError> for SendFailure {
    fn from(e: snapgen_plan::PlanError) -> Self {
        SendFailure::Input(InputError::Plan(e))
    }
}

/// The format to plan in for a board with identity `id`, or why this host cannot.
pub fn board_format(id: &Identity, position_lsb: f64) -> Result<Format, InputError> {
    if id.protocol != PROTOCOL_VERSION {
        return Err(InputError::Protocol {
            device: id.protocol,
        });
    }
    let bad = |what: String| InputError::Format { what };
    if u32::from(id.frac_bits) != FRAC_BITS {
        return Err(bad(format!(
            "{} fractional position bits, this snapgen has {FRAC_BITS}",
            id.frac_bits
        )));
    }
    if id.clock_hz == 0 {
        return Err(bad("a clock of 0 Hz".into()));
    }
    let f = Format {
        ts: id.ts(),
        position_lsb,
        widths: snapgen_model::Widths {
            x: u32::from(id.x_bits),
            v: u32::from(id.v_bits),
            a: u32::from(id.a_bits),
            j: u32::from(id.j_bits),
            d: u32::from(id.d_bits),
        },
        tick_bits: u32::from(id.tick_bits),
        max_segments: usize::from(id.max_segments),
    };
    f.validate()
        .map_err(|e| bad(format!("registers {:?}: {e}", f.widths.as_array())))?;
    if usize::from(id.snap_bytes) != Program::snap_bytes(&f) {
        return Err(bad(format!(
            "{} snap bytes for a {}-bit snap",
            id.snap_bytes, id.d_bits
        )));
    }
    Ok(f)
}

/// The stop limits, raw at the board's Ts: the ones asked for, or the plan's own peaks (from
/// the independent integration of its program). Rounded down (a lower limit is the safe
/// side), at least 1, and the jerk at most the deceleration (a jerk that reaches it within a
/// tick).
pub fn stop_limits(plan: &Plan, opts: &SendOptions) -> Result<StopLimits, InputError> {
    let f = &plan.format;
    let max = Param::StopJerk.max() as f64;
    let raw = |flag: &'static str, v: Option<f64>, q: Quantity, peak: i128| match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(InputError::StopLimit { flag, value: x }),
        Some(x) if (x * f.scale(q)).floor() > max => Err(InputError::StopLimitRange {
            flag,
            value: x,
            raw: x * f.scale(q),
        }),
        Some(x) => {
            let r = ((x * f.scale(q)).floor() as i128).max(1);
            if r < peak {
                eprintln!(
                    "warning: {flag} {x} is below the move's peak ({:.6e}): a stop during the move may begin outside its limits (it still lands exactly, flagged STOP_OVER_LIMITS)",
                    peak as f64 / f.scale(q)
                );
            }
            Ok(r)
        }
        None => Ok(peak.max(1)),
    };
    let run = crate::report::integrate_plan(plan);
    // The peaks fit the registers (the plan is checked), so in i128.
    let peak = |r: usize| run.range(r).max_abs().as_i128();
    let accel = raw(
        "--stop-decel",
        opts.stop_decel,
        Quantity::Acceleration,
        peak(2),
    )?;
    let jerk = raw("--stop-jerk", opts.stop_jerk, Quantity::Jerk, peak(3))?;
    Ok(StopLimits {
        jerk: jerk.min(accel),
        accel,
    })
}

fn progress_bar(ticks: u64) -> ProgressBar {
    if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(ticks);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} ticks {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    }
}

/// Plans, uploads, starts and follows one move; checks its end.
pub fn send(request: &MoveRequest, opts: &SendOptions) -> Result<SendReport, SendFailure> {
    let mut link = Link::open(&opts.port, opts.baud, opts.timeout, opts.retries)?;
    // What the board is, before anything else.
    let identity = link.identity()?;
    let format = board_format(&identity, opts.position_lsb)?;
    link.format = format;
    if let Some(asked) = opts.ts {
        if !(asked.is_finite() && asked > 0.0) {
            return Err(InputError::BadTs(asked).into());
        }
        if (asked - format.ts).abs() > 1e-9 * format.ts {
            return Err(InputError::Ts {
                asked,
                board: format.ts,
                div: identity.tick_divider,
                clock: identity.clock_hz,
            }
            .into());
        }
    }
    // Where it stands.
    let mut status = link.status()?;
    let axis = status.axis().unwrap_or(AxisState::ErrorStop);
    if axis == AxisState::ErrorStop {
        if !opts.reset {
            return Err(SendError::AxisError {
                error: ErrorId::from_byte(status.error).unwrap_or_default(),
            }
            .into());
        }
        link.expect_ack(Command::Reset, false)?;
        status = link.status()?;
    }
    let state = link.state()?;
    let axis = status.axis().unwrap_or(AxisState::ErrorStop);
    let at_rest = (state.v, state.a, state.j) == (0, 0, 0);
    if !matches!(axis, AxisState::Standstill | AxisState::Disabled) || !at_rest {
        return Err(SendError::NotIdle {
            state: axis,
            v: state.v,
            a: state.a,
            j: state.j,
        }
        .into());
    }
    if let Some(s) = &opts.servo {
        configure_servo(&mut link, &identity, &format, s, axis)?;
    }
    // (POWER 0 for the controller's rate leaves the axis Disabled.)
    let axis = link.status()?.axis().unwrap_or(AxisState::ErrorStop);
    let state = link.state()?;
    let start = ChainState::at_rest(state.x);
    let plan = plan_from(request, &format, start)?;
    let limits = stop_limits(&plan, opts)?;
    let ticks = plan.ticks_total();
    // Configuration, each write read back; then the amplifier.
    link.set_stop_limits(limits)?;
    link.configure(Param::WatchdogMs, i128::from(opts.watchdog_ms))?;
    link.configure(
        Param::TelemetryPeriod,
        i128::from((ticks / 50).clamp(1, u64::from(u32::MAX))),
    )?;
    if axis == AxisState::Disabled {
        link.expect_ack(Command::Power { on: true }, false)?;
    }
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
        },
        false,
    )?;
    let bar = progress_bar(ticks);
    link.expect_ack(Command::Start, false)?;
    let started = Instant::now();
    // The tick count last seen before the stop went out: the stop was taken on a later tick.
    let mut stop_from: Option<u32> = None;
    let mut seen_ticks = 0u32;
    let mut last_progress = (Instant::now(), u32::MAX);
    let end_status = loop {
        let _ = link.read_replies(POLL)?;
        if let Some(t) = link.telemetry.take() {
            seen_ticks = seen_ticks.max(t.tick_count);
        }
        if let Some(after) = opts.stop_after {
            if stop_from.is_none() && started.elapsed() >= after {
                stop_from = Some(seen_ticks);
                link.expect_ack(Command::Stop, false)?;
            }
        }
        let s = link.status()?;
        seen_ticks = seen_ticks.max(s.tick_count);
        bar.set_position(u64::from(s.tick_count));
        let axis = s.axis().unwrap_or(AxisState::ErrorStop);
        if axis == AxisState::ErrorStop {
            bar.finish_and_clear();
            return Err(SendError::Stopped {
                error: ErrorId::from_byte(s.error).unwrap_or_default(),
                state: axis,
                tick: s.tick_count,
            }
            .into());
        }
        if axis == AxisState::Standstill {
            break s;
        }
        if s.tick_count != last_progress.1 {
            last_progress = (Instant::now(), s.tick_count);
        } else if last_progress.0.elapsed() > STALL {
            bar.finish_and_clear();
            return Err(SendError::Stalled(STALL).into());
        }
    };
    bar.finish_and_clear();
    link.configure(Param::TelemetryPeriod, 0)?;
    let end = link.state()?;
    let end_chain = ChainState {
        x: end.x,
        v: end.v,
        a: end.a,
        j: end.j,
    };
    let stop = match stop_from {
        None => {
            if end_chain != plan.final_state {
                return Err(SendError::WrongEnd {
                    got: end.x,
                    want: plan.final_state.x,
                    v: end.v,
                    a: end.a,
                    j: end.j,
                }
                .into());
            }
            None
        }
        Some(from) => {
            let found = snapgen_model::stop::explain(
                start,
                &plan.program,
                &format.widths,
                limits,
                end_chain,
                u64::from(end_status.tick_count),
                u64::from(from),
            );
            match found {
                Some(f) => Some(f),
                // The stop came after the move's end: it must then stand on the target.
                None if end_chain == plan.final_state => None,
                None => {
                    return Err(SendError::StopUnexplained {
                        x: end.x,
                        ticks: end_status.tick_count,
                        from,
                    }
                    .into())
                }
            }
        }
    };
    // Let the encoder settle on the final position (a real axis follows the reference with a
    // lag): until |position − encoder| stays within the band, for up to two seconds.
    let band = if opts.servo.is_some() {
        i64::from(opts.settle_lsb)
    } else {
        0
    };
    let settle = Instant::now();
    let mut last = link.status()?;
    let at_end = i64::from(last.position) - i64::from(last.encoder);
    let mut settled: Option<Instant> = None;
    while settle.elapsed() < Duration::from_secs(2) {
        let e = (i64::from(last.position) - i64::from(last.encoder)).abs();
        match (e <= band, settled) {
            (true, None) => settled = Some(Instant::now()),
            (false, Some(_)) => settled = None,
            // Within the band for 200 ms: settled.
            (true, Some(t)) if t.elapsed() >= Duration::from_millis(200) => break,
            _ => {}
        }
        std::thread::sleep(Duration::from_millis(10));
        last = link.status()?;
    }
    let following = opts.servo.as_ref().map(|_| Following {
        peak_lsb: end_status.following_peak_counts(),
        at_end_lsb: at_end,
        settle_s: settled.map(|t| t.duration_since(settle).as_secs_f64()),
        band_lsb: opts.settle_lsb,
    });
    Ok(SendReport {
        identity,
        plan,
        stop_limits: limits,
        status: Status {
            tick_count: end_status.tick_count,
            ..last
        },
        state: end,
        stop,
        following,
    })
}

/// Configures the board's controller for the motor in `s` (each write read back): the rate and
/// following limit only while Disabled (an enabled axis at rest is powered off first when they
/// change), the gains at any time.
fn configure_servo(
    link: &mut Link,
    id: &Identity,
    format: &Format,
    s: &ServoOptions,
    axis: AxisState,
) -> Result<(), SendFailure> {
    let bad = |m: String| SendFailure::Input(InputError::Servo(m));
    let ticks = (1.0 / (s.loop_hz * format.ts)).round();
    if !(s.loop_hz.is_finite() && s.loop_hz > 0.0 && (1.0..=65535.0).contains(&ticks)) {
        return Err(bad(format!(
            "--loop-hz {} is {ticks} ticks of the board's Ts {} s: give a rate of 1 to 65 535 ticks",
            s.loop_hz, format.ts
        )));
    }
    let clocks = (f64::from(id.clock_hz) / s.pwm_hz).round();
    if !(s.pwm_hz.is_finite() && s.pwm_hz > 0.0 && (2.0..=32767.0).contains(&clocks)) {
        return Err(bad(format!(
            "--pwm-hz {} is {clocks} clocks of the board's {} Hz: give a rate with 2 to 32 767",
            s.pwm_hz, id.clock_hz
        )));
    }
    let timing = snapgen_plant::gains::LoopTiming {
        ts: format.ts,
        servo_period: ticks as u16,
        pwm_period: clocks as u16,
    };
    let g = snapgen_plant::gains::derive(&s.plant.physical(), &s.design, &timing)
        .map_err(|e| bad(e.to_string()))?;
    let writes = g.config.writes();
    // Those set only while Disabled (SERVO_PERIOD, FOLLOWING_LIMIT) come first.
    let disabled_only = writes
        .iter()
        .take_while(|(p, _)| p.settable() == snapgen_spec::Settable::Disabled)
        .count();
    let (fixed, rest) = writes.split_at(disabled_only);
    if axis != AxisState::Disabled {
        let mut same = true;
        for &(p, v) in fixed {
            same &= link.read_config(p)? == v;
        }
        if !same {
            link.expect_ack(Command::Power { on: false }, false)?;
        }
    }
    let pwm = [(Param::PwmPeriod, i128::from(timing.pwm_period))];
    for &(p, v) in fixed.iter().chain(&pwm).chain(rest) {
        // The rate and the following limit are already right when the axis stayed enabled.
        if link.read_config(p)? != v {
            link.configure(p, v)?;
        }
    }
    Ok(())
}

/// The report `snapgen send` prints.
pub fn describe(r: &SendReport) -> String {
    let f = &r.plan.format;
    let id = &r.identity;
    let digits = (-f.position_lsb.log10()).ceil().max(0.0) as usize;
    let mut s = format!(
        "board: protocol {}, design {:#010x}, {} Hz, {} baud, Ts {} s (tick divider {}), stop limits {} (jerk) / {} (accel) raw\n",
        id.protocol,
        id.design_hash,
        id.clock_hz,
        id.baud,
        f.ts,
        id.tick_divider,
        r.stop_limits.jerk,
        r.stop_limits.accel
    );
    let pos = |x: i128| f.output_lsb(x);
    match r.stop {
        None => s.push_str(&format!(
            "moved {} units in {} ticks: at {} LSB = {:.*} units, encoder {} counts; the registers match the plan bit for bit (x {:#x}, v = a = j = 0)\n",
            r.plan.request.distance,
            r.status.tick_count,
            pos(r.state.x),
            digits,
            f.position_physical(r.state.x),
            r.status.encoder,
            r.state.x
        )),
        Some(st) => s.push_str(&format!(
            "stopped: the controlled stop was taken on tick {} of {} and ran {} ticks to rest{}; at {} LSB = {:.*} units, encoder {} counts; the registers match the model's stop bit for bit (x {:#x}, v = a = j = 0)\n",
            st.taken,
            r.plan.ticks_total(),
            st.ticks,
            if st.over_limits { " (it began outside the stop limits and landed regardless)" } else { " within the stop limits" },
            pos(r.state.x),
            digits,
            f.position_physical(r.state.x),
            r.status.encoder,
            r.state.x
        )),
    }
    if let Some(fo) = r.following {
        let lsb = f.position_lsb;
        s.push_str(&format!(
            "following error: peak {:.2} LSB = {:.3e} units during the move, {} LSB when the reference came to rest; {}\n",
            fo.peak_lsb,
            fo.peak_lsb * lsb,
            fo.at_end_lsb,
            match fo.settle_s {
                Some(t) => format!("within ±{} LSB {:.2} s later (host-measured, 10 ms polls)", fo.band_lsb, t),
                None => format!("not within ±{} LSB after 2 s", fo.band_lsb),
            }
        ));
    }
    s
}

/// What `snapgen stop` saw.
#[derive(Clone, Debug)]
pub struct StopReport {
    /// The axis state before the stop.
    pub before: AxisState,
    /// The status once the stop was over.
    pub status: Status,
    /// The registers then.
    pub state: StateReply,
}

/// MC_Stop (`halt` false: STOP, the axis goes through Stopping) or MC_Halt (`halt`: HALT, the
/// axis stays in its motion state until at rest) from the host: the board brings the axis to
/// rest by itself, within its stop limits; this waits for it and reads the registers.
pub fn stop(
    port: &str,
    baud: u32,
    timeout: Duration,
    retries: u32,
    halt: bool,
) -> Result<StopReport, SendFailure> {
    let mut link = Link::open(port, baud, timeout, retries)?;
    let identity = link.identity()?;
    link.format = board_format(&identity, snapgen_model::DEFAULT_FORMAT.position_lsb)?;
    let before = link.status()?.axis().unwrap_or(AxisState::ErrorStop);
    if before == AxisState::Disabled {
        return Err(SendError::Nak {
            command: "STOP".into(),
            reason: Reason::NotEnabled,
        }
        .into());
    }
    let c = if halt { Command::Halt } else { Command::Stop };
    link.expect_ack(c, false)?;
    // However long the stop takes: it fails only when nothing changes for STALL.
    let mut last_change = (Instant::now(), None);
    let status = loop {
        std::thread::sleep(Duration::from_millis(20));
        let s = link.status()?;
        let axis = s.axis().unwrap_or(AxisState::ErrorStop);
        if !s.has(snapgen_host::protocol::flag::STOPPING)
            && matches!(axis, AxisState::Standstill | AxisState::ErrorStop)
        {
            break s;
        }
        let seen = Some((s.tick_count, s.position, s.velocity));
        if seen != last_change.1 {
            last_change = (Instant::now(), seen);
        } else if last_change.0.elapsed() > STALL {
            return Err(SendError::Stalled(STALL).into());
        }
    };
    let state = link.state()?;
    if (state.v, state.a, state.j) != (0, 0, 0) {
        return Err(SendError::NotIdle {
            state: status.axis().unwrap_or(AxisState::ErrorStop),
            v: state.v,
            a: state.a,
            j: state.j,
        }
        .into());
    }
    Ok(StopReport {
        before,
        status,
        state,
    })
}
