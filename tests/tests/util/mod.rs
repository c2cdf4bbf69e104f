//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]

use ethnum::I256;
use snapgen_model::{Format, Method, Plan, PlanError, Quantity, Trace};

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

/// The exact peak the plan reports for `q`.
pub fn peak(p: &Plan, q: Quantity) -> I256 {
    match q {
        Quantity::Position => p.peaks.x,
        Quantity::Velocity => p.peaks.v,
        Quantity::Acceleration => p.peaks.a,
        Quantity::Jerk => p.peaks.j,
        Quantity::Snap => p.peaks.d,
    }
}

/// Peaks measured by stepping the program tick by tick (x, v, a, j, d), and the last state.
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

/// Asserts everything an accepted plan promises, from its closed-form results.
pub fn assert_plan_promises(p: &Plan) {
    let f = &p.format;
    assert!(
        p.final_state.is_at_rest(),
        "not at rest: {:?}",
        p.final_state
    );
    assert_eq!(p.final_error_lsb(), 0, "output position misses the target");
    assert!(
        p.residual_raw().abs() < f.half_lsb_raw(),
        "residual {} ≥ half an LSB",
        p.residual_raw()
    );
    for (q, limit) in limits(&p.request.method) {
        assert!(
            peak(p, q) <= raw_limit(f, q, limit),
            "{} peak {} above limit {limit} (raw {})",
            q.name(),
            p.peak_physical(q),
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
            peak(p, q) <= I256::from(Format::register_max(f.width(q))),
            "{} register overflows",
            q.name()
        );
    }
    p.program.validate(f).expect("program fits the format");
}
