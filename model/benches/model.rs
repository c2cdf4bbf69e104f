//! Benchmarks of the model: time per plan for each method (target for order 4: ≤ 1 µs median)
//! and model throughput in ticks per second on long moves (target ≥ 1 G ticks/s, closed-form
//! segment stepping), plus the per-tick trace that co-simulation uses, for comparison.
//!
//! Run with `cargo bench -p snapgen-model`. Criterion prints the median time per iteration and,
//! for the throughput groups, elements (ticks) per second.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use snapgen_model::{plan, ChainState, Method, MoveRequest, DEFAULT_FORMAT};

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
    g.throughput(Throughput::Elements(long.ticks_total()));
    g.bench_function("long_move_ticks", |b| {
        b.iter(|| black_box(long.start).run_program(black_box(&long.program), &w))
    });
    g.finish();

    // The per-tick chain (what co-simulation compares against), on a shorter move.
    let short = plan(&requests()[0].1, &DEFAULT_FORMAT).unwrap();
    let mut g = c.benchmark_group("model_per_tick");
    g.throughput(Throughput::Elements(short.ticks_total()));
    g.bench_function("order4_move_ticks", |b| {
        b.iter(|| {
            let mut s: ChainState = short.start;
            for seg in &black_box(&short.program).segments {
                for _ in 0..seg.ticks {
                    s = s.step(seg.snap, &w);
                }
            }
            s
        })
    });
    g.finish();
}

criterion_group!(benches, bench_plan, bench_throughput);
criterion_main!(benches);
