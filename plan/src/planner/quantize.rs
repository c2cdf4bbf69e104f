//! From planned phase times to an integer program with an exact endpoint.
//!
//! The continuous planners fix the phase times (whole ticks). The amplitude (snap for order 4,
//! jerk for order 3, acceleration for order 2) is then chosen on the *discrete* chain, not from
//! the continuous formulas:
//!
//! 1. Build the *unit program*: the profile's shape with amplitude 1 (order 4: ±1 snap
//!    segments; orders 3 and 2: ±1 one-tick snap impulses that step the jerk, or impulse pairs
//!    that step the acceleration).
//! 2. Run it in closed form ([`snapgen_model::peaks`]): its exact end position `P` (the *position gain*)
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

use super::PhaseTicks;
use snapgen_model::format::Quantity;
use snapgen_model::program::{Program, Segment};

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

/// A short list of `(ticks, snap)` pieces of a unit program, on the stack (at most 17 for
/// these shapes). Unit snaps are small (±1, ±2 where impulses coincide) and a unit program
/// lasts fewer than 2^32 ticks (checked before it is built), so a piece is 5 bytes.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pieces {
    items: [(u32, i8); 17],
    len: usize,
    /// Largest |jerk| the pieces reach (from rest).
    jerk_peak: i64,
    /// Largest |snap| of a piece with ticks.
    snap_peak: i64,
}

