//! The fabric's controlled stop (`snapgen_model::stop`), played on the chain from random states:
//!
//! * from any tick of a move planned within the stop's limits (a state the move itself brings
//!   to rest within those limits, so it is stoppable — known without asking the stop law): the
//!   stop ends exactly at rest (v = a = j = 0), never exceeds the limits on any tick and never
//!   reverses direction, and the law agrees that the state was within its limits;
//! * from arbitrary states: it always ends exactly at rest, in bounded time, within the bound
//!   it keeps from any state (docs/MODEL.md §9: `|a| ≤ max(A, |Λ₀|)`, `|j| ≤ J` but on the
//!   release tick, no reversal the registers had not decided); whenever the law says the state
//!   was within its limits, the trace confirms it (no tick over a limit, no reversal);
//! * from any tick of an online plan that reverses, within the stop's limits (a stop there
//!   may need a jerk above `J` not to reverse): the acceleration never leaves `A` and the jerk
//!   stays within `2A`. The law once landed such states in two ticks at up to 755·A.
//!
//! The chain is stepped here (`x += v; v += a; a += j; j += d`), independently of the model's.
//! `PROPTEST_CASES` raises the case count.

mod util;

use proptest::prelude::*;
use snapgen_model::stop::{StopLaw, StopLimits};
use snapgen_model::{ChainState, Format, Quantity};
use snapgen_plan::{plan, Method, MoveRequest};

/// Plays the law on a chain stepped here, from `s` (the registers after a tick), for at most
/// `max` ticks; returns every tick's registers and the law.
fn stop_from(s: ChainState, limits: StopLimits, max: u64) -> (Vec<ChainState>, StopLaw) {
    let mut law = StopLaw::begin(s.v, s.a, s.j, limits);
    let mut s = s;
    let mut out = Vec::new();
    for _ in 0..max {
        let Some(next_j) = law.next_jerk(s.v, s.a, s.j) else {
            break;
        };
        let d = next_j - s.j;
        s = ChainState {
            x: s.x + s.v,
            v: s.v + s.a,
            a: s.a + s.j,
            j: s.j + d,
        };
        out.push(s);
    }
    (out, law)
}

/// Asserts the three promises on a trace that started with velocity sign `dir`.
fn assert_promises(trace: &[ChainState], start: ChainState, limits: StopLimits) {
    let end = trace.last().copied().unwrap_or(start);
    assert!(end.is_at_rest(), "not at rest: {end:?}");
    // The first registers after the stop begins were decided before it (v + a, a + j).
    let dir = if start.v + start.a != 0 {
        (start.v + start.a).signum()
    } else {
        (start.a + start.j).signum()
    };
    for (k, s) in trace.iter().enumerate() {
        assert!(s.v * dir >= 0, "reversed at tick {k}: {s:?}");
        if k >= 1 {
            assert!(
                s.j.abs() <= limits.jerk,
                "jerk over the limit at tick {k}: {s:?}"
            );
        }
        if k >= 2 {
            assert!(
                s.a.abs() <= limits.accel,
                "accel over the limit at tick {k}: {s:?}"
            );
        }
    }
}

