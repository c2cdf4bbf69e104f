//! The framed command and telemetry protocol spoken over the UART (docs/PROTOCOL.md), version 2.
//!
//! ```text
//! +------+-----+-----+-----+-------------+---------+
//! | 0xA5 | LEN | CMD | SEQ | PAYLOAD     | CRC16   |
//! +------+-----+-----+-----+-------------+---------+
//!    1      1     1     1    LEN bytes     2 (LE)
//! ```
//!
//! `CRC16` is CRC-16/CCITT-FALSE (polynomial [`CRC_POLY`], initial value [`CRC_INIT`], no
//! reflection, no final XOR; check value 0x29B1 for "123456789") over `LEN CMD SEQ PAYLOAD`,
//! sent low byte first. Multi-byte fields are little-endian.
//!
//! This module is the single source of truth for the protocol: the command and reply codes
//! ([`COMMANDS`], [`code`]), the NAK reasons ([`Reason`]), the configuration parameters and
//! their defaults ([`Param`]), the axis states and error identifiers ([`AxisState`],
//! [`ErrorId`]), the status flags ([`flag`]) and the byte layout of every payload
//! ([`STATUS_FIELDS`], [`IDENTITY_FIELDS`], [`STATE_FIELDS`], [`CONFIG_FIELDS`]). The device
//! model, the fabric (`snapgen_hdl`), the host and a test of docs/PROTOCOL.md all read them.

use crate::format::Format;
use crate::program::{Program, Segment};
use crate::stop::StopLimits;

/// Start-of-frame byte.
pub const START: u8 = 0xA5;
/// Bytes around the payload: start, length, command, sequence, two CRC bytes.
pub const OVERHEAD: usize = 6;
/// Protocol version reported by `PING`.
pub const PROTOCOL_VERSION: u8 = 4;
/// The CRC polynomial (CRC-16/CCITT-FALSE).
pub const CRC_POLY: u16 = 0x1021;
/// The CRC's initial value.
pub const CRC_INIT: u16 = 0xFFFF;
/// Bytes of a wide value (a 104-bit register: snap, velocity, acceleration, jerk, a stop
/// limit, a CONFIGURE value).
pub const WIDE_BYTES: usize = 13;
/// Bytes of the position register in a `STATE` reply (112 bits).
pub const POSITION_BYTES: usize = 14;
/// The longest payload a device accepts: a longer `LEN` cannot start a frame, so its start byte
/// is taken as noise at once (a corrupted frame's payload byte 0xA5 then cannot swallow the
/// frames that follow for long).
pub const DEVICE_MAX_PAYLOAD: usize = 32;
/// Replies a device holds while it sends: a host keeps at most this many commands
/// unanswered (a command arriving with the queue full is neither executed nor answered, and
/// raises the [`flag::REPLY_OVERFLOW`] flag).
pub const REPLY_QUEUE: usize = 16;

/// CRC-16/CCITT-FALSE of `crc` followed by `byte`.
#[inline]
pub fn crc16_step(crc: u16, byte: u8) -> u16 {
    let mut crc = crc ^ (u16::from(byte) << 8);
    for _ in 0..8 {
        crc = if crc & 0x8000 != 0 {
            (crc << 1) ^ CRC_POLY
        } else {
            crc << 1
        };
    }
    crc
}

/// CRC-16/CCITT-FALSE of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    data.iter().fold(CRC_INIT, |c, &b| crc16_step(c, b))
}

/// Command and reply codes.
pub mod code {
    /// Host → device: ping; replied with `IDENTITY`.
    pub const PING: u8 = 0x01;
    /// Load one segment into the standby program.
    pub const LOAD_SEGMENT: u8 = 0x02;
    /// Set the standby program's segment count (completes an upload).
    pub const COMMIT: u8 = 0x03;
    /// Start the standby program.
    pub const START: u8 = 0x04;
    /// Controlled stop (MC_Stop): the axis goes to Stopping, then Standstill.
    pub const STOP: u8 = 0x05;
    /// Controlled stop of a move (MC_Halt): the axis stays in its motion state until at rest.
    pub const HALT: u8 = 0x06;
    /// Read status; replied with `STATUS`.
    pub const READ_STATUS: u8 = 0x07;
    /// Set a configuration parameter.
    pub const CONFIGURE: u8 = 0x08;
    /// Read the chain's registers and the tick they belong to; replied with `STATE`.
    pub const READ_STATE: u8 = 0x09;
    /// Read a configuration parameter; replied with `CONFIG`.
    pub const READ_CONFIG: u8 = 0x0A;
    /// Enable (1) or disable (0) the axis and its amplifier (MC_Power).
    pub const POWER: u8 = 0x0B;
    /// Clear an axis error (MC_Reset).
    pub const RESET: u8 = 0x0C;
    /// Arm a program swap at an absolute tick (the standby program takes over from the
    /// registers as they are then).
    pub const SWAP_AT: u8 = 0x0D;
    /// Device → host: identity (reply to `PING`).
    pub const IDENTITY: u8 = 0x41;
    /// Status (reply to `READ_STATUS`).
    pub const STATUS: u8 = 0x47;
    /// Registers (reply to `READ_STATE`).
    pub const STATE: u8 = 0x49;
    /// A parameter's value (reply to `READ_CONFIG`).
    pub const CONFIG: u8 = 0x4A;
    /// Acknowledge.
    pub const ACK: u8 = 0x7E;
    /// Reject with a reason.
    pub const NAK: u8 = 0x7F;
    /// Periodic telemetry (unsolicited, status layout).
    pub const TELEMETRY: u8 = 0x80;
}

/// One command of the protocol, as the device checks it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CommandSpec {
    /// Code.
    pub code: u8,
    /// Name, as in docs/PROTOCOL.md.
    pub name: &'static str,
    /// Payload length (every command has exactly one).
    pub len: u8,
    /// It changes something: a retry (same code, sequence and CRC as the last such command)
    /// is answered again without being executed again.
    pub effect: bool,
    /// Its reply code on success.
    pub reply: u8,
}

