//! The fabric's controlled stop: from any chain state, to rest exactly, within the stop's jerk
//! and acceleration limits, without reversing — decided tick by tick by the fabric itself, with
//! additions and comparisons only (plus exact series sums when the stop begins). The fabric
//! runs this law as a microprogram on a small word-serial engine ([`micro`], [`program`]).
//!
//! # The law (docs/MODEL.md, "The controlled stop")
//!
//! Raw units per tick: `J` is the largest jerk, `A` the largest acceleration (`J ≤ A`). After a
//! tick the registers hold `(v, a, j)`; the next velocity `V = v + a` and the next acceleration
//! `Λ = a + j` are already decided (the chain adds from the previous tick's values). What the
//! stop chooses is the acceleration after that, the *level* `ℓ = Λ + j'`, through the snap
//! `d = j' − j`. Motion is normalised to the stop's direction (positive velocity).
//!
//! * `D(λ)`: the velocity a release from level `λ < 0` takes off when it steps up by `J` each
//!   tick, `D(λ) = Σ λ + iJ` over the levels below zero (`D(λ) = 0` for `λ ≥ 0`).
//! * `E = V + D(Λ)` is the velocity left when the fastest release from `Λ` ends. `E ≥ 0` means
//!   the stop can still end without reversing; the law keeps it so, updating it with additions:
//!   braking a step further to `Λ − J` makes `E' = E + Λ + min(Λ − J, 0)`; holding the level
//!   makes `E' = E + Λ`; stepping up by `J` leaves `E` as it is.
//! * End game (deadbeat): the level `μ = −(V + Λ)` brings velocity and acceleration to zero on
//!   the two ticks after it. When `−J ≤ μ ≤ 0` and `|μ − Λ| ≤ J` the stop takes it and ends.
//! * Otherwise, in mode *Brake* the stop brakes harder (a step of `J`, or the partial step onto
//!   `−A`, where `E' = V + Λ + D(−A)`) if that keeps `E ≥ 0`; in mode *Hold* it holds `−A` while
//!   that keeps `E ≥ 0`; then it *releases*: it holds a level while `E + Λ ≥ 0` and steps up by
//!   `J` otherwise, which lands on the end game with `E ≤ J`. A stop that begins beyond `−A`
//!   steps up by `J` (`E` unchanged) until within, then brakes onto `−A` if `E` allows.
//!
//! `E ≥ 0` implies `V + Λ ≥ 0`, so the velocity never changes sign; from a state within the
//! limits every branch keeps `|j| ≤ J` and `|a| ≤ A`; and the only way to end is the end game,
//! which lands exactly. A state from which a release at `J` would reverse (`E < 0` when the
//! stop begins: the move was braking toward a reversal, harder than a release at `J` can undo
//! in time) releases at once instead: the acceleration steps to zero on the first level the
//! stop chooses (one tick's jerk of `|Λ|`), and the stop brakes within its limits from there;
//! only a reversal the registers had already decided (`V + Λ < 0`) is landed by the end game
//! (`|μ| < |Λ|`; and `V + Λ = 0`, with `μ = 0`). A stop whose next acceleration `Λ` (already decided when it begins) lies
//! beyond `±A` runs outside `A` until it has stepped back within. Both are reported
//! ([`StopLaw::over_limits`]).
//!
//! The bound, from any state: the stop ends exactly at rest; `|a| ≤ max(A, |Λ₀|)` on every
//! tick; `|j| ≤ J` on every tick but the release's (`|Λ₀|`) and a decided reversal's landing
//! (below `2|Λ₀|`); it never reverses but where the registers had already decided it.

use ethnum::I256;
use serde::{Deserialize, Serialize};

pub mod micro;
pub mod program;

pub use program::{phase_clocks, PhaseClocks};

/// Width of the level count `n`: a release longer than 2^48 − 1 ticks saturates `D`.
pub const SUM_COUNT_BITS: u32 = 48;
/// `D` saturates at `−2^126`: a velocity no register can hold, so `E < 0` whenever it applies.
pub const D_FLOOR: i128 = -(1 << 126);
/// The stop's limits, raw (the chain's per-tick units).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct StopLimits {
    /// Largest |jerk|, raw (> 0).
    pub jerk: i128,
    /// Largest |acceleration|, raw (≥ `jerk`).
    pub accel: i128,
}