/// The bound a stop keeps from any state (docs/MODEL.md §9): exactly at rest at the end;
/// `|a| ≤ max(A, |Λ₀|)` on every tick; `|j| ≤ J` on every tick but the release's (`|Λ₀|`) and
/// the landing of a reversal the registers had already decided (below `2|Λ₀|`); no reversal
/// but that one.
fn assert_bound(trace: &[ChainState], start: ChainState, limits: StopLimits) {
    let end = trace.last().copied().unwrap_or(start);
    assert!(end.is_at_rest(), "not at rest: {end:?}");
    let (vv, lambda) = (start.v + start.a, start.a + start.j);
    let dir = if vv != 0 {
        vv.signum()
    } else {
        lambda.signum().max(1)
    };
    let decided = (vv + lambda) * dir < 0;
    let amax = limits.accel.max(lambda.abs());
    let jmax = limits.jerk.max(lambda.abs() * if decided { 2 } else { 1 });
    for (k, s) in trace.iter().enumerate() {
        assert!(
            s.a.abs() <= amax,
            "|a| over max(A, |Λ₀|) at tick {k}: {s:?} from {start:?}"
        );
        assert!(
            s.j.abs() <= jmax,
            "|j| over the bound at tick {k}: {s:?} from {start:?}"
        );
        assert!(
            decided || s.v * dir >= 0,
            "reversed at tick {k}: {s:?} from {start:?}"
        );
    }
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..=hi.ln()).prop_map(f64::exp)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(256)))]

    /// From any tick of an order-3 move planned within the stop's limits.
    #[test]
    fn a_stop_from_any_tick_of_a_move_keeps_its_promises(
        x in log_uniform(1e-4, 2.0), neg in any::<bool>(),
        vmax in log_uniform(0.05, 2.0), amax in log_uniform(1.0, 50.0), jmax in log_uniform(10.0, 5e3),
        at in 0.0f64..1.0, harder in 1.0f64..3.0,
    ) {
        let f = Format::with_ts(1e-4);
        let m = Method::Order3 { vmax, amax, jmax };
        let p = match plan(&MoveRequest { distance: if neg { -x } else { x }, method: m }, &f) {
            Ok(p) => p,
            Err(e) => return Err(TestCaseError::reject(e.to_string())),
        };
        prop_assume!(p.ticks_total() > 2);
        // The stop's limits: at least the move's (raw), up to `harder` times.
        let raw = |q: Quantity, v: f64| util::raw_limit(&f, q, v).as_i128();
        let limits = StopLimits {
            jerk: (raw(Quantity::Jerk, jmax) as f64 * harder) as i128,
            accel: (raw(Quantity::Acceleration, amax) as f64 * harder) as i128,
        };
        prop_assume!(limits.valid());
        // The registers after tick k of the move.
        let k = 1 + (at * (p.ticks_total() - 1) as f64) as u64;
        let mut s = p.start;
        let mut left = k;
        for seg in &p.program.segments {
            let n = left.min(u64::from(seg.ticks));
            for _ in 0..n {
                s = ChainState { x: s.x + s.v, v: s.v + s.a, a: s.a + s.j, j: s.j + seg.snap };
            }
            left -= n;
            if left == 0 {
                break;
            }
        }
        let (trace, law) = stop_from(s, limits, 100_000_000);
        prop_assert!(!law.over_limits(), "a state of a move within the limits was judged over them: {s:?}");
        assert_promises(&trace, s, limits);
    }

    /// From arbitrary states — up to four times over the limits, velocities up to 20 000 ticks
    /// of full deceleration: always at rest; within the limits whenever the law says so.
    #[test]
    fn a_stop_from_any_state_ends_at_rest(
        jerk in 1i128..(1 << 40), ramp in 1i128..2_000,
        v in -20_000.0f64..20_000.0, a in -4.0f64..4.0, j in -4.0f64..4.0,
    ) {
        let limits = StopLimits { jerk, accel: jerk * ramp };
        let s = ChainState {
            x: 0,
            v: (v * limits.accel as f64) as i128,
            a: (a * limits.accel as f64) as i128,
            j: (j * jerk as f64) as i128,
        };
        let (trace, law) = stop_from(s, limits, 10_000_000);
        let (a, j) = (s.a, s.j);
        let end = trace.last().copied().unwrap_or(s);
        prop_assert!(end.is_at_rest(), "not at rest after {} ticks: {:?}", trace.len(), end);
        assert_bound(&trace, s, limits);
        let within = a.abs() <= limits.accel && j.abs() <= limits.jerk;
        if within && !law.over_limits() {
            assert_promises(&trace, s, limits);
        }
    }
}

/// Ruckig's time-optimal stop (velocity control to v = a = 0) from `(v, a)` with the limits, in
/// ticks (continuous time): the oracle for how long a stop should take.
fn ruckig_stop_ticks(v: f64, a: f64, limits: StopLimits) -> f64 {
    use rsruckig::prelude::*;
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 1.0);
    // In units where both limits are 1 (Ruckig's tolerances want moderate numbers): time in
    // ramps of tau = A/J ticks, distance in A·tau².
    let (am, jm) = (limits.accel as f64, limits.jerk as f64);
    let tau = am / jm;
    let mut input = InputParameter::new(None);
    input.control_interface = ControlInterface::Velocity;
    input.current_velocity = daov_stack![v / (am * tau)];
    input.current_acceleration = daov_stack![a / am];
    input.target_velocity = daov_stack![0.0];
    input.target_acceleration = daov_stack![0.0];
    input.max_velocity = daov_stack![1e12];
    input.max_acceleration = daov_stack![1.0];
    input.max_jerk = daov_stack![1.0];
    let mut traj = Trajectory::new(None);
    otg.calculate(&input, &mut traj).expect("Ruckig stops it");
    traj.get_duration() * tau
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(util::proptest_cases(256)))]

    /// Time optimality: from a cruise or mid-acceleration within the limits, the stop takes at
    /// most 5 ticks more than Ruckig's continuous-time optimum from the same state (the first
    /// tick is decided before the stop, the chain's levels are whole ticks, and the landing is
    /// on a grid of jerk steps), and never less than it.
    #[test]
    fn a_stop_is_as_short_as_ruckigs_within_five_ticks(
        v in 0.0f64..3e4, a in -1.0f64..1.0, jerk in 1i128..(1 << 40), ramp in 1i128..5_000,
    ) {
        let limits = StopLimits { jerk, accel: jerk * ramp };
        let s = ChainState { x: 0, v: (v * limits.accel as f64) as i128, a: (a * limits.accel as f64) as i128, j: 0 };
        let (trace, law) = stop_from(s, limits, 1 << 40);
        prop_assume!(!law.over_limits());
        let optimum = ruckig_stop_ticks((s.v + s.a) as f64, (s.a + s.j) as f64, limits);
        let ours = trace.len() as f64;
        // Measured over 5000 cases: 0.7 to 4.3 ticks more, median 2.5.
        prop_assert!(ours <= optimum + 5.0, "{} ticks, Ruckig {:.2}", ours, optimum);
        prop_assert!(ours >= optimum - 1.0, "{} ticks beat Ruckig's {:.2}", ours, optimum);
    }
}

