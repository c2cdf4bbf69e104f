//! One online replan (`snapgen_model::online::plan_online`) against Ruckig (`rsruckig`) from
//! the same moving states, in one process: time per plan for each, and the ratio.
//!
//! Run with `cargo bench -p snapgen-tests --bench online_vs_ruckig`. The states (seeded):
//! velocity uniform in ±v_max, acceleration uniform in ±0.9·a_max (zeroed when braking it at
//! full jerk would pass v_max), jerk register zero; limits log-uniform (v 0.1–10 units/s,
//! a 1–100 units/s², j 10–1e4 units/s³, acceleration = deceleration, as Ruckig has one limit);
//! targets at rest 1e-4–1 units away, either side. Ts = 10 µs. snapgen plans the exact integer
//! program (verified landing and limits included); Ruckig plans the continuous profile. Plans
//! snapgen refuses (a typed error, see docs/MODEL.md §11) are timed like the others and
//! counted. The median of `ROUNDS` interleaved rounds is reported.

use std::hint::black_box;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rsruckig::prelude::*;
use snapgen_model::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_model::{ChainState, Format, Quantity, FRAC_BITS};

const STATES: usize = 5_000;
const ROUNDS: usize = 15;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let quick = !std::env::args().any(|a| a == "--bench");
    let rounds = if quick { 1 } else { ROUNDS };
    let f = Format::with_ts(1e-5);
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
        cases.push((start, target, limits, inp));
    }
    let refused = cases
        .iter()
        .filter(|(s, t, l, _)| plan_online(s, t, l, OnlineOrder::Three, &f).is_err())
        .count();
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 1e-5);
    let mut traj = Trajectory::new(None);
    let (mut t_r, mut t_s) = (Vec::new(), Vec::new());
    let per = |t: Instant| t.elapsed().as_secs_f64() * 1e9 / STATES as f64;
    for _ in 0..rounds {
        let t = Instant::now();
        for (_, _, _, i) in &cases {
            otg.calculate(black_box(i), &mut traj)
                .expect("Ruckig plans");
            black_box(traj.get_duration());
        }
        t_r.push(per(t));
        let t = Instant::now();
        for (s, tg, l, _) in &cases {
            let _ = black_box(plan_online(black_box(s), tg, l, OnlineOrder::Three, &f));
        }
        t_s.push(per(t));
    }
    let (r, s) = (median(t_r), median(t_s));
    println!("{STATES} random moving states to rest, median of {rounds} rounds, ns per plan:");
    println!("  rsruckig (continuous time):                    {r:8.1}");
    println!("  snapgen online (exact integer program, checked): {s:8.1}");
    println!("  ratio snapgen / rsruckig: {:.3}", s / r);
    println!("  refused by snapgen: {refused} of {STATES}");
}
