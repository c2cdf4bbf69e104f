//! One online replan (`snapgen_plan::online::plan_online`) against Ruckig (`rsruckig`) from
//! the same moving states, in one process: criterion's timing of both over the whole set, then
//! the time of every single plan (its median over the states, the mean and the 90th
//! percentile) for each, and the ratios.
//!
//! Run with `cargo bench -p snapgen-tests --bench online_vs_ruckig`. The states (seeded):
//! velocity uniform in ±v_max, acceleration uniform in ±0.9·a_max (zeroed when braking it at
//! full jerk would pass v_max), jerk register zero; limits log-uniform (v 0.1–10 units/s,
//! a 1–100 units/s², j 10–1e4 units/s³, acceleration = deceleration, as Ruckig has one limit);
//! targets at rest 1e-4–1 units away, either side. Ts = 10 µs. snapgen plans the exact integer
//! program (verified landing and limits included); Ruckig plans the continuous profile. Plans
//! snapgen refuses (a typed error, see docs/MODEL.md §11) are timed like the others and
//! counted.
//!
//! The per-plan times: each state is planned [`REPS`] times in a row and the block timed, so
//! the clock's own cost is spread over the repetitions; the two planners alternate state by
//! state, so both see the same machine.

use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use rand::{Rng, SeedableRng};
use rsruckig::prelude::*;
use snapgen_model::{ChainState, Format, Quantity, FRAC_BITS};
use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};

const STATES: usize = 5_000;
/// Plans of one state timed as one block.
const REPS: usize = 16;

struct Case {
    start: ChainState,
    target: OnlineTarget,
    limits: OnlineLimits,
    ruckig: InputParameter<1>,
}

fn cases(f: &Format) -> Vec<Case> {
    let mut r = rand::rngs::StdRng::seed_from_u64(0x5EED_0010);
    let mut cases = Vec::with_capacity(STATES);
    for i in 0..STATES {
        let mut lu = |lo: f64, hi: f64| (r.gen_range(lo.ln()..hi.ln())).exp();
        let (vmax, amax, jmax) = (lu(0.1, 10.0), lu(1.0, 100.0), lu(10.0, 1e4));
        let dist = lu(1e-4, 1.0) * if i % 2 == 1 { -1.0 } else { 1.0 };
        let v = r.gen_range(-1.0..1.0) * vmax;
        let mut a = r.gen_range(-0.9..0.9) * amax;
        if (v + a * a.abs() / (2.0 * jmax)).abs() > 0.99 * vmax {
            a = 0.0;
        }
        let start = ChainState {
            x: f.home_raw(),
            v: (v * f.scale(Quantity::Velocity)) as i128,
            a: (a * f.scale(Quantity::Acceleration)) as i128,
            j: 0,
        };
        let cell = (dist / f.position_lsb).round() as i128;
        let limits = OnlineLimits {
            velocity: vmax,
            acceleration: amax,
            deceleration: amax,
            jerk: jmax,
        };
        let mut inp = InputParameter::new(None);
        inp.current_position = daov_stack![0.0];
        inp.current_velocity = daov_stack![f.to_physical(Quantity::Velocity, start.v)];
        inp.current_acceleration = daov_stack![f.to_physical(Quantity::Acceleration, start.a)];
        inp.target_position =
            daov_stack![f.position_physical((cell << FRAC_BITS) + f.half_lsb_raw())];
        inp.max_velocity = daov_stack![vmax];
        inp.max_acceleration = daov_stack![amax];
        inp.max_jerk = daov_stack![jmax];
        let target = OnlineTarget::Position {
            cell,
            velocity: 0.0,
        };
        cases.push(Case {
            start,
            target,
            limits,
            ruckig: inp,
        });
    }
    cases
}

fn snapgen(c: &Case, f: &Format) -> bool {
    black_box(plan_online(
        black_box(&c.start),
        &c.target,
        &c.limits,
        OnlineOrder::Three,
        f,
    ))
    .is_ok()
}

fn ruckig(c: &Case, otg: &mut Ruckig<1, ThrowErrorHandler>, traj: &mut Trajectory<1>) {
    otg.calculate(black_box(&c.ruckig), traj)
        .expect("Ruckig plans");
    black_box(traj.get_duration());
}

struct Stats {
    median: f64,
    mean: f64,
    p90: f64,
}

fn stats(mut ns: Vec<f64>) -> Stats {
    ns.sort_by(f64::total_cmp);
    Stats {
        median: ns[ns.len() / 2],
        mean: ns.iter().sum::<f64>() / ns.len() as f64,
        p90: ns[ns.len() * 9 / 10],
    }
}

fn main() {
    let f = Format::with_ts(1e-5);
    let set = cases(&f);
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 1e-5);
    let mut traj = Trajectory::new(None);

    let mut c = Criterion::default().configure_from_args().sample_size(20);
    {
        let mut g = c.benchmark_group(format!("online_replan_{STATES}_states"));
        g.bench_function("rsruckig", |b| {
            b.iter(|| {
                for case in &set {
                    ruckig(case, &mut otg, &mut traj);
                }
            })
        });
        g.bench_function("snapgen", |b| {
            b.iter(|| {
                for case in &set {
                    snapgen(case, &f);
                }
            })
        });
        g.finish();
    }
    c.final_summary();

    // Every plan on its own.
    let (mut t_r, mut t_s) = (Vec::with_capacity(STATES), Vec::with_capacity(STATES));
    let mut refused = 0;
    for case in &set {
        let t = Instant::now();
        for _ in 0..REPS {
            ruckig(case, &mut otg, &mut traj);
        }
        t_r.push(t.elapsed().as_secs_f64() * 1e9 / REPS as f64);
        let t = Instant::now();
        let mut ok = true;
        for _ in 0..REPS {
            ok = snapgen(case, &f);
        }
        t_s.push(t.elapsed().as_secs_f64() * 1e9 / REPS as f64);
        refused += usize::from(!ok);
    }
    let (r, s) = (stats(t_r), stats(t_s));
    println!("{STATES} random moving states to rest, ns per plan (each state planned {REPS} times in a row):");
    println!("                                                  median     mean      p90");
    println!(
        "  rsruckig (continuous time):                    {:8.1} {:8.1} {:8.1}",
        r.median, r.mean, r.p90
    );
    println!(
        "  snapgen online (exact integer program, checked): {:6.1} {:8.1} {:8.1}",
        s.median, s.mean, s.p90
    );
    println!(
        "  ratio snapgen / rsruckig: median {:.2}, mean {:.2}",
        s.median / r.median,
        s.mean / r.mean
    );
    println!("  refused by snapgen: {refused} of {STATES}");
}
