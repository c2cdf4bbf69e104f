//! Online planning from arbitrary states (`snapgen_model::online`), checked from outside:
//!
//! * the program is stepped here, tick by tick (`x += v; v += a; a += j; j += d`), from the
//!   start registers — nothing the planner computes about its own program is read;
//! * from random states within the limits, to random targets (rest, velocity, blend), the trace
//!   ends exactly on the requested state (v = the requested raw velocity, a = j = 0, the position
//!   in the target cell), and no tick exceeds a limit — acceleration while |v| grows,
//!   deceleration while it shrinks, jerk, velocity;
//! * an override cut (set speed lowered, even from 200 % to 10 %) never undershoots the new
//!   speed and never reverses, and a state left outside lowered limits is brought back within
//!   without reversal;
//! * the duration is within a stated bound of Ruckig's (rsruckig) from the same state.
//!
//! `PROPTEST_CASES` raises the case count.

mod util;

use proptest::prelude::*;
use rsruckig::prelude::*;
use snapgen_model::online::{plan_online, OnlineError, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_model::{ChainState, Format, Program, Quantity};

/// Per-tick facts of a trace stepped here.
struct Stepped {
    end: ChainState,
    ticks: u64,
    /// Largest |j|, and the largest |a| while |v| grows and while it shrinks.
    max_j: i128,
    max_acc: i128,
    max_dec: i128,
    max_v: i128,
    /// Smallest and largest velocity.
    min_v: i128,
    top_v: i128,
}

fn step(start: ChainState, program: &Program) -> Stepped {
    let mut s = start;
    let mut out = Stepped {
        end: s,
        ticks: 0,
        max_j: 0,
        max_acc: 0,
        max_dec: 0,
        max_v: 0,
        min_v: i128::MAX,
        top_v: i128::MIN,
    };
    for seg in &program.segments {
        for _ in 0..seg.ticks {
            s = ChainState {
                x: s.x + s.v,
                v: s.v + s.a,
                a: s.a + s.j,
                j: s.j + seg.snap,
            };
            out.ticks += 1;
            out.max_j = out.max_j.max(s.j.abs());
            // The acceleration just computed is added to this velocity on the next tick: it
            // accelerates when |v| grows from this tick to the next, decelerates when |v|
            // shrinks, and counts as both when v changes sign.
            let next = s.v + s.a;
            let crosses = next.signum() * s.v.signum() < 0;
            if next.abs() > s.v.abs() || crosses {
                out.max_acc = out.max_acc.max(s.a.abs());
            }
            if next.abs() < s.v.abs() || crosses {
                out.max_dec = out.max_dec.max(s.a.abs());
            }
            out.max_v = out.max_v.max(s.v.abs());
            out.min_v = out.min_v.min(s.v);
            out.top_v = out.top_v.max(s.v);
        }
    }
    out.end = s;
    out
}

struct Raw {
    v: i128,
    acc: i128,
    dec: i128,
    j: i128,
}

fn raw(f: &Format, l: &OnlineLimits) -> Raw {
    let r = |x: f64, q| (x * f.scale(q)).floor() as i128;
    Raw {
        v: r(l.velocity, Quantity::Velocity),
        acc: r(l.acceleration, Quantity::Acceleration),
        dec: r(l.deceleration, Quantity::Acceleration),
        j: r(l.jerk, Quantity::Jerk),
    }
}

/// A random state within the limits: |v| ≤ V, |a| within the limit that applies to it, |j| ≤ J,
/// the next acceleration within too, and braking the acceleration at full jerk stays below V.
fn state_within(f: &Format, l: &OnlineLimits, u: [f64; 5], order: OnlineOrder) -> ChainState {
    let r = raw(f, l);
    let v = (u[0] * 2.0 - 1.0) * r.v as f64;
    let a_lim = if order == OnlineOrder::Two {
        0.0
    } else {
        r.acc.min(r.dec) as f64
    };
    let mut a = (u[1] * 2.0 - 1.0) * a_lim * 0.9;
    let j = if order == OnlineOrder::Two {
        0.0
    } else {
        (u[2] * 2.0 - 1.0) * r.j as f64 * 0.1
    };
    // Keep v + a·|a|/(2J) within V.
    if order == OnlineOrder::Three {
        let vi = v + a * a.abs() / (2.0 * r.j as f64);
        if vi.abs() > 0.99 * r.v as f64 {
            a = 0.0;
        }
    }
    let cell = ((u[3] * 2.0 - 1.0) * 1e6) as i128;
    let x = (cell << snapgen_model::FRAC_BITS) + (u[4] * (1u128 << 80) as f64) as i128;
    ChainState {
        x,
        v: v as i128,
        a: a as i128,
        j: j as i128,
    }
}

fn limits_from(u: [f64; 4]) -> OnlineLimits {
    // Decades of sizes: 0.01–1 unit/s, 0.1–10 unit/s², 1–1000 unit/s³.
    let dec = |u: f64, lo: f64, decades: f64| lo * 10f64.powf(u * decades);
    OnlineLimits {
        velocity: dec(u[0], 0.01, 2.0),
        acceleration: dec(u[1], 0.1, 2.0),
        deceleration: dec(u[2], 0.1, 2.0),
        jerk: dec(u[3], 1.0, 3.0),
    }
}

fn unit() -> impl Strategy<Value = f64> {
    0.0..1.0f64
}

fn order() -> impl Strategy<Value = OnlineOrder> {
    prop_oneof![Just(OnlineOrder::Three), Just(OnlineOrder::Two)]
}

/// Asserts the trace respects the limits `r` (and the start's own values, for the first ticks).
fn assert_within(t: &Stepped, r: &Raw, order: OnlineOrder, what: &str) {
    assert!(t.max_v <= r.v, "{what}: velocity {} > {}", t.max_v, r.v);
    if order == OnlineOrder::Three {
        assert!(t.max_j <= r.j, "{what}: jerk {} > {}", t.max_j, r.j);
    }
    assert!(
        t.max_acc <= r.acc,
        "{what}: acceleration {} > {}",
        t.max_acc,
        r.acc
    );
    assert!(
        t.max_dec <= r.dec,
        "{what}: deceleration {} > {}",
        t.max_dec,
        r.dec
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(256)))]

    /// To a position at rest from any state within the limits: exact, within the limits.
    #[test]
    fn to_rest_from_any_state_is_exact_and_within_limits(
        lu in [unit(), unit(), unit(), unit()],
        su in [unit(), unit(), unit(), unit(), unit()],
        dist in -3e5..3e5f64,
        order in order(),
    ) {
        let f = Format::default();
        let l = limits_from(lu);
        let start = state_within(&f, &l, su, order);
        let cell = f.output_lsb(start.x) + dist as i128;
        let target = OnlineTarget::Position { cell, velocity: 0.0 };
        let p = match plan_online(&start, &target, &l, order, &f) {
            Ok(p) => p,
            // A typed refusal, counted by `refusals_are_rare` below; never a wrong program.
            Err(OnlineError::NotRealisable(_)) => return Ok(()),
            Err(e) => panic!("{start:?} → {cell}: {e}"),
        };
        let t = step(start, &p.program);
        prop_assert!(t.end.is_at_rest(), "not at rest: {:?}", t.end);
        prop_assert_eq!(f.output_lsb(t.end.x), cell);
        prop_assert_eq!(t.end, p.final_state);
        assert_within(&t, &raw(&f, &l), order, "to rest");
    }

    /// To a set velocity from any state within the limits: exact, within the limits, and a
    /// change between speeds of one sign neither undershoots nor reverses.
    #[test]
    fn to_velocity_from_any_state_is_exact_and_monotone(
        lu in [unit(), unit(), unit(), unit()],
        su in [unit(), unit(), unit(), unit(), unit()],
        vu in unit(),
        order in order(),
    ) {
        let f = Format::default();
        let l = limits_from(lu);
        let start = state_within(&f, &l, su, order);
        let vs = (vu * 2.0 - 1.0) * l.velocity;
        let p = plan_online(&start, &OnlineTarget::Velocity(vs), &l, order, &f)
            .unwrap_or_else(|e| panic!("{start:?} → {vs} within {l:?}: {e}"));
        let t = step(start, &p.program);
        let v_raw = (vs * f.scale(Quantity::Velocity)).round() as i128;
        prop_assert_eq!((t.end.v, t.end.a, t.end.j), (v_raw, 0, 0));
        assert_within(&t, &raw(&f, &l), order, "to velocity");
        // From a steady speed (a = j = 0) to another of the same sign: between the two always.
        if start.a == 0 && start.j == 0 && start.v.signum() * v_raw.signum() > 0 {
            let (lo, hi) = (start.v.min(v_raw), start.v.max(v_raw));
            prop_assert!(t.min_v >= lo && t.top_v <= hi, "left [{lo}, {hi}]: {} {}", t.min_v, t.top_v);
        }
    }

    /// To a position passed at a velocity (a blend): exact where it is reachable.
    #[test]
    fn to_a_blend_point_is_exact_and_within_limits(
        lu in [unit(), unit(), unit(), unit()],
        su in [unit(), unit(), unit(), unit(), unit()],
        dist in 1e3..3e5f64,
        vu in 0.05..1.0f64,
        order in order(),
    ) {
        let f = Format::default();
        let l = limits_from(lu);
        let start = state_within(&f, &l, su, order);
        let cell = f.output_lsb(start.x) + dist as i128;
        let vb = vu * l.velocity;
        let target = OnlineTarget::Position { cell, velocity: vb };
        match plan_online(&start, &target, &l, order, &f) {
            Ok(p) => {
                let t = step(start, &p.program);
                let v_raw = (vb * f.scale(Quantity::Velocity)).round() as i128;
                prop_assert_eq!((t.end.v, t.end.a, t.end.j), (v_raw, 0, 0));
                prop_assert_eq!(f.output_lsb(t.end.x), cell);
                assert_within(&t, &raw(&f, &l), order, "blend");
            }
            Err(OnlineError::BlendUnreachable | OnlineError::NotRealisable(_)) => {}
            Err(e) => panic!("{start:?} → {cell} at {vb}: {e}"),
        }
    }
}

