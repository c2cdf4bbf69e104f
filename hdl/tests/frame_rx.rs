//! The frame receiver, simulated by rust-hdl, against the device decoder of the model
//! (`Decoder::device()`): the same events (good frame with its fields, bad CRC, dropped partial
//! frame) in the same order, for a random stream of commands, corrupted frames, noise, false
//! starts, long lengths, cut frames and gaps longer than the inter-byte timeout.

use rust_hdl::prelude::*;
use snapgen_hdl::frame_rx::FrameRx;
use snapgen_host::protocol::{Command, Decoded, Decoder, Param};
use snapgen_model::{Segment, DEFAULT_FORMAT};

mod common;
use common::Rng;

const TIMEOUT: u64 = 20;

#[derive(Clone, Debug, PartialEq, Eq)]
enum Event {
    Frame {
        cmd: u8,
        seq: u8,
        payload: Vec<u8>,
        crc: u16,
    },
    BadCrc,
    Dropped,
}

/// (byte, idle clocks after it), and the events the model expects.
fn stimulus(seed: u64) -> (Vec<(u8, u64)>, Vec<Event>) {
    let f = DEFAULT_FORMAT;
    let mut r = Rng(seed);
    let mut bytes: Vec<(u8, u64)> = Vec::new();
    let mut seq = 0u8;
    for _ in 0..300 {
        seq = seq.wrapping_add(1);
        let cmd = match r.below(6) {
            0 => Command::Ping,
            1 => Command::LoadSegment {
                index: r.below(40) as u8,
                segment: Segment {
                    ticks: r.next() as u32,
                    snap: (r.next() as i128) << 40 | r.next() as i128,
                },
            },
            2 => Command::Commit {
                count: r.below(40) as u8,
            },
            3 => Command::Configure {
                param: Param::StopAccel,
                value: i128::from(r.next()) << 30,
            },
            4 => Command::Start,
            _ => Command::ReadStatus,
        };
        let mut frame = cmd.to_frame(seq, &f).to_bytes();
        match r.below(12) {
            0 => {
                let i = 2 + r.below(frame.len() as u64 - 2) as usize;
                frame[i] ^= 1 << r.below(8);
            }
            1 => {
                let cut = 1 + r.below(frame.len() as u64 - 1) as usize;
                frame.truncate(cut);
            }
            2 => frame = vec![0xA5, 0x40 + r.below(0x60) as u8],
            3 => frame = vec![r.below(256) as u8, 0x11, 0xA5, 0xA5],
            _ => {}
        }
        let n = frame.len();
        for (k, b) in frame.into_iter().enumerate() {
            let gap = if k + 1 == n && r.below(5) == 0 {
                TIMEOUT + 5 + r.below(10)
            } else {
                r.below(4)
            };
            bytes.push((b, gap));
        }
    }
    // The model: the device decoder, with the inter-byte timeout applied to long gaps.
    let mut d = Decoder::device();
    let mut events = Vec::new();
    for &(b, gap) in &bytes {
        match d.push(b) {
            Some(Decoded::Frame(fr)) => {
                let wire = fr.to_bytes();
                let crc = u16::from_le_bytes([wire[wire.len() - 2], wire[wire.len() - 1]]);
                events.push(Event::Frame {
                    cmd: fr.cmd,
                    seq: fr.seq,
                    payload: fr.payload,
                    crc,
                })
            }
            Some(Decoded::BadCrc) => events.push(Event::BadCrc),
            None => {}
        }
        if gap > TIMEOUT && d.reset() {
            events.push(Event::Dropped);
        }
    }
    (bytes, events)
}

#[test]
fn frame_receiver_matches_the_device_decoder() {
    let (bytes, want) = stimulus(0xF00D);
    assert!(
        want.iter()
            .filter(|e| matches!(e, Event::Frame { .. }))
            .count()
            > 100
    );
    assert!(want.contains(&Event::BadCrc) && want.contains(&Event::Dropped));
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<FrameRx>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<FrameRx>| {
        let mut x = sim.init()?;
        x.timeout.next = TIMEOUT.into();
        x.reset.next = true;
        wait_clock_cycle!(sim, clock, x);
        x.reset.next = false;
        let mut got = Vec::new();
        let mut collect = |x: &FrameRx| {
            if x.frame.val() {
                // Byte k of an n-byte payload is bits 8(n-1-k) +: 8.
                let n = x.len.val().to_u64() as usize;
                let payload = (0..n)
                    .map(|k| x.payload.val().get_bits::<8>(8 * (n - 1 - k)).to_u64() as u8)
                    .collect();
                got.push(Event::Frame {
                    cmd: x.cmd.val().to_u64() as u8,
                    seq: x.seq.val().to_u64() as u8,
                    payload,
                    crc: x.crc.val().to_u64() as u16,
                });
            }
            if x.bad_crc.val() {
                got.push(Event::BadCrc);
            }
            if x.dropped.val() {
                got.push(Event::Dropped);
            }
        };
        for &(b, gap) in &bytes {
            x.data.next = u64::from(b).into();
            x.valid.next = true;
            wait_clock_cycle!(sim, clock, x);
            collect(&x);
            x.valid.next = false;
            for _ in 0..gap {
                wait_clock_cycle!(sim, clock, x);
                collect(&x);
            }
        }
        for _ in 0..TIMEOUT + 5 {
            wait_clock_cycle!(sim, clock, x);
            collect(&x);
        }
        // A partial frame left at the very end is dropped by the timeout there too.
        let mut want = want.clone();
        if got.len() == want.len() + 1 && got.last() == Some(&Event::Dropped) {
            want.push(Event::Dropped);
        }
        sim_assert_eq!(sim, got, want, x);
        sim.done(x)
    });
    let mut uut = FrameRx::default();
    uut.connect_all();
    sim.run(Box::new(uut), 100_000_000_000).unwrap();
}
