//! The worked examples of docs/PROTOCOL.md: whole frames, start byte to CRC, made from the
//! payload layouts and [`crate::wire::frame_bytes`]. The page's test checks their CRCs with a
//! second, table-driven CRC (`spec/tests/protocol_doc.rs`).

use crate::codes::{code, flag, AxisState, Reason};
use crate::fields::{
    AckPayload, CommitArgs, ConfigValue, Identity, LoadSegmentArgs, NakPayload, PowerArgs,
    ReadConfigArgs, StateReply, Status, SwapAtArgs,
};
use crate::params::Param;
use crate::widths::{
    A_BITS, D_BITS, E_FRAC, FRAC_BITS, J_BITS, MAX_SEGMENTS, TICK_BITS, V_BITS, WIDE_BYTES, X_BITS,
};
use crate::wire::{frame_bytes, PROTOCOL_VERSION};

/// The stop jerk limit the examples configure (raw).
const STOP_JERK: i128 = 120_892_581_961_462_917;
/// The stop acceleration limit the IDENTITY example reports (raw).
const STOP_ACCEL: i128 = 0x0CCC_CCCC_CCCC_CCCC_CCCD;

/// Every example: what it is, and its bytes.
pub fn frames() -> Vec<(String, Vec<u8>)> {
    let configure = |param: Param, value: i128| {
        ConfigValue {
            param: param as u8,
            value,
        }
        .to_payload()
    };
    let ack = |cmd: u8| AckPayload { cmd }.to_payload();
    let nak = |cmd: u8, reason: Reason| {
        NakPayload {
            cmd,
            reason: reason as u8,
        }
        .to_payload()
    };
    let identity = Identity {
        protocol: PROTOCOL_VERSION,
        design_hash: 0x1234_ABCD,
        clock_hz: 125_000_000,
        baud: 115_207,
        tick_divider: 1249,
        x_bits: X_BITS as u8,
        v_bits: V_BITS as u8,
        a_bits: A_BITS as u8,
        j_bits: J_BITS as u8,
        d_bits: D_BITS as u8,
        frac_bits: FRAC_BITS as u8,
        tick_bits: TICK_BITS as u8,
        max_segments: MAX_SEGMENTS as u8,
        snap_bytes: WIDE_BYTES as u8,
        stop_jerk: STOP_JERK,
        stop_accel: STOP_ACCEL,
    };
    let standstill = Status {
        state: AxisState::Standstill as u8,
        error: 0,
        flags: flag::DONE | flag::AMPLIFIER,
        tick_count: 85_000,
        position: 500_000,
        velocity: 0,
        encoder: 500_000,
        bad_crc: 0,
        bad_frames: 1,
        following_peak: 3 << E_FRAC,
        duty: 12,
    };
    let moving = Status {
        state: AxisState::DiscreteMotion as u8,
        error: 0,
        flags: flag::PLAYING | flag::AMPLIFIER,
        tick_count: 40_000,
        position: 235_702,
        velocity: 123_456,
        encoder: 235_700,
        bad_crc: 0,
        bad_frames: 0,
        following_peak: 5 << (E_FRAC - 1),
        duty: -40,
    };
    let at_rest = StateReply {
        ticks: 1_234_567,
        x: (500_000i128 << FRAC_BITS) + (1i128 << (FRAC_BITS - 1)),
        v: 0,
        a: 0,
        j: 0,
    };
    let f = |label: &str, cmd: u8, seq: u8, payload: Vec<u8>| {
        (label.to_string(), frame_bytes(cmd, seq, &payload))
    };
    vec![
        f("PING, seq 1", code::PING, 1, vec![]),
        f(
            "IDENTITY, seq 1 (Zybo timing, see below)",
            code::IDENTITY,
            1,
            identity.to_payload(),
        ),
        f(
            &format!("CONFIGURE STOP_JERK {STOP_JERK}, seq 2"),
            code::CONFIGURE,
            2,
            configure(Param::StopJerk, STOP_JERK),
        ),
        f("ACK CONFIGURE, seq 2", code::ACK, 2, ack(code::CONFIGURE)),
        f(
            "READ_CONFIG STOP_JERK, seq 3",
            code::READ_CONFIG,
            3,
            ReadConfigArgs {
                param: Param::StopJerk as u8,
            }
            .to_payload(),
        ),
        f(
            &format!("CONFIG STOP_JERK {STOP_JERK}, seq 3"),
            code::CONFIG,
            3,
            configure(Param::StopJerk, STOP_JERK),
        ),
        f(
            "POWER 1, seq 4",
            code::POWER,
            4,
            PowerArgs { on: 1 }.to_payload(),
        ),
        f(
            "LOAD_SEGMENT 2: 5000 ticks, snap -12089258196146, seq 7",
            code::LOAD_SEGMENT,
            7,
            LoadSegmentArgs {
                index: 2,
                ticks: 5000,
                snap: -12_089_258_196_146,
            }
            .to_payload(),
        ),
        f(
            "COMMIT 15, seq 8",
            code::COMMIT,
            8,
            CommitArgs { count: 15 }.to_payload(),
        ),
        f("START, seq 9", code::START, 9, vec![]),
        f("ACK START, seq 9", code::ACK, 9, ack(code::START)),
        f(
            "NAK START NO_PROGRAM, seq 9",
            code::NAK,
            9,
            nak(code::START, Reason::NoProgram),
        ),
        f("READ_STATUS, seq 11", code::READ_STATUS, 11, vec![]),
        f(
            "STATUS, seq 11: Standstill, DONE and AMPLIFIER, 85000 ticks, position 500000, encoder 500000, 1 bad frame, peak following error 3 counts, duty 12",
            code::STATUS,
            11,
            standstill.to_payload(),
        ),
        f("STOP, seq 12", code::STOP, 12, vec![]),
        f("HALT, seq 13", code::HALT, 13, vec![]),
        f("READ_STATE, seq 14", code::READ_STATE, 14, vec![]),
        f(
            "STATE, seq 14: tick 1234567, at rest at the centre of cell 500000",
            code::STATE,
            14,
            at_rest.to_payload(),
        ),
        f("RESET, seq 15", code::RESET, 15, vec![]),
        f(
            "CONFIGURE TICK_DIVIDER 1249, seq 16",
            code::CONFIGURE,
            16,
            configure(Param::TickDivider, 1249),
        ),
        f(
            "CONFIGURE TELEMETRY_PERIOD 100, seq 17",
            code::CONFIGURE,
            17,
            configure(Param::TelemetryPeriod, 100),
        ),
        f(
            "TELEMETRY: DiscreteMotion, PLAYING and AMPLIFIER, 40000 ticks, position 235702, velocity 123456, encoder 235700, peak following error 2.5 counts, duty −40",
            code::TELEMETRY,
            0,
            moving.to_payload(),
        ),
        f(
            "NAK for a frame with a bad CRC",
            code::NAK,
            0,
            nak(0, Reason::BadCrc),
        ),
        f(
            "SWAP_AT tick 1301000, seq 18",
            code::SWAP_AT,
            18,
            SwapAtArgs { tick: 1_301_000 }.to_payload(),
        ),
        f("ACK SWAP_AT, seq 18", code::ACK, 18, ack(code::SWAP_AT)),
        f(
            "NAK SWAP_AT LATE, seq 19",
            code::NAK,
            19,
            nak(code::SWAP_AT, Reason::Late),
        ),
    ]
}

/// The examples as the page's code block: a label, then the bytes (on the next line when the
/// label is long).
pub fn markdown() -> String {
    const COLUMN: usize = 47;
    let mut s = String::from("```\n");
    for (label, bytes) in frames() {
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
        let hex = hex.join(" ");
        if label.chars().count() < COLUMN {
            let pad = COLUMN - label.chars().count();
            s.push_str(&format!("{label}{}{hex}\n", " ".repeat(pad)));
        } else {
            s.push_str(&format!("{label}\n{}{hex}\n", " ".repeat(COLUMN)));
        }
    }
    s.push_str("```\n");
    s
}