/// Every command (docs/PROTOCOL.md, "Commands").
pub const COMMANDS: [CommandSpec; 13] = [
    cmd(code::PING, "PING", 0, false, code::IDENTITY),
    cmd(
        code::LOAD_SEGMENT,
        "LOAD_SEGMENT",
        1 + 4 + WIDE_BYTES as u8,
        true,
        code::ACK,
    ),
    cmd(code::COMMIT, "COMMIT", 1, true, code::ACK),
    cmd(code::START, "START", 0, true, code::ACK),
    cmd(code::STOP, "STOP", 0, true, code::ACK),
    cmd(code::HALT, "HALT", 0, true, code::ACK),
    cmd(code::READ_STATUS, "READ_STATUS", 0, false, code::STATUS),
    cmd(
        code::CONFIGURE,
        "CONFIGURE",
        1 + WIDE_BYTES as u8,
        true,
        code::ACK,
    ),
    cmd(code::READ_STATE, "READ_STATE", 0, false, code::STATE),
    cmd(code::READ_CONFIG, "READ_CONFIG", 1, false, code::CONFIG),
    cmd(code::POWER, "POWER", 1, true, code::ACK),
    cmd(code::RESET, "RESET", 0, true, code::ACK),
    cmd(code::SWAP_AT, "SWAP_AT", 8, true, code::ACK),
];

const fn cmd(code: u8, name: &'static str, len: u8, effect: bool, reply: u8) -> CommandSpec {
    CommandSpec {
        code,
        name,
        len,
        effect,
        reply,
    }
}

/// The spec of command `code`.
pub fn command_spec(code: u8) -> Option<&'static CommandSpec> {
    COMMANDS.iter().find(|c| c.code == code)
}

/// Why a frame was rejected (the `NAK` reason byte).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Reason {
    /// CRC mismatch (sent with command and sequence 0: they are untrusted).
    BadCrc = 1,
    /// Length does not match the command.
    BadLength = 2,
    /// Unknown command code.
    UnknownCommand = 3,
    /// A program is playing.
    Busy = 4,
    /// An argument is out of range.
    BadArgument = 5,
    /// Start without a committed program.
    NoProgram = 6,
    /// UART framing error or a frame cut short (inter-byte timeout).
    Framing = 7,
    /// The axis is disabled (POWER it on first).
    NotEnabled = 8,
    /// The axis is in ErrorStop (RESET it first).
    AxisError = 9,
    /// The axis is stopping (wait for Standstill).
    Stopping = 10,
    /// The stop limits are not set (CONFIGURE STOP_JERK and STOP_ACCEL first).
    NotConfigured = 11,
    /// The program starts toward an active limit switch (move away from it).
    Limit = 12,
    /// The parameter can only be set while the axis is Disabled (POWER it off first).
    NotDisabled = 13,
    /// SWAP_AT for a tick less than five ticks ahead of the time base (replan for a later tick).
    Late = 14,
    /// A program swap is armed (wait until its tick has passed).
    SwapPending = 15,
}

/// Every NAK reason with its meaning (docs/PROTOCOL.md, "NAK reasons").
pub const REASONS: [(Reason, &str); 15] = [
    (Reason::BadCrc, "BAD_CRC"),
    (Reason::BadLength, "BAD_LENGTH"),
    (Reason::UnknownCommand, "UNKNOWN_COMMAND"),
    (Reason::Busy, "BUSY"),
    (Reason::BadArgument, "BAD_ARGUMENT"),
    (Reason::NoProgram, "NO_PROGRAM"),
    (Reason::Framing, "FRAMING"),
    (Reason::NotEnabled, "NOT_ENABLED"),
    (Reason::AxisError, "AXIS_ERROR"),
    (Reason::Stopping, "STOPPING"),
    (Reason::NotConfigured, "NOT_CONFIGURED"),
    (Reason::Limit, "LIMIT"),
    (Reason::NotDisabled, "NOT_DISABLED"),
    (Reason::Late, "LATE"),
    (Reason::SwapPending, "SWAP_PENDING"),
];

impl Reason {
    /// From the reason byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        REASONS.iter().map(|(r, _)| *r).find(|r| *r as u8 == b)
    }

    /// Its name in docs/PROTOCOL.md.
    pub fn name(self) -> &'static str {
        REASONS
            .iter()
            .find(|(r, _)| *r == self)
            .map_or("?", |(_, n)| n)
    }
}

/// One row of the refusal table (docs/PROTOCOL.md, "Commands"): a command, the reasons it is
/// refused with and when (checked in the table's order, after the length).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The command's name, with its argument where the row applies to one (`POWER 1`).
    pub command: &'static str,
    /// The reasons.
    pub reasons: &'static [Reason],
    /// When.
    pub when: &'static str,
}

const fn refusal(command: &'static str, reasons: &'static [Reason], when: &'static str) -> Refusal {
    Refusal {
        command,
        reasons,
        when,
    }
}

