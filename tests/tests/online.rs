//! Online planning from arbitrary states (`snapgen_plan::online`), checked from outside:
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
//! * the duration is within a stated bound of Ruckig's (rsruckig) from the same state;
//! * a target at rest or a velocity is never refused (the planner falls back on braking to
//!   rest and moving on, docs/MODEL.md §11), and how often it falls back is bounded.
//!
//! `PROPTEST_CASES` raises the case count.

mod util;

use proptest::prelude::*;
use rsruckig::prelude::*;
use snapgen_model::{ChainState, Format, Program, Quantity};
use snapgen_plan::online::position::Branch;
use snapgen_plan::online::{
    plan_online, OnlineError, OnlineLimits, OnlineOrder, OnlinePlan, OnlineTarget,
};

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
        let p = plan_online(&start, &target, &l, order, &f)
            .unwrap_or_else(|e| panic!("{start:?} → {cell} within {l:?}: {e}"));
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(256)))]

    /// An override cut: the set speed lowered to 5–95 % of the speed the axis moves at, from a
    /// state within the old limits or beyond the new ones (up to twice the speed limit and
    /// three times the acceleration). Where braking the start's acceleration at full jerk does
    /// not itself take the speed below the new set speed (seed 002 eq 32), the speed never
    /// drops below it and never reverses; the end is exact.
    #[test]
    fn an_override_cut_never_undershoots_or_reverses(
        lu in [unit(), unit(), unit(), unit()],
        vu in 0.2..2.0f64,
        au in -1.0..3.0f64,
        cut in 0.05..0.95f64,
        order in order(),
    ) {
        let f = Format::default();
        let l = limits_from(lu);
        let r = raw(&f, &l);
        let v0 = vu * r.v as f64;
        let a0 = if order == OnlineOrder::Three {
            au * r.acc.min(r.dec) as f64
        } else {
            0.0
        };
        let start = ChainState {
            x: f.home_raw(),
            v: v0 as i128,
            a: a0 as i128,
            j: 0,
        };
        let vs = cut * v0.min(r.v as f64) / f.scale(Quantity::Velocity);
        let vs_raw = (vs * f.scale(Quantity::Velocity)).round() as i128;
        let vi = if order == OnlineOrder::Three {
            v0 + a0 * a0.abs() / (2.0 * r.j as f64)
        } else {
            v0
        };
        prop_assume!(vi > vs_raw as f64 * (1.0 + 1e-3));
        let p = plan_online(&start, &OnlineTarget::Velocity(vs), &l, order, &f)
            .unwrap_or_else(|e| panic!("{start:?} → {vs} within {l:?}: {e}"));
        let t = step(start, &p.program);
        prop_assert_eq!((t.end.v, t.end.a, t.end.j), (vs_raw, 0, 0));
        prop_assert!(t.min_v >= vs_raw, "undershoot to {} below {vs_raw}", t.min_v);
    }

    /// The duration from a random state within the limits (symmetric, as Ruckig's) to a random
    /// target at rest, against Ruckig's from the same state: within the bound docs/MODEL.md
    /// §11 states (at most 2 ticks shorter, and no longer than `RUCKIG_ABOVE_TICKS` ticks or
    /// `RUCKIG_ABOVE_SHARE` of Ruckig's duration, whichever is more). A plan that fell back on
    /// braking to rest (about 1 in 20 000 states; counted and bounded by the seeded tests
    /// below) is exact but slower, and is left out here.
    #[test]
    fn the_duration_is_within_the_stated_bound_of_ruckigs(
        lu in [unit(), unit(), unit(), unit()],
        su in [unit(), unit(), unit(), unit(), unit()],
        dist in -3e5..3e5f64,
    ) {
        let f = Format::default();
        let mut l = limits_from(lu);
        l.deceleration = l.acceleration;
        let start = ChainState {
            j: 0,
            ..state_within(&f, &l, su, OnlineOrder::Three)
        };
        let cell = f.output_lsb(start.x) + dist as i128;
        let target = OnlineTarget::Position { cell, velocity: 0.0 };
        let p = plan_online(&start, &target, &l, OnlineOrder::Three, &f)
            .unwrap_or_else(|e| panic!("{start:?} → {cell} within {l:?}: {e}"));
        prop_assume!(!stopped(&p));
        let theirs = ruckig_duration(&f, &start, cell, &l) / f.ts;
        let over = p.ticks() as f64 - theirs;
        prop_assert!(over >= -2.0, "{over:.1} ticks shorter than Ruckig's {theirs:.0}");
        prop_assert!(
            over <= ruckig_bound(&f, &start, cell, &l, theirs),
            "{over:.1} ticks over Ruckig's {theirs:.0}"
        );
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

/// The bound met against Ruckig (docs/MODEL.md §11): on the seeded set, the median, 90th and
/// 99th percentile of the ticks over Ruckig's duration (measured 7.4, 10.8, 14.7); on every
/// plan, no more than `RUCKIG_ABOVE_TICKS` ticks or `RUCKIG_ABOVE_SHARE` of Ruckig's duration
/// over it, whichever is more (measured: at most 49 ticks on the seeded set; over 20 000
/// random states at most 0.33 %: moves that brake through zero and come back, whose continuous
/// profile is itself up to 0.26 % longer than Ruckig's), or `NEAR_STOP_SHARE` of it for a target within `NEAR_STOP_TICKS` ticks
/// of travel of where braking at once stops the axis: there the integer chain, whose brake
/// cannot be shortened by a fraction of a tick, may have to reverse by a hair (or brake and
/// move on) where the continuous profile just stops.
const MEDIAN_ABOVE_RUCKIG: f64 = 9.0;
const P90_ABOVE_RUCKIG: f64 = 13.0;
const P99_ABOVE_RUCKIG: f64 = 20.0;
const RUCKIG_ABOVE_TICKS: f64 = 64.0;
const RUCKIG_ABOVE_SHARE: f64 = 0.004;
const NEAR_STOP_TICKS: f64 = 8.0;
const NEAR_STOP_SHARE: f64 = 0.02;

/// The most a plan may take over Ruckig's `theirs` ticks (the bound above).
fn ruckig_bound(f: &Format, start: &ChainState, cell: i128, l: &OnlineLimits, theirs: f64) -> f64 {
    let share = if near_stop(f, start, cell, l) {
        NEAR_STOP_SHARE
    } else {
        RUCKIG_ABOVE_SHARE
    };
    RUCKIG_ABOVE_TICKS.max(share * theirs)
}

/// Whether the target cell lies within `NEAR_STOP_TICKS` ticks of travel of where braking at
/// once stops the axis (Ruckig's brake to zero velocity, symmetric limits).
fn near_stop(f: &Format, start: &ChainState, cell: i128, l: &OnlineLimits) -> bool {
    let mut i = InputParameter::new(None);
    i.control_interface = ControlInterface::Velocity;
    i.current_position = daov_stack![f.position_physical(start.x)];
    i.current_velocity = daov_stack![f.to_physical(Quantity::Velocity, start.v)];
    i.current_acceleration = daov_stack![f.to_physical(Quantity::Acceleration, start.a)];
    i.target_velocity = daov_stack![0.0];
    i.max_velocity = daov_stack![l.velocity];
    i.max_acceleration = daov_stack![l.acceleration];
    i.max_jerk = daov_stack![l.jerk];
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, f.ts);
    let mut traj = Trajectory::new(None);
    otg.calculate(&i, &mut traj).expect("Ruckig brakes");
    let mut stop = daov_stack![0.0];
    traj.at_time(
        traj.get_duration(),
        &mut Some(&mut stop),
        &mut None,
        &mut None,
        &mut None,
        &mut None,
    );
    let target = f.position_physical((cell << snapgen_model::FRAC_BITS) + f.half_lsb_raw());
    let travel = f.to_physical(Quantity::Velocity, start.v).abs() * f.ts;
    (target - stop[0]).abs() <= NEAR_STOP_TICKS * travel
}

