//! From a continuous profile to an exact integer program, from any start state.
//!
//! The rest-to-rest planners are exact because the move is one unit program scaled by one
//! integer (§5 of docs/MODEL.md); from an arbitrary start the chain's own state adds a term no
//! scale can absorb. The method here (docs/MODEL.md §11):
//!
//! 1. **Whole ticks.** Every piece of the continuous profile is rounded to whole ticks (the
//!    planner decides how, `super::problem`), jerk pieces and the cruise to at least one tick
//!    so that each keeps a free level; a one-tick *settle* piece returns the highest
//!    derivative to zero at the end.
//! 2. **Levels by a linear solve.** With the tick counts fixed, the chain is linear in the piece
//!    levels, so the end state is `F = F₀ + M·p` (`F₀` the start state played with every free
//!    level zero, `M`'s columns the unit levels played from rest). The free levels `p` solve
//!    the end conditions: acceleration zero in the cruise and at the end, the end velocity,
//!    the end position (position targets) — four equations, four levels for order 3; the
//!    acceleration levels of order 2 make the acceleration exact by construction, leaving two.
//!    `M` is factored once (LU).
//! 3. **Integers, and refinements.** The levels are rounded to integers, the program is
//!    played exactly, and the exact residual is solved again (`M·δ = r`), rounded and added in
//!    integers, up to twice (until the correction is zero): what is left is the rounding of
//!    the levels, a few raw LSBs of acceleration and velocity.
//! 4. **The unimodular tail.** Three one-tick snaps `s₁, s₂, s₃` take any residual
//!    `(v, a, j)` to exactly `(V, 0, 0)`: `v₃ = v + 3a + 3j + s₁`,
//!    `a₃ = a + 3j + 2s₁ + s₂`, `j₃ = j + s₁ + s₂ + s₃`. The matrix
//!    `[[1,0,0],[2,1,0],[1,1,1]]` has determinant 1, so the integer solution
//!    `s₁ = V − v − 3a − 3j`, `s₂ = −a − 3j − 2s₁`, `s₃ = −j − s₁ − s₂` always exists and is as
//!    small as the residual. The tail moves the position by `3v + 3a + j`, which the aim
//!    includes.
//!
//! The result is checked, not assumed: the final state must be exactly the requested one and
//! the position in the target cell, and every tick must stay within the limits: exactly, a
//! piece at a time (`check_pieces`; the segment-level [`check_limits`] is the reference the
//! unit tests compare it with).
//!
//! Everything is computed a *piece* at a time in closed form (a piece: its jerk set on its
//! first tick, held for the rest), in `f64` for the solve and in checked `i128` for the
//! integers; the program's segments are written once, from the final levels.

use arrayvec::ArrayVec;

use snapgen_model::chain::ChainState;
use snapgen_model::program::{Program, Segment};

mod affine;
mod check;
mod jerk;
mod lu;

use affine::*;
pub use affine::{piece_end, to_f64};
pub use check::check_limits;
use check::*;
use jerk::*;
use lu::*;

/// Largest number of free levels.
pub const MAX_FREE: usize = 4;

/// Largest number of pieces (two transitions of three, the cruise, the settle).
pub const MAX_PIECES: usize = 8;

/// Largest number of jerk pieces: order 2 plays each piece as an impulse and a hold.
const MAX_JERK_PIECES: usize = 2 * MAX_PIECES;

/// One discrete piece of the profile: `ticks` ticks of the highest derivative at a level that is
/// free (index into the levels) or zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DPiece {
    /// Ticks (≥ 1).
    pub ticks: u64,
    /// Free level index, or `None` for a zero level.
    pub free: Option<usize>,
    /// Which acceleration cap applies (index into [`Caps::a`]).
    pub cap: usize,
    /// A piece at zero level (a hold or the cruise) whose ticks may be lent to a neighbouring
    /// free piece that needs more time (`fit` in the planner).
    pub slack: bool,
    /// A hold: the sign of the acceleration it holds in the continuous profile (`+1` in a
    /// rising transition, `−1` in a falling one); 0 for other pieces.
    pub held: i8,
}

/// An end condition: a register at the end of a piece.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Condition {
    /// Acceleration at the end of piece `i` equals the value.
    A(usize),
    /// Velocity at the end of the last piece.
    V,
    /// Position at the end of the last piece.
    X,
}

