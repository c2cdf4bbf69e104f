//! Exact peaks of every register over a whole program, in closed form.
//!
//! Within a segment of constant snap the registers are polynomials in the tick offset `k`
//! (degree 1 for jerk up to 4 for position). A register's discrete extremum lies where the
//! register below it (its per-tick increment) changes sign, so the candidates are the segment
//! ends plus the integers around the real roots of that increment. Roots are located in `f64`;
//! every candidate is then evaluated *exactly* in 256-bit integers, with a margin of ±2 ticks
//! around each root. The tests compare these peaks with a per-tick trace.

use ethnum::I256;

use crate::chain::{binomial, wrap, ChainState};
use crate::format::Widths;
use crate::program::Program;

/// Largest magnitude reached by each register over a program (raw, exact).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Peaks {
    /// max |x| (absolute register value).
    pub x: I256,
    /// max |v|.
    pub v: I256,
    /// max |a|.
    pub a: I256,
    /// max |j|.
    pub j: I256,
    /// max |d| (snap input).
    pub d: I256,
}

impl Peaks {
    /// The magnitudes of a state (no snap yet): where peaks start.
    pub fn at(s: &ExactState) -> Self {
        Peaks {
            x: s.x.abs(),
            v: s.v.abs(),
            a: s.a.abs(),
            j: s.j.abs(),
            d: I256::ZERO,
        }
    }
}

/// The exact chain state, without wrapping.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactState {
    /// Position.
    pub x: I256,
    /// Velocity.
    pub v: I256,
    /// Acceleration.
    pub a: I256,
    /// Jerk.
    pub j: I256,
}

impl ExactState {
    /// From a register state.
    pub fn from_chain(s: &ChainState) -> Self {
        ExactState {
            x: I256::from(s.x),
            v: I256::from(s.v),
            a: I256::from(s.a),
            j: I256::from(s.j),
        }
    }

    /// State after `k` ticks of snap `d` (the closed form of [`ChainState::advance`], exact).
    pub fn advance(&self, d: i128, k: u64) -> Self {
        let c = |m| I256::from(binomial(k, m));
        let d = I256::from(d);
        ExactState {
            j: self.j + c(1) * d,
            a: self.a + c(1) * self.j + c(2) * d,
            v: self.v + c(1) * self.a + c(2) * self.j + c(3) * d,
            x: self.x + c(1) * self.v + c(2) * self.a + c(3) * self.j + c(4) * d,
        }
    }

    /// The register state, if every value fits in `i128`.
    pub fn to_chain(&self) -> Option<ChainState> {
        Some(ChainState {
            x: i128::try_from(self.x).ok()?,
            v: i128::try_from(self.v).ok()?,
            a: i128::try_from(self.a).ok()?,
            j: i128::try_from(self.j).ok()?,
        })
    }
}

/// Real roots of the polynomial `c[0] + c[1] k + c[2] k² + c[3] k³` in `[lo, hi]`.
fn real_roots(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let deg = c.iter().rposition(|&v| v != 0.0).unwrap_or(0);
    let eval = |k: f64| c[..=deg].iter().rev().fold(0.0, |acc, &ci| acc * k + ci);
    if deg == 0 {
        return Vec::new();
    }
    if deg == 1 {
        let r = -c[0] / c[1];
        return if (lo..=hi).contains(&r) {
            vec![r]
        } else {
            Vec::new()
        };
    }
    // Split [lo, hi] at the derivative's roots into monotonic pieces, then bisect.
    let deriv: Vec<f64> = (1..=deg).map(|i| c[i] * i as f64).collect();
    let mut cuts = vec![lo];
    cuts.extend(real_roots(&deriv, lo, hi));
    cuts.push(hi);
    let mut roots = Vec::new();
    for w in cuts.windows(2) {
        let (mut a, mut b) = (w[0], w[1]);
        let (fa, fb) = (eval(a), eval(b));
        if fa == 0.0 {
            roots.push(a);
            continue;
        }
        if fa.signum() == fb.signum() {
            continue;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if eval(m).signum() == fa.signum() {
                a = m;
            } else {
                b = m;
            }
        }
        roots.push(0.5 * (a + b));
    }
    roots
}

/// Tick offsets in `[0, n]` at which a register whose increment has the given polynomial
/// coefficients can reach its extremes: both ends and ±2 around each root.
fn candidates(increment: &[f64], n: u64, out: &mut Vec<u64>) {
    out.clear();
    out.push(0);
    out.push(n);
    for r in real_roots(increment, 0.0, n as f64) {
        let base = r.floor() as i64;
        for k in base - 2..=base + 3 {
            if k >= 0 && (k as u64) <= n {
                out.push(k as u64);
            }
        }
    }
}

/// Exact peaks and exact final state of `program` run from `start`.
pub fn peaks(program: &Program, start: &ChainState) -> (Peaks, ExactState) {
    let mut s = ExactState::from_chain(start);
    let mut p = Peaks::at(&s);
    let mut cand = Vec::with_capacity(16);
    for seg in &program.segments {
        s = segment_peaks(&s, seg.snap, u64::from(seg.ticks), &mut p, &mut cand);
    }
    (p, s)
}

