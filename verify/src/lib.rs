//! An independent check of what a segment program does on the integer chain.
//!
//! The planners promise that a program ends exactly on its target at rest and never exceeds a
//! limit on any tick. This crate checks such promises without using anything the planners
//! compute — no peaks, gains or phase relations, and no code of `snapgen-model`: it takes the
//! start registers and the `(ticks, snap)` segments and integrates them itself.
//!
//! * **Exact.** Everything is a 256-bit integer; no floating point anywhere.
//! * **Closed form per segment.** After `k` ticks of constant snap `d` (the chain
//!   `j += d; a += j; v += a; x += v`, every register from the previous tick's values):
//!
//!   ```text
//!   j(k) = j + k·d
//!   a(k) = a + k·j + C(k,2)·d
//!   v(k) = v + k·a + C(k,2)·j + C(k,3)·d
//!   x(k) = x + k·v + C(k,2)·a + C(k,3)·j + C(k,4)·d
//!   ```
//!
//!   so a segment of a billion ticks costs a few dozen evaluations, not a billion steps.
//! * **Per-tick extremes inside each segment.** A register's tick-to-tick increment is the
//!   register below it (`x(k+1) − x(k) = v(k)`, …), so a register can only turn where that
//!   increment changes sign. The jerk is linear in `k`; on each interval where an increment is
//!   monotonic it changes sign at most twice (through zero), and exact bisection on integer
//!   `k` finds where; those points cut the register above into monotonic pieces, and so on up
//!   to the position. The extremes of every register over every tick are then among the
//!   values at the piece ends, all evaluated exactly.
//!
//! The tests compare this with a plain tick-by-tick loop on small programs.
//!
//! [`path`] holds a multi-axis trace against the path it was programmed to follow (lines, arcs,
//! helices) and each axis's limits, from the integer positions alone.

use ethnum::I256;

pub mod path;

/// The four registers of the chain, exact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct State {
    /// Position.
    pub x: I256,
    /// Velocity.
    pub v: I256,
    /// Acceleration.
    pub a: I256,
    /// Jerk.
    pub j: I256,
}

impl State {
    /// From raw register values.
    pub fn new(x: i128, v: i128, a: i128, j: i128) -> Self {
        State {
            x: I256::from(x),
            v: I256::from(v),
            a: I256::from(a),
            j: I256::from(j),
        }
    }

    /// True when velocity, acceleration and jerk are zero.
    pub fn at_rest(&self) -> bool {
        self.v == 0 && self.a == 0 && self.j == 0
    }

    /// Register `r` (0 = x, 1 = v, 2 = a, 3 = j).
    fn get(&self, r: usize) -> I256 {
        [self.x, self.v, self.a, self.j][r]
    }
}

/// The smallest and largest value a register takes, over every tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Range {
    /// Smallest value.
    pub min: I256,
    /// Largest value.
    pub max: I256,
}

impl Range {
    fn at(v: I256) -> Self {
        Range { min: v, max: v }
    }

    fn take(&mut self, v: I256) {
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }

    /// The largest magnitude.
    pub fn max_abs(&self) -> I256 {
        self.min.abs().max(self.max.abs())
    }
}

/// What a program does from a start state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Integration {
    /// The registers after the last tick.
    pub end: State,
    /// Ticks played.
    pub ticks: u64,
    /// Range of the position over every tick, the start included.
    pub x: Range,
    /// Range of the velocity.
    pub v: Range,
    /// Range of the acceleration.
    pub a: Range,
    /// Range of the jerk.
    pub j: Range,
    /// Range of the snap played (zero for an empty program).
    pub d: Range,
}

impl Integration {
    /// The range of register `r` (0 = x, 1 = v, 2 = a, 3 = j, 4 = d).
    pub fn range(&self, r: usize) -> Range {
        [self.x, self.v, self.a, self.j, self.d][r]
    }
}

/// `C(k, m)` for `m ≤ 4`, exact.
fn binomial(k: u64, m: u32) -> I256 {
    let k = I256::from(k);
    let mut num = I256::ONE;
    let mut den = I256::ONE;
    for i in 0..m {
        num *= k - I256::from(i);
        den *= I256::from(i + 1);
    }
    // A product of m consecutive integers is divisible by m!; for k < m it is 0.
    num / den
}

/// Register `r` after `k` ticks of snap `d` from `s` (the closed form above).
fn value(s: &State, d: I256, r: usize, k: u64) -> I256 {
    // Register r is the sum over the registers at or below it (down to the snap), each times
    // C(k, distance): x(k) = Σ C(k, i)·[x, v, a, j, d][i].
    let below = [s.x, s.v, s.a, s.j, d];
    (0..=4 - r)
        .map(|i| binomial(k, i as u32) * below[r + i])
        .fold(I256::ZERO, |acc, t| acc + t)
}