impl Pieces {
    #[inline(always)]
    fn push(&mut self, (ticks, snap): (u64, i128)) {
        debug_assert!(
            ticks < 1 << 32,
            "unit programs are checked to last < 2^32 ticks"
        );
        debug_assert!(snap.abs() <= 4, "unit snaps are small");
        self.items[self.len] = (ticks as u32, snap as i8);
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
    #[inline]
    pub fn as_slice(&self) -> &[(u32, i8)] {
        &self.items[..self.len]
    }

    /// The program with amplitude `k`: empty pieces dropped, equal neighbours joined.
    pub fn to_program(&self, k: i128) -> Program {
        let mut out = Program {
            segments: Vec::with_capacity(self.len),
        };
        self.write_program(k, &mut out);
        out
    }

    /// [`Pieces::to_program`] into `out`, reusing its memory.
    pub fn write_program(&self, k: i128, out: &mut Program) {
        let out = &mut out.segments;
        out.clear();
        for &(ticks, snap) in self.as_slice() {
            if ticks == 0 {
                continue;
            }
            let snap = i128::from(snap) * k;
            match out.last_mut() {
                Some(last) if last.snap == snap => last.ticks += ticks,
                _ => out.push(Segment { ticks, snap }),
            }
        }
    }
}

/// Pieces `(ticks, snap)` from one-tick snap impulses `(tick, snap)` (coinciding impulses
/// add), zero snap between them, lasting `total` ticks.
#[inline]
fn impulse_pieces(impulses: &mut [(u64, i128)], total: u64) -> Pieces {
    // The shapes list their impulses in tick order except when a phase is empty (a trapezoid
    // without cruise); sort only then.
    if !impulses.windows(2).all(|w| w[0].0 <= w[1].0) {
        impulses.sort_unstable_by_key(|&(t, _)| t);
    }
    let mut out = Pieces::default();
    let mut at = 0u64;
    let mut i = 0;
    // The jerk only changes at an impulse: its peak is the largest prefix sum.
    let mut jerk = 0i64;
    while i < impulses.len() {
        let t = impulses[i].0;
        let mut d = 0i128;
        while i < impulses.len() && impulses[i].0 == t {
            d += impulses[i].1;
            i += 1;
        }
        out.push((t - at, 0));
        out.push((1, d));
        jerk += d as i64;
        out.jerk_peak = out.jerk_peak.max(jerk.abs());
        out.snap_peak = out.snap_peak.max((d as i64).abs());
        at = t + 1;
    }
    out.push((total - at, 0));
    out
}

/// The unit profile of `shape` as pieces of constant snap, one per phase (not merged, some
/// possibly empty): every register is monotonic inside a piece.
#[inline]
fn unit_pieces(shape: Shape, p: &PhaseTicks) -> Pieces {
    let total = u64::try_from(unit_ticks(shape, p)).expect("checked by the caller");
    match shape {
        Shape::Snap4 => {
            let (td, tj, ta, tv) = (p.d, p.j, p.a, p.v);
            // Eq 63: snap +, 0, −, 0, −, 0, + over the accel half; the decel half negated.
            // The jerk ramps to ±td and back in each snap pair: its peak is td; the snap's is 1.
            let mut pieces = Pieces::from_slice(&[
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
            ]);
            pieces.jerk_peak = td as i64;
            pieces.snap_peak = 1;
            pieces
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

/// Exact peak magnitudes of a unit program from rest (its position peak is its gain).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitPeaks {
    /// max |v|.
    pub v: u128,
    /// max |a|.
    pub a: u128,
    /// max |j|.
    pub j: u128,
    /// max |d|.
    pub d: u128,
}

impl UnitPeaks {
    /// The peak of `q` (position: none, 0).
    pub fn get(&self, q: Quantity) -> u128 {
        match q {
            Quantity::Velocity => self.v,
            Quantity::Acceleration => self.a,
            Quantity::Jerk => self.j,
            Quantity::Snap => self.d,
            Quantity::Position => 0,
        }
    }
}

/// What the unit program does: exact gain and peaks from rest (its end is at rest, checked by
/// the tests on an independent integration).
#[derive(Clone, Debug)]
pub struct UnitResponse {
    /// The unit profile's phases.
    pub pieces: Pieces,
    /// Exact end position `P` from rest at 0.
    pub gain: u128,
    /// Exact peaks from rest at 0.
    pub peaks: UnitPeaks,
}

/// Builds and measures the unit program; `None` if it lasts 2^32 ticks or more or a value
/// leaves `i128` (such a move is far
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
#[inline]
pub fn unit_response(shape: Shape, p: &PhaseTicks) -> Option<UnitResponse> {
    if unit_ticks(shape, p) >= 1 << 32 {
        return None;
    }
    let pieces = unit_pieces(shape, p);
    let (jpk, dpk) = (pieces.jerk_peak, pieces.snap_peak);
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
        gain: x as u128,
        peaks: UnitPeaks {
            v: v as u128,
            a: a as u128,
            j: jpk as u128,
            d: dpk as u128,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ethnum::I256;

    /// `program` integrated from rest by snapgen-verify.
    fn integrate_from_rest(program: &Program) -> snapgen_verify::Integration {
        snapgen_verify::integrate(
            snapgen_verify::State::default(),
            program
                .segments
                .iter()
                .map(|s| (u64::from(s.ticks), s.snap)),
        )
    }

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
            // Integrated independently (snapgen-verify), not read off the unit response.
            let r = integrate_from_rest(&program);
            assert!(r.end.at_rest(), "{shape:?} {p:?}: {:?}", r.end);
            assert!(r.end.x > 0, "{shape:?} {p:?}");
            assert_eq!(
                r.end.x,
                I256::from(u.gain),
                "{shape:?} {p:?}: the gain is where it ends"
            );
            assert_eq!(u128::from(r.ticks), unit_ticks(shape, &p));
        }
    }

    #[test]
    fn unit_peaks_match_the_chain() {
        use snapgen_model::chain::ChainState;
        use snapgen_model::peaks::peaks;
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
                            let program = u.pieces.to_program(1);
                            let (full, _) = peaks(&program, &ChainState::default());
                            let pk = u.peaks;
                            assert_eq!(
                                [pk.v, pk.a, pk.j, pk.d].map(I256::from),
                                [full.v, full.a, full.j, full.d],
                                "{shape:?} {p:?}"
                            );
                            assert_eq!(I256::from(u.gain), full.x);
                            // And against the independent integration (snapgen-verify).
                            let r = integrate_from_rest(&program);
                            let ext = [0, 1, 2, 3, 4].map(|k| r.range(k).max_abs());
                            assert_eq!(
                                ext,
                                [u.gain, pk.v, pk.a, pk.j, pk.d].map(I256::from),
                                "{shape:?} {p:?}"
                            );
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
        assert_eq!(u.peaks.j, 5);
        assert_eq!(u.peaks.a, 5 * (5 + 3));
        // 16 switching times (eq 53) bound 15 segments.
        assert_eq!(u.pieces.to_program(1).segments.len(), 15);
    }
}