#[test]
fn override_cut_from_200_to_10_percent_slows_without_undershoot_or_reversal() {
    let f = Format::default();
    // Limits as the seed's demonstration (mm): 4000 mm/s² up, 3000 down, jerk 5000.
    let l = OnlineLimits {
        velocity: 200.0,
        acceleration: 4000.0,
        deceleration: 3000.0,
        jerk: 5000.0,
    };
    let f = Format {
        position_lsb: 1e-3,
        ..f
    };
    let fast = 200.0 * f.scale(Quantity::Velocity);
    for a_frac in [-0.5, 0.0, 0.5] {
        // Cruising at 200 % of 100 mm/s, accelerating or decelerating, when cut to 10 %.
        let start = ChainState {
            x: f.home_raw(),
            v: fast as i128,
            a: (a_frac * 2000.0 * f.scale(Quantity::Acceleration)) as i128,
            j: 0,
        };
        let p = plan_online(
            &start,
            &OnlineTarget::Velocity(10.0),
            &l,
            OnlineOrder::Three,
            &f,
        )
        .expect("plans");
        let t = step(start, &p.program);
        let ten = (10.0 * f.scale(Quantity::Velocity)).round() as i128;
        assert_eq!((t.end.v, t.end.a, t.end.j), (ten, 0, 0));
        assert!(t.min_v >= ten, "undershoot to {} below {ten}", t.min_v);
        let r = raw(&f, &l);
        assert!(t.max_dec <= r.dec, "deceleration {} > {}", t.max_dec, r.dec);
    }
}

