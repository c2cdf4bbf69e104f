//! The one rule every host uses for the board's controlled stop (STOP_JERK, STOP_ACCEL): the
//! limits the user gives, or the peaks of what the axis will do, raw at the board's Ts.
//!
//! * A limit given must be a finite positive number whose raw value (rounded down: a lower
//!   limit is the safe side) lies between one LSB and the register's maximum; anything else is
//!   refused with what to change, before anything moves (never clamped: a stop of one LSB per
//!   tick² would never end, one at the register's maximum would exceed the machine).
//! * Without a limit, the peak the axis reaches (a move's own peak, or the largest of a
//!   script's commands) is used, at least one LSB.
//! * The jerk is at most the deceleration: a jerk that reaches the deceleration within one
//!   tick changes nothing but the board's check `0 < STOP_JERK ≤ STOP_ACCEL`. The jerk is
//!   lowered to it (never the deceleration raised to the jerk: that would stop harder than
//!   the machine was rated for).
//! * A limit given below the axis's own peak is allowed, with a warning: a stop from that
//!   peak begins outside its limits (flagged STOP_OVER_LIMITS), and is bounded by the move's
//!   own acceleration (docs/MODEL.md §9).

use snapgen_model::format::{Format, Quantity};
use snapgen_model::stop::StopLimits;
use snapgen_spec::Param;

use crate::session::InputError;

/// One limit: the user's (physical units, with the flag it came from), and the peak the axis
/// reaches (raw; the default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitSource {
    /// The flag or field the value was given by (for messages).
    pub flag: &'static str,
    /// The value given (unit/s² or unit/s³), if any.
    pub given: Option<f64>,
    /// The axis's peak, raw (the default).
    pub peak: i128,
}

/// The stop limits, raw in `format`, and the warnings to print.
pub fn stop_limits(
    decel: LimitSource,
    jerk: LimitSource,
    format: &Format,
) -> Result<(StopLimits, Vec<String>), InputError> {
    let mut warnings = Vec::new();
    let accel = raw(
        decel,
        Quantity::Acceleration,
        Param::StopAccel,
        format,
        &mut warnings,
    )?;
    let j = raw(jerk, Quantity::Jerk, Param::StopJerk, format, &mut warnings)?;
    if j > accel {
        warnings.push(format!(
            "{} lowered to the deceleration's raw value ({accel}): the stop reaches its deceleration within one tick either way",
            jerk.flag
        ));
    }
    Ok((
        StopLimits {
            jerk: j.min(accel),
            accel,
        },
        warnings,
    ))
}

fn raw(
    s: LimitSource,
    q: Quantity,
    p: Param,
    f: &Format,
    warnings: &mut Vec<String>,
) -> Result<i128, InputError> {
    let Some(x) = s.given else {
        return Ok(s.peak.clamp(1, p.max()));
    };
    if !(x.is_finite() && x > 0.0) {
        return Err(InputError::StopLimit {
            flag: s.flag,
            value: x,
        });
    }
    let r = (x * f.scale(q)).floor();
    let max = p.max() as f64;
    if r > max {
        return Err(InputError::StopLimitRange {
            flag: s.flag,
            value: x,
            raw: x * f.scale(q),
            max,
        });
    }
    if r < 1.0 {
        return Err(InputError::StopLimitResolution {
            flag: s.flag,
            value: x,
            raw: x * f.scale(q),
        });
    }
    let r = r as i128;
    if r < s.peak {
        warnings.push(format!(
            "{} {x} is below the axis's peak ({:.6e}): a stop from there begins outside its limits (flagged STOP_OVER_LIMITS; it is bounded by the move's own acceleration, docs/PROTOCOL.md \"Stopping\")",
            s.flag,
            s.peak as f64 / f.scale(q)
        ));
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_model::DEFAULT_FORMAT;

    fn src(flag: &'static str, given: Option<f64>, peak: i128) -> LimitSource {
        LimitSource { flag, given, peak }
    }

    #[test]
    fn the_rule_by_hand() {
        let f = DEFAULT_FORMAT;
        // Defaults: the peaks.
        let (l, w) = stop_limits(src("d", None, 1000), src("j", None, 10), &f).unwrap();
        assert_eq!((l.jerk, l.accel, w.len()), (10, 1000, 0));
        // A jerk above the deceleration is lowered to it, with a warning.
        let (l, w) = stop_limits(src("d", None, 10), src("j", None, 1000), &f).unwrap();
        assert_eq!((l.jerk, l.accel, w.len()), (10, 10, 1));
        // Given values: floored, a warning below the peak.
        let a = 5.0;
        let want = (a * f.scale(Quantity::Acceleration)).floor() as i128;
        let (l, w) = stop_limits(src("d", Some(a), want + 1), src("j", None, 1), &f).unwrap();
        assert_eq!((l.accel, w.len()), (want, 1));
        // Refused, never clamped.
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                stop_limits(src("d", Some(bad), 1), src("j", None, 1), &f),
                Err(InputError::StopLimit { .. })
            ));
        }
        assert!(matches!(
            stop_limits(src("d", Some(1e-40), 1), src("j", None, 1), &f),
            Err(InputError::StopLimitResolution { .. })
        ));
        assert!(matches!(
            stop_limits(src("d", Some(1e40), 1), src("j", None, 1), &f),
            Err(InputError::StopLimitRange { .. })
        ));
    }
}
