//! From planned phase times to an integer program with an exact endpoint.
//!
//! The continuous planners fix the phase times (whole ticks). The amplitude (snap for order 4,
//! jerk for order 3, acceleration for order 2) is then chosen on the *discrete* chain, not from
//! the continuous formulas:
//!
//! 1. Build the *unit program*: the profile's shape with amplitude 1 (order 4: ±1 snap
//!    segments; orders 3 and 2: ±1 one-tick snap impulses that step the jerk, or impulse pairs
//!    that step the acceleration).
//! 2. Run it in closed form ([`crate::peaks`]): its exact end position `P` (the *position gain*)
//!    and its exact register peaks. The chain is linear and starts at rest, so amplitude `K`
//!    moves exactly `K·P` and peaks at exactly `K·peak`.
//! 3. `K = round(X / P)` where `X` is the distance from the start register to the *centre* of
//!    the target output cell. The residual `|K·P − X| ≤ P/2`; the format requires `P < 2^F`,
//!    so the residual is below half an output LSB and the output lands exactly on the target.
//! 4. The limits hold on the integer trace: `K ≤ K_lim = min(floor(limit_raw / unit_peak))`.
//!    If rounding asked for more, the cruise is lengthened by the closed-form number of ticks
//!    that brings `X / P` down to `K_lim` (each cruise tick adds the unit cruise velocity to `P`).
//!
//! Because the unit program's accel and decel halves cancel, jerk, acceleration and velocity
//! end at exactly 0 for every amplitude.

use core::ops::Range;

use ethnum::I256;

use super::PhaseTicks;
use crate::peaks::{ExactState, Peaks};
use crate::program::{Program, Segment};

/// Profile shapes the quantizer knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Snap segments (seed 000, 15 or 16 segments).
    Snap4,
    /// Jerk steps as one-tick snap impulses (seven-segment S-curve).
    Jerk3,
    /// Acceleration steps as impulse pairs (trapezoid).
    Accel2,
}

/// A short list of `(ticks, snap)` pieces, on the stack (at most 17 for these shapes).
#[derive(Clone, Copy, Debug, Default)]
pub struct Pieces {
    items: [(u64, i128); 17],
    len: usize,
}

impl Pieces {
    fn push(&mut self, piece: (u64, i128)) {
        self.items[self.len] = piece;
        self.len += 1;
    }

    fn from_slice(s: &[(u64, i128)]) -> Self {
        let mut p = Pieces::default();
        for &x in s {
            p.push(x);
        }
        p
    }

    /// The pieces.
    pub fn as_slice(&self) -> &[(u64, i128)] {
        &self.items[..self.len]
    }

    /// Index of the segment of `program` (built by [`Pieces::to_program`]) that is the cruise:
    /// the zero-snap segment lying inside `cruise` (ticks from the program start, half-open)
    /// and ending at its end, if there is one. A zero-snap segment that begins before the
    /// cruise (an acceleration plateau joined to it, or a triangular profile with no cruise at
    /// all) is not a cruise: cutting it would leave the axis moving.
    pub fn cruise_segment(program: &Program, cruise: Range<u64>) -> Option<usize> {
        let mut end = 0u64;
        for (i, s) in program.segments.iter().enumerate() {
            let start = end;
            end += u64::from(s.ticks);
            if end == cruise.end {
                return (s.snap == 0 && start >= cruise.start && start < end).then_some(i);
            }
            if end > cruise.end {
                return None;
            }
        }
        None
    }

    /// The program with amplitude `k`: empty pieces dropped, equal neighbours joined.
    pub fn to_program(&self, k: i128) -> Program {
        let mut out: Vec<Segment> = Vec::with_capacity(self.len);
        for &(ticks, snap) in self.as_slice() {
            if ticks == 0 {
                continue;
            }
            let ticks =
                u32::try_from(ticks).expect("unit programs are checked to last < 2^32 ticks");
            let snap = snap * k;
            match out.last_mut() {
                Some(last) if last.snap == snap => last.ticks += ticks,
                _ => out.push(Segment { ticks, snap }),
            }
        }
        Program { segments: out }
    }
}

/// Pieces `(ticks, snap)` from one-tick snap impulses `(tick, snap)` (coinciding impulses
/// add), zero snap between them, lasting `total` ticks.
fn impulse_pieces(impulses: &mut [(u64, i128)], total: u64) -> Pieces {
    impulses.sort_unstable_by_key(|&(t, _)| t);
    let mut out = Pieces::default();
    let mut at = 0u64;
    let mut i = 0;
    while i < impulses.len() {
        let t = impulses[i].0;
        let mut d = 0i128;
        while i < impulses.len() && impulses[i].0 == t {
            d += impulses[i].1;
            i += 1;
        }
        out.push((t - at, 0));
        out.push((1, d));
        at = t + 1;
    }
    out.push((total - at, 0));
    out
}

