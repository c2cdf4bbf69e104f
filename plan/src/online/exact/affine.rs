//! Values affine in the free levels, and the chain's closed forms in exact `i128` and in
//! `f64`: what the linear solve builds its equations from.

use super::*;

/// A value affine in the free levels: `c + Σ k[i]·p[i]`, stored `[c, k₀, k₁, k₂, k₃]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Affine(pub(super) [f64; MAX_FREE + 1]);

impl Affine {
    pub(super) fn constant(c: f64) -> Self {
        let mut a = Affine::default();
        a.0[0] = c;
        a
    }

    /// The coefficients of the levels.
    pub(super) fn k(&self) -> &[f64] {
        &self.0[1..]
    }

    /// The value at levels `p`.
    pub(super) fn at(&self, p: &[f64; MAX_FREE]) -> f64 {
        self.0[0] + self.0[1] * p[0] + self.0[2] * p[1] + self.0[3] * p[2] + self.0[4] * p[3]
    }
}

/// A state whose registers are affine in the free levels.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct AffineState {
    pub(super) x: Affine,
    pub(super) v: Affine,
    pub(super) a: Affine,
    pub(super) j: Affine,
}

/// The closed-form coefficients of `m` ticks at constant jerk: `C(m,1)`, `C(m,2)`, `C(m,3)`.
#[inline(always)]
pub(super) fn binomials_f(m: u64) -> (f64, f64, f64) {
    let m = m as f64;
    let c2 = m * (m - 1.0) * 0.5;
    (m, c2, c2 * (m - 2.0) / 3.0)
}

impl AffineState {
    /// `n ≥ 1` ticks with the jerk held at `level` from the first tick (snap `level − j` on the
    /// first tick, zero after): the closed form of [`piece_end`], lane by lane.
    pub(super) fn jerk_piece(&mut self, level: &Affine, n: u64) {
        let (c1, c2, c3) = binomials_f(n - 1);
        for i in 0..=MAX_FREE {
            // First tick: every register from the previous tick's values.
            let (x, v, a) = (
                self.x.0[i] + self.v.0[i],
                self.v.0[i] + self.a.0[i],
                self.a.0[i] + self.j.0[i],
            );
            let l = level.0[i];
            self.x.0[i] = x + c1 * v + c2 * a + c3 * l;
            self.v.0[i] = v + c1 * a + c2 * l;
            self.a.0[i] = a + c1 * l;
            self.j.0[i] = l;
        }
    }
}

/// The closed form of `n ≥ 1` ticks whose jerk is `level` from the first tick, exactly;
/// `None` when a register leaves `i128`. Equal to playing a one-tick segment of snap
/// `level − j` and an `(n − 1)`-tick segment of zero snap.
#[inline]
pub fn piece_end(s: &ChainState, level: i128, n: u64) -> Option<ChainState> {
    let x1 = s.x.checked_add(s.v)?;
    let v1 = s.v.checked_add(s.a)?;
    let a1 = s.a.checked_add(s.j)?;
    zero_snap(
        &ChainState {
            x: x1,
            v: v1,
            a: a1,
            j: level,
        },
        n - 1,
    )
}

/// `a·b`, `None` when it leaves `i128`: one wrapping multiplication when the operands' bit
/// lengths prove it cannot overflow (the usual case), the checked library routine otherwise.
#[inline(always)]
pub(super) fn mul(a: i128, b: i128) -> Option<i128> {
    let bits = |x: i128| 128 - x.unsigned_abs().leading_zeros();
    if bits(a) + bits(b) <= 126 {
        Some(a.wrapping_mul(b))
    } else {
        a.checked_mul(b)
    }
}

/// `v` as an f64, from its two 64-bit halves: two hardware conversions and one fused step
/// instead of the library's 128-bit routine. Within an ulp or two of `v as f64` (what the
/// real-valued solve needs) and, being plain IEEE-754 arithmetic, the same on every platform.
#[inline(always)]
pub fn to_f64(v: i128) -> f64 {
    let (hi, lo) = ((v >> 64) as i64, v as i64);
    if hi == lo >> 63 {
        // Fits an i64.
        return lo as f64;
    }
    hi as f64 * 18_446_744_073_709_551_616.0 + (v as u64) as f64
}

/// `m` ticks of zero snap from `s` in closed form (`m < 2^42`), exactly; `None` when a
/// register leaves `i128`.
#[inline]
pub(super) fn zero_snap(s: &ChainState, m: u64) -> Option<ChainState> {
    if m == 0 {
        return Some(*s);
    }
    let m = u128::from(m);
    let c2 = m * (m - 1) / 2;
    // C(m,3) = C(m,2)·(m − 2)/3, exact: 3 divides m(m−1)(m−2).
    let c3 = c2 * m.saturating_sub(2) / 3;
    let (c1, c2, c3) = (m as i128, c2 as i128, i128::try_from(c3).ok()?);
    Some(ChainState {
        x: s.x
            .checked_add(mul(c1, s.v)?)?
            .checked_add(mul(c2, s.a)?)?
            .checked_add(mul(c3, s.j)?)?,
        v: s.v.checked_add(mul(c1, s.a)?)?.checked_add(mul(c2, s.j)?)?,
        a: s.a.checked_add(mul(c1, s.j)?)?,
        j: s.j,
    })
}

/// One tick with snap `d`, exactly.
#[inline]
pub(super) fn one_tick(s: &ChainState, d: i128) -> Option<ChainState> {
    Some(ChainState {
        x: s.x.checked_add(s.v)?,
        v: s.v.checked_add(s.a)?,
        a: s.a.checked_add(s.j)?,
        j: s.j.checked_add(d)?,
    })
}
