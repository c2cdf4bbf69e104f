//! How often the online planner refuses to replan from states on its own trajectories: plans
//! three moves from rest, then, from every ~1/200th of each, replans to the same target at rest
//! and to a blend at half the velocity. Prints the refusals, the blend points already passed
//! (`BlendUnreachable`: a right answer, not a refusal) and how much longer than the continuous
//! profile the plans made are (median, 90th percentile, largest). `SWEEP_VERBOSE=1` prints each
//! refused state. docs/ONLINE.md quotes its output.
//!
//! `cargo run --release -p snapgen-model --example replan_sweep`

use snapgen_model::{ChainState, DEFAULT_FORMAT};
use snapgen_plan::online::{plan_online, OnlineError, OnlineLimits, OnlineOrder, OnlineTarget};

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
            let (mut refused, mut unreachable, mut n) = (0, 0, 0);
            let mut over = Vec::new();
            let step = (p.ticks() / 200).max(1) as usize;
            for t in (0..p.ticks()).step_by(step) {
                let s = s0.after_ticks(&p.program, t, &f.widths);
                n += 1;
                match plan_online(&s, &rest(vb), &l, OnlineOrder::Three, &f) {
                    Ok(q) => over.push(q.ticks() as f64 - q.continuous_ticks),
                    Err(OnlineError::BlendUnreachable) => unreachable += 1,
                    Err(e) => {
                        refused += 1;
                        if std::env::var_os("SWEEP_VERBOSE").is_some() {
                            eprintln!("refused at tick {t}: {e} from {s:?}");
                        }
                    }
                }
            }
            over.sort_by(f64::total_cmp);
            let q = |f: f64| over.get(((over.len() as f64 - 1.0) * f) as usize).copied();
            let q = |f| q(f).map_or("-".to_string(), |x| format!("{x:.0}"));
            println!(
                "{v} mm/s, {a}/{d} mm/s², jerk {j} mm/s³, {} mm, to {}: of {n} states {refused} refused ({:.1} %), {unreachable} blend points already passed; plans made last longer than the continuous profile by {} ticks median, {} p90, {} at most",
                cell as f64 * 1e-6,
                if vb == 0.0 { "rest".to_string() } else { format!("a blend at {vb} mm/s") },
                100.0 * refused as f64 / n as f64,
                q(0.5),
                q(0.9),
                q(1.0),
            );
        }
    }
}