impl StopLimits {
    /// True when the fabric can use them: `0 < jerk ≤ accel`.
    pub fn valid(&self) -> bool {
        self.jerk > 0 && self.jerk <= self.accel
    }
}

/// `D(λ)`: the velocity taken off by the fastest release from level `λ` with jerk `j`
/// (`Σ λ + i·j` over the levels below zero), saturated at [`D_FLOOR`]. Exact.
pub fn release_drop(lambda: i128, jerk: i128) -> i128 {
    if lambda >= 0 {
        return 0;
    }
    if jerk <= 0 {
        // No release at all: as good as infinite (the fabric's division overflows).
        return D_FLOOR;
    }
    let l = I256::from(lambda);
    let j = I256::from(jerk);
    // n = ceil(−λ/J) levels below zero: λ, λ + J, …, λ + (n − 1)·J.
    let n = (-l + j - 1) / j;
    if n >= I256::ONE << SUM_COUNT_BITS {
        return D_FLOOR;
    }
    // D = n·λ + J·n(n−1)/2 = n·(2λ + J(n−1))/2, exactly (the numerator is even).
    let d = n * (l * 2 + j * (n - 1)) / 2;
    if d < I256::from(D_FLOOR) {
        D_FLOOR
    } else {
        d.as_i128()
    }
}

/// Where a stop is in its law.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum StopMode {
    /// Braking harder, toward `−A`.
    #[default]
    Brake,
    /// Holding `−A`.
    Hold,
    /// Releasing toward zero acceleration.
    Release,
    /// Landing (deadbeat), or landed.
    End,
}

/// The state of a stop in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct StopLaw {
    limits: StopLimits,
    /// `D(−A)`.
    hold_drop: i128,
    /// +1 or −1: the stop's direction (that of the motion it stops).
    dir: i128,
    /// `E`, normalised.
    excess: i128,
    mode: StopMode,
    /// The state could not be stopped within the limits: the end game ignores them.
    over: bool,
    /// The stop's trace leaves the limits: `over`, or `|Λ| > A` when it begins.
    exceeds: bool,
}

impl StopLaw {
    /// A stop beginning after a tick that left the registers at `(v, a, j)`.
    pub fn begin(v: i128, a: i128, j: i128, limits: StopLimits) -> Self {
        let (vv, lambda) = (v + a, a + j);
        // The direction of the motion: the next velocity's sign, else the next acceleration's.
        let dir = if vv != 0 {
            vv.signum()
        } else if lambda != 0 {
            lambda.signum()
        } else {
            1
        };
        let (vn, ln) = (dir * vv, dir * lambda);
        let excess = vn.saturating_add(release_drop(ln, limits.jerk));
        StopLaw {
            limits,
            hold_drop: release_drop(-limits.accel, limits.jerk),
            dir,
            excess,
            mode: StopMode::Brake,
            over: excess < 0,
            exceeds: excess < 0 || ln.abs() > limits.accel,
        }
    }

    /// The stop's direction: +1 or −1.
    pub fn direction(&self) -> i128 {
        self.dir
    }

    /// True when the stop leaves its limits on some tick: the state it began from could not
    /// be stopped within them (the end game then lands it regardless of them), or its next
    /// acceleration was already beyond `±A`.
    pub fn over_limits(&self) -> bool {
        self.exceeds
    }

    /// Where the law is.
    pub fn mode(&self) -> StopMode {
        self.mode
    }

    /// The jerk for the tick after next, given the registers `(v, a, j)` after the last tick;
    /// the snap to feed is `next_jerk − j`. Returns `None` once the stop is over: the registers
    /// are at rest (v = a = j = 0).
    pub fn next_jerk(&mut self, v: i128, a: i128, j: i128) -> Option<i128> {
        if v == 0 && a == 0 && j == 0 {
            self.mode = StopMode::End;
            return None;
        }
        let (jm, lo) = (self.limits.jerk, -self.limits.accel);
        let (vv, lambda) = (self.dir * (v + a), self.dir * (a + j));
        let level = self.level(vv, lambda, jm, lo);
        Some(self.dir * (level - lambda))
    }

