//! Sine and cosine of an angle by CORDIC, in integers: the rule an arc's interpolator follows
//! on every tick, bit for bit, in the model and (later) in the fabric.
//!
//! An angle is a [`Turn`]: a fraction of a full turn in 64 bits (2⁶⁴ = one turn), so angles
//! wrap as the integers do and the quadrant is the top two bits. [`cos_sin`] takes the nearest
//! quarter turn off (an exact swap and sign change) and rotates the rest, at most ⅛ turn,
//! by [`ITERATIONS`] CORDIC steps: with `x₀ = K·2⁶²`, `y₀ = 0` and `z₀` the rest,
//!
//! ```text
//! dᵢ = +1 if zᵢ ≥ 0 else −1
//! xᵢ₊₁ = xᵢ − dᵢ·(yᵢ >> i)      yᵢ₊₁ = yᵢ + dᵢ·(xᵢ >> i)      zᵢ₊₁ = zᵢ − dᵢ·atanᵢ
//! ```
//!
//! (`>>` an arithmetic shift: rounding toward −∞), which leaves `x ≈ cos·2⁶²`, `y ≈ sin·2⁶²`.
//! Adds and shifts only: one step per clock in a fabric.
//!
//! The constants are computed here from exact integer series, not typed: `atanᵢ =
//! atan(2⁻ⁱ)/(2π)·2⁶⁴` rounded to the nearest integer (the arctangent's series in 160-bit
//! fixed point, π from Machin's formula `π/4 = 4·atan(1/5) − atan(1/239)`), and the gain
//! `K = ∏ (1 + 2⁻²ⁱ)^(−½)` as `⌊2⁶²·K⌋` from an integer square root.
//!
//! Accuracy (tested): within [`ERROR_BOUND`] units of `2⁻⁶²` of the exact sine and cosine
//! at every angle tested. Along a fine ramp of angles the third differences, the noise an
//! axis's jerk would see, were at most 62 units when measured (the test allows 128): on an arc
//! of radius 2³¹ output LSBs that is about 3·10⁻⁸ LSB per tick³, some thousand times below a
//! jerk of 500 000 mm/s³ at Ts = 50 µs on a 1 µm grid.

use std::sync::OnceLock;

use ethnum::{I256, U256};

/// An angle: a fraction of a full turn, `2⁶⁴` = one turn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Turn(pub u64);

/// Fraction bits of the results (`1.0` is `2⁶²`).
pub const ONE_BITS: u32 = snapgen_spec::widths::SHARE_FRAC;
/// CORDIC steps.
pub const ITERATIONS: usize = 62;
/// The error the tests allow [`cos_sin`], in units of `2⁻⁶²` (measured: at most 11 at the
/// exact angles, the radius within 23 over 20 000 angles).
pub const ERROR_BOUND: i128 = 32;

/// Fraction bits of the series that give the constants.
const SERIES_BITS: u32 = 160;

/// The constants: `atanᵢ` in turns·2⁶⁴ and `⌊K·2⁶²⌋`.
pub struct Constants {
    /// `atan(2⁻ⁱ)/(2π)·2⁶⁴`, rounded.
    pub atan: [i128; ITERATIONS],
    /// `⌊K·2⁶²⌋`, the start of `x` that makes the steps' gain 1.
    pub gain: i128,
}

/// The constants, computed once.
pub fn constants() -> &'static Constants {
    static C: OnceLock<Constants> = OnceLock::new();
    C.get_or_init(|| {
        let one = I256::ONE << SERIES_BITS;
        let pi4 = atan_inv(5) * 4 - atan_inv(239);
        let turn = pi4 * 8; // 2π in the series' fixed point
        let mut atan = [0i128; ITERATIONS];
        for (i, a) in atan.iter_mut().enumerate() {
            let t = if i == 0 { pi4 } else { atan_pow2(i as u32) };
            let t: I256 = t << 64u32;
            *a = ((t + turn / 2) / turn).as_i128();
        }
        // ∏ (1 + 2^-2i) with SERIES_BITS fraction bits, then ⌊2^62 / √∏⌋ = ⌊√(2^124 / ∏)⌋.
        let mut p = one;
        for i in 0..ITERATIONS as u32 {
            p += p >> (2 * i);
        }
        // √(2^124 / (p·2^-160)) with p cut to 100 fraction bits (2^224 fits; 2^284 would not).
        let q = (I256::ONE << (2 * ONE_BITS + 100)) / (p >> (SERIES_BITS - 100));
        Constants {
            atan,
            gain: isqrt(q.as_u256()).as_i128(),
        }
    })
}

/// `atan(1/n)` with [`SERIES_BITS`] fraction bits: `Σ (−1)ᵏ / ((2k+1)·n^(2k+1))`.
fn atan_inv(n: u32) -> I256 {
    let n = I256::from(n);
    let mut power = (I256::ONE << SERIES_BITS) / n; // 1/n^(2k+1)
    let (mut sum, mut k) = (I256::ZERO, 0i32);
    while power != 0 {
        let term = power / I256::from(2 * k + 1);
        sum += if k % 2 == 0 { term } else { -term };
        power /= n * n;
        k += 1;
    }
    sum
}

/// `atan(2⁻ⁱ)`, `i ≥ 1`, with [`SERIES_BITS`] fraction bits: `Σ (−1)ᵏ 2^(−i(2k+1)) / (2k+1)`.
fn atan_pow2(i: u32) -> I256 {
    let (mut sum, mut k) = (I256::ZERO, 0u32);
    while i * (2 * k + 1) <= SERIES_BITS {
        let term = (I256::ONE << (SERIES_BITS - i * (2 * k + 1))) / I256::from(2 * k + 1);
        sum += if k % 2 == 0 { term } else { -term };
        k += 1;
    }
    sum
}

