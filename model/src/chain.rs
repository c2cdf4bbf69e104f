//! The snap integrator chain and the segment sequencer, exactly as the fabric computes them.
//!
//! Per tick, every register updates from the previous tick's values (seed 000 eqs 72–75 with the
//! shared-LSB scaling of [`crate::format`], so `Ts` disappears):
//!
//! ```text
//! j[k+1] = j[k] + d[k]      (eq 72)
//! a[k+1] = a[k] + j[k]      (eq 73)
//! v[k+1] = v[k] + a[k]      (eq 74)
//! x[k+1] = x[k] + v[k]      (eq 75)
//! ```
//!
//! Each addition wraps to its register's width, as the hardware's adders do. Accepted plans are
//! checked at plan time so that no register ever wraps; the wrapping is modelled so that the
//! model and the fabric also agree on programs that were *not* checked.
//!
//! Besides the per-tick step, [`ChainState::advance`] steps a whole segment in closed form:
//! after `n` ticks of constant snap `d`,
//!
//! ```text
//! j' = j + n·d
//! a' = a + n·j + C(n,2)·d
//! v' = v + n·a + C(n,2)·j + C(n,3)·d
//! x' = x + n·v + C(n,2)·a + C(n,3)·j + C(n,4)·d
//! ```
//!
//! which equals `n` per-tick steps whenever no register wraps on the way.

use serde::{Deserialize, Serialize};

use crate::format::Widths;
use crate::program::Program;

/// Sign-extends the low `bits` bits of `value`: the value a `bits`-wide register holds.
///
/// Registers wider than 64 bits (all of the chain's) only change the high word: that path
/// costs two shifts instead of a 128-bit shift pair by a run-time count.
#[inline(always)]
pub fn wrap(value: i128, bits: u32) -> i128 {
    if bits > 64 && bits < 128 {
        let s = 128 - bits;
        let hi = (((value >> 64) as i64) << s) >> s;
        (i128::from(hi) << 64) | i128::from(value as u64)
    } else {
        let s = 128 - bits;
        (value << s) >> s
    }
}

/// Binomial coefficient `C(n, k)` for `k ≤ 4` and `n < 2^32`, exact in `u128`.
///
/// Written without 128-bit division (a library call): the small factors are divided out of
/// 64-bit partial products, which the compiler turns into multiplications.
#[inline]
pub fn binomial(n: u64, k: u32) -> u128 {
    debug_assert!(n < 1 << 32, "segment tick counts are 32-bit");
    // C(n, 2) for n and n − 2, as u64 (no overflow for n < 2^32).
    let c2 = |m: u64| m * m.saturating_sub(1) / 2;
    match k {
        0 => 1,
        1 => u128::from(n),
        2 => u128::from(c2(n)),
        3 => {
            // C(n,3) = C(n,2)·(n−2)/3, and 3 divides one of n, n−1, n−2.
            let (a, b) = (c2(n), n.saturating_sub(2));
            if a % 3 == 0 {
                u128::from(a / 3) * u128::from(b)
            } else {
                u128::from(a) * u128::from(b / 3)
            }
        }
        4 => {
            // C(n,4) = C(n,2)·C(n−2,2)/6; 3 divides one factor and 2 one factor.
            let (mut a, mut b) = (c2(n), c2(n.saturating_sub(2)));
            if a % 3 == 0 {
                a /= 3;
            } else {
                b /= 3;
            }
            if a % 2 == 0 {
                a /= 2;
            } else {
                b /= 2;
            }
            u128::from(a) * u128::from(b)
        }
        _ => unreachable!("the chain has four integrators"),
    }
}

/// The four accumulators of the chain, raw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ChainState {
    /// Position (internal LSBs).
    pub x: i128,
    /// Velocity (internal LSBs per tick).
    pub v: i128,
    /// Acceleration.
    pub a: i128,
    /// Jerk.
    pub j: i128,
}

impl ChainState {
    /// At rest at raw position `x`.
    pub fn at_rest(x: i128) -> Self {
        ChainState {
            x,
            ..Default::default()
        }
    }

    /// True when velocity, acceleration and jerk are all zero.
    pub fn is_at_rest(&self) -> bool {
        self.v == 0 && self.a == 0 && self.j == 0
    }

    /// One tick with snap input `d` (eqs 72–75), each register wrapping to its width.
    #[inline(always)]
    pub fn step(&self, d: i128, w: &Widths) -> Self {
        ChainState {
            x: wrap(self.x.wrapping_add(self.v), w.x),
            v: wrap(self.v.wrapping_add(self.a), w.v),
            a: wrap(self.a.wrapping_add(self.j), w.a),
            j: wrap(self.j.wrapping_add(wrap(d, w.d)), w.j),
        }
    }

