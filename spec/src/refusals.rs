//! Why a command is refused after its length and code are accepted: the refusal table of
//! docs/PROTOCOL.md ("Commands"), checked in the table's order. The frame-level reasons
//! BAD_CRC, FRAMING, BAD_LENGTH and UNKNOWN_COMMAND apply to any frame.

use crate::codes::{command_spec, Reason};

/// One row: a command, the reasons it is refused with and when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The command's name, with its argument where the row applies to one (`POWER 1`).
    pub command: &'static str,
    /// The reasons.
    pub reasons: &'static [Reason],
    /// When (may name constants as `{NAME}`).
    pub when: &'static str,
}

const fn refusal(command: &'static str, reasons: &'static [Reason], when: &'static str) -> Refusal {
    Refusal {
        command,
        reasons,
        when,
    }
}

/// Every refusal, in the order the device checks them.
pub const REFUSALS: [Refusal; 24] = {
    use Reason::*;
    [
        refusal("LOAD_SEGMENT", &[BadArgument], "`index` ≥ {MAX_SEGMENTS} or `ticks` = 0"),
        refusal("LOAD_SEGMENT", &[SwapPending], "a swap is armed"),
        refusal("COMMIT", &[BadArgument], "`count` > {MAX_SEGMENTS}"),
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
            "a parameter set only while Disabled, in another state (but ErrorStop with the amplifier off and the axis at rest)",
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
            "`tick` lies 2^{SWAP_REACH_LOG2} ticks or more beyond the time base (the core compares {SWAP_BITS} bits)",
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
            "`tick` − (the time base on the clock before the one that executes the command) < {SWAP_MIN_LEAD}, as a signed 64-bit difference",
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
        (r.command == spec.name
            || r.command
                .strip_prefix(spec.name)
                .is_some_and(|a| a.starts_with(' ')))
            && r.reasons.contains(&reason)
    })
}
