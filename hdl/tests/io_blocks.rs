//! Each I/O block, simulated by rust-hdl, against its model in `snapgen_model::io`, clock by
//! clock, under random stimulus: encoder steps both ways, illegal double steps and glitches
//! shorter and longer than the filter; PWM periods, duties (including saturation and −32768),
//! enable and fault; UART bytes at ±2 % baud error with injected bit errors, truncated frames
//! and breaks; FIFO writes and reads at random, full and empty.

use rust_hdl::prelude::*;
use snapgen_hdl::byte_fifo::ByteFifo;
use snapgen_hdl::pwm::PwmGenerator;
use snapgen_hdl::quadrature::QuadratureDecoder;
use snapgen_hdl::uart_rx::UartRx;
use snapgen_hdl::uart_tx::UartTx;
use snapgen_model::io::fifo::ByteFifo as FifoModel;
use snapgen_model::io::pwm::{Pwm, PwmInputs};
use snapgen_model::io::quadrature::{QuadInputs, Quadrature};
use snapgen_model::io::uart::{UartRx as RxModel, UartTx as TxModel};

mod common;
use common::Rng;

fn b16(v: u16) -> Bits<16> {
    u64::from(v).into()
}

/// Encoder pin levels over time: steps, holds, glitches and double steps.
fn encoder_stimulus(seed: u64, clocks: usize) -> Vec<QuadInputs> {
    let mut r = Rng(seed);
    let mut out = Vec::with_capacity(clocks);
    let gray = [(false, false), (false, true), (true, true), (true, false)];
    let mut phase = 0usize;
    let mut filter = 1u16;
    while out.len() < clocks {
        if r.chance(2) {
            filter = [0, 1, 3, 7][r.below(4) as usize];
        }
        let roll = r.below(100);
        if roll < 80 {
            // A legal step either way.
            phase = if r.chance(60) {
                (phase + 1) % 4
            } else {
                (phase + 3) % 4
            };
        } else if roll < 85 {
            // An illegal double step.
            phase = (phase + 2) % 4;
        }
        let (a, b) = gray[phase];
        let hold = 1 + r.below(24) as usize;
        let index = r.chance(3);
        for k in 0..hold {
            let mut i = QuadInputs {
                a,
                b,
                index: index && k < hold / 2,
                filter,
                clear: false,
            };
            // Glitches shorter and longer than the filter.
            if (85..95).contains(&roll) && k < 1 + r.below(6) as usize {
                i.a = !i.a;
            }
            if roll >= 95 && r.chance(30) {
                i.b = !i.b;
            }
            out.push(i);
        }
        if r.chance(1) {
            out.push(QuadInputs {
                a,
                b,
                filter,
                clear: true,
                ..Default::default()
            });
        }
    }
    out.truncate(clocks);
    out
}

#[test]
fn quadrature_decoder_matches_the_model() {
    let stimulus = encoder_stimulus(0x5eed_0001, 20_000);
    let mut sim = Simulation::new();
    // A 6-bit count, so that the random walk also reaches its ends and wraps.
    sim.add_clock(5, |x: &mut Box<QuadratureDecoder<6>>| {
        x.clock.next = !x.clock.val()
    });
    sim.add_testbench(move |mut sim: Sim<QuadratureDecoder<6>>| {
        let mut x = sim.init()?;
        let mut m = Quadrature::with_width(6);
        let mut wrapped = false;
        let (mut steps, mut errors) = (0u64, 0u64);
        for i in &stimulus {
            x.a.next = i.a;
            x.b.next = i.b;
            x.index.next = i.index;
            x.filter.next = b16(i.filter);
            x.clear.next = i.clear;
            wait_clock_cycle!(sim, clock, x);
            let o = m.clock(i);
            sim_assert_eq!(sim, (x.count.val().to_u64() as i64) << 58 >> 58, o.count, x);
            wrapped |= o.count == -32;
            sim_assert_eq!(sim, x.errors.val().to_u64() as u16, o.errors, x);
            sim_assert_eq!(
                sim,
                (x.index_count.val().to_u64() as i64) << 58 >> 58,
                o.index_count,
                x
            );
            sim_assert_eq!(sim, x.index_seen.val(), o.index_seen, x);
            steps = steps.max(o.count.unsigned_abs());
            errors = errors.max(o.errors.into());
        }
        // The stimulus exercised counting and errors.
        sim_assert!(sim, steps > 10 && errors > 0 && wrapped, x);
        sim.done(x)
    });
    let mut uut = QuadratureDecoder::<6>::default();
    uut.connect_all();
    sim.run(Box::new(uut), 1_000_000_000).unwrap();
}

