//! The timed program swap of the motion core's model (`CoreModel`, SWAP_AT), checked from
//! outside with random programs, tick dividers and arming times:
//!
//! * a swap armed for a tick the time base has reached, or less than three ticks ahead of it,
//!   or 2^31 + 3 or more ahead (the window a 32-bit compare can tell from the past), changes
//!   nothing: every output of the core equals, clock by clock, that of a core never armed;
//! * a swap armed in time continues from the registers at its tick: the chain is the old
//!   program's first `T − t0` ticks followed by the whole new program, stepped here.
//!
//! The fabric is held to the same model clock by clock by the co-simulation (`snapgen cosim`,
//! `sim/tests/cosim.rs`), late swaps among its events.

mod util;

use proptest::prelude::*;
use snapgen_model::{ChainState, CoreInputs, CoreModel, Program, Segment, DEFAULT_FORMAT};

fn program() -> impl Strategy<Value = Program> {
    prop::collection::vec((1u32..400, -50i128..50), 1..6).prop_map(|s| Program {
        segments: s
            .into_iter()
            .map(|(ticks, snap)| Segment { ticks, snap })
            .collect(),
    })
}

fn core(tick_div: u32) -> CoreModel {
    let mut m = CoreModel::new(&DEFAULT_FORMAT);
    m.clock(&CoreInputs {
        reset: true,
        tick_div,
        ..Default::default()
    });
    m
}

/// Writes `p` into the standby bank, one clock a segment and one for the count.
fn load(m: &mut CoreModel, p: &Program, tick_div: u32) {
    for (k, s) in p.segments.iter().enumerate() {
        m.clock(&CoreInputs {
            tick_div,
            write_enable: true,
            write_address: k as u8,
            write_ticks: s.ticks,
            write_snap: s.snap,
            ..Default::default()
        });
    }
    m.clock(&CoreInputs {
        tick_div,
        count_enable: true,
        count_value: p.segments.len() as u8,
        ..Default::default()
    });
}

/// A core playing `old` for `run` clocks with `new` in its standby bank.
fn playing(old: &Program, new: &Program, tick_div: u32, run: u32) -> CoreModel {
    let mut m = core(tick_div);
    load(&mut m, old, tick_div);
    m.clock(&CoreInputs {
        tick_div,
        start: true,
        ..Default::default()
    });
    for _ in 0..run {
        m.clock(&CoreInputs {
            tick_div,
            ..Default::default()
        });
    }
    load(&mut m, new, tick_div);
    m
}

/// Late offsets `T − ticks` (before the arming edge): the past, up to two ahead, or too far;
/// the window's edges often.
fn late() -> impl Strategy<Value = i64> {
    prop_oneof![
        -4i64..=2,
        Just(2i64),
        Just((1i64 << 31) + 3),
        -(1i64 << 31)..=2,
        ((1i64 << 31) + 3)..(1i64 << 32),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(256)))]

    #[test]
    fn a_late_swap_changes_nothing(
        old in program(),
        new in program(),
        tick_div in 0u32..4,
        run in 0u32..400,
        d in late(),
    ) {
        let mut armed = playing(&old, &new, tick_div, run);
        let mut idle = armed.clone();
        let idle_in = CoreInputs {
            tick_div,
            ..Default::default()
        };
        let at = armed.outputs().ticks.wrapping_add(d as u64);
        armed.clock(&CoreInputs {
            swap: true,
            swap_last: at.wrapping_sub(1) as u32,
            ..idle_in
        });
        idle.clock(&idle_in);
        prop_assert_eq!(armed.outputs(), idle.outputs());
        // Until both have played the old program out, and a while after.
        let mut left = 64u32;
        while left > 0 {
            armed.clock(&idle_in);
            idle.clock(&idle_in);
            prop_assert_eq!(armed.outputs(), idle.outputs());
            if !armed.busy() {
                left -= 1;
            }
        }
        prop_assert_eq!(armed.outputs().standby_count, new.segments.len() as u8);
    }

    #[test]
    fn a_timely_swap_continues_from_the_registers_at_its_tick(
        old in program(),
        new in program(),
        tick_div in 0u32..4,
        run in 0u32..400,
        frac in prop_oneof![Just(0.0), 0.0..1.0f64],
    ) {
        let f = DEFAULT_FORMAT;
        let idle_in = CoreInputs {
            tick_div,
            ..Default::default()
        };
        let mut m = core(tick_div);
        load(&mut m, &old, tick_div);
        m.clock(&CoreInputs {
            start: true,
            ..idle_in
        });
        // The time base when the old program started: its tick k is the chain after k ticks.
        let t0 = m.outputs().ticks;
        for _ in 0..run {
            m.clock(&idle_in);
        }
        load(&mut m, &new, tick_div);
        // T somewhere in what is left of the old program, three or more ticks ahead (often
        // exactly three: the window's edge).
        let now = m.outputs().ticks;
        let left = (t0 + old.total_ticks()).saturating_sub(now);
        prop_assume!(left > 3);
        let at = now + 3 + (frac * (left - 3) as f64) as u64;
        m.clock(&CoreInputs {
            swap: true,
            swap_last: (at - 1) as u32,
            ..idle_in
        });
        prop_assert!(m.outputs().swap_pending);
        while m.outputs().ticks < at {
            m.clock(&idle_in);
        }
        // The registers at T: the old program's first T − t0 ticks, stepped here.
        let at_t = step(
            ChainState::at_rest(f.home_raw()),
            &old,
            at - t0,
        );
        prop_assert_eq!(m.chain(), at_t);
        let mut clocks = 0u64;
        while m.busy() {
            m.clock(&idle_in);
            clocks += 1;
        }
        prop_assert_eq!(clocks, new.total_ticks() * u64::from(tick_div + 1));
        prop_assert_eq!(m.chain(), step(at_t, &new, u64::MAX));
    }
}

/// The chain after the first `ticks` ticks of `p` from `s`, one tick at a time.
fn step(s: ChainState, p: &Program, ticks: u64) -> ChainState {
    let w = DEFAULT_FORMAT.widths;
    let mut s = s;
    let mut left = ticks;
    for seg in &p.segments {
        for _ in 0..seg.ticks {
            if left == 0 {
                return s;
            }
            s = s.step(seg.snap, &w);
            left -= 1;
        }
    }
    s
}