/// The unit profile of `shape` as pieces of constant snap, one per phase (not merged, some
/// possibly empty): every register is monotonic inside a piece.
fn unit_pieces(shape: Shape, p: &PhaseTicks) -> Pieces {
    let total = u64::try_from(unit_ticks(shape, p)).expect("checked by the caller");
    match shape {
        Shape::Snap4 => {
            let (td, tj, ta, tv) = (p.d, p.j, p.a, p.v);
            // Eq 63: snap +, 0, −, 0, −, 0, + over the accel half; the decel half negated.
            Pieces::from_slice(&[
                (td, 1),
                (tj, 0),
                (td, -1),
                (ta, 0),
                (td, -1),
                (tj, 0),
                (td, 1),
                (tv, 0),
                (td, -1),
                (tj, 0),
                (td, 1),
                (ta, 0),
                (td, 1),
                (tj, 0),
                (td, -1),
            ])
        }
        Shape::Jerk3 => {
            // Jerk steps +, −, −, + at the phase boundaries of each half. The last impulse is
            // the program's last tick: jerk, acceleration and velocity are all back at zero
            // right after it.
            let (tj, ta) = (p.j, p.a);
            let o = 2 * tj + ta + p.v;
            let mut imp = [
                (0, 1),
                (tj, -1),
                (tj + ta, -1),
                (2 * tj + ta, 1),
                (o, -1),
                (o + tj, 1),
                (o + tj + ta, 1),
                (o + 2 * tj + ta, -1),
            ];
            impulse_pieces(&mut imp, total)
        }
        Shape::Accel2 => {
            // An acceleration step of c is the impulse pair (c, −c) on consecutive ticks.
            let ta = p.a;
            let o = ta + p.v;
            let mut imp = [
                (0, 1),
                (1, -1),
                (ta, -1),
                (ta + 1, 1),
                (o, -1),
                (o + 1, 1),
                (o + ta, 1),
                (o + ta + 1, -1),
            ];
            impulse_pieces(&mut imp, total)
        }
    }
}

/// The program of `shape` with amplitude 1 and the given phase ticks.
pub fn unit_program(shape: Shape, p: &PhaseTicks) -> Program {
    unit_pieces(shape, p).to_program(1)
}

/// The ticks of a unit program of `shape` during which the velocity is constant and jerk,
/// acceleration and snap are zero (half-open, from the program start): from the end of the
/// acceleration half (after its last snap piece or impulse) to where deceleration starts.
/// Empty when the profile has no cruise.
pub fn cruise_ticks(shape: Shape, p: &PhaseTicks) -> Range<u64> {
    let (start, end) = match shape {
        // Eq 63: the acceleration half is 4·T_d + 2·T_j + T_a ticks of pieces.
        Shape::Snap4 => (4 * p.d + 2 * p.j + p.a, 4 * p.d + 2 * p.j + p.a + p.v),
        // The jerk impulse at tick 2·T_j + T_a ends the acceleration half.
        Shape::Jerk3 => (2 * p.j + p.a + 1, 2 * p.j + p.a + p.v),
        // The acceleration step back to zero is the impulse pair at T_a, T_a + 1.
        Shape::Accel2 => (p.a + 2, p.a + p.v),
    };
    start..end.max(start)
}

/// The total ticks of a unit program of `shape`, without building it.
pub fn unit_ticks(shape: Shape, p: &PhaseTicks) -> u128 {
    let (d, j, a, v) = (
        u128::from(p.d),
        u128::from(p.j),
        u128::from(p.a),
        u128::from(p.v),
    );
    match shape {
        Shape::Snap4 => 8 * d + 4 * j + 2 * a + v,
        Shape::Jerk3 => 4 * j + 2 * a + v + 1,
        Shape::Accel2 => 2 * a + v + 2,
    }
}

/// What the unit program does: exact gain and peaks from rest.
#[derive(Clone, Debug)]
pub struct UnitResponse {
    /// The unit profile's phases.
    pub pieces: Pieces,
    /// Exact end position `P` from rest at 0.
    pub gain: I256,
    /// Exact peaks from rest at 0.
    pub peaks: Peaks,
    /// Exact final state (j = a = v = 0 by construction; checked in tests).
    pub end: ExactState,
}