/// Whether a plan fell back on braking to rest and moving on.
fn stopped(p: &OnlinePlan) -> bool {
    p.cases.branch == Some(Branch::Stop)
}

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

/// 2000 seeded states within the limits (symmetric, as Ruckig's), random targets at rest: none
/// refused, how many fell back on braking to rest, and the duration against Ruckig's.
#[test]
fn durations_against_ruckig_and_refusals() {
    use rand::{Rng, SeedableRng};
    let f = Format::default();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut diffs = Vec::new();
    let mut stops = 0;
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
        let p = plan_online(&start, &target, &l, OnlineOrder::Three, &f)
            .unwrap_or_else(|e| panic!("{start:?} → {cell} {l:?}: {e}"));
        stops += usize::from(stopped(&p));
        let ours = p.ticks() as f64;
        let theirs = ruckig_duration(&f, &start, cell, &l) / f.ts;
        diffs.push((ours - theirs, ruckig_bound(&f, &start, cell, &l, theirs)));
    }
    diffs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = diffs.len();
    let d = |q: usize| diffs[q].0;
    eprintln!(
        "{stops} of {cases} braked to rest first; ticks over Ruckig: min {:.2} median {:.2} p90 {:.2} p99 {:.2} max {:.2}",
        d(0),
        d(n / 2),
        d(n * 9 / 10),
        d(n * 99 / 100),
        d(n - 1)
    );
    // Never faster than the continuous optimum by more than the chain's own tick offsets.
    assert!(d(0) >= -2.0, "{:.2} ticks faster than Ruckig", -d(0));
    assert!(d(n / 2) <= MEDIAN_ABOVE_RUCKIG, "median {:.2}", d(n / 2));
    assert!(
        d(n * 9 / 10) <= P90_ABOVE_RUCKIG,
        "p90 {:.2}",
        d(n * 9 / 10)
    );
    assert!(
        d(n * 99 / 100) <= P99_ABOVE_RUCKIG,
        "p99 {:.2}",
        d(n * 99 / 100)
    );
    for &(over, bound) in &diffs {
        assert!(
            over <= bound,
            "{over:.1} ticks over Ruckig's (bound {bound:.0})"
        );
    }
    assert!(
        stops * 200 <= cases,
        "{stops} of {cases} braked to rest first"
    );
}