/// The discrete problem: pieces, conditions and their right-hand sides.
#[derive(Clone, Debug)]
pub struct Problem {
    /// Profile order (3: levels are jerks; 2: levels are accelerations).
    pub order: u8,
    /// Pieces, in play order; the last one is the settle piece.
    pub pieces: ArrayVec<DPiece, MAX_PIECES>,
    /// Number of free levels.
    pub free: usize,
    /// Conditions (as many as free levels).
    pub conditions: ArrayVec<Condition, MAX_FREE>,
    /// End velocity (raw per tick).
    pub v_end: i128,
    /// Side the end velocity is approached from: `+1` from below (a rising last transition),
    /// `−1` from above.
    pub approach: i128,
    /// Position the end of the tail must reach (raw: the centre of the target cell).
    pub x_centre: i128,
    /// Initial guess of the free levels (from the continuous profile).
    pub guess: [f64; MAX_FREE],
    /// Index of the cruise piece (position targets).
    pub cruise: Option<usize>,
}

/// The real solution of the level equations (step 2), before rounding: what the planner
/// checks against the limits before it asks for integers.
#[derive(Clone, Copy, Debug)]
pub struct Linear {
    /// The end conditions' matrix (rows: conditions, columns: free levels), factored.
    lu: Lu,
    /// The real levels.
    pub levels: [f64; MAX_FREE],
    /// The velocity of the cruise piece at these levels (raw per tick), if there is one.
    pub cruise_v: Option<f64>,
    /// The acceleration at the end of each piece at these levels (raw per tick²).
    pub piece_a: [f64; MAX_PIECES],
    /// The velocity at the end of each piece at these levels (raw per tick).
    pub piece_v: [f64; MAX_PIECES],
}

impl Linear {
    /// How the real levels move with the position the end must reach (`∂p/∂x`, raw level per
    /// raw position), for a position target; `None` for another.
    pub fn position_sensitivity(&self, p: &Problem) -> Option<[f64; MAX_FREE]> {
        let row = p.conditions.iter().position(|c| *c == Condition::X)?;
        let mut unit = [0.0; MAX_FREE];
        unit[row] = 1.0;
        self.lu.solve(&unit)
    }
}

/// Exact caps on the registers (raw magnitudes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Caps {
    /// Velocity.
    pub v: i128,
    /// Acceleration while |v| grows (PLCopen's Acceleration).
    pub acc: i128,
    /// Acceleration while |v| shrinks (PLCopen's Deceleration).
    pub dec: i128,
    /// A start beyond its limits (lowered mid-move): the |a| its first transition may keep
    /// while it brings it back; 0 for a start within them.
    pub entry: i128,
    /// The acceleration limit each transition was planned with, per cap index (what the
    /// planner fits a level to; the checks use `acc` and `dec`).
    pub a: [i128; 3],
    /// Jerk (order 3; `i128::MAX` for order 2).
    pub j: i128,
    /// `±1`: the velocity never points against this direction (a position target ahead of a
    /// start that is not moving away from it: the axis does not reverse); 0: no such cap.
    pub heading: i128,
}

impl Caps {
    /// The acceleration cap of consecutive ticks whose acceleration keeps its sign, from the
    /// velocity's and the acceleration's ranges over them and the velocity after the last
    /// (what the last acceleration leads to): `acc` when |v| grows on every tick, `dec` when
    /// it shrinks without crossing zero, the smaller of the two otherwise; `entry` (cap index 0,
    /// the first transition) raises it for a start beyond its limits.
    pub fn a_cap(&self, v: (i128, i128), a: (i128, i128), v_after: i128, cap: usize) -> i128 {
        let (v_lo, v_hi) = v;
        let (a_lo, a_hi) = a;
        let grows = (v_lo >= 0 && a_lo >= 0) || (v_hi <= 0 && a_hi <= 0);
        // Shrinking toward zero, the velocity is closest to it after the last tick.
        let shrinks =
            (v_lo > 0 && a_hi <= 0 && v_after >= 0) || (v_hi < 0 && a_lo >= 0 && v_after <= 0);
        let by_direction = if grows {
            self.acc
        } else if shrinks {
            self.dec
        } else {
            self.acc.min(self.dec)
        };
        if cap == 0 {
            by_direction.max(self.entry)
        } else {
            by_direction
        }
    }
}

/// Why an exact realisation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExactFailure {
    /// A value left `i128` (the move is too long or too large for the registers).
    Overflow,
    /// The level equations were singular (a degenerate piece layout).
    Singular,
    /// A register would exceed its cap on some tick.
    Limit,
}