    /// `n` ticks of constant snap `d` in closed form (see the module documentation). Equal to
    /// `n` calls of [`ChainState::step`] when no register wraps on the way; `n < 2^32`.
    #[inline]
    pub fn advance(&self, d: i128, n: u64, w: &Widths) -> Self {
        let c = |k| binomial(n, k) as i128;
        let d = wrap(d, w.d);
        let (c1, c2, c3, c4) = (c(1), c(2), c(3), c(4));
        ChainState {
            j: wrap(self.j.wrapping_add(c1.wrapping_mul(d)), w.j),
            a: wrap(
                self.a
                    .wrapping_add(c1.wrapping_mul(self.j))
                    .wrapping_add(c2.wrapping_mul(d)),
                w.a,
            ),
            v: wrap(
                self.v
                    .wrapping_add(c1.wrapping_mul(self.a))
                    .wrapping_add(c2.wrapping_mul(self.j))
                    .wrapping_add(c3.wrapping_mul(d)),
                w.v,
            ),
            x: wrap(
                self.x
                    .wrapping_add(c1.wrapping_mul(self.v))
                    .wrapping_add(c2.wrapping_mul(self.a))
                    .wrapping_add(c3.wrapping_mul(self.j))
                    .wrapping_add(c4.wrapping_mul(d)),
                w.x,
            ),
        }
    }

    /// `n` ticks of constant snap `d` in closed form without wrapping: `None` if any value or
    /// intermediate product leaves `i128`.
    #[inline]
    pub fn checked_advance(&self, d: i128, n: u64) -> Option<Self> {
        let c = |k| i128::try_from(binomial(n, k)).ok();
        let (c1, c2, c3, c4) = (c(1)?, c(2)?, c(3)?, c(4)?);
        let m = |a: i128, b: i128| a.checked_mul(b);
        Some(ChainState {
            j: self.j.checked_add(m(c1, d)?)?,
            a: self.a.checked_add(m(c1, self.j)?)?.checked_add(m(c2, d)?)?,
            v: self
                .v
                .checked_add(m(c1, self.a)?)?
                .checked_add(m(c2, self.j)?)?
                .checked_add(m(c3, d)?)?,
            x: self
                .x
                .checked_add(m(c1, self.v)?)?
                .checked_add(m(c2, self.a)?)?
                .checked_add(m(c3, self.j)?)?
                .checked_add(m(c4, d)?)?,
        })
    }

    /// Runs a whole program segment by segment in closed form and returns the final state.
    pub fn run_program(&self, program: &Program, w: &Widths) -> Self {
        program
            .segments
            .iter()
            .fold(*self, |s, seg| s.advance(seg.snap, u64::from(seg.ticks), w))
    }

    /// The state after the first `ticks` ticks of `program` (closed form per segment; past the
    /// program's end the chain keeps its last velocity, acceleration and jerk, as it would
    /// with snap 0).
    pub fn after_ticks(&self, program: &Program, ticks: u64, w: &Widths) -> Self {
        let mut left = ticks;
        let mut s = *self;
        for seg in &program.segments {
            let n = left.min(u64::from(seg.ticks));
            s = s.advance(seg.snap, n, w);
            left -= n;
            if left == 0 {
                return s;
            }
        }
        s.advance(0, left, w)
    }
}

/// The segment sequencer: plays a program one tick at a time, as the fabric does.
#[derive(Clone, Debug)]
pub struct Sequencer<'p> {
    program: &'p Program,
    index: usize,
    left: u32,
}

impl<'p> Sequencer<'p> {
    /// A sequencer at the start of `program`.
    pub fn new(program: &'p Program) -> Self {
        let left = program.segments.first().map_or(0, |s| s.ticks);
        Sequencer {
            program,
            index: 0,
            left,
        }
    }

    /// Index of the segment that the next tick plays (equals the segment count when done).
    pub fn segment_index(&self) -> usize {
        self.index
    }

    /// True while ticks remain.
    pub fn busy(&self) -> bool {
        self.index < self.program.segments.len()
    }

    /// The snap for this tick, or `None` once the program is done.
    #[inline]
    pub fn tick(&mut self) -> Option<i128> {
        let seg = self.program.segments.get(self.index)?;
        let d = seg.snap;
        self.left -= 1;
        if self.left == 0 {
            self.index += 1;
            self.left = self.program.segments.get(self.index).map_or(0, |s| s.ticks);
        }
        Some(d)
    }
}

/// One row of a per-tick trace: the state *after* `tick` ticks, and the snap that was applied
/// on the tick before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TickSample {
    /// Ticks elapsed since the start.
    pub tick: u64,
    /// Index of the segment playing on the next tick.
    pub segment: usize,
    /// Snap applied during the previous tick (0 for the start row).
    pub d: i128,
    /// Registers.
    pub state: ChainState,
}

