//! Seed 001's experiment (sections 3–4), as moves and the paper's figures: Table 1's move
//! (12π rad in 1.8 s) as the S-curve of Table 1, as a trapezoid at 32 rad/s and as an order-4
//! profile of the same duration, and Table 3's S-curve out and back (the return starting at
//! 4 s). Each profile is a run of its own, from rest at 0.

use std::f64::consts::PI;

use serde::Serialize;
use snapgen_model::{ChainState, Format};
use snapgen_plan::{plan_from, Method, MoveRequest, Plan, PlanError};

use crate::metrics::MoveSpan;

/// Table 1's displacement (rad).
pub const DISTANCE: f64 = 12.0 * PI;
/// Table 1's duration (s).
pub const DURATION: f64 = 1.8;
/// Table 1's γ and φ.
pub const GAMMA: f64 = 0.4;
/// φ.
pub const PHI: f64 = 0.25;
/// Section 4.1: the trapezoid's velocity (rad/s).
pub const TRAPEZOID_VELOCITY: f64 = 32.0;
/// Table 3: when the return move starts (s after the first).
pub const RETURN_AT: f64 = 4.0;
/// The settling band the paper reports (rad, Figure 15).
pub const SETTLE_BAND: f64 = 0.009;

/// What the paper reports for a profile (`None`: not reported).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PaperFigures {
    /// Error at T (rad).
    pub error_at_t_rad: Option<f64>,
    /// Peak velocity (rad/s).
    pub peak_velocity: Option<f64>,
    /// Peak control signal (V).
    pub peak_effort: Option<f64>,
    /// Time from T to within the band (s).
    pub settle_s: Option<f64>,
}

/// One profile: its moves (start time and plan) and the span whose figures are reported.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Name in the JSON and the table: `scurve`, `trapezoid`, `order4`, `return`.
    pub name: &'static str,
    /// What it is.
    pub description: String,
    /// The moves, each started at its time (s from the run's start).
    pub moves: Vec<(f64, Plan)>,
    /// The reported move.
    pub span: MoveSpan,
    /// The paper's figures.
    pub paper: PaperFigures,
}

/// The four profiles in `format` (its output LSB is one encoder count, in rad), each move
/// started at `t0` and watched for `window` s after its end.
pub fn profiles(format: &Format, t0: f64, window: f64) -> Result<Vec<Profile>, PlanError> {
    let rest = ChainState::at_rest(format.home_raw());
    let plan =
        |method, distance, start| plan_from(&MoveRequest { distance, method }, format, start);
    let duration = Method::Duration {
        duration: DURATION,
        gamma: GAMMA,
        phi: PHI,
    };
    let secs = |p: &Plan| p.ticks_total() as f64 * format.ts;
    let span = |p: &Plan, start: f64| MoveSpan {
        start,
        end: start + secs(p),
        window_end: start + secs(p) + window,
    };
    let scurve = plan(duration, DISTANCE, rest)?;
    // The trapezoid at 32 rad/s that takes 1.8 s: D = v·T − v²/a.
    let amax = TRAPEZOID_VELOCITY.powi(2) / (TRAPEZOID_VELOCITY * DURATION - DISTANCE);
    let trapezoid = plan(
        Method::Order2 {
            vmax: TRAPEZOID_VELOCITY,
            amax,
        },
        DISTANCE,
        rest,
    )?;
    let order4 = order4_same_duration(format, rest)?;
    let back = plan(duration, -DISTANCE, scurve.final_state)?;
    let v = scurve.duration_values.map_or(0.0, |d| d.velocity);
    Ok(vec![
        Profile {
            name: "scurve",
            description: format!(
                "Table 1's S-curve: 12π rad in 1.8 s, γ 0.4, φ 0.25 (ω {v:.4} rad/s)"
            ),
            span: span(&scurve, t0),
            moves: vec![(t0, scurve.clone())],
            paper: PaperFigures {
                error_at_t_rad: Some(0.04),
                peak_velocity: None,
                peak_effort: Some(1.5),
                settle_s: Some(0.47),
            },
        },
        Profile {
            name: "trapezoid",
            description: format!(
                "section 4.1's trapezoid: 32 rad/s, {amax:.3} rad/s², 12π rad in 1.8 s"
            ),
            span: span(&trapezoid, t0),
            moves: vec![(t0, trapezoid)],
            paper: PaperFigures {
                error_at_t_rad: Some(0.18),
                peak_velocity: Some(34.3),
                peak_effort: Some(1.39),
                settle_s: None,
            },
        },
        Profile {
            name: "order4",
            description: "seed 000's order 4 (snap-limited), the same duration".to_string(),
            span: span(&order4, t0),
            moves: vec![(t0, order4)],
            paper: PaperFigures::default(),
        },
        Profile {
            name: "return",
            description: "Table 3: the S-curve out, then back to 0 from 4 s".to_string(),
            span: span(&back, t0 + RETURN_AT),
            moves: vec![(t0, scurve), (t0 + RETURN_AT, back)],
            paper: PaperFigures {
                error_at_t_rad: Some(0.049),
                peak_velocity: None,
                peak_effort: None,
                // The paper gives the time to zero error (e = 0 at t = 6.5 s, T = 5.8 s): an
                // upper bound of the time to within the band.
                settle_s: Some(0.7),
            },
        },
    ])
}