/// Builds and measures the unit program; `None` if a value leaves `i128` (such a move is far
/// outside every format: its gain is past 2^80).
///
/// The discrete chain reproduces the continuous relations *exactly* for these symmetric
/// shapes (each register updates from the previous tick's values, and the rectangle-rule
/// errors of a ramp up and its mirrored ramp down cancel), so the unit's peaks and gain are:
///
/// ```text
/// order 4: a = td·(td+tj)   v = a·(2td+tj+ta)   P = v·(4td+2tj+ta+tv)
/// order 3: a = tj           v = tj·(tj+ta)      P = v·(2tj+ta+tv)
/// order 2: a = 1            v = ta              P = ta·(ta+tv)
/// ```
///
/// Jerk and snap peaks are read off the phases (the jerk is linear inside each one).
/// `unit_peaks_match_the_chain` checks all of it against a full closed-form run of the chain,
/// and the property tests against a per-tick trace.
pub fn unit_response(shape: Shape, p: &PhaseTicks) -> Option<UnitResponse> {
    let pieces = unit_pieces(shape, p);
    let (mut j, mut jpk, mut dpk) = (0i128, 0i128, 0i128);
    for &(ticks, snap) in pieces.as_slice() {
        // ticks < 2^32 and |snap| ≤ 2: no overflow.
        j += i128::from(ticks) * snap;
        jpk = jpk.max(j.abs());
        if ticks > 0 {
            dpk = dpk.max(snap.abs());
        }
    }
    let w = |t: u64| i128::from(t);
    let m = |a: i128, b: i128| a.checked_mul(b);
    let (a, v, x) = match shape {
        Shape::Snap4 => {
            let (td, tj, ta, tv) = (w(p.d), w(p.j), w(p.a), w(p.v));
            let a = m(td, td + tj)?;
            let v = m(a, 2 * td + tj + ta)?;
            (a, v, m(v, 4 * td + 2 * tj + ta + tv)?)
        }
        Shape::Jerk3 => {
            let (tj, ta, tv) = (w(p.j), w(p.a), w(p.v));
            let v = m(tj, tj + ta)?;
            (tj, v, m(v, 2 * tj + ta + tv)?)
        }
        Shape::Accel2 => {
            let (ta, tv) = (w(p.a), w(p.v));
            (1, ta, m(ta, ta + tv)?)
        }
    };
    Some(UnitResponse {
        pieces,
        gain: I256::from(x),
        peaks: Peaks {
            x: I256::from(x),
            v: I256::from(v),
            a: I256::from(a),
            j: I256::from(jpk),
            d: I256::from(dpk),
        },
        end: ExactState {
            x: I256::from(x),
            ..Default::default()
        },
    })
}

/// `ceil(x / p)` for `x ≥ 0`, `p > 0`.
pub fn div_ceil(x: I256, p: I256) -> I256 {
    (x + p - 1) / p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_programs_end_at_rest() {
        for (shape, p) in [
            (
                Shape::Snap4,
                PhaseTicks {
                    d: 3,
                    j: 2,
                    a: 5,
                    v: 7,
                },
            ),
            (
                Shape::Snap4,
                PhaseTicks {
                    d: 1,
                    j: 0,
                    a: 0,
                    v: 0,
                },
            ),
            (
                Shape::Jerk3,
                PhaseTicks {
                    d: 0,
                    j: 4,
                    a: 0,
                    v: 3,
                },
            ),
            (
                Shape::Jerk3,
                PhaseTicks {
                    d: 0,
                    j: 1,
                    a: 0,
                    v: 0,
                },
            ),
            (
                Shape::Accel2,
                PhaseTicks {
                    d: 0,
                    j: 0,
                    a: 1,
                    v: 0,
                },
            ),
            (
                Shape::Accel2,
                PhaseTicks {
                    d: 0,
                    j: 0,
                    a: 6,
                    v: 9,
                },
            ),
        ] {
            let u = unit_response(shape, &p).unwrap();
            let program = u.pieces.to_program(1);
            assert_eq!(
                (u.end.v, u.end.a, u.end.j),
                (I256::ZERO, I256::ZERO, I256::ZERO),
                "{shape:?} {p:?}"
            );
            assert!(u.gain > 0, "{shape:?} {p:?}");
            assert_eq!(program.total_ticks() as u128, unit_ticks(shape, &p));
        }
    }

    #[test]
    fn unit_peaks_match_the_chain() {
        use crate::chain::ChainState;
        use crate::peaks::peaks;
        for shape in [Shape::Snap4, Shape::Jerk3, Shape::Accel2] {
            for d in 0..4u64 {
                for j in 0..4u64 {
                    for a in 0..4u64 {
                        for v in 0..3u64 {
                            let p = PhaseTicks {
                                d: if shape == Shape::Snap4 { d + 1 } else { 0 },
                                j: if shape == Shape::Jerk3 {
                                    j + 1
                                } else {
                                    j * (shape == Shape::Snap4) as u64
                                },
                                a: if shape == Shape::Accel2 { a + 1 } else { a },
                                v,
                            };
                            let u = unit_response(shape, &p).unwrap();
                            let (full, end) =
                                peaks(&u.pieces.to_program(1), &ChainState::default());
                            assert_eq!(u.peaks, full, "{shape:?} {p:?}");
                            assert_eq!(u.end, end);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn order4_unit_peaks_follow_the_relations() {
        // j_peak = td and a_peak = td·(td+tj) hold exactly on the discrete chain.
        let p = PhaseTicks {
            d: 5,
            j: 3,
            a: 4,
            v: 2,
        };
        let u = unit_response(Shape::Snap4, &p).unwrap();
        assert_eq!(u.peaks.j, I256::from(5));
        assert_eq!(u.peaks.a, I256::from(5 * (5 + 3)));
        // 16 switching times (eq 53) bound 15 segments.
        assert_eq!(u.pieces.to_program(1).segments.len(), 15);
    }
}