    /// The next level, normalised.
    fn level(&mut self, vv: i128, lambda: i128, jm: i128, lo: i128) -> i128 {
        let mu = -(vv + lambda);
        if self.over && mu < 0 {
            // Even the fastest release at J would reverse, but the next velocity and
            // acceleration do not (V + Λ > 0): the acceleration steps to zero at once (one
            // tick's jerk of |Λ|, never a larger acceleration than the motion had), then the
            // stop brakes within its limits from there (E = V + Λ: a release from level 0
            // takes nothing off).
            self.over = false;
            self.excess = vv + lambda;
            self.mode = StopMode::Brake;
            return 0;
        }
        // End game: land in two ticks (from `over`: a reversal the registers had already
        // decided, V + Λ < 0, where |μ| < |Λ|; or V + Λ = 0, where μ = 0).
        if self.over || (-jm <= mu && mu <= 0 && (mu - lambda).abs() <= jm) {
            self.mode = StopMode::End;
            return mu;
        }
        if self.mode == StopMode::Brake {
            if lambda < lo {
                // A stop that began beyond the limit: step up on the level grid (E stays as it
                // is); once within, braking onto −A is reconsidered with E.
                return lambda + jm;
            }
            if lambda > lo {
                let b = (lambda - jm).max(lo);
                let e = if b == lo {
                    vv + lambda + self.hold_drop
                } else {
                    self.excess + lambda + b.min(0)
                };
                if e >= 0 {
                    self.excess = e;
                    if b == lo {
                        self.mode = StopMode::Hold;
                    }
                    return b;
                }
                self.mode = StopMode::Release;
            } else {
                self.mode = StopMode::Hold;
            }
        }
        if self.mode == StopMode::Hold {
            if self.excess + lambda >= 0 {
                self.excess += lambda;
                return lambda;
            }
            self.mode = StopMode::Release;
        }
        // Release (levels only rise here, from −A or above): hold while E allows, step up
        // otherwise.
        if self.excess + lambda >= 0 {
            self.excess += lambda;
            lambda
        } else {
            lambda + jm
        }
    }
}

/// A whole stop played on the chain from `(x, v, a, j)` after a tick: every tick's registers,
/// until rest. For tests and the host's prediction; the fabric decides tick by tick.
pub fn play(
    start: crate::ChainState,
    limits: StopLimits,
    max_ticks: u64,
) -> (Vec<crate::ChainState>, StopLaw) {
    let mut law = StopLaw::begin(start.v, start.a, start.j, limits);
    let mut s = start;
    let mut out = Vec::new();
    for _ in 0..max_ticks {
        let Some(next_j) = law.next_jerk(s.v, s.a, s.j) else {
            break;
        };
        let d = next_j - s.j;
        s = crate::ChainState {
            x: s.x + s.v,
            v: s.v + s.a,
            a: s.a + s.j,
            j: s.j + d,
        };
        out.push(s);
    }
    (out, law)
}

/// A controlled stop that explains where a program ended: it was taken on program tick
/// `taken` and ran `ticks` ticks to rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StopFound {
    /// The program tick that took the stop (the chain stepped with the program's snap on it).
    pub taken: u64,
    /// Ticks of the stop after it.
    pub ticks: u64,
    /// The stop began outside its limits.
    pub over_limits: bool,
}