/// The order-4 move of Table 1's distance that lasts as long as its S-curve: the S-curve's
/// velocity, acceleration and jerk, and a snap that reaches the jerk in a quarter of the
/// S-curve's jerk phase, all scaled by the one factor that makes it last 1.8 s (to the tick,
/// or the closest below it).
pub fn order4_same_duration(format: &Format, rest: ChainState) -> Result<Plan, PlanError> {
    let target = (DURATION / format.ts).round() as u64;
    let v = DISTANCE / ((1.0 - GAMMA) * DURATION);
    let a = DISTANCE / (GAMMA * (1.0 - GAMMA) * (1.0 - PHI) * DURATION * DURATION);
    let t_jerk = PHI * GAMMA * DURATION;
    let j = a / t_jerk;
    let d = j / (t_jerk / 4.0);
    let plan = |k: f64| {
        plan_from(
            &MoveRequest {
                distance: DISTANCE,
                method: Method::Order4 {
                    vmax: k * v,
                    amax: k * a,
                    jmax: k * j,
                    dmax: k * d,
                },
            },
            format,
            rest,
        )
    };
    // Longer with smaller limits: bisect the factor between one too slow and one fast enough.
    let (mut lo, mut hi) = (1.0, 4.0);
    let mut best = plan(hi)?;
    if best.ticks_total() > target {
        return Ok(best);
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let p = plan(mid)?;
        if p.ticks_total() > target {
            lo = mid;
        } else {
            hi = mid;
            best = p;
        }
        if best.ticks_total() == target {
            break;
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_model::DEFAULT_FORMAT;

    fn format() -> Format {
        Format {
            position_lsb: 2.0 * PI / 8000.0,
            ..DEFAULT_FORMAT
        }
    }

    #[test]
    fn the_profiles_are_the_papers_moves() {
        let f = format();
        let ps = profiles(&f, 0.1, 1.0).unwrap();
        let names: Vec<&str> = ps.iter().map(|p| p.name).collect();
        assert_eq!(names, ["scurve", "trapezoid", "order4", "return"]);
        for p in &ps[..3] {
            let (_, plan) = &p.moves[0];
            // 12π rad, to the count, in 1.8 s (within a few ticks: each phase is whole ticks).
            let target = (DISTANCE / f.position_lsb).round() as i128;
            assert_eq!(plan.target_lsb, target, "{}", p.name);
            let ticks = plan.ticks_total() as f64 * f.ts;
            assert!(
                (ticks - DURATION).abs() <= 5.0 * f.ts,
                "{}: {ticks}",
                p.name
            );
        }
        // Table 1's values.
        let d = ps[0].moves[0].1.duration_values.unwrap();
        assert!((d.velocity - 34.9065).abs() < 1e-3 && (d.acceleration - 64.6418).abs() < 1e-3);
        assert!((d.jerk - 359.1212).abs() < 1e-3);
        // The return ends where the first move began.
        let back = &ps[3].moves[1].1;
        assert_eq!(back.final_state, ChainState::at_rest(f.home_raw()));
    }
}
