//! Properties over random moves for every order: limits hold on the integer trace, the end
//! state is exact, duration is monotonic in distance, programs round-trip, and negative moves
//! mirror positive ones exactly. Raise the case count with `PROPTEST_CASES=100000`.

mod util;

use ethnum::I256;
use proptest::prelude::*;
use snapgen_model::{Format, Program, Quantity, DEFAULT_FORMAT};
use snapgen_plan::{plan, Method, MoveRequest, Plan};
use util::{assert_plan_promises, integrated, is_range_error, peak, traced};

/// A log-uniform value in `[lo, hi]`.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> + Clone {
    (lo.ln()..=hi.ln()).prop_map(f64::exp)
}

fn method() -> impl Strategy<Value = Method> {
    let v = log_uniform(0.01, 10.0);
    let a = log_uniform(0.1, 1e3);
    let j = log_uniform(1.0, 1e5);
    let d = log_uniform(10.0, 1e7);
    prop_oneof![
        (v.clone(), a.clone(), j.clone(), d).prop_map(|(vmax, amax, jmax, dmax)| {
            Method::Order4 {
                vmax,
                amax,
                jmax,
                dmax,
            }
        }),
        (v.clone(), a.clone(), j).prop_map(|(vmax, amax, jmax)| Method::Order3 {
            vmax,
            amax,
            jmax
        }),
        (v, a).prop_map(|(vmax, amax)| Method::Order2 { vmax, amax }),
        (log_uniform(0.01, 20.0), 0.01f64..=0.5, 0.01f64..=0.5).prop_map(
            |(duration, gamma, phi)| Method::Duration {
                duration,
                gamma,
                phi
            }
        ),
    ]
}

fn distance() -> impl Strategy<Value = f64> {
    (log_uniform(1e-6, 20.0), any::<bool>()).prop_map(|(d, neg)| if neg { -d } else { d })
}

fn format() -> impl Strategy<Value = Format> {
    prop_oneof![Just(1e-5), Just(1e-4), Just(1e-3)].prop_map(Format::with_ts)
}

/// Plans, discarding moves that are only outside the format's range (which must be typed
/// errors, never panics or other errors).
fn try_plan(r: &MoveRequest, f: &Format) -> Result<Plan, TestCaseError> {
    match plan(r, f) {
        Ok(p) => Ok(p),
        Err(e) if is_range_error(&e) => Err(TestCaseError::reject(e.to_string())),
        Err(e) => Err(TestCaseError::fail(format!("{r:?}: unexpected error {e}"))),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { max_global_rejects: 100_000, ..ProptestConfig::default() })]

    /// Limits, registers and exact endpoint, on the independent integration of the program.
    #[test]
    fn accepted_plans_keep_their_promises(m in method(), x in distance(), f in format()) {
        let p = try_plan(&MoveRequest { distance: x, method: m }, &f)?;
        assert_plan_promises(&p);
    }

    /// The model's per-tick chain (what the fabric is compared with) agrees with the
    /// independent closed-form integration: same peaks, same final state; and the planner's
    /// own peaks are the true ones.
    #[test]
    fn per_tick_trace_matches_the_independent_integration(m in method(), x in distance()) {
        let f = Format::with_ts(1e-3);
        let p = try_plan(&MoveRequest { distance: x, method: m }, &f)?;
        prop_assume!(p.ticks_total() <= 200_000);
        let (pk, last) = traced(&p);
        let r = integrated(&p);
        prop_assert_eq!(
            [last.x, last.v, last.a, last.j].map(I256::from),
            [r.end.x, r.end.v, r.end.a, r.end.j]
        );
        prop_assert_eq!(pk, [0, 1, 2, 3, 4].map(|k| r.range(k).max_abs()));
        prop_assert_eq!([p.peaks.v, p.peaks.a, p.peaks.j, p.peaks.d], [pk[1], pk[2], pk[3], pk[4]]);
    }

    /// A longer move never takes fewer ticks.
    #[test]
    fn duration_is_monotonic_in_distance(m in method(), x in log_uniform(1e-6, 20.0), k in 1.0f64..4.0, f in format()) {
        prop_assume!(!matches!(m, Method::Duration { .. }));
        let near = try_plan(&MoveRequest { distance: x, method: m }, &f)?;
        let far = try_plan(&MoveRequest { distance: x * k, method: m }, &f)?;
        prop_assert!(near.ticks_total() <= far.ticks_total(),
            "{} ticks for {} but {} ticks for {}", near.ticks_total(), x, far.ticks_total(), x * k);
    }

    /// Programs survive the binary upload form and JSON unchanged.
    #[test]
    fn programs_round_trip(m in method(), x in distance()) {
        let f = DEFAULT_FORMAT;
        let p = try_plan(&MoveRequest { distance: x, method: m }, &f)?;
        let bytes = p.program.to_bytes(&f).unwrap();
        prop_assert_eq!(&Program::from_bytes(&bytes, &f).unwrap(), &p.program);
        let json = serde_json::to_string(&p.program).unwrap();
        prop_assert_eq!(&serde_json::from_str::<Program>(&json).unwrap(), &p.program);
    }

    /// The move of −x is the move of +x with every snap negated, and ends at the mirrored
    /// register value, bit for bit.
    #[test]
    fn negative_moves_mirror_positive_ones(m in method(), x in log_uniform(1e-6, 20.0), f in format()) {
        let pos = try_plan(&MoveRequest { distance: x, method: m }, &f)?;
        let neg = try_plan(&MoveRequest { distance: -x, method: m }, &f)?;
        prop_assert_eq!(&neg.program, &pos.program.negated());
        let (rn, rp) = (integrated(&neg), integrated(&pos));
        prop_assert_eq!(rn.end.x - I256::from(neg.start.x), -(rp.end.x - I256::from(pos.start.x)));
        for q in [Quantity::Velocity, Quantity::Acceleration, Quantity::Jerk, Quantity::Snap] {
            prop_assert_eq!(peak(&rn, q), peak(&rp, q));
        }
        prop_assert_eq!(neg.target_lsb, -pos.target_lsb);
    }
}

/// Guards the properties above against testing nothing: most random moves must be accepted
/// (rejected ones are only moves outside the format's range).
#[test]
fn most_random_moves_are_accepted() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let strategy = (method(), distance(), format());
    let (mut ok, mut total) = (0, 0);
    let mut kinds = std::collections::BTreeMap::new();
    for _ in 0..2000 {
        let (m, x, f) = strategy.new_tree(&mut runner).unwrap().current();
        total += 1;
        match plan(
            &MoveRequest {
                distance: x,
                method: m,
            },
            &f,
        ) {
            Ok(_) => ok += 1,
            Err(e) => {
                assert!(is_range_error(&e), "unexpected error {e}");
                let kind = format!("{e:?}");
                *kinds
                    .entry(kind.split([' ', '{']).next().unwrap().to_string())
                    .or_insert(0) += 1;
            }
        }
    }
    println!("accepted {ok} of {total}; rejected by kind: {kinds:?}");
    assert!(
        ok * 10 >= total * 8,
        "only {ok} of {total} accepted: {kinds:?}"
    );
}