/// Every refusal a command can get after its length and code are accepted (the frame-level
/// reasons BAD_CRC, FRAMING, BAD_LENGTH and UNKNOWN_COMMAND apply to any frame).
pub const REFUSALS: [Refusal; 24] = {
    use Reason::*;
    [
        refusal("LOAD_SEGMENT", &[BadArgument], "`index` ≥ 32 or `ticks` = 0"),
        refusal("LOAD_SEGMENT", &[SwapPending], "a swap is armed"),
        refusal("COMMIT", &[BadArgument], "`count` > 32"),
        refusal("COMMIT", &[SwapPending], "a swap is armed"),
        refusal(
            "START",
            &[NotEnabled, AxisError, Stopping],
            "the axis is Disabled, in ErrorStop, Stopping",
        ),
        refusal(
            "START",
            &[Busy, Stopping, SwapPending, NoProgram],
            "a program plays, a stop runs, a swap is armed, the standby program is empty",
        ),
        refusal("START", &[Busy], "the axis is not at rest (v, a or j ≠ 0)"),
        refusal(
            "START",
            &[Limit],
            "segment 0's snap heads toward an active limit switch",
        ),
        refusal("STOP", &[NotEnabled], "the axis is Disabled"),
        refusal(
            "HALT",
            &[NotEnabled, AxisError, Stopping],
            "the axis is Disabled, in ErrorStop, Stopping",
        ),
        refusal(
            "CONFIGURE",
            &[BadArgument],
            "unknown `param`, or `value` < 0 or above the parameter's maximum",
        ),
        refusal(
            "CONFIGURE",
            &[Busy],
            "a parameter set only at rest while the axis moves (a program plays, a stop runs, or v, a or j ≠ 0), in any state",
        ),
        refusal(
            "CONFIGURE",
            &[NotDisabled],
            "a parameter set only while Disabled, in another state",
        ),
        refusal(
            "CONFIGURE",
            &[BadArgument],
            "STOP_JERK or STOP_ACCEL while the axis is not Disabled, when the pair would fail 0 < STOP_JERK ≤ STOP_ACCEL",
        ),
        refusal("READ_CONFIG", &[BadArgument], "unknown `param`"),
        refusal("POWER", &[BadArgument], "`on` > 1"),
        refusal(
            "POWER 1",
            &[AxisError, NotConfigured],
            "in ErrorStop; Disabled with invalid stop limits (STOP_JERK = 0 or > STOP_ACCEL), or with the controller on (SERVO_PERIOD ≠ 0) and FOLLOWING_LIMIT = 0",
        ),
        refusal("POWER 0", &[Busy], "the axis moves, in any state"),
        refusal(
            "RESET",
            &[AxisError],
            "in ErrorStop while the axis moves or the emergency stop is active",
        ),
        refusal(
            "SWAP_AT",
            &[BadArgument],
            "`tick` lies 2^31 ticks or more beyond the time base (the core compares 32 bits)",
        ),
        refusal(
            "SWAP_AT",
            &[NotEnabled, AxisError, Stopping],
            "the axis is Disabled, in ErrorStop, Stopping",
        ),
        refusal(
            "SWAP_AT",
            &[Stopping, SwapPending, NoProgram],
            "a stop runs, a swap is armed, the standby program is empty",
        ),
        refusal(
            "SWAP_AT",
            &[Late],
            "`tick` − (the time base on the clock before the one that executes the command) < 5, as a signed 64-bit difference",
        ),
        refusal(
            "SWAP_AT",
            &[Limit],
            "the axis is at rest and segment 0's snap heads toward an active limit switch",
        ),
    ]
};

/// True when the refusal table lists `reason` for the command `code` (frame-level reasons are
/// listed for none).
pub fn refusal_documented(code: u8, reason: Reason) -> bool {
    let Some(spec) = command_spec(code) else {
        return false;
    };
    REFUSALS.iter().any(|r| {
        (r.command == spec.name || r.command.starts_with(&format!("{} ", spec.name)))
            && r.reasons.contains(&reason)
    })
}

/// Configuration parameters (`CONFIGURE`, `READ_CONFIG`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Param {
    /// Clocks per tick − 1 (so `Ts = (value + 1) / clock`). Default: the one the design was
    /// generated with. Set only at rest: the stop limits are per tick, so a new `Ts` rescales
    /// their physical values (by `Ts²` and `Ts³`).
    TickDivider = 1,
    /// PWM period in clocks (0: PWM off). Default 0.
    PwmPeriod = 2,
    /// Encoder glitch filter in clocks. Default 0.
    EncoderFilter = 3,
    /// Telemetry period in ticks (0: off). Default 0.
    TelemetryPeriod = 4,
    /// The stop's jerk limit, raw (jerk LSBs per tick). Default 0: unset, POWER is refused.
    /// Set only at rest; while the axis is enabled a value that leaves the pair invalid
    /// (`0 < STOP_JERK ≤ STOP_ACCEL`) is refused.
    StopJerk = 5,
    /// The stop's acceleration limit, raw (acceleration LSBs, ≥ the jerk limit). Default 0.
    /// The same rules as `STOP_JERK`.
    StopAccel = 6,
    /// Host watchdog in milliseconds: a moving axis without a good frame for this long stops
    /// and goes to ErrorStop (0: off). Default 1000.
    WatchdogMs = 7,
    /// Input polarity: bit 0 inverts limit+, bit 1 limit−, bit 2 the emergency stop (set for
    /// normally-closed contacts). Default: the design's (`input_polarity` in the board file).
    /// Set only while Disabled.
    InputPolarity = 8,
    /// Glitch filter of the limit and emergency-stop inputs, in clocks. Default 0. Set only
    /// while Disabled.
    InputFilter = 9,
    /// The position controller's sample period, in ticks (0: controller off, duty 0, no
    /// following-error check). Default 0. Set only while Disabled.
    ServoPeriod = 10,
    /// Proportional gain, `Kp·2^32` (PWM clocks per count of following error). Default 0.
    Kp = 11,
    /// Integral gain, `Ki·2^32` (PWM clocks per count·sample). Default 0.
    Ki = 12,
    /// Derivative gain, `Kd·2^32` (PWM clocks per count/sample). Default 0.
    Kd = 13,
    /// Velocity feed-forward, `Kv·2^16` (PWM clocks per count/tick). Default 0.
    Kv = 14,
    /// Acceleration feed-forward, `Ka·2^8` (PWM clocks per count/tick²). Default 0.
    Ka = 15,
    /// The integrator's limit (counts·samples·2^16). Default 0 (no integral action).
    IntegralLimit = 16,
    /// The duty's limit, PWM clocks. Default 32 767 (the PWM period limits it).
    OutputLimit = 17,
    /// The following-error limit, counts: beyond it the amplifier is disabled and the axis
    /// latches ErrorStop (FOLLOWING_ERROR). Default 0: with the controller on, POWER is
    /// refused until it is set. Set only while Disabled.
    FollowingLimit = 18,
    /// The derivative filter's shift `k`: a first-order low-pass of about `2^k` samples on the
    /// error's change (0: none). Default 0.
    DFilter = 19,
}

