//! How often the online planner refuses to replan from states on its own trajectories: plans
//! three moves from rest, then, from every ~1/200th of each, replans to the same target at rest
//! and to a blend at half the velocity. Prints the refusals and the longest rounding (ticks
//! over the continuous profile) of the plans made. docs/ONLINE.md quotes its output.
//!
//! `cargo run --release -p snapgen-model --example replan_sweep`

use snapgen_model::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_model::{ChainState, DEFAULT_FORMAT};

fn main() {
    let f = DEFAULT_FORMAT;
    // (velocity, acceleration, deceleration, jerk, target cell): mm, s with a 1 nm LSB.
    for (v, a, d, j, cell) in [
        (200.0, 4000.0, 3000.0, 500_000.0, 30_000_000i128),
        (100.0, 4000.0, 3000.0, 50_000.0, 20_000_000),
        (50.0, 1000.0, 800.0, 5_000.0, 5_000_000),
    ] {
        let l = OnlineLimits {
            velocity: v,
            acceleration: a,
            deceleration: d,
            jerk: j,
        };
        let s0 = ChainState::at_rest(f.home_raw());
        let rest = |velocity| OnlineTarget::Position { cell, velocity };
        let Ok(p) = plan_online(&s0, &rest(0.0), &l, OnlineOrder::Three, &f) else {
            println!("{v} mm/s, jerk {j}: the move from rest was refused");
            continue;
        };
        for vb in [0.0, v / 2.0] {
            let (mut refused, mut n, mut worst) = (0, 0, 0.0f64);
            let step = (p.ticks() / 200).max(1) as usize;
            for t in (0..p.ticks()).step_by(step) {
                let s = s0.after_ticks(&p.program, t, &f.widths);
                n += 1;
                match plan_online(&s, &rest(vb), &l, OnlineOrder::Three, &f) {
                    Ok(q) => worst = worst.max(q.ticks() as f64 - q.continuous_ticks),
                    Err(_) => refused += 1,
                }
            }
            println!(
                "{v} mm/s, {a}/{d} mm/s², jerk {j} mm/s³, {} mm, to {}: {refused} of {n} states refused ({:.0} %); plans made round up by {worst:.0} ticks at most",
                cell as f64 * 1e-6,
                if vb == 0.0 { "rest".to_string() } else { format!("a blend at {vb} mm/s") },
                100.0 * refused as f64 / n as f64
            );
        }
    }
}
