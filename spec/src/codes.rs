//! Every code on the wire and in the status block, each with its name and meaning: commands
//! and replies ([`code`], [`COMMANDS`], [`REPLIES`]), NAK reasons ([`Reason`]), axis states
//! ([`AxisState`]), error identifiers ([`ErrorId`]) and status flags ([`flag`], [`FLAGS`]).
//!
//! Each list is written once, in a macro call that makes the Rust constants or enum and the
//! table the generators (docs, C header, JSON, Verilog `localparam`s) read.

use crate::fields::{
    Field, ACK_FIELDS, COMMIT_FIELDS, CONFIG_FIELDS, IDENTITY_FIELDS, LOAD_SEGMENT_FIELDS,
    NAK_FIELDS, NO_FIELDS, POWER_FIELDS, READ_CONFIG_FIELDS, STATE_FIELDS, STATUS_FIELDS,
    SWAP_AT_FIELDS,
};

/// One command of the protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CommandSpec {
    /// Code.
    pub code: u8,
    /// Name, as in docs/PROTOCOL.md.
    pub name: &'static str,
    /// Payload layout (every command has exactly one length).
    pub fields: &'static [Field],
    /// Payload length.
    pub len: u8,
    /// It changes something: a retry (same code, sequence and CRC as the last such command)
    /// is answered again without being executed again.
    pub effect: bool,
    /// Its reply code on success.
    pub reply: u8,
    /// What it does.
    pub meaning: &'static str,
}

/// One reply of the protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReplySpec {
    /// Code.
    pub code: u8,
    /// Name.
    pub name: &'static str,
    /// Payload layout.
    pub fields: &'static [Field],
    /// Payload length.
    pub len: u8,
    /// What it carries.
    pub meaning: &'static str,
}

macro_rules! protocol_codes {
    (
        commands { $( $c:ident = $cv:literal, $cf:expr, $effect:literal, $reply:ident, $cm:literal; )* }
        replies { $( $r:ident = $rv:literal, $rf:expr, $rm:literal; )* }
    ) => {
        /// Command (host → device) and reply (device → host) codes.
        pub mod code {
            $( #[doc = $cm] pub const $c: u8 = $cv; )*
            $( #[doc = $rm] pub const $r: u8 = $rv; )*
        }

        /// Every command, in code order (docs/PROTOCOL.md, "Commands").
        pub const COMMANDS: [CommandSpec; [$($cv),*].len()] = [
            $( CommandSpec {
                code: $cv,
                name: stringify!($c),
                fields: &$cf,
                len: crate::fields::payload_bytes(&$cf) as u8,
                effect: $effect,
                reply: code::$reply,
                meaning: $cm,
            }, )*
        ];

        /// Every reply, in code order (docs/PROTOCOL.md, "Replies").
        pub const REPLIES: [ReplySpec; [$($rv),*].len()] = [
            $( ReplySpec {
                code: $rv,
                name: stringify!($r),
                fields: &$rf,
                len: crate::fields::payload_bytes(&$rf) as u8,
                meaning: $rm,
            }, )*
        ];
    };
}

protocol_codes! {
    commands {
        PING = 0x01, NO_FIELDS, false, IDENTITY, "Ask the device what it is; replied with IDENTITY. Clears the retry memory.";
        LOAD_SEGMENT = 0x02, LOAD_SEGMENT_FIELDS, true, ACK, "Write one segment of the standby program.";
        COMMIT = 0x03, COMMIT_FIELDS, true, ACK, "Set the standby program's segment count (completes an upload).";
        START = 0x04, NO_FIELDS, true, ACK, "Play the standby program from the registers as they are.";
        STOP = 0x05, NO_FIELDS, true, ACK, "Controlled stop (MC_Stop): the axis goes to Stopping, then Standstill.";
        HALT = 0x06, NO_FIELDS, true, ACK, "Controlled stop of a move (MC_Halt): the axis keeps its motion state until at rest.";
        READ_STATUS = 0x07, NO_FIELDS, false, STATUS, "Read the status block; replied with STATUS.";
        CONFIGURE = 0x08, CONFIG_FIELDS, true, ACK, "Set a configuration parameter.";
        READ_STATE = 0x09, NO_FIELDS, false, STATE, "Read the chain's registers and the tick they belong to; replied with STATE.";
        READ_CONFIG = 0x0A, READ_CONFIG_FIELDS, false, CONFIG, "Read a configuration parameter; replied with CONFIG.";
        POWER = 0x0B, POWER_FIELDS, true, ACK, "Enable (1) or disable (0) the axis and its amplifier (MC_Power).";
        RESET = 0x0C, NO_FIELDS, true, ACK, "Clear an axis error and the sticky flags (MC_Reset).";
        SWAP_AT = 0x0D, SWAP_AT_FIELDS, true, ACK, "Arm a program swap at an absolute tick: the standby program takes over from the registers as they are then.";
    }
    replies {
        IDENTITY = 0x41, IDENTITY_FIELDS, "identity (below)";
        STATUS = 0x47, STATUS_FIELDS, "status block (below)";
        STATE = 0x49, STATE_FIELDS, "registers (below)";
        CONFIG = 0x4A, CONFIG_FIELDS, "parameter value (below)";
        ACK = 0x7E, ACK_FIELDS, "the acknowledged command's code";
        NAK = 0x7F, NAK_FIELDS, "the rejected command's code (0 if unknown), reason";
        TELEMETRY = 0x80, STATUS_FIELDS, "status block; `SEQ` 0; unsolicited";
    }
}

/// The spec of command `code`.
pub fn command_spec(code: u8) -> Option<&'static CommandSpec> {
    COMMANDS.iter().find(|c| c.code == code)
}

/// The spec of reply `code`.
pub fn reply_spec(code: u8) -> Option<&'static ReplySpec> {
    REPLIES.iter().find(|r| r.code == code)
}