#[test]
fn a_state_beyond_lowered_limits_comes_back_without_reversal() {
    let f = Format::default();
    let l = OnlineLimits {
        velocity: 0.1,
        acceleration: 1.0,
        deceleration: 1.0,
        jerk: 10.0,
    };
    // Moving at 0.5 unit/s (5× the new limit) and accelerating at 3 unit/s² (3×).
    let start = ChainState {
        x: f.home_raw(),
        v: (0.5 * f.scale(Quantity::Velocity)) as i128,
        a: (3.0 * f.scale(Quantity::Acceleration)) as i128,
        j: 0,
    };
    let cell = 2_000_000; // 2 units ahead: far enough to stop without passing it
    let p = plan_online(
        &start,
        &OnlineTarget::Position {
            cell,
            velocity: 0.0,
        },
        &l,
        OnlineOrder::Three,
        &f,
    )
    .expect("plans");
    let t = step(start, &p.program);
    assert!(t.end.is_at_rest());
    assert_eq!(f.output_lsb(t.end.x), cell);
    assert!(t.min_v >= 0, "reversed: {}", t.min_v);
    assert!(t.max_j <= raw(&f, &l).j);
}

/// Bounds met on the seeded set (docs/MODEL.md §11): ticks over Ruckig, median and 90th
/// percentile (measured 7.7 and 12.2).
const MEDIAN_ABOVE_RUCKIG: f64 = 10.0;
const P90_ABOVE_RUCKIG: f64 = 20.0;