/// Per-tick trace of a program: the start row, then one row per tick.
pub struct Trace<'p> {
    seq: Sequencer<'p>,
    state: ChainState,
    widths: Widths,
    tick: u64,
    started: bool,
}

impl<'p> Trace<'p> {
    /// Traces `program` from `start`.
    pub fn new(program: &'p Program, start: ChainState, widths: Widths) -> Self {
        Trace {
            seq: Sequencer::new(program),
            state: start,
            widths,
            tick: 0,
            started: false,
        }
    }
}

impl Iterator for Trace<'_> {
    type Item = TickSample;

    fn next(&mut self) -> Option<TickSample> {
        if !self.started {
            self.started = true;
            return Some(TickSample {
                tick: 0,
                segment: self.seq.segment_index(),
                d: 0,
                state: self.state,
            });
        }
        let d = self.seq.tick()?;
        self.state = self.state.step(d, &self.widths);
        self.tick += 1;
        Some(TickSample {
            tick: self.tick,
            segment: self.seq.segment_index(),
            d,
            state: self.state,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn after_ticks_is_the_sequencer_tick_by_tick() {
        let w = crate::DEFAULT_FORMAT.widths;
        let p = Program {
            segments: vec![
                crate::Segment { ticks: 3, snap: 5 },
                crate::Segment { ticks: 1, snap: -9 },
                crate::Segment { ticks: 4, snap: 2 },
            ],
        };
        let start = ChainState::at_rest(17);
        let mut seq = Sequencer::new(&p);
        let mut s = start;
        for k in 0..=10u64 {
            assert_eq!(start.after_ticks(&p, k, &w), s, "tick {k}");
            s = s.step(seq.tick().unwrap_or(0), &w);
        }
    }
    use crate::format::DEFAULT_FORMAT;
    use crate::program::Segment;

    proptest::proptest! {
        #[test]
        fn wrap_sign_extends_the_low_bits_at_every_width(value: i128, bits in 1u32..=128) {
            let s = 128 - bits;
            proptest::prop_assert_eq!(wrap(value, bits), (value << s) >> s);
        }
    }

    #[test]
    fn wrap_at_the_register_edges() {
        assert_eq!(wrap(1 << 103, 104), -(1 << 103));
        assert_eq!(wrap((1 << 103) - 1, 104), (1 << 103) - 1);
        assert_eq!(wrap(-1, 112), -1);
        assert_eq!(wrap(i128::MIN, 128), i128::MIN);
        assert_eq!(wrap(1 << 64, 65), -(1 << 64));
    }

    #[test]
    fn closed_form_equals_per_tick() {
        let w = DEFAULT_FORMAT.widths;
        let start = ChainState {
            x: 17,
            v: -3,
            a: 11,
            j: -5,
        };
        for (d, n) in [(7i128, 1u64), (-4, 9), (0, 13), (123_456_789, 1000)] {
            let mut s = start;
            for _ in 0..n {
                s = s.step(d, &w);
            }
            assert_eq!(start.advance(d, n, &w), s, "d={d} n={n}");
        }
    }

    #[test]
    fn binomials_are_exact() {
        let reference = |n: u64, k: u32| -> u128 {
            let n = u128::from(n);
            (0..u128::from(k)).fold(1u128, |acc, i| acc * (n - i) / (i + 1))
        };
        for n in (0..200u64).chain([(1 << 32) - 1, (1 << 32) - 2, 3_000_000_007, 65_536]) {
            for k in 0..=4 {
                let want = if n < u64::from(k) { 0 } else { reference(n, k) };
                assert_eq!(binomial(n, k), want, "C({n},{k})");
            }
        }
    }

    #[test]
    fn registers_wrap_like_hardware() {
        let w = Widths {
            x: 16,
            v: 8,
            a: 8,
            j: 8,
            d: 8,
        };
        let s = ChainState {
            x: 0,
            v: 127,
            a: 1,
            j: 0,
        }
        .step(0, &w);
        assert_eq!(s.v, -128);
        assert_eq!(s.x, 127);
    }

    #[test]
    fn sequencer_plays_each_segment_for_its_ticks() {
        let p = Program {
            segments: vec![
                Segment { ticks: 2, snap: 1 },
                Segment { ticks: 1, snap: -2 },
            ],
        };
        let mut seq = Sequencer::new(&p);
        let got: Vec<_> = std::iter::from_fn(|| seq.tick()).collect();
        assert_eq!(got, vec![1, 1, -2]);
        assert!(!seq.busy());
    }
}