/// `⌊√n⌋` by Newton's iteration from above (also the host's, for lengths and radii).
pub fn isqrt(n: U256) -> U256 {
    if n < 2 {
        return n;
    }
    let mut x = U256::ONE << (256 - n.leading_zeros()).div_ceil(2);
    loop {
        let y = (x + n / x) >> 1;
        if y >= x {
            return x;
        }
        x = y;
    }
}

/// `(cos θ, sin θ)·2⁶²` by the module's rule.
pub fn cos_sin(theta: Turn) -> (i128, i128) {
    let c = constants();
    let quadrant = (theta.0.wrapping_add(1 << 61) >> 62) & 3;
    let mut z = i128::from(theta.0.wrapping_sub(quadrant << 62) as i64);
    let (mut x, mut y) = (c.gain, 0i128);
    for (i, &a) in c.atan.iter().enumerate() {
        let (dx, dy) = (y >> i, x >> i);
        if z >= 0 {
            (x, y, z) = (x - dx, y + dy, z - a);
        } else {
            (x, y, z) = (x + dx, y - dy, z + a);
        }
    }
    match quadrant {
        0 => (x, y),
        1 => (-y, x),
        2 => (-x, -y),
        _ => (y, -x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: i128 = 1 << ONE_BITS;

    fn turn(fraction: f64) -> Turn {
        Turn((fraction * 2f64.powi(64)) as u64)
    }

    #[test]
    fn the_constants_are_the_known_ones() {
        let c = constants();
        // atan(1) = 1/8 turn exactly; atan(1/2)/2π = 0.0737918088252166...
        assert_eq!(c.atan[0], 1 << 61);
        let a1 = c.atan[1] as f64 / 2f64.powi(64);
        assert!(
            (a1 - 0.5f64.atan() / std::f64::consts::TAU).abs() < 1e-16,
            "{a1}"
        );
        // K = 0.6072529350088812561694...
        let k = c.gain as f64 / ONE as f64;
        assert!((k - 0.607_252_935_008_881_3).abs() < 1e-15, "{k}");
        // The last steps halve: atan(2^-i) ≈ 2^-i for large i.
        for i in 40..ITERATIONS {
            let want = 2f64.powi(64 - i as i32) / std::f64::consts::TAU;
            assert!((c.atan[i] as f64 - want).abs() <= 1.0, "{i}");
        }
    }

    #[test]
    fn exact_angles_within_the_bound() {
        let half_sqrt2 = isqrt(U256::ONE << (2 * ONE_BITS - 1)).as_i128(); // √½·2^62
        let cases = [
            (Turn(0), ONE, 0),
            (Turn(1 << 62), 0, ONE),
            (Turn(1 << 63), -ONE, 0),
            (Turn(3 << 62), 0, -ONE),
            (Turn(1 << 61), half_sqrt2, half_sqrt2),
            (Turn(7 << 61), half_sqrt2, -half_sqrt2),
            // 30°: sin = ½ (the angle rounded to the turn's grid: off by < 2^-63 of ½).
            (Turn(u64::MAX / 12 + 1), 3 * ONE / 2, ONE / 2),
        ];
        for (theta, c, s) in cases {
            let (x, y) = cos_sin(theta);
            let c = if theta == Turn(u64::MAX / 12 + 1) {
                isqrt(U256::from(3u32) << (2 * ONE_BITS - 2)).as_i128() // √3/2
            } else {
                c
            };
            assert!((x - c).abs() <= ERROR_BOUND, "{theta:?} cos {x} {c}");
            assert!((y - s).abs() <= ERROR_BOUND, "{theta:?} sin {y} {s}");
        }
    }

    #[test]
    fn agrees_with_the_library_at_many_angles() {
        // The f64 angle is good to about 2^-52 of its size, its sin and cos as well: this
        // checks the rule at that level (10^-15), the unit circle below it.
        let mut worst = 0i128;
        for k in 0..20_000u64 {
            let theta = Turn(k.wrapping_mul(0x9e37_79b9_7f4a_7c15));
            let (x, y) = cos_sin(theta);
            let a = theta.0 as i64 as f64 / 2f64.powi(64) * std::f64::consts::TAU;
            assert!((x as f64 / ONE as f64 - a.cos()).abs() < 1e-15, "{theta:?}");
            assert!((y as f64 / ONE as f64 - a.sin()).abs() < 1e-15, "{theta:?}");
            // x² + y² = 2^124 within the bound's square-ish: |r − 1| ≤ ERROR_BOUND ulp.
            let r2 = I256::from(x) * I256::from(x) + I256::from(y) * I256::from(y);
            let r = isqrt(r2.as_u256()).as_i128();
            worst = worst.max((r - ONE).abs());
        }
        assert!(worst <= ERROR_BOUND, "radius off by {worst}");
    }

    #[test]
    fn the_noise_an_axis_would_see_is_tiny() {
        // Angles on a ramp of 2^40 per step (~3.7e-7 rad): the third difference of sin·2^62
        // along it is the exact curve's (−cos·δ³·2^62, about 0.2 here) plus the rule's
        // rounding; it stays within a few units.
        let step = 1u64 << 40;
        let start = turn(0.1).0;
        let ys: Vec<i128> = (0..2000)
            .map(|k| cos_sin(Turn(start + k * step)).1)
            .collect();
        let worst = ys
            .windows(4)
            .map(|w| (w[3] - 3 * w[2] + 3 * w[1] - w[0]).abs())
            .max()
            .unwrap();
        assert!(worst <= 4 * ERROR_BOUND, "third difference {worst}");
    }
}