/// Which controlled stop ends a run of `program` from `start` at `end` after `tick_count`
/// ticks (the fabric's count: program ticks, then stop ticks), if one taken on a program tick
/// in `from..=tick_count` does: the host's bit-for-bit check of a stop whose exact tick it
/// could not know. Every candidate is played tick by tick with the law.
pub fn explain(
    start: crate::ChainState,
    program: &crate::Program,
    widths: &crate::Widths,
    limits: StopLimits,
    end: crate::ChainState,
    tick_count: u64,
    from: u64,
) -> Option<StopFound> {
    let last = tick_count.min(program.total_ticks());
    (from..=last).find_map(|k| {
        let at = start.after_ticks(program, k, widths);
        let (trace, law) = play(at, limits, tick_count - k);
        let stop_end = trace.last().copied().unwrap_or(at);
        (k + trace.len() as u64 == tick_count && stop_end == end && end.is_at_rest()).then_some(
            StopFound {
                taken: k,
                ticks: trace.len() as u64,
                over_limits: law.over_limits(),
            },
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ChainState;
    use proptest::prelude::*;

    fn brute_drop(lambda: i128, jerk: i128) -> i128 {
        let mut d = 0;
        let mut l = lambda;
        while l < 0 {
            d += l;
            l += jerk;
        }
        d
    }

    #[test]
    fn release_drop_by_hand() {
        // Levels −10, −7, −4, −1: −22.
        assert_eq!(release_drop(-10, 3), -22);
        assert_eq!(release_drop(-9, 3), -18);
        assert_eq!(release_drop(-1, 3), -1);
        assert_eq!(release_drop(0, 3), 0);
        assert_eq!(release_drop(5, 3), 0);
        // Past 2^48 levels: saturated.
        assert_eq!(release_drop(-(1 << 100), 1), D_FLOOR);
    }

    proptest! {
        #[test]
        fn release_drop_is_the_sum(lambda in -5000i128..100, jerk in 1i128..300) {
            prop_assert_eq!(release_drop(lambda, jerk), brute_drop(lambda, jerk));
        }

        #[test]
        fn release_drop_at_scale(lambda in -(1i128 << 100)..0, jerk in (1i128 << 70)..(1i128 << 90)) {
            let n = (-lambda + jerk - 1) / jerk;
            let want = n * lambda + jerk * (n * (n - 1) / 2);
            prop_assert_eq!(release_drop(lambda, jerk), want);
        }
    }

    /// The host finds the tick a stop was taken on from where it ended, and nothing else
    /// explains that end.
    #[test]
    fn explain_finds_the_tick_a_stop_was_taken_on() {
        use crate::program::{Program, Segment};
        let w = crate::DEFAULT_FORMAT.widths;
        let p = Program {
            segments: vec![
                Segment { ticks: 1, snap: 40 },
                Segment { ticks: 9, snap: 0 },
                Segment {
                    ticks: 1,
                    snap: -40,
                },
                Segment {
                    ticks: 200,
                    snap: 0,
                },
                Segment {
                    ticks: 1,
                    snap: -40,
                },
                Segment { ticks: 9, snap: 0 },
                Segment { ticks: 1, snap: 40 },
            ],
        };
        let limits = StopLimits {
            jerk: 7,
            accel: 200,
        };
        let start = ChainState::at_rest(0);
        for taken in [5u64, 60, 150] {
            let at = start.after_ticks(&p, taken, &w);
            let (trace, _) = play(at, limits, 1 << 20);
            let end = *trace.last().unwrap();
            let n = taken + trace.len() as u64;
            let found = explain(start, &p, &w, limits, end, n, 0).unwrap();
            assert_eq!((found.taken, found.ticks), (taken, trace.len() as u64));
            // A different end is not explained.
            let wrong = ChainState {
                x: end.x + 1,
                ..end
            };
            assert_eq!(explain(start, &p, &w, limits, wrong, n, 0), None);
        }
    }

    /// From cruise at velocity v with a = j = 0: at rest, no reversal, within limits.
    #[test]
    fn a_stop_from_cruise_lands_at_rest() {
        let limits = StopLimits {
            jerk: 7,
            accel: 100,
        };
        let (trace, law) = play(
            ChainState {
                x: 0,
                v: 123_457,
                a: 0,
                j: 0,
            },
            limits,
            100_000,
        );
        let end = trace.last().unwrap();
        assert!(end.is_at_rest(), "{end:?}");
        assert!(!law.over_limits());
        assert!(trace
            .iter()
            .all(|s| s.v >= 0 && s.a.abs() <= 100 && s.j.abs() <= 7));
    }
}
