//! The fabric's controlled stop (`snapgen_model::stop`), played on the chain from random states:
//!
//! * from any tick of a move planned within the stop's limits (a state the move itself brings
//!   to rest within those limits, so it is stoppable — known without asking the stop law): the
//!   stop ends exactly at rest (v = a = j = 0), never exceeds the limits on any tick and never
//!   reverses direction, and the law agrees that the state was within its limits;
//! * from arbitrary states: it always ends exactly at rest, in bounded time; whenever the law
//!   says the state was within its limits, the trace confirms it (no tick over a limit, no
//!   reversal).
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
