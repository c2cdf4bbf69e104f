//! An LU factorisation of the condition matrix: factored once per tick layout, solved for
//! the real levels and for each integer refinement.

use super::*;

/// An LU factorisation (partial pivoting) of the `n × n` (n ≤ 4) condition matrix: factored
/// once per tick layout, solved for the real levels and again for each integer refinement.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lu {
    pub(super) lu: [[f64; MAX_FREE]; MAX_FREE],
    pub(super) perm: [usize; MAX_FREE],
    pub(super) n: usize,
}

impl Lu {
    /// Factors `m`; `None` when it is singular.
    pub(super) fn new(m: &[[f64; MAX_FREE]; MAX_FREE], n: usize) -> Option<Lu> {
        let mut lu = *m;
        let mut perm = [0, 1, 2, 3];
        for col in 0..n {
            let mut piv = col;
            for row in col + 1..n {
                if lu[row][col].abs() > lu[piv][col].abs() {
                    piv = row;
                }
            }
            if lu[piv][col] == 0.0 || !lu[piv][col].is_finite() {
                return None;
            }
            lu.swap(col, piv);
            perm.swap(col, piv);
            let pivot_row = lu[col];
            for row in lu[col + 1..n].iter_mut() {
                let f = row[col] / pivot_row[col];
                row[col] = f;
                for (x, p) in row[col + 1..n].iter_mut().zip(&pivot_row[col + 1..n]) {
                    *x -= f * p;
                }
            }
        }
        Some(Lu { lu, perm, n })
    }

    /// Solves `m·x = r`; `None` when a component is not finite.
    pub(super) fn solve(&self, r: &[f64; MAX_FREE]) -> Option<[f64; MAX_FREE]> {
        let n = self.n;
        let mut y = [0.0; MAX_FREE];
        for i in 0..n {
            let dot: f64 = self.lu[i][..i]
                .iter()
                .zip(&y[..i])
                .map(|(l, y)| l * y)
                .sum();
            y[i] = r[self.perm[i]] - dot;
        }
        for i in (0..n).rev() {
            let dot: f64 = self.lu[i][i + 1..n]
                .iter()
                .zip(&y[i + 1..n])
                .map(|(l, y)| l * y)
                .sum();
            y[i] = (y[i] - dot) / self.lu[i][i];
            if !y[i].is_finite() {
                return None;
            }
        }
        Some(y)
    }
}