/// The law is not vacuous: a state that is decelerating hard at a tiny velocity cannot be
/// stopped within the limits without reversing, and the law says so (then lands it anyway).
#[test]
fn an_unstoppable_state_is_reported_and_still_lands() {
    let limits = StopLimits {
        jerk: 10,
        accel: 1000,
    };
    // Next velocity 100, next acceleration −900: a release at 10 per tick takes off far more.
    let s = ChainState {
        x: 0,
        v: 1000,
        a: -900,
        j: 0,
    };
    let (trace, law) = stop_from(s, limits, 1000);
    assert!(law.over_limits());
    assert!(trace.last().unwrap().is_at_rest());
}

/// From any tick of an online plan that reverses (a move, then a target behind it planned
/// from a tick of it), with stop limits at exactly the two programs' own peaks: some states
/// brake toward the reversal harder than a release at J can undo (the law reports them), and
/// from every state the stop keeps `|a| ≤ A` and `|j| ≤ 2A` (`≤ A` but when landing a reversal
/// the registers had already decided), never reversing but there. Before the release rule the end game landed such states
/// in two ticks at up to 755·A.
#[test]
fn a_stop_from_a_reversing_plan_within_the_limits_keeps_the_bound() {
    use rand::{Rng, SeedableRng};
    use snapgen_model::peaks::peaks;
    use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
    let f = Format::with_ts(1e-4);
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut lu = |lo: f64, hi: f64| rng.gen_range(lo.ln()..hi.ln()).exp();
    let (mut stops, mut over) = (0, 0);
    let mut cases = Vec::new();
    for _ in 0..3000 {
        cases.push((
            OnlineLimits {
                velocity: lu(0.05, 2.0),
                acceleration: lu(1.0, 50.0),
                deceleration: lu(1.0, 50.0),
                jerk: lu(10.0, 5e3),
            },
            lu(100.0, 1e6),
            lu(1.0, 1e6),
        ));
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for (l, ahead, behind) in cases {
        let start = ChainState::at_rest(f.home_raw());
        let target = |cell| OnlineTarget::Position {
            cell,
            velocity: 0.0,
        };
        let Ok(first) = plan_online(
            &start,
            &target(f.output_lsb(start.x) + ahead as i128),
            &l,
            OnlineOrder::Three,
            &f,
        ) else {
            continue;
        };
        let k = rng.gen_range(1..first.program.total_ticks().max(2));
        let mid = start.after_ticks(&first.program, k, &f.widths);
        let Ok(back) = plan_online(
            &mid,
            &target(f.output_lsb(mid.x) - behind as i128),
            &l,
            OnlineOrder::Three,
            &f,
        ) else {
            continue;
        };
        let (p1, _) = peaks(&first.program, &start);
        let (p2, _) = peaks(&back.program, &mid);
        let accel = p1.a.max(p2.a).as_i128();
        let limits = StopLimits {
            jerk: p1.j.max(p2.j).as_i128().min(accel),
            accel,
        };
        if !limits.valid() {
            continue;
        }
        let at = rng.gen_range(0..back.program.total_ticks().max(1));
        let s = mid.after_ticks(&back.program, at, &f.widths);
        let (trace, law) = stop_from(s, limits, 100_000_000);
        stops += 1;
        over += usize::from(law.over_limits());
        assert_bound(&trace, s, limits);
        for t in &trace {
            assert!(
                t.a.abs() <= limits.accel && t.j.abs() <= 2 * limits.accel,
                "{t:?} from {s:?}"
            );
        }
    }
    assert!(stops > 2000, "{stops} stops");
    assert!(
        over > 50,
        "only {over} states beyond a release at J: the case is not exercised"
    );
}
