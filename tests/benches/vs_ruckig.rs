//! snapgen's planner against Ruckig (the pure-Rust `rsruckig`), in one process, on the same
//! random rest-to-rest 1-DoF moves: time per plan for each, and the ratio.
//!
//! Run with `cargo bench -p snapgen-tests --bench vs_ruckig`. The moves (seeded, so every run
//! plans the same ones): distance log-uniform in [1e-4, 10] units with a random sign, velocity
//! limit in [0.1, 10] units/s, acceleration limit in [1, 100] units/s², jerk limit in
//! [10, 1e4] units/s³, and for order 4 a snap limit in [1e3, 1e6] units/s⁴ (all log-uniform);
//! Ts = 10 µs. Ruckig plans the continuous-time jerk-limited profile of the same move (its
//! `calculate`); snapgen plans it on the integer chain, exact to the output LSB (order 3), and
//! snap-limited (order 4). Each method runs over all the moves `ROUNDS` times, interleaved, and
//! the median round is reported.

use std::hint::black_box;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rsruckig::prelude::*;
use snapgen_model::{ChainState, Format};
use snapgen_plan::{plan, plan_into, Method, MoveRequest};

/// Moves in the set.
const MOVES: usize = 20_000;
/// Timed passes over the set, per method.
const ROUNDS: usize = 15;

struct Move {
    distance: f64,
    vmax: f64,
    amax: f64,
    jmax: f64,
    dmax: f64,
}

fn moves() -> Vec<Move> {
    let mut r = rand::rngs::StdRng::seed_from_u64(0x5EED_0009);
    let mut lu = |lo: f64, hi: f64| (r.gen_range(lo.ln()..hi.ln())).exp();
    (0..MOVES)
        .map(|_| {
            let distance = lu(1e-4, 10.0);
            Move {
                distance,
                vmax: lu(0.1, 10.0),
                amax: lu(1.0, 100.0),
                jmax: lu(10.0, 1e4),
                dmax: lu(1e3, 1e6),
            }
        })
        .enumerate()
        .map(|(i, m)| Move {
            distance: if i % 2 == 1 { -m.distance } else { m.distance },
            ..m
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` runs this once as a smoke test.
    let quick = !std::env::args().any(|a| a == "--bench");
    let rounds = if quick { 1 } else { ROUNDS };
    let set = moves();
    let f = Format::with_ts(1e-5);
    let order3: Vec<MoveRequest> = set
        .iter()
        .map(|m| MoveRequest {
            distance: m.distance,
            method: Method::Order3 {
                vmax: m.vmax,
                amax: m.amax,
                jmax: m.jmax,
            },
        })
        .collect();
    let order4: Vec<MoveRequest> = set
        .iter()
        .map(|m| MoveRequest {
            distance: m.distance,
            method: Method::Order4 {
                vmax: m.vmax,
                amax: m.amax,
                jmax: m.jmax,
                dmax: m.dmax,
            },
        })
        .collect();
    let inputs: Vec<InputParameter<1>> = set
        .iter()
        .map(|m| {
            let mut i = InputParameter::new(None);
            i.current_position = daov_stack![0.0];
            i.target_position = daov_stack![m.distance];
            i.max_velocity = daov_stack![m.vmax];
            i.max_acceleration = daov_stack![m.amax];
            i.max_jerk = daov_stack![m.jmax];
            i
        })
        .collect();
    // Every move of the set must plan, on both sides.
    for (k, r) in order3.iter().chain(&order4).enumerate() {
        if let Err(e) = plan(r, &f) {
            panic!("move {k} ({r:?}) does not plan: {e}");
        }
    }
    // Both fill an output they are given, as a host planning move after move would: Ruckig
    // its trajectory, snapgen its plan (whose program memory is reused).
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 1e-5);
    let mut traj = Trajectory::new(None);
    let mut out = plan(&order3[0], &f).expect("checked above");
    let home = ChainState::at_rest(f.home_raw());
    let (mut t_ruckig, mut t3, mut t4) = (Vec::new(), Vec::new(), Vec::new());
    let per_plan = |start: Instant| start.elapsed().as_secs_f64() * 1e9 / MOVES as f64;
    for _ in 0..rounds {
        let t = Instant::now();
        for i in &inputs {
            otg.calculate(black_box(i), &mut traj)
                .expect("Ruckig plans every move");
            black_box(traj.get_duration());
        }
        t_ruckig.push(per_plan(t));
        let t = Instant::now();
        for r in &order3 {
            plan_into(black_box(r), &f, home, &mut out).expect("checked above");
            black_box(&out);
        }
        t3.push(per_plan(t));
        let t = Instant::now();
        for r in &order4 {
            plan_into(black_box(r), &f, home, &mut out).expect("checked above");
            black_box(&out);
        }
        t4.push(per_plan(t));
    }
    let (r, s3, s4) = (median(t_ruckig), median(t3), median(t4));
    println!("{MOVES} random rest-to-rest moves, median of {rounds} rounds, ns per plan:");
    println!("  rsruckig (order 3, continuous time):        {r:8.1}");
    println!("  snapgen order 3 (integer chain, exact end):  {s3:8.1}");
    println!("  snapgen order 4 (snap-limited, exact end):   {s4:8.1}");
    println!("  ratio snapgen order 3 / rsruckig: {:.3}", s3 / r);
    println!("  ratio snapgen order 4 / rsruckig: {:.3}", s4 / r);
}
