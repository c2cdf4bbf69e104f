//! Fuzzing the frame decoder: arbitrary input never panics, and corrupt frames are never
//! accepted. Raise the case count with `PROPTEST_CASES`.

use proptest::prelude::*;
use snapgen_host::protocol::{
    crc16, Command, Decoded, Decoder, Frame, Reply, DEVICE_MAX_PAYLOAD, START,
};
use snapgen_model::DEFAULT_FORMAT;
use snapgen_spec::COMMANDS;

fn frame() -> impl Strategy<Value = Frame> {
    (
        any::<u8>(),
        any::<u8>(),
        proptest::collection::vec(any::<u8>(), 0..40),
    )
        .prop_map(|(cmd, seq, payload)| Frame { cmd, seq, payload })
}

fn decode_all(bytes: &[u8]) -> Vec<Decoded> {
    let mut d = Decoder::new();
    bytes.iter().filter_map(|&b| d.push(b)).collect()
}

/// As a device decodes: lengths above `DEVICE_MAX_PAYLOAD` are not frame starts.
fn device_decode_all(bytes: &[u8]) -> Vec<Decoded> {
    let mut d = Decoder::device();
    bytes.iter().filter_map(|&b| d.push(b)).collect()
}

proptest! {
    /// Any byte stream: no panic; every frame the decoder accepts carries a matching CRC, and
    /// parsing it as a command or a reply never panics.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        for d in decode_all(&bytes).into_iter().chain(device_decode_all(&bytes)) {
            if let Decoded::Frame(f) = d {
                let wire = f.to_bytes();
                let n = wire.len();
                prop_assert_eq!(u16::from_le_bytes([wire[n - 2], wire[n - 1]]), crc16(&wire[1..n - 2]));
                let _ = Command::from_frame(&f, &DEFAULT_FORMAT);
                let _ = Reply::from_frame(&f);
            }
        }
    }

    /// A valid frame, surrounded by noise, decodes to itself.
    #[test]
    fn frames_survive_noise(f in frame(), pre in proptest::collection::vec(any::<u8>().prop_filter("no start byte", |b| *b != START), 0..20)) {
        let mut bytes = pre;
        bytes.extend(f.to_bytes());
        let got = decode_all(&bytes);
        prop_assert_eq!(got.last(), Some(&Decoded::Frame(f.clone())));
        if f.payload.len() <= DEVICE_MAX_PAYLOAD {
            let dev = device_decode_all(&bytes);
            prop_assert_eq!(dev.last(), Some(&Decoded::Frame(f)));
        }
    }

    /// One to three flipped bits anywhere after the length byte are always detected
    /// (CRC-16/CCITT has Hamming distance 4 at these lengths): the frame is never accepted.
    #[test]
    fn bit_errors_are_never_accepted(f in frame(), flips in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..8), 1..=3)) {
        let mut bytes = f.to_bytes();
        let body = bytes.len() - 2; // bytes 2.. (cmd, seq, payload, crc)
        let mut seen = std::collections::BTreeSet::new();
        for (i, bit) in flips {
            let at = 2 + i.index(body);
            if seen.insert((at, bit)) {
                bytes[at] ^= 1 << bit;
            }
        }
        prop_assume!(!seen.is_empty());
        for d in decode_all(&bytes).into_iter().chain(device_decode_all(&bytes)) {
            if let Decoded::Frame(g) = d {
                prop_assert!(false, "a corrupt frame decoded as {:?}", g);
            }
        }
    }

    /// A frame cut short never decodes.
    #[test]
    fn truncated_frames_never_decode(f in frame(), cut in any::<prop::sample::Index>()) {
        let bytes = f.to_bytes();
        let n = cut.index(bytes.len());
        prop_assert!(decode_all(&bytes[..n]).iter().all(|d| !matches!(d, Decoded::Frame(_))));
    }
}