/// Ruckig's duration (s) from the same state, continuous time, symmetric limits.
fn ruckig_duration(f: &Format, start: &ChainState, cell: i128, l: &OnlineLimits) -> f64 {
    let mut i = InputParameter::new(None);
    let p0 = f.position_physical(start.x);
    let p1 = f.position_physical((cell << snapgen_model::FRAC_BITS) + f.half_lsb_raw());
    i.current_position = daov_stack![p0];
    i.current_velocity = daov_stack![f.to_physical(Quantity::Velocity, start.v)];
    i.current_acceleration = daov_stack![f.to_physical(Quantity::Acceleration, start.a)];
    i.target_position = daov_stack![p1];
    i.max_velocity = daov_stack![l.velocity];
    i.max_acceleration = daov_stack![l.acceleration];
    i.max_jerk = daov_stack![l.jerk];
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, f.ts);
    let mut traj = Trajectory::new(None);
    otg.calculate(&i, &mut traj).expect("Ruckig plans");
    traj.get_duration()
}

/// 2000 seeded states within the limits (symmetric, as Ruckig's), random targets at rest: how
/// many plans are refused, and the duration against Ruckig's.
#[test]
fn durations_against_ruckig_and_refusals() {
    use rand::{Rng, SeedableRng};
    let f = Format::default();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut diffs = Vec::new();
    let mut refused = 0;
    let cases = 2000;
    for _ in 0..cases {
        let mut lu = [0.0; 4];
        lu.iter_mut().for_each(|x| *x = rng.gen());
        let mut l = limits_from(lu);
        l.deceleration = l.acceleration;
        let mut su = [0.0; 5];
        su.iter_mut().for_each(|x| *x = rng.gen());
        let start = state_within(&f, &l, su, OnlineOrder::Three);
        let start = ChainState { j: 0, ..start };
        let cell = f.output_lsb(start.x) + rng.gen_range(-300_000..300_000);
        let target = OnlineTarget::Position {
            cell,
            velocity: 0.0,
        };
        let p = match plan_online(&start, &target, &l, OnlineOrder::Three, &f) {
            Ok(p) => p,
            Err(OnlineError::NotRealisable(_)) => {
                refused += 1;
                continue;
            }
            Err(e) => panic!("{start:?} → {cell} {l:?}: {e}"),
        };
        let ours = p.ticks() as f64;
        let theirs = ruckig_duration(&f, &start, cell, &l) / f.ts;
        diffs.push(ours - theirs);
    }
    diffs.sort_by(|a, b| a.total_cmp(b));
    let n = diffs.len();
    eprintln!(
        "refused {refused} of {cases}; ticks over Ruckig: min {:.2} median {:.2} p90 {:.2} p99 {:.2} max {:.2}",
        diffs[0],
        diffs[n / 2],
        diffs[n * 9 / 10],
        diffs[n * 99 / 100],
        diffs[n - 1]
    );
    assert!(
        refused * 200 <= cases,
        "{refused} of {cases} refused (bound 0.5 %)"
    );
    // Never faster than the continuous optimum by more than the chain's own tick offsets.
    assert!(
        diffs[0] >= -2.0,
        "{:.2} ticks faster than Ruckig",
        -diffs[0]
    );
    // The bound met on most states; the tail (measured p99 24 ticks, worst 5.7 % of the move
    // on a reversal) is a known gap, reported above and in docs/MODEL.md §11.
    assert!(
        diffs[n / 2] <= MEDIAN_ABOVE_RUCKIG,
        "median {:.2} ticks over Ruckig",
        diffs[n / 2]
    );
    assert!(
        diffs[n * 9 / 10] <= P90_ABOVE_RUCKIG,
        "p90 {:.2} ticks over Ruckig",
        diffs[n * 9 / 10]
    );
}