/// When a parameter may be set (`CONFIGURE` is refused otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Settable {
    /// In any state.
    Always,
    /// While the axis is at rest: no program plays, no stop runs and v = a = j = 0
    /// (otherwise BUSY).
    AtRest,
    /// While the axis is Disabled (otherwise NOT_DISABLED).
    Disabled,
}

/// Every parameter with its name (docs/PROTOCOL.md, "Parameters").
pub const PARAMS: [(Param, &str); 19] = [
    (Param::TickDivider, "TICK_DIVIDER"),
    (Param::PwmPeriod, "PWM_PERIOD"),
    (Param::EncoderFilter, "ENCODER_FILTER"),
    (Param::TelemetryPeriod, "TELEMETRY_PERIOD"),
    (Param::StopJerk, "STOP_JERK"),
    (Param::StopAccel, "STOP_ACCEL"),
    (Param::WatchdogMs, "WATCHDOG_MS"),
    (Param::InputPolarity, "INPUT_POLARITY"),
    (Param::InputFilter, "INPUT_FILTER"),
    (Param::ServoPeriod, "SERVO_PERIOD"),
    (Param::Kp, "KP"),
    (Param::Ki, "KI"),
    (Param::Kd, "KD"),
    (Param::Kv, "KV"),
    (Param::Ka, "KA"),
    (Param::IntegralLimit, "INTEGRAL_LIMIT"),
    (Param::OutputLimit, "OUTPUT_LIMIT"),
    (Param::FollowingLimit, "FOLLOWING_LIMIT"),
    (Param::DFilter, "D_FILTER"),
];

/// The watchdog's default, in milliseconds.
pub const DEFAULT_WATCHDOG_MS: u32 = 1000;

impl Param {
    /// From the parameter byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        PARAMS.iter().map(|(p, _)| *p).find(|p| *p as u8 == b)
    }

    /// Its name in docs/PROTOCOL.md.
    pub fn name(self) -> &'static str {
        PARAMS
            .iter()
            .find(|(p, _)| *p == self)
            .map_or("?", |(_, n)| n)
    }

    /// When it may be set.
    pub fn settable(self) -> Settable {
        match self {
            Param::TickDivider | Param::StopJerk | Param::StopAccel => Settable::AtRest,
            Param::InputPolarity
            | Param::InputFilter
            | Param::ServoPeriod
            | Param::FollowingLimit => Settable::Disabled,
            _ => Settable::Always,
        }
    }

    /// The largest value it takes (a larger one is refused with BAD_ARGUMENT).
    pub fn max(self) -> i128 {
        match self {
            Param::StopJerk | Param::StopAccel => (1i128 << 103) - 1,
            Param::InputPolarity => 7,
            Param::PwmPeriod | Param::EncoderFilter | Param::InputFilter | Param::ServoPeriod => {
                0xFFFF
            }
            Param::Kp | Param::Ki | Param::Kd | Param::Kv | Param::Ka | Param::IntegralLimit => {
                (1i128 << crate::io::servo::GAIN_BITS) - 1
            }
            Param::OutputLimit => i128::from(i16::MAX),
            Param::DFilter => 15,
            Param::FollowingLimit => i128::from(i32::MAX),
            _ => i128::from(u32::MAX),
        }
    }
}

/// The axis states, after PLCopen's (seed 000 Figure 1); `state` in the status block.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum AxisState {
    /// The amplifier is off; nothing moves. After reset.
    #[default]
    Disabled = 0,
    /// Enabled, at rest.
    Standstill = 1,
    /// Playing a program that ends at rest.
    DiscreteMotion = 2,
    /// Playing a program that ends moving (a later issue's velocity moves).
    ContinuousMotion = 3,
    /// A controlled stop (STOP) runs; motion commands are refused.
    Stopping = 4,
    /// An error stopped the axis (emergency stop: amplifier off at once; limit switch or
    /// watchdog: a controlled stop); RESET clears it.
    ErrorStop = 5,
}

/// Every state with its name.
pub const STATES: [(AxisState, &str); 6] = [
    (AxisState::Disabled, "DISABLED"),
    (AxisState::Standstill, "STANDSTILL"),
    (AxisState::DiscreteMotion, "DISCRETE_MOTION"),
    (AxisState::ContinuousMotion, "CONTINUOUS_MOTION"),
    (AxisState::Stopping, "STOPPING"),
    (AxisState::ErrorStop, "ERROR_STOP"),
];

impl AxisState {
    /// From the state byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        STATES.iter().map(|(s, _)| *s).find(|s| *s as u8 == b)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        STATES
            .iter()
            .find(|(s, _)| *s == self)
            .map_or("?", |(_, n)| n)
    }

    /// True in the states where the axis may move.
    pub fn moving(self) -> bool {
        matches!(
            self,
            AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::Stopping
        )
    }
}

/// Why the axis is in ErrorStop (`error` in the status block; 0 otherwise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum ErrorId {
    /// No error.
    #[default]
    None = 0,
    /// The emergency-stop input: amplifier off at once, reference held.
    EmergencyStop = 1,
    /// Motion toward an active positive limit switch: controlled stop.
    LimitPositive = 2,
    /// Motion toward an active negative limit switch: controlled stop.
    LimitNegative = 3,
    /// No good frame for the watchdog's time while moving: controlled stop.
    Watchdog = 4,
    /// A program ended with the axis not at rest (v, a or j ≠ 0): controlled stop.
    ProgramEnd = 5,
    /// The following error exceeded FOLLOWING_LIMIT: amplifier off at once, reference held.
    FollowingError = 6,
}