/// A `u8` code with a name and a meaning: an enum with `ALL`, `from_byte`, `name` and
/// `meaning`.
macro_rules! named_codes {
    (
        $(#[$meta:meta])*
        pub enum $name:ident { $( $var:ident = $val:literal, $text:literal, $meaning:literal; )* }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[repr(u8)]
        pub enum $name {
            $( #[doc = $meaning] $var = $val, )*
        }

        impl $name {
            /// Every value, in order.
            pub const ALL: [$name; [$($val),*].len()] = [$($name::$var),*];

            /// From its byte.
            pub fn from_byte(b: u8) -> Option<Self> {
                match b {
                    $( $val => Some($name::$var), )*
                    _ => None,
                }
            }

            /// Its name in docs/PROTOCOL.md.
            pub const fn name(self) -> &'static str {
                match self {
                    $( $name::$var => $text, )*
                }
            }

            /// What it means.
            pub const fn meaning(self) -> &'static str {
                match self {
                    $( $name::$var => $meaning, )*
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

named_codes! {
    /// Why a frame was rejected (the NAK reason byte).
    pub enum Reason {
        BadCrc = 1, "BAD_CRC", "CRC mismatch (`CMD` and `SEQ` 0)";
        BadLength = 2, "BAD_LENGTH", "`LEN` is not the command's";
        UnknownCommand = 3, "UNKNOWN_COMMAND", "unknown command code";
        Busy = 4, "BUSY", "a program plays (or the axis moves)";
        BadArgument = 5, "BAD_ARGUMENT", "an argument is out of range";
        NoProgram = 6, "NO_PROGRAM", "START without a committed program";
        Framing = 7, "FRAMING", "a UART framing error or a frame cut short (`CMD` and `SEQ` 0)";
        NotEnabled = 8, "NOT_ENABLED", "the axis is disabled: POWER it first";
        AxisError = 9, "AXIS_ERROR", "the axis is in ErrorStop: RESET it first";
        Stopping = 10, "STOPPING", "the axis is stopping: wait for Standstill";
        NotConfigured = 11, "NOT_CONFIGURED", "the stop limits are not set: CONFIGURE STOP_JERK and STOP_ACCEL";
        Limit = 12, "LIMIT", "the program starts toward an active limit switch: move away from it";
        NotDisabled = 13, "NOT_DISABLED", "the parameter is set only while Disabled: POWER 0 first";
        Late = 14, "LATE", "SWAP_AT for a tick less than {SWAP_MIN_LEAD} ticks ahead of the time base: replan for a later tick";
        SwapPending = 15, "SWAP_PENDING", "a program swap is armed: wait until its tick has passed (flag SWAP_PENDING clears)";
    }
}

named_codes! {
    /// The axis states, after PLCopen's (seed 000 Figure 1); `state` in the status block.
    pub enum AxisState {
        Disabled = 0, "DISABLED", "the amplifier is off; nothing moves; after reset";
        Standstill = 1, "STANDSTILL", "enabled, at rest";
        DiscreteMotion = 2, "DISCRETE_MOTION", "a program plays (or a HALT's stop runs)";
        ContinuousMotion = 3, "CONTINUOUS_MOTION", "reserved for velocity moves (not reachable yet)";
        Stopping = 4, "STOPPING", "a STOP runs; motion commands are refused";
        ErrorStop = 5, "ERROR_STOP", "an error stopped the axis; RESET clears it";
    }
}

#[allow(clippy::derivable_impls)] // the enum is made by `named_codes!`
impl Default for AxisState {
    fn default() -> Self {
        AxisState::Disabled
    }
}

impl AxisState {
    /// True in the states where the axis may move.
    pub fn moving(self) -> bool {
        matches!(
            self,
            AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::Stopping
        )
    }
}

named_codes! {
    /// Why the axis is in ErrorStop (`error` in the status block; 0 otherwise).
    pub enum ErrorId {
        None = 0, "NONE", "no error";
        EmergencyStop = 1, "EMERGENCY_STOP", "the emergency-stop input";
        LimitPositive = 2, "LIMIT_POSITIVE", "motion toward the active positive limit switch";
        LimitNegative = 3, "LIMIT_NEGATIVE", "motion toward the active negative limit switch";
        Watchdog = 4, "WATCHDOG", "no good frame for WATCHDOG_MS in DiscreteMotion or ContinuousMotion (moving, or at rest with a swap armed)";
        ProgramEnd = 5, "PROGRAM_END", "a program ended with the axis not at rest (v, a or j ≠ 0): controlled stop";
        FollowingError = 6, "FOLLOWING_ERROR", "the following error passed FOLLOWING_LIMIT: amplifier off at once, the reference holds";
    }
}

#[allow(clippy::derivable_impls)] // the enum is made by `named_codes!`
impl Default for ErrorId {
    fn default() -> Self {
        ErrorId::None
    }
}

/// One bit of `flags` in the status block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FlagSpec {
    /// Bit number.
    pub bit: u32,
    /// Name.
    pub name: &'static str,
    /// The fabric signal that sets it.
    pub port: &'static str,
    /// Meaning.
    pub meaning: &'static str,
}

impl FlagSpec {
    /// Its mask in `flags`.
    pub const fn mask(&self) -> u16 {
        1 << self.bit
    }
}

/// Calls `$callback! { $($extra)* $( NAME = bit, port, "meaning"; )* }` with every status flag:
/// its name, its bit in `flags` and the name of the fabric signal that sets it (the status
/// block's input).
#[macro_export]
macro_rules! with_flags {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)*
            PLAYING = 0, playing, "a program plays";
            DONE = 1, done, "the last program ran to its end";
            CUT = 2, cut, "the last program was cut short (a stop or the emergency stop)";
            STOPPING = 3, stopping, "a controlled stop is requested or runs";
            STOP_OVER_LIMITS = 4, stop_over, "the last stop left its limits on some tick (it began outside them; it still landed exactly)";
            AMPLIFIER = 5, amplifier, "the amplifier is enabled";
            LIMIT_POSITIVE = 6, limit_pos, "the positive limit input is active (after polarity and filter)";
            LIMIT_NEGATIVE = 7, limit_neg, "the negative limit input is active";
            EMERGENCY_STOP = 8, estop, "the emergency-stop input is active";
            ENCODER_ERROR = 9, encoder_error, "an illegal encoder transition was seen (since reset or the last RESET command)";
            UART_ERROR = 10, uart_error, "a UART framing error was seen (since reset or the last RESET command)";
            REPLY_OVERFLOW = 11, reply_overflow, "a frame was dropped with the reply queue full (since reset or the last RESET command)";
            SERVO_OVERRUN = 12, servo_overrun, "the controller skipped a sample, still computing the last one (samples {SERVO_LATENCY} clocks apart or less: SERVO_PERIOD × clocks per tick ≤ {SERVO_LATENCY}; since reset or the last RESET command)";
            SWAP_PENDING = 13, swap_pending, "a program swap is armed (SWAP_AT accepted, its tick not reached yet)";
        }
    };
}

macro_rules! flag_table {
    ( $( $name:ident = $bit:literal, $port:ident, $meaning:literal; )* ) => {
        /// Bits of `flags` in the status block.
        pub mod flag {
            $( #[doc = $meaning] pub const $name: u16 = 1 << $bit; )*
        }

        /// Every flag, in bit order (docs/PROTOCOL.md, "Status block").
        pub const FLAGS: [FlagSpec; [$($bit),*].len()] = [
            $( FlagSpec { bit: $bit, name: stringify!($name), port: stringify!($port), meaning: $meaning }, )*
        ];
    };
}

with_flags!(flag_table! {});

impl crate::fields::Status {
    /// The axis state.
    pub fn axis(&self) -> Option<AxisState> {
        AxisState::from_byte(self.state)
    }

    /// The error identifier.
    pub fn error_id(&self) -> Option<ErrorId> {
        ErrorId::from_byte(self.error)
    }

    /// True when `flag` (a mask of [`flag`]) is set.
    pub fn has(&self, flag: u16) -> bool {
        self.flags & flag != 0
    }

    /// The peak following error, in encoder counts.
    pub fn following_peak_counts(&self) -> f64 {
        f64::from(self.following_peak) / f64::from(1u32 << crate::widths::E_FRAC)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_names_are_unique() {
        let mut codes: Vec<u8> = COMMANDS.iter().map(|c| c.code).collect();
        codes.extend(REPLIES.iter().map(|r| r.code));
        let n = codes.len();
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), n);
        for c in COMMANDS {
            assert!(
                usize::from(c.len) <= crate::wire::DEVICE_MAX_PAYLOAD,
                "{}",
                c.name
            );
            assert!(reply_spec(c.reply).is_some(), "{}", c.name);
        }
        assert_eq!(command_spec(code::LOAD_SEGMENT).map(|c| c.len), Some(18));
        assert_eq!(reply_spec(code::STATE).map(|r| r.len), Some(61));
    }

    #[test]
    fn enums_round_trip_through_their_bytes() {
        for r in Reason::ALL {
            assert_eq!(Reason::from_byte(r as u8), Some(r));
        }
        for s in AxisState::ALL {
            assert_eq!(AxisState::from_byte(s as u8), Some(s));
            assert!((s as u32) < 1 << crate::widths::STATE_BITS);
        }
        for e in ErrorId::ALL {
            assert_eq!(ErrorId::from_byte(e as u8), Some(e));
            assert!((e as u32) < 1 << crate::widths::STATE_BITS);
        }
        assert_eq!(Reason::from_byte(0), None);
        assert_eq!(Reason::Late.name(), "LATE");
        for (k, f) in FLAGS.iter().enumerate() {
            assert_eq!(f.bit as usize, k);
        }
        assert_eq!(flag::SWAP_PENDING, 1 << 13);
    }
}