/// Folds into `p` the peaks of `n` ticks of snap `d` from `s`; returns the state after them.
fn segment_peaks(
    s: &ExactState,
    d: i128,
    n: u64,
    p: &mut Peaks,
    cand: &mut Vec<u64>,
) -> ExactState {
    let df = d as f64;
    let (jf, af, vf) = (s.j.as_f64(), s.a.as_f64(), s.v.as_f64());
    p.d = p.d.max(I256::from(d).abs());
    // Jerk is linear: its ends.
    p.j = p.j.max(s.advance(d, n).j.abs());
    // Acceleration: increment j_k = j + d k.
    candidates(&[jf, df], n, cand);
    for &k in cand.iter() {
        p.a = p.a.max(s.advance(d, k).a.abs());
    }
    // Velocity: increment a_k = a + (j - d/2) k + (d/2) k².
    candidates(&[af, jf - df / 2.0, df / 2.0], n, cand);
    for &k in cand.iter() {
        p.v = p.v.max(s.advance(d, k).v.abs());
    }
    // Position: increment v_k = v + (a - j/2 + d/3) k + (j/2 - d/2) k² + (d/6) k³.
    candidates(
        &[vf, af - jf / 2.0 + df / 3.0, jf / 2.0 - df / 2.0, df / 6.0],
        n,
        cand,
    );
    for &k in cand.iter() {
        p.x = p.x.max(s.advance(d, k).x.abs());
    }
    s.advance(d, n)
}

/// True when `n` ticks of snap `d` from `start` keep every register (and the snap) inside its
/// width: then wrapping never happens and plain additions give the hardware's result.
pub fn segment_fits(start: &ChainState, d: i128, n: u64, w: &Widths) -> bool {
    let s = ExactState::from_chain(start);
    let mut p = Peaks::at(&s);
    let mut cand = Vec::with_capacity(16);
    segment_peaks(&s, d, n, &mut p, &mut cand);
    let max = |bits: u32| I256::from(crate::format::Format::register_max(bits));
    p.x <= max(w.x) && p.v <= max(w.v) && p.a <= max(w.a) && p.j <= max(w.j) && p.d <= max(w.d)
}

/// Playing a segment tick by tick, with the fast path the peaks allow (here, beside the
/// closed-form extremes it needs, so that the chain does not depend on the peaks).
impl ChainState {
    /// Plays `n` ticks of snap `d`, calling `visit` with the state after each tick: the same
    /// states as `n` calls of [`ChainState::step`]. When the segment's registers provably stay
    /// inside their widths (its exact extremes, checked once in closed form), nothing can wrap
    /// and each tick is four plain additions; otherwise every tick wraps as the hardware does.
    #[inline]
    pub fn play(&self, d: i128, n: u64, w: &Widths, mut visit: impl FnMut(&ChainState)) -> Self {
        let mut s = *self;
        if n > 16 && wrap(d, w.d) == d && segment_fits(self, d, n, w) {
            for _ in 0..n {
                s = ChainState {
                    x: s.x + s.v,
                    v: s.v + s.a,
                    a: s.a + s.j,
                    j: s.j + d,
                };
                visit(&s);
            }
        } else {
            for _ in 0..n {
                s = s.step(d, w);
                visit(&s);
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::Trace;
    use crate::format::DEFAULT_FORMAT;
    use crate::program::Segment;

    fn traced_peaks(p: &Program, start: ChainState) -> Peaks {
        let mut out = Peaks::default();
        for t in Trace::new(p, start, DEFAULT_FORMAT.widths) {
            out.x = out.x.max(I256::from(t.state.x).abs());
            out.v = out.v.max(I256::from(t.state.v).abs());
            out.a = out.a.max(I256::from(t.state.a).abs());
            out.j = out.j.max(I256::from(t.state.j).abs());
            out.d = out.d.max(I256::from(t.d).abs());
        }
        out
    }

    #[test]
    fn closed_form_peaks_match_trace() {
        let p = Program {
            segments: vec![
                Segment { ticks: 37, snap: 5 },
                Segment {
                    ticks: 80,
                    snap: -3,
                },
                Segment { ticks: 11, snap: 0 },
                Segment {
                    ticks: 150,
                    snap: 2,
                },
                Segment {
                    ticks: 60,
                    snap: -1,
                },
            ],
        };
        let start = ChainState {
            x: -1000,
            v: 40,
            a: -7,
            j: 3,
        };
        let (pk, fin) = peaks(&p, &start);
        assert_eq!(pk, traced_peaks(&p, start));
        let traced_final = Trace::new(&p, start, DEFAULT_FORMAT.widths)
            .last()
            .unwrap()
            .state;
        assert_eq!(fin.to_chain().unwrap(), traced_final);
    }

    #[test]
    fn roots_of_a_cubic() {
        // (k-1)(k-5)(k-9) = k³ - 15k² + 59k - 45
        let r = real_roots(&[-45.0, 59.0, -15.0, 1.0], 0.0, 10.0);
        assert_eq!(r.len(), 3);
        for (got, want) in r.iter().zip([1.0, 5.0, 9.0]) {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
    }
    proptest::proptest! {
        /// `play` visits exactly the states of `step`, fast path or not (registers near
        /// their limits included, so some segments wrap).
        #[test]
        fn play_equals_stepping(
            d in -40i128..40, n in 0u64..200, v in -120i128..120, a in -60i128..60, j in -9i128..9,
        ) {
            let w = Widths { x: 20, v: 10, a: 8, j: 8, d: 8 };
            let start = ChainState { x: 1000, v, a: wrap(a, 8), j };
            let mut seen = Vec::new();
            let end = start.play(d, n, &w, |s| seen.push(*s));
            let mut s = start;
            for (k, got) in seen.iter().enumerate() {
                s = s.step(d, &w);
                proptest::prop_assert_eq!(*got, s, "tick {}", k + 1);
            }
            proptest::prop_assert_eq!(end, s);
            proptest::prop_assert_eq!(seen.len() as u64, n);
        }
    }
}