/// Replans from states on the planner's own trajectories (a host's feed override or a new
/// target arrives while a move runs): three moves from rest (seed 002's limits at its three
/// jerks, in mm with the default 1 nm LSB) in both orders; from every ~1/60th of each, the
/// same target again at rest and a blend at half the velocity limit. Every plan made is
/// stepped here: exact end, within the limits on every tick. None is refused at rest (a blend
/// point already passed, BlendUnreachable, is a right answer; a blend may be refused, counted);
/// the plans that brake to rest first are counted (measured: 9 of 720, from states in the
/// final brake of a jerk-limited move whose rounding asks one tick more than the brake
/// playing, 2 of them since a program that dips back past the target is refused), bound 2 %.
#[test]
fn replans_from_states_on_a_trajectory_are_exact_and_rarely_refused() {
    let f = Format::default();
    let (mut refused, mut made, mut asked, mut stops) = (0, 0, 0, 0);
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
                        Err(OnlineError::NotRealisable(_)) if vb != 0.0 => {
                            refused += 1;
                            continue;
                        }
                        Err(e) => panic!("{what}: {e}"),
                    };
                    made += 1;
                    stops += usize::from(stopped(&p));
                    let t = step(s, &p.program);
                    let v_raw = (vb * f.scale(Quantity::Velocity)).round() as i128;
                    assert_eq!((t.end.v, t.end.a, t.end.j), (v_raw, 0, 0), "{what}");
                    assert_eq!(f.output_lsb(t.end.x), cell, "{what}");
                    assert_within(&t, &r, order, &what);
                }
            }
        }
    }
    eprintln!("{refused} of {asked} replans refused, {made} made, {stops} braked to rest first");
    assert!(made > asked / 2, "only {made} of {asked} replans made");
    assert!(
        refused * 100 <= asked,
        "{refused} of {asked} blends refused (bound 1 %)"
    );
    assert!(
        stops * 50 <= asked,
        "{stops} of {asked} replans braked to rest first (bound 2 %)"
    );
}

