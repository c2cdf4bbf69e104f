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

use ethnum::I256;

use super::PhaseTicks;
use crate::chain::ChainState;
use crate::peaks::{peaks, ExactState, Peaks};
use crate::program::{Program, SnapTimeline};

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

/// The program of `shape` with amplitude 1 and the given phase ticks.
pub fn unit_program(shape: Shape, p: &PhaseTicks) -> Program {
    let mut t = SnapTimeline::new();
    match shape {
        Shape::Snap4 => {
            let (td, tj, ta) = (p.d, p.j, p.a);
            let half = 4 * td + 2 * tj + ta;
            let mut pulse_pair = |at: u64, sign: i128| {
                // Eq 63: snap +, 0, −, 0, −, 0, + over one half (negated for deceleration).
                t.add(at, td, sign);
                t.add(at + td + tj, td, -sign);
                t.add(at + 2 * td + tj + ta, td, -sign);
                t.add(at + 3 * td + 2 * tj + ta, td, sign);
            };
            pulse_pair(0, 1);
            pulse_pair(half + p.v, -1);
            t.extend_to(2 * half + p.v);
        }
        Shape::Jerk3 => {
            let (tj, ta) = (p.j, p.a);
            let half = 2 * tj + ta;
            let mut steps = |at: u64, sign: i128| {
                t.impulse(at, sign);
                t.impulse(at + tj, -sign);
                t.impulse(at + tj + ta, -sign);
                t.impulse(at + 2 * tj + ta, sign);
            };
            steps(0, 1);
            steps(half + p.v, -1);
            // The last impulse is the program's last tick: jerk, acceleration and velocity are
            // all back at zero right after it.
            t.extend_to(2 * half + p.v + 1);
        }
        Shape::Accel2 => {
            let ta = p.a;
            let mut step = |at: u64, sign: i128| {
                t.impulse(at, sign);
                t.impulse(at + 1, -sign);
            };
            step(0, 1);
            step(ta, -1);
            step(ta + p.v, -1);
            step(2 * ta + p.v, 1);
            t.extend_to(2 * ta + p.v + 2);
        }
    }
    t.to_program()
        .expect("unit programs have runs shorter than 2^32 ticks (checked by the caller)")
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
    /// The unit program.
    pub program: Program,
    /// Exact end position `P` from rest at 0.
    pub gain: I256,
    /// Exact peaks from rest at 0.
    pub peaks: Peaks,
    /// Exact final state (j = a = v = 0 by construction; checked in tests).
    pub end: ExactState,
}

/// Builds and measures the unit program.
pub fn unit_response(shape: Shape, p: &PhaseTicks) -> UnitResponse {
    let program = unit_program(shape, p);
    let (pk, end) = peaks(&program, &ChainState::default());
    UnitResponse {
        program,
        gain: end.x,
        peaks: pk,
        end,
    }
}

/// `round(x / p)` for `x ≥ 0`, `p > 0`, ties away from zero.
pub fn div_round(x: I256, p: I256) -> I256 {
    (x * 2 + p) / (p * 2)
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
            let u = unit_response(shape, &p);
            assert_eq!(
                (u.end.v, u.end.a, u.end.j),
                (I256::ZERO, I256::ZERO, I256::ZERO),
                "{shape:?} {p:?}"
            );
            assert!(u.gain > 0, "{shape:?} {p:?}");
            assert_eq!(u.program.total_ticks() as u128, unit_ticks(shape, &p));
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
        let u = unit_response(Shape::Snap4, &p);
        assert_eq!(u.peaks.j, I256::from(5));
        assert_eq!(u.peaks.a, I256::from(5 * (5 + 3)));
        // 16 switching times (eq 53) bound 15 segments.
        assert_eq!(u.program.segments.len(), 15);
    }
}
