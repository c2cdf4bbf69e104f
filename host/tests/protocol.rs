//! The host's codecs: every command and reply through its frame and back, refusals of bad
//! arguments, and the fabric's frame receiver (its clock-by-clock model) against the host's
//! device decoder on random byte streams.

use proptest::prelude::*;
use snapgen_host::protocol::*;
use snapgen_model::io::frame_rx::{FrameRx, FrameRxInputs, FrameRxOutputs};
use snapgen_model::{Segment, DEFAULT_FORMAT};
use snapgen_spec::wire::PROTOCOL_VERSION;

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
        x_bits: 112,
        v_bits: 104,
        a_bits: 104,
        j_bits: 104,
        d_bits: 104,
        frac_bits: 80,
        tick_bits: 32,
        max_segments: 32,
        snap_bytes: 13,
        stop_jerk: 1 << 60,
        stop_accel: 1 << 90,
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
    assert!(DEFAULT_FORMAT.matches_identity(&id));
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

/// Byte by byte (one a clock, with gaps shorter than the timeout), the receiver finds the
/// frames the device decoder finds, with the same command, sequence and payload.
fn feed(bytes: &[u8]) -> Vec<Decoded> {
    let mut rx = FrameRx::new();
    let mut out = Vec::new();
    let got = |o: FrameRxOutputs, out: &mut Vec<Decoded>| {
        if o.frame {
            out.push(Decoded::Frame(Frame {
                cmd: o.cmd,
                seq: o.seq,
                payload: (0..usize::from(o.len)).map(|k| o.byte(k)).collect(),
            }));
        }
        if o.bad_crc {
            out.push(Decoded::BadCrc);
        }
    };
    for &b in bytes {
        let o = rx.clock(&FrameRxInputs {
            data: b,
            valid: true,
            timeout: 100,
            ..Default::default()
        });
        got(o, &mut out);
        let o = rx.clock(&FrameRxInputs {
            timeout: 100,
            ..Default::default()
        });
        got(o, &mut out);
    }
    out
}

proptest! {
    #[test]
    fn decodes_as_the_device_decoder(bytes in proptest::collection::vec(any::<u8>(), 0..300), frames in 0usize..4, seed in any::<u64>()) {
        let f = DEFAULT_FORMAT;
        let mut stream = bytes;
        for k in 0..frames {
            let c = Command::Configure { param: Param::WatchdogMs, value: i128::from(seed as u16) + k as i128 };
            let at = (seed as usize + 7 * k) % (stream.len() + 1);
            let frame = c.to_frame(k as u8, &f).to_bytes();
            stream.splice(at..at, frame);
        }
        let mut d = Decoder::device();
        let want: Vec<Decoded> = stream.iter().filter_map(|&b| d.push(b)).collect();
        prop_assert_eq!(feed(&stream), want);
    }
}