#[test]
fn pwm_generator_matches_the_model() {
    let mut r = Rng(0x5eed_0002);
    let mut stimulus = Vec::new();
    let mut i = PwmInputs {
        period: 20,
        duty: 5,
        enable: true,
        fault: false,
    };
    for _ in 0..20_000 {
        if r.chance(1) {
            i.period = r.below(60) as u16;
        }
        if r.chance(3) {
            i.duty = match r.below(10) {
                0 => i16::MIN,
                1 => i16::MAX,
                _ => r.below(140) as i16 - 70,
            };
        }
        if r.chance(1) {
            i.enable = !i.enable;
        }
        if r.chance(1) {
            i.fault = !i.fault;
        }
        stimulus.push(i);
    }
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<PwmGenerator>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<PwmGenerator>| {
        let mut x = sim.init()?;
        let mut m = Pwm::new();
        let (mut highs, mut dirs) = (0u32, 0u32);
        for i in &stimulus {
            x.period.next = b16(i.period);
            x.duty.next = b16(i.duty as u16);
            x.enable.next = i.enable;
            x.fault.next = i.fault;
            wait_clock_cycle!(sim, clock, x);
            let o = m.clock(i);
            sim_assert_eq!(sim, x.pwm.val(), o.pwm, x);
            sim_assert_eq!(sim, x.dir.val(), o.dir, x);
            highs += u32::from(o.pwm);
            dirs += u32::from(o.dir);
        }
        sim_assert!(sim, highs > 100 && dirs > 100, x);
        sim.done(x)
    });
    let mut uut = PwmGenerator::default();
    uut.connect_all();
    sim.run(Box::new(uut), 1_000_000_000).unwrap();
}

/// The RX line: bytes from a model transmitter whose bit time is off by up to ±2 %, with
/// injected bit errors, truncated frames and breaks. Returns (line levels, bytes sent clean).
fn uart_line(seed: u64, divisor: u16, bytes: usize) -> (Vec<bool>, usize) {
    let mut r = Rng(seed);
    let mut line = Vec::new();
    let mut clean = 0;
    for _ in 0..bytes {
        let tx_div = divisor - divisor / 50 + r.below(u64::from(divisor / 25) + 1) as u16;
        let data = r.below(256) as u8;
        let mut tx = TxModel::new();
        let mut levels = Vec::new();
        let mut started = false;
        loop {
            let o = tx.clock(!started, data, tx_div);
            started = true;
            levels.push(o.tx);
            if !o.busy {
                break;
            }
        }
        match r.below(10) {
            0 => {
                // A bit error: invert one bit time somewhere in the frame.
                let at = r.below(levels.len() as u64) as usize;
                for l in levels.iter_mut().skip(at).take(usize::from(tx_div)) {
                    *l = !*l;
                }
            }
            1 => {
                // Truncated: the line goes back high mid-frame.
                let at = r.below(levels.len() as u64) as usize;
                for l in levels.iter_mut().skip(at) {
                    *l = true;
                }
            }
            2 => {
                // A break: low for longer than a frame.
                levels = vec![false; 12 * usize::from(divisor)];
            }
            _ => clean += 1,
        }
        line.extend(levels);
        line.extend(std::iter::repeat_n(
            true,
            1 + r.below(3 * u64::from(divisor)) as usize,
        ));
    }
    (line, clean)
}