/// Replans from states on the planner's own trajectories (a host's feed override or a new
/// target arrives while a move runs): three moves from rest (seed 002's limits at its three
/// jerks, in mm with the default 1 nm LSB) in both orders; from every ~1/60th of each, the
/// same target again at rest and a blend at half the velocity limit. Every plan made is
/// stepped here: exact end, within the limits on every tick. Refusals are counted (measured:
/// 1 of 720 replans; BlendUnreachable, a blend point already passed, is a right answer and
/// not counted); the bound is 1 %.
#[test]
fn replans_from_states_on_a_trajectory_are_exact_and_rarely_refused() {
    let f = Format::default();
    let (mut refused, mut made, mut asked) = (0, 0, 0);
    for order in [OnlineOrder::Three, OnlineOrder::Two] {
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
            let r = raw(&f, &l);
            let s0 = ChainState::at_rest(f.home_raw());
            let to = |velocity| OnlineTarget::Position { cell, velocity };
            let first = plan_online(&s0, &to(0.0), &l, order, &f)
                .unwrap_or_else(|e| panic!("{order:?} {v} mm/s from rest: {e}"));
            let n = first.ticks();
            for k in 0..60u64 {
                let at = n * k / 60;
                let s = s0.after_ticks(&first.program, at, &f.widths);
                for vb in [0.0, v / 2.0] {
                    asked += 1;
                    let what = format!("{order:?} {v} mm/s, tick {at} of {n}, to {vb} mm/s");
                    let p = match plan_online(&s, &to(vb), &l, order, &f) {
                        Ok(p) => p,
                        Err(OnlineError::BlendUnreachable) if vb != 0.0 => continue,
                        Err(OnlineError::NotRealisable(_)) => {
                            refused += 1;
                            continue;
                        }
                        Err(e) => panic!("{what}: {e}"),
                    };
                    made += 1;
                    let t = step(s, &p.program);
                    let v_raw = (vb * f.scale(Quantity::Velocity)).round() as i128;
                    assert_eq!((t.end.v, t.end.a, t.end.j), (v_raw, 0, 0), "{what}");
                    assert_eq!(f.output_lsb(t.end.x), cell, "{what}");
                    assert_within(&t, &r, order, &what);
                }
            }
        }
    }
    eprintln!("{refused} of {asked} replans refused, {made} made");
    assert!(made > asked / 2, "only {made} of {asked} replans made");
    assert!(
        refused * 100 <= asked,
        "{refused} of {asked} replans refused (bound 1 %)"
    );
}
