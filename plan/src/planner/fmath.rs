//! The few floating-point functions the planners need, written with IEEE-754 basic
//! operations only (`+ − × ÷ √` and integer conversions), which every platform rounds the same
//! way. Two reasons:
//!
//! * **The same plan everywhere.** A host on a 64-bit ARM (seed 001's Raspberry Pi) must
//!   compute exactly the program an x86 host computes. The platform's `libm` (`cbrt`, `ceil`
//!   on a CPU without SSE4.1, …) is not bound to give identical results across architectures;
//!   these functions are.
//! * **Speed.** On baseline x86-64, `f64::ceil`/`floor`/`round` are library calls and `cbrt`
//!   a software routine; planning calls them a dozen times.
//!
//! Each is tested against the standard library (exactly for the rounding functions, within one
//! unit in the last place for `cbrt`).

/// 2^52: from here on every f64 is an integer.
const INTEGRAL: f64 = 4_503_599_627_370_496.0;

/// A zero result takes the sign of the input, as the standard library's rounding does.
#[inline]
fn signed_zero(r: f64, t: f64) -> f64 {
    if r == 0.0 {
        r.copysign(t)
    } else {
        r
    }
}

/// Rounds toward zero.
#[inline]
pub fn trunc(t: f64) -> f64 {
    if t.abs() < INTEGRAL {
        signed_zero(t as i64 as f64, t)
    } else {
        t
    }
}

/// Rounds toward +∞ (as [`f64::ceil`]).
#[inline]
pub fn ceil(t: f64) -> f64 {
    let i = trunc(t);
    signed_zero(if i < t { i + 1.0 } else { i }, t)
}

/// Rounds toward −∞ (as [`f64::floor`]).
#[inline]
pub fn floor(t: f64) -> f64 {
    let i = trunc(t);
    signed_zero(if i > t { i - 1.0 } else { i }, t)
}

/// Rounds to the nearest integer, halves away from zero (as [`f64::round`]).
#[inline]
pub fn round(t: f64) -> f64 {
    let i = trunc(t);
    // Exact: t − trunc(t) loses no bits below 2^52.
    let frac = t - i;
    let r = if frac >= 0.5 {
        i + 1.0
    } else if frac <= -0.5 {
        i - 1.0
    } else {
        i
    };
    signed_zero(r, t)
}

/// The real cube root, within one unit in the last place.
///
/// An estimate from the exponent (the high word divided by 3 plus a bias, as in FreeBSD's
/// `cbrt`, good to about 3 %), two Halley steps `y ← y·(y³ + 2x)/(2y³ + x)` (cubic
/// convergence: 3e-2 → 3e-5 → 3e-14), then one Newton step (quadratic: below rounding).
pub fn cbrt(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let a = x.abs();
    // Bring subnormal and huge inputs into the range where the estimate works.
    let (a, scale) = if a < 1e-290 {
        (a * 2f64.powi(300), 2f64.powi(-100))
    } else if a > 1e290 {
        (a * 2f64.powi(-300), 2f64.powi(100))
    } else {
        (a, 1.0)
    };
    let high = (a.to_bits() >> 32) as u32;
    let mut y = f64::from_bits(u64::from(high / 3 + 715_094_163) << 32);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * a) / (2.0 * y3 + a);
    }
    y -= (y * y * y - a) / (3.0 * y * y);
    (y * scale).copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ulps(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn edge_values() {
        for t in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
            1e-300,
            4503599627370495.5,
            4503599627370496.0,
            1e20,
            -1e20,
            3.0000000002,
        ] {
            assert_eq!(ceil(t).to_bits(), t.ceil().to_bits(), "ceil {t}");
            assert_eq!(floor(t).to_bits(), t.floor().to_bits(), "floor {t}");
            assert_eq!(round(t).to_bits(), t.round().to_bits(), "round {t}");
        }
        assert!(ceil(f64::NAN).is_nan() && round(f64::NAN).is_nan());
        assert_eq!(cbrt(27.0), 3.0);
        assert_eq!(cbrt(-8.0), -2.0);
        assert_eq!(cbrt(0.0), 0.0);
        assert!(ulps(cbrt(1e-310), 1e-310f64.cbrt()) <= 1);
        assert!(ulps(cbrt(1e300), 1e300f64.cbrt()) <= 1);
    }

    proptest! {
        #[test]
        fn rounding_equals_std(t in -1e17f64..1e17, k in -60i32..60) {
            let t = t * 2f64.powi(k);
            prop_assert_eq!(ceil(t).to_bits(), t.ceil().to_bits());
            prop_assert_eq!(floor(t).to_bits(), t.floor().to_bits());
            prop_assert_eq!(round(t).to_bits(), t.round().to_bits());
        }

        #[test]
        fn cbrt_within_one_ulp_of_std(m in 1.0f64..2.0, e in -1000i32..1000) {
            let x = m * 2f64.powi(e);
            prop_assert!(ulps(cbrt(x), x.cbrt()) <= 1, "{} vs {}", cbrt(x), x.cbrt());
        }
    }
}
