//! A straight line in N-space, and whether a point lies on it within a bound per axis.
//!
//! The bound is the one a user of a CNC reads off each axis: `p` lies on the segment from `A`
//! to `B` within `b` when some point `A + t·(B − A)`, `0 ≤ t ≤ 1`, of the exact segment has
//! every axis within `b` of `p`. For each axis `i` with `Dᵢ = Bᵢ − Aᵢ ≠ 0` that asks
//! `t ∈ [(pᵢ − Aᵢ − b)/Dᵢ, (pᵢ − Aᵢ + b)/Dᵢ]` (the ends swapped when `Dᵢ < 0`); an axis that does
//! not move asks `|pᵢ − Aᵢ| ≤ b`. The point lies on the line when these intervals and `[0, 1]`
//! meet, compared as exact fractions.

use num_bigint::BigInt;
use num_traits::{One, Zero};

use super::big;

/// The segment from `from` to `to` (one coordinate per axis).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Line {
    /// Start point.
    pub from: Vec<i128>,
    /// End point.
    pub to: Vec<i128>,
}

/// `n / d` with `d > 0`.
#[derive(Clone, Debug)]
struct Fraction {
    n: BigInt,
    d: BigInt,
}

impl Fraction {
    fn new(n: BigInt, d: BigInt) -> Self {
        if d < BigInt::zero() {
            Fraction { n: -n, d: -d }
        } else {
            Fraction { n, d }
        }
    }

    /// `self ≤ other`.
    fn le(&self, other: &Fraction) -> bool {
        &self.n * &other.d <= &other.n * &self.d
    }
}

impl Line {
    /// True when `p` lies on the segment within `bound` on every axis (module documentation).
    pub fn holds(&self, p: &[i128], bound: i128) -> bool {
        let b = big(bound);
        let mut lo = Fraction::new(BigInt::zero(), BigInt::one());
        let mut hi = Fraction::new(BigInt::one(), BigInt::one());
        for ((&a, &e), &q) in self.from.iter().zip(&self.to).zip(p) {
            let (r, d) = (big(q) - big(a), big(e) - big(a));
            if d.is_zero() {
                if r.magnitude() > b.magnitude() {
                    return false;
                }
                continue;
            }
            let (mut l, mut h) = (
                Fraction::new(&r - &b, d.clone()),
                Fraction::new(&r + &b, d.clone()),
            );
            if d < BigInt::zero() {
                std::mem::swap(&mut l, &mut h);
            }
            if lo.le(&l) {
                lo = l;
            }
            if h.le(&hi) {
                hi = h;
            }
            if !lo.le(&hi) {
                return false;
            }
        }
        true
    }
}

impl Line {
    /// How far along the segment `p`'s projection lies (0 at the start, 1 at the end,
    /// clamped), and the segment's length, in `f64`: for following its progress, not for the
    /// bound.
    pub(crate) fn progress(&self, p: &[i128]) -> (f64, f64) {
        let (mut dot, mut len2) = (0.0, 0.0);
        for ((&a, &e), &q) in self.from.iter().zip(&self.to).zip(p) {
            let d = (e - a) as f64;
            dot += (q - a) as f64 * d;
            len2 += d * d;
        }
        if len2 == 0.0 {
            return (1.0, 0.0);
        }
        ((dot / len2).clamp(0.0, 1.0), len2.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(from: &[i128], to: &[i128]) -> Line {
        Line {
            from: from.to_vec(),
            to: to.to_vec(),
        }
    }

    /// The same question answered by brute force: t on a fine grid of fractions k/n.
    fn brute(l: &Line, p: &[i128], b: i128, n: i128) -> bool {
        (0..=n).any(|k| {
            l.from.iter().zip(&l.to).zip(p).all(|((&a, &e), &q)| {
                // |q − a − k/n·(e − a)| ≤ b  ⇔  |n(q − a) − k(e − a)| ≤ n·b
                (n * (q - a) - k * (e - a)).abs() <= n * b
            })
        })
    }

    #[test]
    fn points_of_a_diagonal() {
        let l = line(&[0, 0, 0], &[30, 20, 10]);
        assert!(l.holds(&[0, 0, 0], 0));
        assert!(l.holds(&[15, 10, 5], 0));
        assert!(l.holds(&[30, 20, 10], 0));
        assert!(!l.holds(&[16, 10, 5], 0), "one axis off by one");
        assert!(l.holds(&[16, 10, 5], 1));
        assert!(!l.holds(&[31, 21, 11], 0), "beyond the end");
        assert!(l.holds(&[31, 21, 11], 1));
        assert!(!l.holds(&[-2, 0, 0], 1), "before the start");
        // Between lattice points: t = 1/20 puts the line at (1.5, 1, 0.5).
        assert!(l.holds(&[1, 1, 0], 1));
        assert!(!l.holds(&[3, 0, 0], 1));
    }

    #[test]
    fn an_axis_that_does_not_move() {
        let l = line(&[5, -7], &[5, 100]);
        assert!(l.holds(&[5, 40], 0));
        assert!(l.holds(&[6, 40], 1));
        assert!(!l.holds(&[7, 40], 1));
        let still = line(&[1, 2], &[1, 2]);
        assert!(still.holds(&[2, 3], 1) && !still.holds(&[3, 2], 1));
    }

    #[test]
    fn agrees_with_brute_force() {
        // A deterministic walk over small segments and points: the exact answer agrees with
        // a search over t = k/n for n the product of the moving axes' lengths (where every
        // interval end lies on the grid).
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: i128| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % (2 * m as u64 + 1)) as i128 - m
        };
        let (mut yes, mut no) = (0, 0);
        for _ in 0..3000 {
            let l = line(&[next(6), next(6)], &[next(6), next(6)]);
            let p = [next(8), next(8)];
            let b = next(2).abs();
            let n = l
                .from
                .iter()
                .zip(&l.to)
                .map(|(a, e)| (e - a).abs().max(1))
                .product::<i128>();
            let exact = l.holds(&p, b);
            assert_eq!(exact, brute(&l, &p, b, n), "{l:?} {p:?} {b}");
            if exact {
                yes += 1
            } else {
                no += 1
            }
        }
        assert!(yes > 300 && no > 300, "{yes} {no}");
    }

    #[test]
    fn wide_coordinates_are_exact() {
        // Coordinates near 2^100: a product of two would overflow i128.
        let big = 1i128 << 100;
        let l = line(&[-big, -big], &[big, big - 2]);
        assert!(l.holds(&[0, -1], 0));
        assert!(!l.holds(&[0, 0], 0));
        assert!(l.holds(&[0, 0], 1));
    }
}
