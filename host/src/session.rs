//! A session with a board over any [`Link`]: it begins with PING (which clears the board's
//! retry memory), checks that the board is one this host plans for (protocol, format) and
//! gives the typed requests every host needs: status, registers, configuration written and
//! read back, the stop limits in an order an enabled board accepts, the amplifier.
//!
//! Host and board never silently disagree: the format a session plans with is the one the
//! board reports ([`board_format`]); a board of another protocol or format is refused before
//! anything moves.

use snapgen_model::stop::StopLimits;
use snapgen_model::{Format, Program, Widths, FRAC_BITS};
use snapgen_spec::wire::PROTOCOL_VERSION;

use crate::link::{command_name, Link, LinkError};
use crate::protocol::{
    AxisState, Command, ErrorId, Identity, Param, Reason, Reply, StateReply, Status,
};

/// What the user can do about a NAK.
pub fn reason_hint(r: Reason) -> &'static str {
    match r {
        Reason::NotEnabled => "the axis is disabled",
        Reason::AxisError => "the axis is in ErrorStop: clear the cause and reset it",
        Reason::NotConfigured => "the stop limits are not set",
        Reason::Busy => "the axis is moving",
        Reason::Stopping => "the axis is stopping",
        Reason::BadArgument => "an argument is out of range",
        Reason::Limit => "the move heads into an active limit switch: move away from it",
        Reason::NotDisabled => "that parameter is set only while the axis is disabled",
        Reason::SwapPending => "a program swap is armed: wait until its tick has passed",
        Reason::Late => "the swap's tick is too close: plan for a later one",
        _ => "see docs/PROTOCOL.md",
    }
}

/// What went wrong talking to a board, or on it (exit 1).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HostError {
    /// The link failed.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The device refused a command.
    #[error("the device refused {command}: {} ({})", reason.name(), reason_hint(*reason))]
    Nak {
        /// The command.
        command: String,
        /// Its reason.
        reason: Reason,
    },
    /// An answer that does not fit the command.
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
    /// The axis stopped itself during a move.
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
    #[error("no progress for {0:.1} s: the axis is not moving toward its end (is the board's clock running?)")]
    Stalled(f64),
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

/// Errors that are the user's to fix (exit 2): nothing was moved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
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
    /// `--ts` is not a positive number of seconds.
    #[error("--ts {0}: give a positive number of seconds (or drop it: the board's Ts is used)")]
    BadTs(f64),
    /// A stop limit that is not a positive number.
    #[error("{flag} {value}: give a positive number (units/s² or units/s³)")]
    StopLimit {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
    },
    /// A stop limit the board's register cannot hold at its Ts.
    #[error("{flag} {value} is {raw:.3e} raw at the board's Ts, above the register's maximum {max:.3e}: give a smaller limit")]
    StopLimitRange {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
        /// Raw.
        raw: f64,
        /// The register's largest value.
        max: f64,
    },
    /// A stop limit below one raw LSB of its register at the board's Ts.
    #[error("{flag} {value} is {raw:.3e} raw at the board's Ts, below one LSB: the stop would never end; give a larger limit")]
    StopLimitResolution {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
        /// Raw.
        raw: f64,
    },
    /// The controller cannot be configured as asked.
    #[error("the controller for this board: {0}")]
    Servo(String),
}

/// A run failed: the user's input (exit 2, nothing moved) or the link or the board (exit 1).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Failure {
    /// The user's to fix.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The link or the board.
    #[error(transparent)]
    Host(#[from] HostError),
}

impl From<LinkError> for Failure {
    fn from(e: LinkError) -> Self {
        Failure::Host(HostError::Link(e))
    }
}