/// The points of `[lo, hi]` where a monotonic integer sequence `f` changes sign: the first `k`
/// where `f(k) ≥ 0` differs from `f(lo) ≥ 0`, and the first where `f(k) > 0` does (each
/// predicate flips at most once along a monotonic sequence; exact bisection finds where).
fn sign_changes(f: &dyn Fn(u64) -> I256, lo: u64, hi: u64, out: &mut Vec<u64>) {
    for pred in [&(|v: I256| v >= 0) as &dyn Fn(I256) -> bool, &|v: I256| {
        v > 0
    }] {
        let p0 = pred(f(lo));
        if pred(f(hi)) == p0 {
            continue;
        }
        let (mut a, mut b) = (lo + 1, hi);
        while a < b {
            let m = a + (b - a) / 2;
            if pred(f(m)) != p0 {
                b = m;
            } else {
                a = m + 1;
            }
        }
        out.push(a);
    }
}

/// Integrates `segments` (`(ticks, snap)`) from `start`: the exact end state and the range of
/// every register over every tick.
pub fn integrate(start: State, segments: impl IntoIterator<Item = (u64, i128)>) -> Integration {
    let mut out = Integration {
        end: start,
        ticks: 0,
        x: Range::at(start.x),
        v: Range::at(start.v),
        a: Range::at(start.a),
        j: Range::at(start.j),
        d: Range::at(I256::ZERO),
    };
    let mut first = true;
    for (n, d) in segments {
        if n == 0 {
            continue;
        }
        let d = I256::from(d);
        if first {
            out.d = Range::at(d);
            first = false;
        } else {
            out.d.take(d);
        }
        let s = out.end;
        // Cut points of the register at each level: the jerk (level 3) is linear, monotonic on
        // [0, n]; each register's cuts come from the sign changes of the one below it.
        let mut cuts: Vec<u64> = vec![0, n];
        for r in (0..4).rev() {
            let ranges = [&mut out.x, &mut out.v, &mut out.a, &mut out.j];
            let range = ranges.into_iter().nth(r).expect("four registers");
            for &k in &cuts {
                range.take(value(&s, d, r, k));
            }
            if r == 0 {
                break;
            }
            // Register r is monotonic between its cuts; the register above (r − 1) turns
            // where register r changes sign.
            cuts.sort_unstable();
            cuts.dedup();
            let mut next = cuts.clone();
            for w in cuts.windows(2) {
                let f = |k: u64| value(&s, d, r, k);
                sign_changes(&f, w[0], w[1], &mut next);
            }
            cuts = next;
        }
        out.end = State {
            x: value(&s, d, 0, n),
            v: value(&s, d, 1, n),
            a: value(&s, d, 2, n),
            j: value(&s, d, 3, n),
        };
        out.ticks += n;
    }
    out
}

/// The same by stepping every tick (for tests and short programs).
pub fn step_by_step(start: State, segments: impl IntoIterator<Item = (u64, i128)>) -> Integration {
    let mut out = integrate(start, std::iter::empty());
    let mut s = start;
    let mut first = true;
    for (n, d) in segments {
        let d = I256::from(d);
        for _ in 0..n {
            if first {
                out.d = Range::at(d);
                first = false;
            } else {
                out.d.take(d);
            }
            s = State {
                x: s.x + s.v,
                v: s.v + s.a,
                a: s.a + s.j,
                j: s.j + d,
            };
            for (r, range) in [&mut out.x, &mut out.v, &mut out.a, &mut out.j]
                .into_iter()
                .enumerate()
            {
                range.take(s.get(r));
            }
            out.ticks += 1;
        }
    }
    out.end = s;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn binomials() {
        assert_eq!(binomial(0, 2), I256::ZERO);
        assert_eq!(binomial(5, 2), I256::from(10));
        assert_eq!(binomial(10, 4), I256::from(210));
        assert_eq!(binomial(3, 4), I256::ZERO);
        let big = (1u64 << 32) - 1;
        let b = I256::from(big);
        assert_eq!(binomial(big, 4), b * (b - 1) * (b - 2) * (b - 3) / 24);
    }

    #[test]
    fn a_ramp_up_and_down_by_hand() {
        // Snap +1 for 3 ticks then −1 for 3: j = 1,2,3,2,1,0; a = 0,1,3,6,8,9,9.
        let r = integrate(State::default(), [(3, 1), (3, -1)]);
        assert_eq!(r.end.j, I256::ZERO);
        assert_eq!(r.end.a, I256::from(9));
        assert_eq!(r.j.max, I256::from(3));
        assert_eq!(r, step_by_step(State::default(), [(3, 1), (3, -1)]));
    }

    fn segments() -> impl Strategy<Value = Vec<(u64, i128)>> {
        prop::collection::vec((0u64..60, -50i128..50), 0..8)
    }

    proptest! {
        /// Closed form and per-tick extremes agree with a tick-by-tick loop, from any start.
        #[test]
        fn closed_form_equals_stepping(
            segs in segments(),
            x in -10_000i128..10_000, v in -500i128..500, a in -50i128..50, j in -20i128..20,
        ) {
            let s = State::new(x, v, a, j);
            prop_assert_eq!(integrate(s, segs.clone()), step_by_step(s, segs));
        }

        /// The same with huge values (the registers of real plans).
        #[test]
        fn closed_form_equals_stepping_at_scale(
            segs in prop::collection::vec((0u64..40, -(1i128 << 100)..(1i128 << 100)), 0..6),
            v in -(1i128 << 105)..(1i128 << 105),
        ) {
            let s = State::new(1 << 110, v, 0, 0);
            prop_assert_eq!(integrate(s, segs.clone()), step_by_step(s, segs));
        }
    }
}