/// A corrupted length byte changes where the decoder looks for the CRC; it is not covered by
/// the Hamming-distance guarantee, so it is checked exhaustively on example frames: every
/// single-bit error of the length byte, followed by enough bytes to complete any length, is
/// rejected.
#[test]
fn corrupted_length_bytes_are_rejected() {
    let f = &DEFAULT_FORMAT;
    let frames: Vec<Frame> = vec![
        Command::Ping.to_frame(1, f),
        Command::Start.to_frame(2, f),
        Command::Commit { count: 15 }.to_frame(3, f),
        Command::Configure {
            param: snapgen_host::protocol::Param::StopJerk,
            value: 12_345,
        }
        .to_frame(5, f),
        Command::LoadSegment {
            index: 2,
            segment: snapgen_model::Segment {
                ticks: 5000,
                snap: -12_089_258_196_146,
            },
        }
        .to_frame(4, f),
    ];
    for fr in frames {
        for bit in 0..8 {
            let mut bytes = fr.to_bytes();
            bytes[1] ^= 1 << bit;
            bytes.extend(std::iter::repeat_n(0u8, 300));
            let got = decode_all(&bytes);
            assert!(
                got.iter().all(|d| !matches!(d, Decoded::Frame(_))),
                "{fr:?} with length bit {bit} flipped decoded as {got:?}"
            );
        }
    }
}

/// A small device (16 clocks per UART bit, a tick every 8 clocks).
fn device() -> snapgen_model::device::Device {
    use snapgen_model::device::{Design, Device};
    let d = Design {
        format: DEFAULT_FORMAT,
        dividers: snapgen_model::timing::Dividers {
            uart_divisor: 16,
            tick_div: 7,
            frame_timeout: 2000,
            heartbeat_bit: 10,
            clocks_per_ms: 2000,
        },
        clock_hz: 2_000_000,
        baud: 125_000,
        design_hash: 0,
        input_polarity: 0,
    };
    Device::powered_up(&d, 4)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64)
    ))]

    /// The device model, over its UART, answers every frame with a good CRC and a length the
    /// device takes (≤ DEVICE_MAX_PAYLOAD) exactly once, with the frame's sequence number (or
    /// NAKs it, for a reason the refusal table lists), whatever its code and payload — and
    /// never panics.
    #[test]
    fn the_device_answers_every_frame_once(frames in proptest::collection::vec(
        (any::<bool>(), any::<u8>(), 1u8..=255, proptest::collection::vec(any::<u8>(), 0..=DEVICE_MAX_PAYLOAD)),
        1..6,
    )) {
        let mut dev = device();
        let mut peer = snapgen_model::peer::Peer::new(16);
        peer.reset_clocks = 0;
        let mut decoder = Decoder::new();
        for (known, code, seq, mut payload) in frames {
            // Half the frames are real commands with payloads of their exact length (random
            // arguments); the others any code and length.
            let cmd = if known {
                let spec = COMMANDS[usize::from(code) % COMMANDS.len()];
                payload.resize(usize::from(spec.len), 0x5A);
                spec.code
            } else {
                code
            };
            peer.send(&Frame { cmd, seq, payload: payload.clone() }.to_bytes());
            let mut replies = Vec::new();
            // The frame's airtime, then room for the longest reply.
            for _ in 0..(payload.len() as u64 + 6) * 160 + 80 * 160 {
                let i = peer.inputs();
                let o = dev.clock(&i);
                peer.observe(&o);
                for b in peer.take_received() {
                    if let Some(Decoded::Frame(f)) = decoder.push(b) {
                        if f.cmd != snapgen_host::protocol::code::TELEMETRY {
                            replies.push(f);
                        }
                    }
                }
            }
            prop_assert_eq!(replies.len(), 1, "{:?}", replies);
            let r = &replies[0];
            prop_assert_eq!(r.seq, seq);
            let reply = Reply::from_frame(r);
            prop_assert!(reply.is_some(), "{:?}", r);
            // A refusal is one the refusal table (docs/PROTOCOL.md) lists for its command.
            if let Some(Reply::Nak { cmd, reason }) = reply {
                use snapgen_host::protocol::Reason;
                use snapgen_spec::refusals::refusal_documented;
                let frame_level = matches!(
                    reason,
                    Reason::BadCrc | Reason::Framing | Reason::BadLength | Reason::UnknownCommand
                );
                prop_assert!(frame_level || refusal_documented(cmd, reason), "{:?} {:?}", cmd, reason);
            }
        }
    }
}