impl From<snapgen_plan::PlanError> for Failure {
    fn from(e: snapgen_plan::PlanError) -> Self {
        Failure::Input(InputError::Plan(e))
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
        widths: Widths {
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

/// A session with a board.
pub struct Session<L: Link> {
    /// The link.
    pub link: L,
    /// What the board said it is (PING).
    pub identity: Identity,
    /// The format the host plans with: the board's.
    pub format: Format,
}

impl<L: Link> Session<L> {
    /// PING, the board's identity checked and its format taken (`position_lsb` is the
    /// host's scale: units per output LSB).
    pub fn open(mut link: L, position_lsb: f64) -> Result<Self, Failure> {
        let identity = match link.ask(&Command::Ping)? {
            Reply::Identity(i) => i,
            r => return Err(unexpected(&Command::Ping, r).into()),
        };
        let format = board_format(&identity, position_lsb)?;
        link.set_format(&format);
        Ok(Session {
            link,
            identity,
            format,
        })
    }

    /// Sends `c` and returns its reply; a NAK is an error.
    pub fn request(&mut self, c: &Command) -> Result<Reply, HostError> {
        match self.link.ask(c)? {
            Reply::Nak { reason, .. } => Err(HostError::Nak {
                command: command_name(c),
                reason,
            }),
            r => Ok(r),
        }
    }

    /// Sends a command that is answered with an ACK.
    pub fn expect_ack(&mut self, c: &Command) -> Result<(), HostError> {
        match self.request(c)? {
            Reply::Ack { cmd } if cmd == c.code() => Ok(()),
            r => Err(unexpected(c, r)),
        }
    }

    /// The status block.
    pub fn status(&mut self) -> Result<Status, HostError> {
        match self.request(&Command::ReadStatus)? {
            Reply::Status(s) => Ok(s),
            r => Err(unexpected(&Command::ReadStatus, r)),
        }
    }

    /// The chain's registers and their tick.
    pub fn state(&mut self) -> Result<StateReply, HostError> {
        match self.request(&Command::ReadState)? {
            Reply::State(s) => Ok(s),
            r => Err(unexpected(&Command::ReadState, r)),
        }
    }

    /// A parameter's value.
    pub fn read_config(&mut self, param: Param) -> Result<i128, HostError> {
        let c = Command::ReadConfig { param };
        match self.request(&c)? {
            Reply::Config { param: p, value } if p == param => Ok(value),
            r => Err(unexpected(&c, r)),
        }
    }

    /// Writes a parameter and reads it back.
    pub fn configure(&mut self, param: Param, value: i128) -> Result<(), HostError> {
        self.expect_ack(&Command::Configure { param, value })?;
        match self.read_config(param)? {
            v if v == value => Ok(()),
            read => Err(HostError::ReadBack { param, value, read }),
        }
    }

    /// Writes both stop limits (read back) in an order the board accepts while enabled: every
    /// intermediate pair keeps `0 < STOP_JERK ≤ STOP_ACCEL`.
    pub fn set_stop_limits(&mut self, limits: StopLimits) -> Result<(), HostError> {
        let accel_now = self.read_config(Param::StopAccel)?;
        if limits.jerk <= accel_now {
            self.configure(Param::StopJerk, limits.jerk)?;
            self.configure(Param::StopAccel, limits.accel)
        } else {
            self.configure(Param::StopAccel, limits.accel)?;
            self.configure(Param::StopJerk, limits.jerk)
        }
    }

    /// The axis state now.
    pub fn axis(&mut self) -> Result<AxisState, HostError> {
        Ok(self.status()?.axis().unwrap_or(AxisState::ErrorStop))
    }

    /// The stop limits written (and read back), then the amplifier on if the axis is
    /// Disabled (MC_Power: the reference takes the encoder's position).
    pub fn power_up(&mut self, limits: StopLimits) -> Result<(), HostError> {
        self.set_stop_limits(limits)?;
        if self.axis()? == AxisState::Disabled {
            self.expect_ack(&Command::Power { on: true })?;
        }
        Ok(())
    }
}

/// An answer that does not fit `c`.
pub fn unexpected(c: &Command, reply: Reply) -> HostError {
    HostError::Unexpected {
        command: command_name(c),
        reply: Box::new(reply),
    }
}
