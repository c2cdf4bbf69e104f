//! Closed-loop simulation speed, in simulated seconds per wall second: seed 001's S-curve
//! (12π rad in 1.8 s) and its return, over and over (the next starts on the first iteration
//! after the last has ended, so the axis moves nine tenths of the time), on the default motor
//! at the experiment's design (10 MHz, Ts = 10 µs, PWM 20 kHz, a 10 kHz loop, 1 µs plant
//! steps), 0.2 s per iteration, on
//!
//! * `fast`: the event-driven model-only loop (`snapgen_plant::fast`);
//! * `model`: the device model clock by clock with the plant (`ClosedLoop`, no fabric);
//! * `fabric`: the Verilated I/O top driving the plant, the device model in lockstep compared
//!   on every clock (what `snapgen experiment seed001` runs).
//!
//! Run with `cargo bench -p snapgen-sim --bench closed_loop` (the fabric needs Verilator).
//! Criterion reports the throughput in elements per second with one element per simulated
//! microsecond: "1 Melem/s" is one simulated second per wall second (real time).

use std::f64::consts::PI;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::{ChainState, Format, DEFAULT_FORMAT};
use snapgen_plan::{plan_from, Method, MoveRequest, Plan};
use snapgen_plant::fast::{FabricTiming, FastLoop};
use snapgen_plant::gains::{derive, LoopDesign, LoopTiming};
use snapgen_plant::PlantParams;
use snapgen_sim::closed_loop::{AxisSetup, ClosedLoop};

/// Simulated time per iteration (s).
const SPAN: f64 = 0.2;

fn setup() -> (Design, Format, AxisSetup, [Plan; 2]) {
    let t = Timing {
        clock_hz: 10_000_000,
        baud: 115_200,
        ts: 1e-5,
    };
    let design =
        snapgen_hdl::verilog::io_design(&Design::from_timing(&DEFAULT_FORMAT, &t).unwrap());
    let p = PlantParams::default_plant().physical();
    let f = Format {
        ts: design.ts(),
        position_lsb: p.rad_per_count(),
        ..DEFAULT_FORMAT
    };
    let g = derive(
        &p,
        &LoopDesign::default(),
        &LoopTiming {
            ts: f.ts,
            servo_period: 10,
            pwm_period: 500,
        },
    )
    .unwrap();
    let stop = AxisSetup::stop_limits(&f).unwrap();
    let scurve = |distance, from| {
        plan_from(
            &MoveRequest {
                distance,
                method: Method::Duration {
                    duration: 1.8,
                    gamma: 0.4,
                    phi: 0.25,
                },
            },
            &f,
            from,
        )
        .unwrap()
    };
    let out = scurve(12.0 * PI, ChainState::at_rest(f.home_raw()));
    let back = scurve(-12.0 * PI, out.final_state);
    (
        design,
        f,
        AxisSetup {
            pwm_period: 500,
            servo: g.config,
            stop,
        },
        [out, back],
    )
}

fn bench(c: &mut Criterion) {
    let (design, f, axis, moves) = setup();
    let seconds = |p: &Plan| p.ticks_total() as f64 * f.ts;
    let p = PlantParams::default_plant().physical();
    let mut g = c.benchmark_group("closed_loop");
    g.sample_size(10);
    g.throughput(Throughput::Elements((SPAN * 1e6) as u64));
    g.bench_function("fast", |b| {
        let timing = FabricTiming {
            clock_hz: f64::from(design.clock_hz),
            clocks_per_tick: u64::from(design.dividers.tick_div) + 1,
            pwm_period: 500,
        };
        let mut l = FastLoop::new(&p, &f, timing, axis.servo, 1e-6).unwrap();
        let mut next = 0;
        b.iter(|| {
            if !l.playing() {
                l.play(&moves[next].program);
                next ^= 1;
            }
            let t = l.time() + SPAN;
            l.run_until(t, |_| {});
        })
    });
    for fabric in [false, true] {
        let name = if fabric { "fabric" } else { "model" };
        g.bench_function(name, |b| {
            let mut l = ClosedLoop::new(&design, &p, 1e-6, fabric, 1000).unwrap();
            l.run(1000);
            l.setup(&axis).unwrap();
            let (mut next, mut ends) = (0, 0.0);
            b.iter(|| {
                if l.time() >= ends {
                    l.start(&moves[next].program).unwrap();
                    ends = l.time() + seconds(&moves[next]);
                    next ^= 1;
                }
                let t = l.time() + SPAN;
                l.run_until(t);
                l.take_samples();
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
