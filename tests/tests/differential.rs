//! Differential tests of the order-4 planner against independent computations written here:
//!
//! 1. a piecewise-exact integration of the continuous snap profile (Taylor steps over the 15
//!    segments of seed 000 eq 63), which must reach the distance with every limit respected and
//!    confirms the re-derived relations `j = s·td`, `a = j·(td+tj)`, `v = a·(2td+tj+ta)`,
//!    `x = v·(4td+2tj+ta+tv)`;
//! 2. a plain `f64` simulation of seed 000 eqs 72–75 in physical units
//!    (`j += Ts·d`, `a += Ts·j`, `v += Ts·a`, `x += Ts·v`), fed the program's snap, which must
//!    follow the integer trace at every tick.

mod util;

use proptest::prelude::*;
use snapgen_model::{Format, Quantity, Trace};
use snapgen_plan::{plan, Method, MoveRequest};

/// Integrates a piecewise-constant snap profile exactly (Taylor polynomials per piece):
/// returns the final (x, v, a, j) and the peaks of |v|, |a|, |j| (checked at piece ends and
/// at interior extrema found by sampling each piece finely).
fn integrate(pieces: &[(f64, f64)]) -> ([f64; 4], [f64; 3]) {
    let (mut x, mut v, mut a, mut j) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut peak = [0.0f64; 3];
    for &(dt, d) in pieces {
        let state = |t: f64| {
            (
                x + v * t + a * t * t / 2.0 + j * t.powi(3) / 6.0 + d * t.powi(4) / 24.0,
                v + a * t + j * t * t / 2.0 + d * t.powi(3) / 6.0,
                a + j * t + d * t * t / 2.0,
                j + d * t,
            )
        };
        for k in 0..=64 {
            let (_, vv, aa, jj) = state(dt * k as f64 / 64.0);
            peak[0] = peak[0].max(vv.abs());
            peak[1] = peak[1].max(aa.abs());
            peak[2] = peak[2].max(jj.abs());
        }
        (x, v, a, j) = state(dt);
    }
    ([x, v, a, j], peak)
}

/// The 15 pieces of seed 000's snap profile (eq 63) for phase times and snap `s`.
fn seed000_pieces(td: f64, tj: f64, ta: f64, tv: f64, s: f64) -> Vec<(f64, f64)> {
    let half = |sign: f64| {
        vec![
            (td, sign * s),
            (tj, 0.0),
            (td, -sign * s),
            (ta, 0.0),
            (td, -sign * s),
            (tj, 0.0),
            (td, sign * s),
        ]
    };
    let mut p = half(1.0);
    p.push((tv, 0.0));
    p.extend(half(-1.0));
    p
}

fn order4() -> impl Strategy<Value = (f64, Method)> {
    let lu = |lo: f64, hi: f64| (lo.ln()..=hi.ln()).prop_map(f64::exp);
    (
        lu(1e-5, 5.0),
        lu(0.05, 5.0),
        lu(0.5, 100.0),
        lu(10.0, 1e4),
        lu(100.0, 1e6),
    )
        .prop_map(|(x, vmax, amax, jmax, dmax)| {
            (
                x,
                Method::Order4 {
                    vmax,
                    amax,
                    jmax,
                    dmax,
                },
            )
        })
}

proptest! {
    // 128 cases unless PROPTEST_CASES says otherwise (each integrates up to 3e5 ticks).
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(128)))]

    /// The planner's phase times and continuous snap, integrated independently, reach the
    /// distance within the limits; the re-derived relations agree with the integration.
    #[test]
    fn continuous_profile_reaches_distance_within_limits((x, m) in order4()) {
        let f = Format::with_ts(1e-4);
        let p = plan(&MoveRequest { distance: x, method: m }, &f).unwrap();
        let Method::Order4 { vmax, amax, jmax, dmax } = m else { unreachable!() };
        // Undo the cruise extension: it belongs to the integer step, not to seed 000.
        let ts = f.ts;
        let td = p.phases.d as f64 * ts;
        let tj = p.phases.j as f64 * ts;
        let ta = p.phases.a as f64 * ts;
        let tv = (p.phases.v - p.cruise_extension) as f64 * ts;
        let s = p.continuous_amplitude;
        prop_assert!(s <= dmax * (1.0 + 1e-9), "snap {s} > {dmax}");
        let ([xe, ve, ae, je], [vp, ap, jp]) = integrate(&seed000_pieces(td, tj, ta, tv, s));
        // The distance covered is the integer target the plan aims at.
        let target = p.target_physical();
        prop_assert!((xe - target).abs() <= 1e-9 * target.abs().max(1e-6), "x {xe} vs {target}");
        prop_assert!(ve.abs() <= 1e-9 * vmax && ae.abs() <= 1e-9 * amax && je.abs() <= 1e-9 * jmax);
        prop_assert!(vp <= vmax * (1.0 + 1e-9), "v {vp} > {vmax}");
        prop_assert!(ap <= amax * (1.0 + 1e-9), "a {ap} > {amax}");
        prop_assert!(jp <= jmax * (1.0 + 1e-9), "j {jp} > {jmax}");
        // The relations, against the integration.
        let jr = s * td;
        let ar = jr * (td + tj);
        let vr = ar * (2.0 * td + tj + ta);
        let xr = vr * (4.0 * td + 2.0 * tj + ta + tv);
        prop_assert!((jr - jp).abs() <= 1e-9 * jp && (ar - ap).abs() <= 1e-6 * ap);
        prop_assert!((vr - vp).abs() <= 1e-6 * vp && (xr - xe).abs() <= 1e-9 * xe);
    }

    /// The integer chain follows eqs 72–75 simulated in physical units at every tick.
    #[test]
    fn integer_trace_follows_the_physical_equations((x, m) in order4()) {
        let f = Format::with_ts(1e-4);
        let p = plan(&MoveRequest { distance: x, method: m }, &f).unwrap();
        prop_assume!(p.ticks_total() <= 300_000);
        let ts = f.ts;
        let (mut xs, mut vs, mut as_, mut js) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let tol = |peak: f64| 1e-9 * peak.max(f64::MIN_POSITIVE);
        let peaks = [
            p.peak_physical(Quantity::Velocity),
            p.peak_physical(Quantity::Acceleration),
            p.peak_physical(Quantity::Jerk),
        ];
        let x0 = f.position_physical(p.start.x);
        let mut prev_d = 0.0;
        for t in Trace::new(&p.program, p.start, f.widths) {
            if t.tick > 0 {
                // eqs 72–75: every register from the previous tick's values.
                xs += ts * vs;
                vs += ts * as_;
                as_ += ts * js;
                js += ts * prev_d;
            }
            prev_d = f.to_physical(Quantity::Snap, snap_after(&p.program, t.tick));
            let s = t.state;
            prop_assert!((f.position_physical(s.x) - x0 - xs).abs() <= 1e-9 * x.abs() + 1e-12);
            prop_assert!((f.to_physical(Quantity::Velocity, s.v) - vs).abs() <= tol(peaks[0]));
            prop_assert!((f.to_physical(Quantity::Acceleration, s.a) - as_).abs() <= tol(peaks[1]));
            prop_assert!((f.to_physical(Quantity::Jerk, s.j) - js).abs() <= tol(peaks[2]));
        }
    }
}

/// The snap the program plays on tick `tick` (0 past its end).
fn snap_after(p: &snapgen_model::Program, tick: u64) -> i128 {
    let mut t = 0u64;
    for s in &p.segments {
        t += u64::from(s.ticks);
        if tick < t {
            return s.snap;
        }
    }
    0
}