#[test]
fn uart_rx_matches_the_model() {
    let divisor = 50u16;
    let (line, clean) = uart_line(0x5eed_0003, divisor, 300);
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<UartRx>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<UartRx>| {
        let mut x = sim.init()?;
        let mut m = RxModel::new();
        let (mut bytes, mut errors) = (0usize, 0usize);
        for &level in &line {
            x.rx.next = level;
            x.divisor.next = b16(divisor);
            wait_clock_cycle!(sim, clock, x);
            let o = m.clock(level, divisor);
            sim_assert_eq!(sim, x.valid.val(), o.valid, x);
            sim_assert_eq!(sim, x.framing_error.val(), o.framing_error, x);
            sim_assert_eq!(sim, x.data.val().to_u64() as u8, o.data, x);
            bytes += usize::from(o.valid);
            errors += usize::from(o.framing_error);
        }
        // Every clean byte arrived despite the baud error; the faults made framing errors.
        sim_assert!(sim, bytes >= clean && errors > 0, x);
        sim.done(x)
    });
    let mut uut = UartRx::default();
    uut.connect_all();
    sim.run(Box::new(uut), 10_000_000_000).unwrap();
}

#[test]
fn clean_bytes_survive_two_percent_baud_error() {
    // Model-only (exhaustive over bytes): TX at ±2 % of the RX's bit time.
    for tx_div in [98u16, 100, 102] {
        for data in 0..=255u8 {
            let mut tx = TxModel::new();
            let mut rx = RxModel::new();
            let mut got = None;
            for k in 0..1300 {
                let o = tx.clock(k == 0, data, tx_div);
                let r = rx.clock(o.tx, 100);
                assert!(!r.framing_error, "byte {data:#x} at divisor {tx_div}");
                if r.valid {
                    got = Some(r.data);
                }
            }
            assert_eq!(got, Some(data), "byte {data:#x} at divisor {tx_div}");
        }
    }
}

#[test]
fn uart_tx_matches_the_model() {
    let mut r = Rng(0x5eed_0004);
    let stimulus: Vec<(bool, u8, u16)> = (0..30_000)
        .map(|_| (r.chance(30), r.below(256) as u8, 1 + r.below(12) as u16))
        .collect();
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<UartTx>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<UartTx>| {
        let mut x = sim.init()?;
        let mut m = TxModel::new();
        let mut divisor = 7u16;
        let mut lows = 0u32;
        for &(start, data, d) in &stimulus {
            // The divisor changes only between bytes, as a configuration would.
            if !m.busy() {
                divisor = d;
            }
            x.start.next = start;
            x.data.next = u64::from(data).into();
            x.divisor.next = b16(divisor);
            wait_clock_cycle!(sim, clock, x);
            let o = m.clock(start, data, divisor);
            sim_assert_eq!(sim, x.tx.val(), o.tx, x);
            sim_assert_eq!(sim, x.busy.val(), o.busy, x);
            lows += u32::from(!o.tx);
        }
        sim_assert!(sim, lows > 1000, x);
        sim.done(x)
    });
    let mut uut = UartTx::default();
    uut.connect_all();
    sim.run(Box::new(uut), 1_000_000_000).unwrap();
}

#[test]
fn byte_fifo_matches_the_model() {
    let mut r = Rng(0x5eed_0005);
    let stimulus: Vec<(bool, u8, bool)> = (0..20_000)
        .map(|_| (r.chance(45), r.below(256) as u8, r.chance(40)))
        .collect();
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<ByteFifo>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<ByteFifo>| {
        let mut x = sim.init()?;
        let mut m = FifoModel::new();
        let (mut fulls, mut empties) = (0u32, 0u32);
        for &(w, d, rd) in &stimulus {
            x.write.next = w;
            x.write_data.next = u64::from(d).into();
            x.read.next = rd;
            wait_clock_cycle!(sim, clock, x);
            let o = m.clock(w, d, rd);
            sim_assert_eq!(sim, x.empty.val(), o.empty, x);
            sim_assert_eq!(sim, x.full.val(), o.full, x);
            if !o.empty {
                sim_assert_eq!(sim, x.data.val().to_u64() as u8, o.data, x);
            }
            fulls += u32::from(o.full);
            empties += u32::from(o.empty);
        }
        sim_assert!(sim, fulls > 10 && empties > 10, x);
        sim.done(x)
    });
    let mut uut = ByteFifo::default();
    uut.connect_all();
    sim.run(Box::new(uut), 1_000_000_000).unwrap();
}