/// Every error identifier with its name.
pub const ERRORS: [(ErrorId, &str); 7] = [
    (ErrorId::None, "NONE"),
    (ErrorId::EmergencyStop, "EMERGENCY_STOP"),
    (ErrorId::LimitPositive, "LIMIT_POSITIVE"),
    (ErrorId::LimitNegative, "LIMIT_NEGATIVE"),
    (ErrorId::Watchdog, "WATCHDOG"),
    (ErrorId::ProgramEnd, "PROGRAM_END"),
    (ErrorId::FollowingError, "FOLLOWING_ERROR"),
];

impl ErrorId {
    /// From the error byte.
    pub fn from_byte(b: u8) -> Option<Self> {
        ERRORS.iter().map(|(e, _)| *e).find(|e| *e as u8 == b)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        ERRORS
            .iter()
            .find(|(e, _)| *e == self)
            .map_or("?", |(_, n)| n)
    }
}

/// Bits of `flags` in the status block.
pub mod flag {
    /// A program is playing.
    pub const PLAYING: u16 = 1 << 0;
    /// The last program ran to its end.
    pub const DONE: u16 = 1 << 1;
    /// The last program was cut short (a stop or the emergency stop).
    pub const CUT: u16 = 1 << 2;
    /// The stop law is running.
    pub const STOPPING: u16 = 1 << 3;
    /// The last stop began outside its limits and landed regardless of them.
    pub const STOP_OVER_LIMITS: u16 = 1 << 4;
    /// The amplifier is enabled.
    pub const AMPLIFIER: u16 = 1 << 5;
    /// The positive limit input is active (after polarity and filter).
    pub const LIMIT_POSITIVE: u16 = 1 << 6;
    /// The negative limit input is active.
    pub const LIMIT_NEGATIVE: u16 = 1 << 7;
    /// The emergency-stop input is active.
    pub const EMERGENCY_STOP: u16 = 1 << 8;
    /// An illegal encoder transition was seen (since reset).
    pub const ENCODER_ERROR: u16 = 1 << 9;
    /// A UART framing error was seen (since reset).
    pub const UART_ERROR: u16 = 1 << 10;
    /// A command was dropped with the reply queue full (since reset).
    pub const REPLY_OVERFLOW: u16 = 1 << 11;
    /// The controller skipped a sample: it was still computing the last one (since reset).
    pub const SERVO_OVERRUN: u16 = 1 << 12;
    /// A program swap is armed (SWAP_AT accepted, its tick not yet reached).
    pub const SWAP_PENDING: u16 = 1 << 13;

    /// Every flag with its name.
    pub const ALL: [(u16, &str); 14] = [
        (PLAYING, "PLAYING"),
        (DONE, "DONE"),
        (CUT, "CUT"),
        (STOPPING, "STOPPING"),
        (STOP_OVER_LIMITS, "STOP_OVER_LIMITS"),
        (AMPLIFIER, "AMPLIFIER"),
        (LIMIT_POSITIVE, "LIMIT_POSITIVE"),
        (LIMIT_NEGATIVE, "LIMIT_NEGATIVE"),
        (EMERGENCY_STOP, "EMERGENCY_STOP"),
        (ENCODER_ERROR, "ENCODER_ERROR"),
        (UART_ERROR, "UART_ERROR"),
        (REPLY_OVERFLOW, "REPLY_OVERFLOW"),
        (SERVO_OVERRUN, "SERVO_OVERRUN"),
        (SWAP_PENDING, "SWAP_PENDING"),
    ];
}

/// One field of a payload: its name, first byte and size (little-endian).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Name, as in docs/PROTOCOL.md.
    pub name: &'static str,
    /// First byte.
    pub offset: usize,
    /// Bytes.
    pub bytes: usize,
}

