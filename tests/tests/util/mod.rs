//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]

use ethnum::I256;
use snapgen_model::{Format, Quantity, Trace, FRAC_BITS};
use snapgen_plan::{Method, Plan, PlanError};
pub use snapgen_verify::{integrate, Integration, State};

/// The case count of a property: `PROPTEST_CASES` when set (as proptest's own default
/// configuration reads it), else `default`.
pub fn proptest_cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// The limits a method requests, as `(quantity, value)`.
pub fn limits(m: &Method) -> Vec<(Quantity, f64)> {
    match *m {
        Method::Order4 {
            vmax,
            amax,
            jmax,
            dmax,
        } => vec![
            (Quantity::Velocity, vmax),
            (Quantity::Acceleration, amax),
            (Quantity::Jerk, jmax),
            (Quantity::Snap, dmax),
        ],
        Method::Order3 { vmax, amax, jmax } => vec![
            (Quantity::Velocity, vmax),
            (Quantity::Acceleration, amax),
            (Quantity::Jerk, jmax),
        ],
        Method::Order2 { vmax, amax } => {
            vec![(Quantity::Velocity, vmax), (Quantity::Acceleration, amax)]
        }
        Method::Duration { .. } => vec![],
    }
}

/// The raw bound of a physical limit: `floor(limit · scale)`.
pub fn raw_limit(f: &Format, q: Quantity, limit: f64) -> I256 {
    let raw = (limit * f.scale(q)).floor();
    if raw >= 2f64.powi(126) {
        I256::MAX
    } else {
        I256::from(raw as i128)
    }
}

/// The plan's program integrated independently from its start (snapgen-verify: exact, closed
/// form per segment, per-tick extremes; none of the planner's numbers).
pub fn integrated(p: &Plan) -> Integration {
    integrate_from(p.start, &p.program)
}

/// `program` integrated from `start` by snapgen-verify.
pub fn integrate_from(
    start: snapgen_model::ChainState,
    program: &snapgen_model::Program,
) -> Integration {
    integrate(
        State::new(start.x, start.v, start.a, start.j),
        program
            .segments
            .iter()
            .map(|g| (u64::from(g.ticks), g.snap)),
    )
}

/// The largest magnitude of `q` over every tick of an integration.
pub fn peak(r: &Integration, q: Quantity) -> I256 {
    r.range(match q {
        Quantity::Position => 0,
        Quantity::Velocity => 1,
        Quantity::Acceleration => 2,
        Quantity::Jerk => 3,
        Quantity::Snap => 4,
    })
    .max_abs()
}

/// The same in physical units.
pub fn peak_physical(p: &Plan, r: &Integration, q: Quantity) -> f64 {
    peak(r, q).as_f64() / p.format.scale(q)
}

/// Whole output LSBs of an exact position register: `floor(x / 2^FRAC_BITS)`.
pub fn output_cell(x: I256) -> I256 {
    x >> FRAC_BITS
}

/// Peaks measured by stepping the program tick by tick with the model's chain (x, v, a, j, d),
/// and the last state.
pub fn traced(p: &Plan) -> ([I256; 5], snapgen_model::ChainState) {
    let mut m = [I256::ZERO; 5];
    let mut last = p.start;
    for t in Trace::new(&p.program, p.start, p.format.widths) {
        let s = t.state;
        for (i, v) in [s.x, s.v, s.a, s.j, t.d].into_iter().enumerate() {
            m[i] = m[i].max(I256::from(v).abs());
        }
        last = s;
    }
    (m, last)
}

/// True for the errors that only say "this move is outside the format's range".
pub fn is_range_error(e: &PlanError) -> bool {
    matches!(
        e,
        PlanError::TooLong { .. }
            | PlanError::GainTooLarge { .. }
            | PlanError::DistanceOutOfRange { .. }
            | PlanError::LimitBelowResolution { .. }
            | PlanError::Overflow { .. }
            | PlanError::DurationTooShort { .. }
    )
}

/// Asserts everything an accepted plan promises, on the independent integration of its
/// program: at rest at the end, on the requested output cell, within every limit and every
/// register's width on every tick. Returns the integration.
pub fn assert_plan_promises(p: &Plan) -> Integration {
    let f = &p.format;
    let r = integrated(p);
    assert!(r.end.at_rest(), "not at rest: {:?}", r.end);
    // The request rounded to whole output LSBs, measured from the start's output cell.
    let want = (p.request.distance / f.position_lsb).round();
    let moved = output_cell(r.end.x) - output_cell(I256::from(p.start.x));
    assert_eq!(moved.as_f64(), want, "output position misses the target");
    for (q, limit) in limits(&p.request.method) {
        assert!(
            peak(&r, q) <= raw_limit(f, q, limit),
            "{} peak {} above limit {limit} (raw {} > {})",
            q.name(),
            peak_physical(p, &r, q),
            peak(&r, q),
            raw_limit(f, q, limit)
        );
    }
    for q in [
        Quantity::Position,
        Quantity::Velocity,
        Quantity::Acceleration,
        Quantity::Jerk,
        Quantity::Snap,
    ] {
        assert!(
            peak(&r, q) <= I256::from(Format::register_max(f.width(q))),
            "{} register overflows",
            q.name()
        );
    }
    assert_eq!(u128::from(r.ticks), u128::from(p.ticks_total()));
    p.program.validate(f).expect("program fits the format");
    // What the plan reports about itself is what its program does.
    assert_eq!(
        I256::from(p.final_state.x),
        r.end.x,
        "the plan's final state is not where its program ends"
    );
    r
}