/// The exact states at the end of every jerk piece for integer levels `lv` (order 3: jerks;
/// order 2: accelerations), without the tail, into `ends`; `at` receives the index of the jerk
/// piece that ends each problem piece.
fn piece_ends(
    jp: JerkPieces,
    start: &ChainState,
    lv: &[i128; MAX_FREE],
    ends: &mut ArrayVec<ChainState, MAX_JERK_PIECES>,
    at: &mut ArrayVec<usize, MAX_PIECES>,
) -> Result<(), ExactFailure> {
    ends.clear();
    at.clear();
    let mut s = *start;
    for q in jp {
        let l = q.level.exact(lv).ok_or(ExactFailure::Overflow)?;
        s = piece_end(&s, l, q.ticks).ok_or(ExactFailure::Overflow)?;
        if q.ends_piece {
            at.push(ends.len());
        }
        ends.push(s);
    }
    Ok(())
}

/// Checks every tick of the jerk pieces `jp` at levels `lv` from `start` against the caps,
/// given the exact state at the end of each (`ends`, from [`piece_ends`]): the same checks, on
/// the same segments, as [`check_limits`] on the program [`write_program`] writes, without
/// playing the segments again.
fn check_pieces(
    jp: JerkPieces,
    start: &ChainState,
    lv: &[i128; MAX_FREE],
    ends: &[ChainState],
    caps: &Caps,
) -> Result<(), ExactFailure> {
    let ov = ExactFailure::Overflow;
    let mut s = *start;
    for (q, end) in jp.zip(ends) {
        let l = q.level.exact(lv).ok_or(ov)?;
        // The one-tick segment that sets the jerk: from its tick on the acceleration is linear
        // (the jerk is the level), so the piece's ticks are one zero-snap run from it.
        let first = one_tick(&s, l.checked_sub(s.j).ok_or(ov)?).ok_or(ov)?;
        let rest = q.ticks - 1;
        if rest <= u64::from(u32::MAX) {
            check_from(caps, q.cap, &first, end, q.ticks)?;
        } else {
            check_ticks(caps, q.cap, &first, &first)?;
            // Written in segments of at most u32::MAX ticks: each checked on its own.
            let mut from = first;
            let mut left = rest;
            while left > 0 {
                let n = left.min(u64::from(u32::MAX));
                let to = zero_snap(&from, n).ok_or(ov)?;
                check_run(caps, q.cap, &from, &to, n)?;
                from = to;
                left -= n;
            }
        }
        s = *end;
    }
    Ok(())
}

/// Writes the program of integer levels `lv` into `out`: a one-tick segment setting each jerk
/// piece's jerk, then its zero-snap rest in segments of at most `u32::MAX` ticks.
fn write_program(
    jp: JerkPieces,
    start: &ChainState,
    lv: &[i128; MAX_FREE],
    out: &mut Program,
) -> Result<(), ExactFailure> {
    out.segments.clear();
    out.segments.reserve(2 * MAX_JERK_PIECES + 3);
    let mut j = start.j;
    for q in jp {
        let l = q.level.exact(lv).ok_or(ExactFailure::Overflow)?;
        out.segments.push(Segment {
            ticks: 1,
            snap: l.checked_sub(j).ok_or(ExactFailure::Overflow)?,
        });
        j = l;
        let mut left = q.ticks - 1;
        while left > 0 {
            let n = left.min(u64::from(u32::MAX));
            out.segments.push(Segment {
                ticks: n as u32,
                snap: 0,
            });
            left -= n;
        }
    }
    Ok(())
}

/// The residual of the conditions for the exact states `ends` (goal minus actual).
fn residual(p: &Problem, aim: &Aim, ends: &[ChainState], at: &[usize], r: &mut [f64; MAX_FREE]) {
    let last = ends[ends.len() - 1];
    for (i, c) in p.conditions.iter().enumerate() {
        r[i] = match *c {
            Condition::A(k) => -to_f64(ends[at[k]].a),
            Condition::V => to_f64(aim.v.saturating_sub(last.v)),
            Condition::X => to_f64(aim.x.saturating_sub(last.x)),
        };
    }
}