const fn fields<const N: usize>(spec: [(&'static str, usize); N]) -> [Field; N] {
    let mut out = [Field {
        name: "",
        offset: 0,
        bytes: 0,
    }; N];
    let mut at = 0;
    let mut k = 0;
    while k < N {
        out[k] = Field {
            name: spec[k].0,
            offset: at,
            bytes: spec[k].1,
        };
        at += spec[k].1;
        k += 1;
    }
    out
}

/// Bytes of a payload laid out by `fields`.
pub const fn payload_bytes(fields: &[Field]) -> usize {
    let last = fields[fields.len() - 1];
    last.offset + last.bytes
}

/// The status block (`STATUS`, `TELEMETRY`).
pub const STATUS_FIELDS: [Field; 11] = fields([
    ("state", 1),
    ("error", 1),
    ("flags", 2),
    ("tick_count", 4),
    ("position", 4),
    ("velocity", 4),
    ("encoder", 4),
    ("bad_crc", 2),
    ("bad_frames", 2),
    ("following_peak", 4),
    ("duty", 2),
]);

/// The identity (`IDENTITY`, the reply to `PING`).
pub const IDENTITY_FIELDS: [Field; 16] = fields([
    ("protocol", 1),
    ("design_hash", 4),
    ("clock_hz", 4),
    ("baud", 4),
    ("tick_divider", 4),
    ("x_bits", 1),
    ("v_bits", 1),
    ("a_bits", 1),
    ("j_bits", 1),
    ("d_bits", 1),
    ("frac_bits", 1),
    ("tick_bits", 1),
    ("max_segments", 1),
    ("snap_bytes", 1),
    ("stop_jerk", WIDE_BYTES),
    ("stop_accel", WIDE_BYTES),
]);

/// The registers (`STATE`, the reply to `READ_STATE`).
pub const STATE_FIELDS: [Field; 5] = fields([
    ("ticks", 8),
    ("x", POSITION_BYTES),
    ("v", WIDE_BYTES),
    ("a", WIDE_BYTES),
    ("j", WIDE_BYTES),
]);

/// A parameter's value (`CONFIG`, the reply to `READ_CONFIG`; also `CONFIGURE`'s payload).
pub const CONFIG_FIELDS: [Field; 2] = fields([("param", 1), ("value", WIDE_BYTES)]);

/// Writes `value` (two's complement, little-endian) into `field` of `out`.
fn put(out: &mut [u8], field: &Field, value: i128) {
    out[field.offset..field.offset + field.bytes]
        .copy_from_slice(&value.to_le_bytes()[..field.bytes]);
}

/// Reads `field` of `p`: sign-extended when `signed`.
fn get(p: &[u8], field: &Field, signed: bool) -> i128 {
    let mut wide = [0u8; 16];
    wide[..field.bytes].copy_from_slice(&p[field.offset..field.offset + field.bytes]);
    if signed && p[field.offset + field.bytes - 1] & 0x80 != 0 {
        wide[field.bytes..].fill(0xff);
    }
    i128::from_le_bytes(wide)
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

/// Device state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Status {
    /// Axis state ([`AxisState`] byte).
    pub state: u8,
    /// Why in ErrorStop ([`ErrorId`] byte).
    pub error: u8,
    /// [`flag`] bits.
    pub flags: u16,
    /// Ticks since the last start (while playing or stopping).
    pub tick_count: u32,
    /// Position in output LSBs (`x >> 80`, low 32 bits).
    pub position: i32,
    /// Velocity, raw, top 32 bits of the velocity register (`v >> (v_bits − 32)`).
    pub velocity: i32,
    /// Encoder count.
    pub encoder: i32,
    /// Frames dropped for a bad CRC.
    pub bad_crc: u16,
    /// Frames dropped for a bad length, an unknown command or a cut.
    pub bad_frames: u16,
    /// The largest |following error| at a controller sample since the last START, counts ·
    /// 2^-16.
    pub following_peak: u32,
    /// The controller's duty, PWM clocks (signed: the direction).
    pub duty: i16,
}

/// What a device says about itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Identity {
    /// Protocol version.
    pub protocol: u8,
    /// Hash of the generated design (docs/HDL.md).
    pub design_hash: u32,
    /// Fabric clock (Hz).
    pub clock_hz: u32,
    /// UART baud rate.
    pub baud: u32,
    /// Clocks per tick − 1 (now).
    pub tick_divider: u32,
    /// Register widths x, v, a, j, d.
    pub widths: [u8; 5],
    /// Fractional bits of the position below the output LSB.
    pub frac_bits: u8,
    /// Width of a segment's tick count.
    pub tick_bits: u8,
    /// Segments per program.
    pub max_segments: u8,
    /// Bytes per snap value in LOAD_SEGMENT.
    pub snap_bytes: u8,
    /// The stop's limits (raw; now).
    pub stop: StopLimits,
}

impl Identity {
    /// The tick period it implies (s).
    pub fn ts(&self) -> f64 {
        (f64::from(self.tick_divider) + 1.0) / f64::from(self.clock_hz)
    }

    /// True when `f`'s widths, fractional bits, tick bits and program depth are the device's.
    pub fn matches_format(&self, f: &Format) -> bool {
        let w = f.widths.as_array();
        self.widths.iter().zip(w).all(|(&a, b)| u32::from(a) == b)
            && u32::from(self.frac_bits) == crate::FRAC_BITS
            && u32::from(self.tick_bits) == f.tick_bits
            && usize::from(self.max_segments) == f.max_segments
            && usize::from(self.snap_bytes) == Program::snap_bytes(f)
    }
}

/// The chain's registers and the tick they belong to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StateReply {
    /// Ticks since reset.
    pub ticks: u64,
    /// Position register.
    pub x: i128,
    /// Velocity.
    pub v: i128,
    /// Acceleration.
    pub a: i128,
    /// Jerk.
    pub j: i128,
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

    /// The frame carrying this command.
    pub fn to_frame(&self, seq: u8, format: &Format) -> Frame {
        let payload = match *self {
            Command::LoadSegment { index, segment } => {
                let nb = Program::snap_bytes(format);
                let mut p = vec![index];
                p.extend_from_slice(&segment.ticks.to_le_bytes());
                p.extend_from_slice(&segment.snap.to_le_bytes()[..nb]);
                p
            }
            Command::Commit { count } => vec![count],
            Command::Configure { param, value } => {
                let mut p = vec![0u8; payload_bytes(&CONFIG_FIELDS)];
                put(&mut p, &CONFIG_FIELDS[0], i128::from(param as u8));
                put(&mut p, &CONFIG_FIELDS[1], value);
                p
            }
            Command::ReadConfig { param } => vec![param as u8],
            Command::Power { on } => vec![u8::from(on)],
            Command::SwapAt { tick } => tick.to_le_bytes().to_vec(),
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
        let spec = command_spec(f.cmd).ok_or(reject(Reason::UnknownCommand))?;
        let p = &f.payload;
        if p.len() != usize::from(spec.len) {
            return Err(reject(Reason::BadLength));
        }
        Ok(match f.cmd {
            code::PING => Command::Ping,
            code::LOAD_SEGMENT => {
                let index = p[0];
                let ticks = u32::from_le_bytes([p[1], p[2], p[3], p[4]]);
                let snap = get(
                    p,
                    &Field {
                        name: "snap",
                        offset: 5,
                        bytes: WIDE_BYTES,
                    },
                    true,
                );
                let segment = Segment { ticks, snap };
                let check = Program {
                    segments: vec![segment],
                };
                if usize::from(index) >= format.max_segments || check.validate(format).is_err() {
                    return Err(reject(Reason::BadArgument));
                }
                Command::LoadSegment { index, segment }
            }
            code::COMMIT => {
                if usize::from(p[0]) > format.max_segments {
                    return Err(reject(Reason::BadArgument));
                }
                Command::Commit { count: p[0] }
            }
            code::START => Command::Start,
            code::STOP => Command::Stop,
            code::HALT => Command::Halt,
            code::READ_STATUS => Command::ReadStatus,
            code::READ_STATE => Command::ReadState,
            code::RESET => Command::Reset,
            code::CONFIGURE => {
                let param = Param::from_byte(p[0]).ok_or(reject(Reason::BadArgument))?;
                let value = get(p, &CONFIG_FIELDS[1], true);
                if value < 0 || value > param.max() {
                    return Err(reject(Reason::BadArgument));
                }
                Command::Configure { param, value }
            }
            code::READ_CONFIG => Command::ReadConfig {
                param: Param::from_byte(p[0]).ok_or(reject(Reason::BadArgument))?,
            },
            code::POWER => {
                if p[0] > 1 {
                    return Err(reject(Reason::BadArgument));
                }
                Command::Power { on: p[0] == 1 }
            }
            code::SWAP_AT => Command::SwapAt {
                tick: u64::from_le_bytes(p[..8].try_into().expect("length checked")),
            },
            _ => unreachable!("command_spec knows every code handled here"),
        })
    }
}

impl Status {
    /// Payload bytes of a status.
    pub const BYTES: usize = payload_bytes(&STATUS_FIELDS);

    /// The status block.
    pub fn to_payload(self) -> Vec<u8> {
        let mut p = vec![0u8; Self::BYTES];
        let values = [
            i128::from(self.state),
            i128::from(self.error),
            i128::from(self.flags),
            i128::from(self.tick_count),
            i128::from(self.position),
            i128::from(self.velocity),
            i128::from(self.encoder),
            i128::from(self.bad_crc),
            i128::from(self.bad_frames),
            i128::from(self.following_peak),
            i128::from(self.duty),
        ];
        for (f, v) in STATUS_FIELDS.iter().zip(values) {
            put(&mut p, f, v);
        }
        p
    }

    /// From a status block.
    pub fn from_payload(p: &[u8]) -> Option<Self> {
        if p.len() != Self::BYTES {
            return None;
        }
        let g = |k: usize, signed| get(p, &STATUS_FIELDS[k], signed);
        Some(Status {
            state: g(0, false) as u8,
            error: g(1, false) as u8,
            flags: g(2, false) as u16,
            tick_count: g(3, false) as u32,
            position: g(4, true) as i32,
            velocity: g(5, true) as i32,
            encoder: g(6, true) as i32,
            bad_crc: g(7, false) as u16,
            bad_frames: g(8, false) as u16,
            following_peak: g(9, false) as u32,
            duty: g(10, true) as i16,
        })
    }

    /// The axis state.
    pub fn axis(&self) -> Option<AxisState> {
        AxisState::from_byte(self.state)
    }

    /// True when `flag` is set.
    pub fn has(&self, flag: u16) -> bool {
        self.flags & flag != 0
    }

    /// The peak following error, in encoder counts.
    pub fn following_peak_counts(&self) -> f64 {
        f64::from(self.following_peak) / f64::from(1u32 << crate::io::servo::E_FRAC)
    }
}

impl Identity {
    /// Payload bytes.
    pub const BYTES: usize = payload_bytes(&IDENTITY_FIELDS);

    /// The payload.
    pub fn to_payload(&self) -> Vec<u8> {
        let mut p = vec![0u8; Self::BYTES];
        let w = self.widths;
        let values = [
            i128::from(self.protocol),
            i128::from(self.design_hash),
            i128::from(self.clock_hz),
            i128::from(self.baud),
            i128::from(self.tick_divider),
            i128::from(w[0]),
            i128::from(w[1]),
            i128::from(w[2]),
            i128::from(w[3]),
            i128::from(w[4]),
            i128::from(self.frac_bits),
            i128::from(self.tick_bits),
            i128::from(self.max_segments),
            i128::from(self.snap_bytes),
            self.stop.jerk,
            self.stop.accel,
        ];
        for (f, v) in IDENTITY_FIELDS.iter().zip(values) {
            put(&mut p, f, v);
        }
        p
    }

    /// From the payload.
    pub fn from_payload(p: &[u8]) -> Option<Self> {
        if p.len() != Self::BYTES {
            return None;
        }
        let g = |k: usize| get(p, &IDENTITY_FIELDS[k], false);
        Some(Identity {
            protocol: g(0) as u8,
            design_hash: g(1) as u32,
            clock_hz: g(2) as u32,
            baud: g(3) as u32,
            tick_divider: g(4) as u32,
            widths: [g(5) as u8, g(6) as u8, g(7) as u8, g(8) as u8, g(9) as u8],
            frac_bits: g(10) as u8,
            tick_bits: g(11) as u8,
            max_segments: g(12) as u8,
            snap_bytes: g(13) as u8,
            stop: StopLimits {
                jerk: get(p, &IDENTITY_FIELDS[14], true),
                accel: get(p, &IDENTITY_FIELDS[15], true),
            },
        })
    }
}

impl StateReply {
    /// Payload bytes.
    pub const BYTES: usize = payload_bytes(&STATE_FIELDS);

    /// The payload.
    pub fn to_payload(&self) -> Vec<u8> {
        let mut p = vec![0u8; Self::BYTES];
        let values = [self.ticks as i128, self.x, self.v, self.a, self.j];
        for (f, v) in STATE_FIELDS.iter().zip(values) {
            put(&mut p, f, v);
        }
        p
    }

    /// From the payload.
    pub fn from_payload(p: &[u8]) -> Option<Self> {
        if p.len() != Self::BYTES {
            return None;
        }
        Some(StateReply {
            ticks: get(p, &STATE_FIELDS[0], false) as u64,
            x: get(p, &STATE_FIELDS[1], true),
            v: get(p, &STATE_FIELDS[2], true),
            a: get(p, &STATE_FIELDS[3], true),
            j: get(p, &STATE_FIELDS[4], true),
        })
    }
}

impl Reply {
    /// The frame carrying this reply.
    pub fn to_frame(&self, seq: u8) -> Frame {
        let (cmd, payload) = match *self {
            Reply::Identity(i) => (code::IDENTITY, i.to_payload()),
            Reply::Ack { cmd } => (code::ACK, vec![cmd]),
            Reply::Nak { cmd, reason } => (code::NAK, vec![cmd, reason as u8]),
            Reply::Status(s) => (code::STATUS, s.to_payload()),
            Reply::Telemetry(s) => (code::TELEMETRY, s.to_payload()),
            Reply::State(s) => (code::STATE, s.to_payload()),
            Reply::Config { param, value } => {
                let mut p = vec![0u8; payload_bytes(&CONFIG_FIELDS)];
                put(&mut p, &CONFIG_FIELDS[0], i128::from(param as u8));
                put(&mut p, &CONFIG_FIELDS[1], value);
                (code::CONFIG, p)
            }
        };
        Frame { cmd, seq, payload }
    }

    /// Parses a frame with a good CRC into a reply.
    pub fn from_frame(f: &Frame) -> Option<Reply> {
        let p = &f.payload;
        Some(match (f.cmd, p.len()) {
            (code::IDENTITY, _) => Reply::Identity(Identity::from_payload(p)?),
            (code::ACK, 1) => Reply::Ack { cmd: p[0] },
            (code::NAK, 2) => Reply::Nak {
                cmd: p[0],
                reason: Reason::from_byte(p[1])?,
            },
            (code::STATUS, _) => Reply::Status(Status::from_payload(p)?),
            (code::TELEMETRY, _) => Reply::Telemetry(Status::from_payload(p)?),
            (code::STATE, _) => Reply::State(StateReply::from_payload(p)?),
            (code::CONFIG, 14) => Reply::Config {
                param: Param::from_byte(p[0])?,
                value: get(p, &CONFIG_FIELDS[1], true),
            },
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;

    #[test]
    fn crc_check_value() {
        assert_eq!(crc16(b"123456789"), 0x29B1);
    }

    #[test]
    fn codes_and_names_are_unique() {
        let mut codes: Vec<u8> = COMMANDS.iter().map(|c| c.code).collect();
        codes.extend([
            code::IDENTITY,
            code::STATUS,
            code::STATE,
            code::CONFIG,
            code::ACK,
            code::NAK,
            code::TELEMETRY,
        ]);
        let n = codes.len();
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), n);
        for c in COMMANDS {
            assert!(usize::from(c.len) <= DEVICE_MAX_PAYLOAD, "{}", c.name);
        }
        for (r, _) in REASONS {
            assert_eq!(Reason::from_byte(r as u8), Some(r));
        }
        for (p, _) in PARAMS {
            assert_eq!(Param::from_byte(p as u8), Some(p));
        }
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
            Command::Commit { count: 32 },
            Command::Start,
            Command::Stop,
            Command::Halt,
            Command::ReadStatus,
            Command::Configure {
                param: Param::StopJerk,
                value: (1 << 102) + 5,
            },
            Command::ReadState,
            Command::ReadConfig {
                param: Param::WatchdogMs,
            },
            Command::Power { on: true },
            Command::Power { on: false },
            Command::Reset,
        ] {
            let bytes = c.to_frame(200, &f).to_bytes();
            let mut d = Decoder::device();
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
            state: AxisState::DiscreteMotion as u8,
            error: 0,
            flags: flag::PLAYING | flag::AMPLIFIER,
            tick_count: 123_456,
            position: -5_000_000,
            velocity: 77,
            encoder: -4,
            bad_crc: 3,
            bad_frames: 9,
            following_peak: 0x8000_0000,
            duty: -32768,
        };
        let id = Identity {
            protocol: PROTOCOL_VERSION,
            design_hash: 0xDEAD_BEEF,
            clock_hz: 125_000_000,
            baud: 115_200,
            tick_divider: 1249,
            widths: [112, 104, 104, 104, 104],
            frac_bits: 80,
            tick_bits: 32,
            max_segments: 32,
            snap_bytes: 13,
            stop: StopLimits {
                jerk: 1 << 60,
                accel: 1 << 90,
            },
        };
        for r in [
            Reply::Identity(id),
            Reply::Ack { cmd: 4 },
            Reply::Nak {
                cmd: 9,
                reason: Reason::NotConfigured,
            },
            Reply::Status(s),
            Reply::Telemetry(s),
            Reply::State(StateReply {
                ticks: u64::MAX - 3,
                x: -(1i128 << 110) + 7,
                v: -(1 << 100),
                a: 5,
                j: -1,
            }),
            Reply::Config {
                param: Param::StopAccel,
                value: (1 << 102) - 1,
            },
        ] {
            let f = r.to_frame(3);
            assert_eq!(Reply::from_frame(&f), Some(r));
        }
        assert!(id.matches_format(&DEFAULT_FORMAT));
        assert!((id.ts() - 1e-5).abs() < 1e-18);
    }

    #[test]
    fn bad_arguments_are_rejected_with_a_reason() {
        let f = DEFAULT_FORMAT;
        let fr = |cmd, payload: Vec<u8>| Frame {
            cmd,
            seq: 0,
            payload,
        };
        let reason = |cmd, p| Command::from_frame(&fr(cmd, p), &f).unwrap_err().reason;
        assert_eq!(reason(0x55, vec![]), Reason::UnknownCommand);
        assert_eq!(reason(code::START, vec![1]), Reason::BadLength);
        assert_eq!(reason(code::COMMIT, vec![33]), Reason::BadArgument);
        assert_eq!(reason(code::POWER, vec![2]), Reason::BadArgument);
        assert_eq!(reason(code::READ_CONFIG, vec![99]), Reason::BadArgument);
        // A zero-tick segment.
        let mut p = vec![0u8; 18];
        p[0] = 1;
        assert_eq!(reason(code::LOAD_SEGMENT, p), Reason::BadArgument);
        // A negative or too large CONFIGURE value.
        let bad = |param: Param, value: i128| {
            let mut frame = Command::Configure { param, value }.to_frame(0, &f);
            frame.cmd = code::CONFIGURE;
            Command::from_frame(&frame, &f).map_err(|e| e.reason)
        };
        assert_eq!(bad(Param::WatchdogMs, -1), Err(Reason::BadArgument));
        assert_eq!(bad(Param::InputPolarity, 8), Err(Reason::BadArgument));
        assert!(bad(Param::InputPolarity, 7).is_ok());
    }
}
