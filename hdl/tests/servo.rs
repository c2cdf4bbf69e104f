//! The position controller's register-level design (`snapgen_hdl::servo::Servo`, run by
//! rust-hdl's simulator: a digit-serial multiplier, magnitudes, rounding) against the model's
//! arithmetic law (`snapgen_model::io::servo::Servo`, exact i128), clock by clock, under random
//! registers, encoder counts, gains, limits, ticks, starts and the amplifier going off and on.
//! Verilator runs the block's Verilog against the same model in the I/O top's co-simulations.

use rust_hdl::prelude::*;
use snapgen_hdl::servo::Servo;
use snapgen_model::io::servo::{Servo as Model, ServoConfig, ServoInputs, GAIN_BITS, LATENCY};

mod common;
use common::Rng;

fn bits<const N: usize>(v: i128) -> Bits<N> {
    let u = (v as u128) & (u128::MAX >> (128 - N));
    let mut b = Bits::<N>::default();
    for k in 0..N {
        b = b.replace_bit(k, (u >> k) & 1 == 1);
    }
    b
}

/// A random value of magnitude up to about 2^`max_bits`, either sign, log-uniform-ish.
fn wide(r: &mut Rng, max_bits: u32) -> i128 {
    let b = r.below(u64::from(max_bits) + 1) as u32;
    let mag = if b == 0 {
        0
    } else {
        (i128::from(r.next()) << 64 | i128::from(r.next())) & ((1i128 << b) - 1)
    };
    if r.chance(50) {
        -mag
    } else {
        mag
    }
}

fn config(r: &mut Rng) -> ServoConfig {
    let gmax = (1i64 << GAIN_BITS) - 1;
    let g = |r: &mut Rng| {
        if r.chance(10) {
            [0, gmax][r.below(2) as usize]
        } else {
            (wide(r, GAIN_BITS) as i64).abs()
        }
    };
    ServoConfig {
        servo_period: [1, 1, 2, 3][r.below(4) as usize],
        kp: g(r),
        ki: g(r),
        kd: g(r),
        kv: g(r),
        ka: g(r),
        integral_limit: g(r),
        output_limit: {
            let any = r.below(32768) as u16;
            [0, 1, 500, 32767, any][r.below(5) as usize]
        },
        following_limit: [0, 1, 1000, i32::MAX as u32][r.below(4) as usize],
        d_filter: [0, 0, 3, 15, r.below(16) as u8][r.below(5) as usize],
    }
}

/// Runs the RTL against the model for `clocks` clocks; with `inject`, the model's duty is off
/// by one from that clock on (the comparison must then fail).
fn run(clocks: usize, inject: Option<usize>) -> Result<(), SimError> {
    let mut r = Rng(0x5e40_0001);
    // The stimulus, clock by clock.
    let mut stim = Vec::with_capacity(clocks);
    let mut cfg = config(&mut r);
    let (mut x, mut v, mut a) = (0i128, 0i128, 0i128);
    let mut count = 0i64;
    let mut enable = true;
    for k in 0..clocks {
        if r.chance(1) {
            cfg = config(&mut r);
        }
        if k % 97 == 0 || r.chance(2) {
            x = wide(&mut r, 111);
            v = wide(&mut r, 103);
            a = wide(&mut r, 103);
            // Mostly near the ref_position; sometimes anywhere.
            let cell = (x >> 80) as i64;
            count = if r.chance(80) {
                cell.wrapping_add(wide(&mut r, 20) as i64)
            } else {
                i64::from(r.next() as u32 as i32)
            };
        }
        if r.chance(1) {
            enable = !enable;
        }
        stim.push(ServoInputs {
            reset: k < 2 || r.below(5000) == 0,
            enable,
            tick: {
                let p = if r.chance(50) { 3 } else { 40 };
                r.chance(p)
            },
            start: r.chance(1),
            x,
            v,
            a,
            count: i64::from(count as i32),
            config: cfg,
        });
    }
    let mut sim = Simulation::new();
    sim.add_clock(5, |s: &mut Box<Servo>| s.clock.next = !s.clock.val());
    sim.add_testbench(move |mut sim: Sim<Servo>| {
        let mut s = sim.init()?;
        let mut m = Model::new();
        let (mut faults, mut duties, mut overruns, mut saturated) = (0, 0, 0, 0);
        for (k, i) in stim.iter().enumerate() {
            let c = &i.config;
            s.reset.next = i.reset;
            s.enable.next = i.enable;
            s.tick.next = i.tick;
            s.start.next = i.start;
            s.ref_position.next = bits(i.x >> 64);
            s.velocity.next = bits(i.v >> 48);
            s.accel.next = bits(i.a >> 40);
            s.count.next = bits(i128::from(i.count));
            s.servo_period.next = bits(i128::from(c.servo_period));
            s.kp.next = bits(i128::from(c.kp));
            s.ki.next = bits(i128::from(c.ki));
            s.kd.next = bits(i128::from(c.kd));
            s.kv.next = bits(i128::from(c.kv));
            s.ka.next = bits(i128::from(c.ka));
            s.integral_limit.next = bits(i128::from(c.integral_limit));
            s.output_limit.next = bits(i128::from(c.output_limit));
            s.following_limit.next = bits(i128::from(c.following_limit));
            s.d_filter.next = bits(i128::from(c.d_filter));
            wait_clock_cycle!(sim, clock, s);
            let mut o = m.clock(i);
            if inject.is_some_and(|at| k >= at) {
                o.duty = o.duty.wrapping_add(1);
            }
            sim_assert_eq!(sim, s.duty.val().to_u64() as u16 as i16, o.duty, s);
            sim_assert_eq!(sim, s.fault.val(), o.fault, s);
            sim_assert_eq!(sim, s.overrun.val(), o.overrun, s);
            sim_assert_eq!(sim, s.peak.val().to_u64() as u32, o.peak, s);
            faults += usize::from(o.fault);
            overruns += usize::from(o.overrun);
            duties += usize::from(o.duty != 0);
            saturated += usize::from(o.duty != 0 && o.duty.unsigned_abs() == c.output_limit);
        }
        // The stimulus reached every path.
        sim_assert!(
            sim,
            clocks < 10_000 || (faults > 10 && overruns > 10 && duties > 1000 && saturated > 100),
            s
        );
        sim.done(s)
    });
    let mut uut = Servo::default();
    uut.connect_all();
    sim.run(Box::new(uut), 10 * (clocks as u64 + 10) * (LATENCY as u64))
}

#[test]
fn servo_rtl_matches_the_model() {
    run(40_000, None).unwrap();
}

/// The comparison can fail: a duty off by one is caught.
#[test]
fn a_duty_off_by_one_is_caught() {
    assert!(run(2_000, Some(500)).is_err());
}