/// Starts that no program keeps within the new limits, met by the co-simulation's random
/// PLCopen streams (docs/MODEL.md §11): braking so hard that releasing at full jerk still takes
/// the speed through zero with more acceleration than the other side allows; first ticks (whose
/// accelerations are already decided) that carry the speed over the new limit or through zero.
/// Each is planned — to rest, or to a velocity — exact at its end, and its acceleration never
/// goes beyond the start's own.
#[test]
fn starts_with_an_inevitable_excursion_are_planned() {
    let cases = [
        // Braking at 29 unit/s² at 0.028 unit/s; new acceleration limit 9 (deceleration 814).
        (
            ChainState {
                x: 6737740593234717703369152772654,
                v: 334037700051419921847535,
                a: -3540152143380918593975,
                j: 0,
            },
            OnlineTarget::Position {
                cell: 5583005,
                velocity: 0.0,
            },
            OnlineLimits {
                velocity: 0.12618630054041355,
                acceleration: 9.0748898038313,
                deceleration: 813.8742230686198,
                jerk: 10400.996115740869,
            },
            OnlineOrder::Three,
            1e-5,
        ),
        // Order 2 at 2.065 unit/s, accelerating at 543: its next two ticks pass 2.152.
        (
            ChainState {
                x: 6472228522161360925439987724544,
                v: -249662554321957146204212998,
                a: -6570067218998872268531921,
                j: 0,
            },
            OnlineTarget::Position {
                cell: -2456327,
                velocity: 0.0,
            },
            OnlineLimits {
                velocity: 2.1522365032711046,
                acceleration: 548.7803496185712,
                deceleration: 16.566693369109416,
                jerk: 209.63342933247472,
            },
            OnlineOrder::Two,
            1e-4,
        ),
        // Ts = 1 ms: the release's ticks carry 0.878 unit/s past 1.006.
        (
            ChainState {
                x: 3346902322843052601990844062051,
                v: 1061156996831051948530779713,
                a: 20759048843058982190821944,
                j: 0,
            },
            OnlineTarget::Position {
                cell: 12218715,
                velocity: 0.0,
            },
            OnlineLimits {
                velocity: 1.0061616020296997,
                acceleration: 17.43378174133318,
                deceleration: 102.3857380012521,
                jerk: 1396.9936805553034,
            },
            OnlineOrder::Three,
            1e-3,
        ),
        // Beyond the new speed and deceleration limits, to a velocity the other way.
        (
            ChainState {
                x: 11366669957371524144351211515447,
                v: -5250414661653931555280091,
                a: 335233263008642468662,
                j: 0,
            },
            OnlineTarget::Velocity(-0.07978065881536284),
            OnlineLimits {
                velocity: 0.07978065881536284,
                acceleration: 1.1726256559005777,
                deceleration: 2.1174272334465476,
                jerk: 1575.9500465582591,
            },
            OnlineOrder::Three,
            1e-5,
        ),
    ];
    for (start, target, l, order, ts) in cases {
        let f = Format::with_ts(ts);
        let what = format!("{start:?} → {target:?} within {l:?}");
        let p =
            plan_online(&start, &target, &l, order, &f).unwrap_or_else(|e| panic!("{what}: {e}"));
        let t = step(start, &p.program);
        match target {
            OnlineTarget::Position { cell, .. } => {
                assert!(t.end.is_at_rest(), "{what}");
                assert_eq!(f.output_lsb(t.end.x), cell, "{what}");
            }
            OnlineTarget::Velocity(v) => {
                let raw = (v * f.scale(Quantity::Velocity)).round() as i128;
                assert_eq!((t.end.v, t.end.a, t.end.j), (raw, 0, 0), "{what}");
            }
        }
        let r = raw(&f, &l);
        let own = start.a.abs().max((start.a + start.j).abs());
        assert!(
            t.max_acc.max(t.max_dec) <= own.max(r.acc.max(r.dec)),
            "{what}: acceleration beyond the start's own"
        );
    }
}