/// What the main program (before the tail) aims at: the end velocity short of the requested
/// one by a margin `m` on the side it is approached from, so that the tail, which moves the
/// velocity by `m` plus the residual, finishes the approach monotonically (no overshoot of a
/// set speed, no reversal at rest). `m = 2n² + 2^20` for `n` ticks bounds the velocity the
/// rounding of the levels can leave (each level rounds by ≤ ½ and moves the end velocity by
/// at most its ticks times the ticks after it); physically it is nothing (2^20 raw is 1e-19
/// unit/s at the default format). The tail adds `3v` to the position (`x₃ = x + 3v + 3a + j`
/// does not depend on the tail's snaps).
struct Aim {
    v: i128,
    x: i128,
}

fn aim(p: &Problem) -> Result<Aim, ExactFailure> {
    let n: u64 = p.pieces.iter().map(|d| d.ticks).sum();
    let n = i128::from(n.min(1 << 40));
    let m = 2 * n * n + (1 << 20);
    let v = p.v_end - p.approach * m;
    let x = v
        .checked_mul(3)
        .and_then(|t| p.x_centre.checked_sub(t))
        .ok_or(ExactFailure::Overflow)?;
    Ok(Aim { v, x })
}

/// Rounds real levels to integers (`None` if one is not finite or too large).
fn round_levels(l: &[f64; MAX_FREE], n: usize) -> Option<[i128; MAX_FREE]> {
    let mut out = [0i128; MAX_FREE];
    for i in 0..n {
        let r = crate::planner::fmath::round(l[i]);
        if !r.is_finite() || r.abs() >= 1.6e38 {
            return None;
        }
        // f64 → i64 is one instruction, f64 → i128 a library call.
        out[i] = if r.abs() < 9.2e18 {
            i128::from(r as i64)
        } else {
            r as i128
        };
    }
    Some(out)
}

/// Step 2 of the module documentation: the real levels that meet the end conditions with the
/// tick counts of `p`, from `start`.
pub fn linearise(p: &Problem, start: &ChainState) -> Result<Linear, ExactFailure> {
    let n = p.free;
    let aim = aim(p)?;
    // The linear map, in f64: F₀ from the start, columns from rest; positions relative to
    // the start's (exact differences, so the f64s keep their precision for the move).
    let mut st = AffineState {
        x: Affine::constant(0.0),
        v: Affine::constant(to_f64(start.v)),
        a: Affine::constant(to_f64(start.a)),
        j: Affine::constant(to_f64(start.j)),
    };
    let aim_x = to_f64(aim.x.checked_sub(start.x).ok_or(ExactFailure::Overflow)?);
    let mut end_a = [Affine::default(); MAX_PIECES];
    let mut end_v = [Affine::default(); MAX_PIECES];
    let mut k = 0;
    for q in jerk_pieces(p, start) {
        st.jerk_piece(&q.level.affine(), q.ticks);
        if q.ends_piece {
            end_a[k] = st.a;
            end_v[k] = st.v;
            k += 1;
        }
    }
    let row = |c: &Condition| -> Affine {
        match *c {
            Condition::A(i) => end_a[i],
            Condition::V => st.v,
            Condition::X => st.x,
        }
    };
    let mut m = [[0.0; MAX_FREE]; MAX_FREE];
    let mut r = [0.0; MAX_FREE];
    // The real levels: the continuous guess corrected so that the conditions hold.
    let mut levels = p.guess;
    for (i, c) in p.conditions.iter().enumerate() {
        let f = row(c);
        m[i][..n].copy_from_slice(&f.k()[..n]);
        let val = f.at(&levels);
        r[i] = match *c {
            Condition::A(_) => -val,
            Condition::V => to_f64(aim.v) - val,
            Condition::X => aim_x - val,
        };
    }
    let lu = Lu::new(&m, n).ok_or(ExactFailure::Singular)?;
    let d = lu.solve(&r).ok_or(ExactFailure::Singular)?;
    for q in 0..n {
        levels[q] += d[q];
    }
    let cruise_v = p.cruise.map(|c| end_v[c].at(&levels));
    let (mut piece_a, mut piece_v) = ([0.0; MAX_PIECES], [0.0; MAX_PIECES]);
    for i in 0..p.pieces.len() {
        piece_a[i] = end_a[i].at(&levels);
        piece_v[i] = end_v[i].at(&levels);
    }
    Ok(Linear {
        lu,
        levels,
        cruise_v,
        piece_a,
        piece_v,
    })
}

