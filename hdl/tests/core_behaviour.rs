//! The rust-hdl description of the motion core, simulated by rust-hdl's own simulator, against
//! the clock-accurate model: a third, independent check beside Verilator co-simulation (which
//! runs the generated Verilog). rust-hdl's simulator is slow on wide registers, so the run is
//! short: two small programs, a tick divider and a stop.

use rust_hdl::prelude::*;
use snapgen_hdl::core::MotionCore;
use snapgen_model::chain::wrap;
use snapgen_model::{CoreInputs, CoreModel, Program, Segment, DEFAULT_FORMAT};

fn bits<const N: usize>(v: i128) -> Bits<N> {
    let mut b = Bits::<N>::default();
    for i in 0..N {
        if (v >> i) & 1 == 1 {
            b = b.replace_bit(i, true);
        }
    }
    b
}

/// The clock-by-clock stimulus: (inputs, clocks).
fn stimulus() -> Vec<(CoreInputs, usize)> {
    let idle = CoreInputs::default();
    let mut s = vec![(
        CoreInputs {
            reset: true,
            ..idle
        },
        2,
    )];
    let programs = [
        Program {
            segments: vec![
                Segment { ticks: 3, snap: 7 },
                Segment {
                    ticks: 1,
                    snap: -(1i128 << 100),
                },
                Segment { ticks: 2, snap: 0 },
                Segment {
                    ticks: 1,
                    snap: (1i128 << 100) - 21,
                },
            ],
        },
        Program {
            segments: vec![
                Segment { ticks: 5, snap: -3 },
                Segment { ticks: 4, snap: 9 },
            ],
        },
    ];
    for (n, p) in programs.iter().enumerate() {
        let div = n as u32; // the second program ticks every other clock
        let base = CoreInputs {
            tick_div: div,
            ..idle
        };
        for (k, seg) in p.segments.iter().enumerate() {
            s.push((
                CoreInputs {
                    write_enable: true,
                    write_address: k as u8,
                    write_ticks: seg.ticks,
                    write_snap: seg.snap,
                    ..base
                },
                1,
            ));
        }
        s.push((
            CoreInputs {
                count_enable: true,
                count_value: p.segments.len() as u8,
                ..base
            },
            1,
        ));
        s.push((
            CoreInputs {
                start: true,
                ..base
            },
            1,
        ));
        if n == 1 {
            s.push((base, 9));
            s.push((
                CoreInputs {
                    abort_move: true,
                    ..base
                },
                1,
            ));
        }
        s.push((base, 14));
    }
    s
}

#[test]
fn rust_hdl_core_matches_the_model_clock_by_clock() {
    let mut sim = Simulation::new();
    sim.add_clock(5, |x: &mut Box<MotionCore>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<MotionCore>| {
        let f = DEFAULT_FORMAT;
        let mut model = CoreModel::new(&f);
        let mut x = sim.init()?;
        let mut clocks = 0;
        for (i, n) in stimulus() {
            x.reset.next = i.reset;
            x.tick_div.next = u64::from(i.tick_div).into();
            x.start.next = i.start;
            x.abort_move.next = i.abort_move;
            x.write_enable.next = i.write_enable;
            x.write_address.next = u64::from(i.write_address).into();
            x.write_ticks.next = u64::from(i.write_ticks).into();
            x.write_snap.next = bits(i.write_snap);
            x.count_enable.next = i.count_enable;
            x.count_value.next = u64::from(i.count_value).into();
            for _ in 0..n {
                wait_clock_cycle!(sim, clock, x);
                let m = model.clock(&i);
                clocks += 1;
                sim_assert_eq!(sim, wrap(x.x.val().to_u128() as i128, f.widths.x), m.x, x);
                sim_assert_eq!(sim, wrap(x.v.val().to_u128() as i128, f.widths.v), m.v, x);
                sim_assert_eq!(sim, wrap(x.a.val().to_u128() as i128, f.widths.a), m.a, x);
                sim_assert_eq!(sim, wrap(x.j.val().to_u128() as i128, f.widths.j), m.j, x);
                sim_assert_eq!(sim, x.position.val().to_u64() as u32, m.position, x);
                sim_assert_eq!(sim, x.segment.val().to_u64() as u8, m.segment, x);
                sim_assert_eq!(sim, x.busy.val(), m.busy, x);
                sim_assert_eq!(sim, x.done.val(), m.done, x);
                sim_assert_eq!(sim, x.aborted.val(), m.aborted, x);
                sim_assert_eq!(sim, x.tick_count.val().to_u64() as u32, m.tick_count, x);
                sim_assert_eq!(sim, x.tick.val(), m.tick, x);
                sim_assert_eq!(sim, x.active_bank.val(), m.active_bank, x);
                sim_assert_eq!(
                    sim,
                    x.standby_count.val().to_u64() as u8,
                    m.standby_count,
                    x
                );
            }
        }
        // The program ran: the second one was stopped, the first completed and moved.
        sim_assert!(sim, model.outputs().aborted && clocks == 50, x);
        sim.done(x)
    });
    let mut uut = MotionCore::default();
    uut.connect_all();
    sim.run(Box::new(uut), 1_000_000).unwrap();
}
