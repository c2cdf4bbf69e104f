//! Benchmarks of the model, each measuring what its name says:
//!
//! * `plan/*`: time per plan for each method (target for order 4: ≤ 1 µs median);
//! * `model_per_tick/*`: ticks per second when every tick's state is computed and handed to a
//!   consumer (`ChainState::play`, what a per-tick trace does);
//! * `model_closed_form/long_move` and `verify/long_move`: the time to evaluate a 1.2e9-tick
//!   move's end state in closed form (the model), and to check it independently, end state and
//!   every tick's extremes (snapgen-verify). These cost per segment, not per tick, so they are
//!   reported as time per move, not as ticks per second.
//!
//! Run with `cargo bench -p snapgen-plan --bench plan`. Criterion prints the median time per
//! iteration and, for `model_per_tick`, elements (ticks) per second. (`cargo bench -p snapgen-tests --bench vs_ruckig`
//! compares the planner with Ruckig.)

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use snapgen_model::{ChainState, DEFAULT_FORMAT};
use snapgen_plan::{plan, Method, MoveRequest};

fn requests() -> Vec<(&'static str, MoveRequest)> {
    vec![
        (
            "order4",
            MoveRequest {
                distance: 0.5,
                method: Method::Order4 {
                    vmax: 1.0,
                    amax: 5.0,
                    jmax: 50.0,
                    dmax: 1000.0,
                },
            },
        ),
        (
            "order3",
            MoveRequest {
                distance: 0.5,
                method: Method::Order3 {
                    vmax: 1.0,
                    amax: 5.0,
                    jmax: 50.0,
                },
            },
        ),
        (
            "order2",
            MoveRequest {
                distance: 0.5,
                method: Method::Order2 {
                    vmax: 1.0,
                    amax: 5.0,
                },
            },
        ),
        (
            "duration_seed001",
            MoveRequest {
                distance: 12.0 * std::f64::consts::PI,
                method: Method::Duration {
                    duration: 1.8,
                    gamma: 0.4,
                    phi: 0.25,
                },
            },
        ),
    ]
}

fn bench_plan(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan");
    for (name, r) in requests() {
        g.bench_function(name, |b| {
            b.iter(|| plan(black_box(&r), black_box(&DEFAULT_FORMAT)).unwrap())
        });
    }
    g.finish();
}

fn bench_throughput(c: &mut Criterion) {
    // A long move: 1200 units at 0.1 units/s, 1.2e9 ticks (3.3 h at 10 µs).
    let long = plan(
        &MoveRequest {
            distance: 1200.0,
            method: Method::Order4 {
                vmax: 0.1,
                amax: 1.0,
                jmax: 10.0,
                dmax: 100.0,
            },
        },
        &DEFAULT_FORMAT,
    )
    .unwrap();
    let w = DEFAULT_FORMAT.widths;
    let mut g = c.benchmark_group("model_closed_form");
    g.bench_function("long_move", |b| {
        b.iter(|| black_box(long.start).run_program(black_box(&long.program), &w))
    });
    g.finish();
    let mut g = c.benchmark_group("verify");
    g.bench_function("long_move", |b| {
        b.iter(|| {
            let s = long.start;
            snapgen_verify::integrate(
                snapgen_verify::State::new(s.x, s.v, s.a, s.j),
                black_box(&long.program)
                    .segments
                    .iter()
                    .map(|g| (u64::from(g.ticks), g.snap)),
            )
        })
    });
    g.finish();

    // Every tick of a move computed and seen by a consumer.
    let short = plan(&requests()[0].1, &DEFAULT_FORMAT).unwrap();
    let mut g = c.benchmark_group("model_per_tick");
    g.throughput(Throughput::Elements(short.ticks_total()));
    g.bench_function("order4_move", |b| {
        b.iter(|| {
            let mut s: ChainState = short.start;
            let mut seen = 0i128;
            for seg in &black_box(&short.program).segments {
                s = s.play(seg.snap, u64::from(seg.ticks), &w, |t| seen ^= t.x);
            }
            (s, seen)
        })
    });
    g.finish();
}

criterion_group!(benches, bench_plan, bench_throughput);
criterion_main!(benches);