/// Steps 3 and 4 of the module documentation: realises `p` from `start` exactly into `out`
/// from its real levels `lin` ([`linearise`]); returns the final state.
pub fn realise(
    p: &Problem,
    start: &ChainState,
    caps: &Caps,
    lin: &Linear,
    out: &mut Program,
) -> Result<ChainState, ExactFailure> {
    let n = p.free;
    let aim = aim(p)?;
    let jp = jerk_pieces(p, start);
    let mut r = [0.0; MAX_FREE];
    let (mut ends, mut at) = (ArrayVec::new(), ArrayVec::new());
    // 3. Integers, played exactly; two refinements on the exact residual.
    let mut lv = round_levels(&lin.levels, n).ok_or(ExactFailure::Overflow)?;
    piece_ends(jp.clone(), start, &lv, &mut ends, &mut at)?;
    for _ in 0..2 {
        residual(p, &aim, &ends, &at, &mut r);
        let d = lin.lu.solve(&r).ok_or(ExactFailure::Singular)?;
        // The correction is small: rounded on its own and added in integers, so the levels
        // keep every bit (an f64 level above 2^53 would not).
        let d = round_levels(&d, n).ok_or(ExactFailure::Overflow)?;
        if d == [0; MAX_FREE] {
            break;
        }
        for q in 0..n {
            lv[q] = lv[q].checked_add(d[q]).ok_or(ExactFailure::Overflow)?;
        }
        piece_ends(jp.clone(), start, &lv, &mut ends, &mut at)?;
    }
    let checked = check_pieces(jp.clone(), start, &lv, &ends, caps);
    #[cfg(test)]
    tests::cross_check(jp.clone(), start, &lv, caps, checked);
    checked?;
    // 4. The tail.
    let e = ends[ends.len() - 1];
    let ov = ExactFailure::Overflow;
    let s1 = p
        .v_end
        .checked_sub(e.v)
        .and_then(|x| x.checked_sub(e.a.checked_mul(3)?))
        .and_then(|x| x.checked_sub(e.j.checked_mul(3)?))
        .ok_or(ov)?;
    let s2 = (-e.a)
        .checked_sub(e.j.checked_mul(3).ok_or(ov)?)
        .and_then(|x| x.checked_sub(s1.checked_mul(2)?))
        .ok_or(ov)?;
    let s3 = (-e.j)
        .checked_sub(s1)
        .and_then(|x| x.checked_sub(s2))
        .ok_or(ov)?;
    let mut fin = e;
    for s in [s1, s2, s3] {
        fin = one_tick(&fin, s).ok_or(ov)?;
        check_ticks(caps, 2, &fin, &fin)?;
    }
    write_program(jp, start, &lv, out)?;
    for s in [s1, s2, s3] {
        out.segments.push(Segment { ticks: 1, snap: s });
    }
    Ok(fin)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit tests of the planner call this from [`realise`]: the piece-level check must judge
    /// the jerk pieces exactly as the segment-level [`check_limits`] judges the program they
    /// write.
    pub(super) fn cross_check(
        jp: JerkPieces,
        start: &ChainState,
        lv: &[i128; MAX_FREE],
        caps: &Caps,
        pieces: Result<(), ExactFailure>,
    ) {
        let mut program = Program::empty();
        write_program(jp.clone(), start, lv, &mut program).expect("the levels were played");
        let mut caps_of = Vec::new();
        for q in jp {
            caps_of.push(q.cap);
            let mut left = q.ticks - 1;
            while left > 0 {
                caps_of.push(q.cap);
                left -= left.min(u64::from(u32::MAX));
            }
        }
        assert_eq!(caps_of.len(), program.segments.len());
        let segments = check_limits(&program, start, caps, &caps_of);
        assert_eq!(
            pieces.is_ok(),
            segments.is_ok(),
            "{program:?} from {start:?}"
        );
    }

    /// The closed form of a piece equals the chain stepped tick by tick.
    #[test]
    fn a_piece_in_closed_form_is_the_chain_stepped() {
        let w = snapgen_model::format::Widths {
            x: 127,
            v: 127,
            a: 127,
            j: 127,
            d: 127,
        };
        let start = ChainState {
            x: 123_456_789,
            v: -98_765,
            a: 4_321,
            j: -17,
        };
        for (level, n) in [(5i128, 1u64), (-3, 2), (11, 3), (-7, 40), (0, 17)] {
            let mut s = start.step(level - start.j, &w);
            for _ in 1..n {
                s = s.step(0, &w);
            }
            assert_eq!(
                piece_end(&start, level, n),
                Some(s),
                "level {level}, {n} ticks"
            );
        }
    }
}
