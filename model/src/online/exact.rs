//! From a continuous profile to an exact integer program, from any start state.
//!
//! The rest-to-rest planners are exact because the move is one unit program scaled by one
//! integer (§5 of docs/MODEL.md); from an arbitrary start the chain's own state adds a term no
//! scale can absorb. The method here (docs/MODEL.md §11):
//!
//! 1. **Whole ticks.** Every piece of the continuous profile is rounded *up* to whole ticks
//!    (seed 000 eq 3), jerk pieces and the cruise to at least one tick so that each keeps a free
//!    level; a one-tick *settle* piece returns the highest derivative to zero at the end.
//! 2. **Levels by a linear solve.** With the tick counts fixed, the chain is linear in the piece
//!    levels, so the end state is `F = F₀ + M·p` (`F₀` the start state played with every free
//!    level zero, `M`'s columns the unit levels played from rest). The free levels `p` solve
//!    the end conditions: acceleration zero in the cruise and at the end, the end velocity,
//!    the end position (position targets) — four equations, four levels for order 3; the
//!    acceleration levels of order 2 make the acceleration exact by construction, leaving two.
//! 3. **Integers, and one refinement.** The levels are rounded to integers, the program is
//!    played exactly, and the exact residual is solved again (`M·δ = r`) and rounded: what is
//!    left is the rounding of the levels, a few raw LSBs of acceleration and velocity.
//! 4. **The unimodular tail.** Three one-tick snap impulses `s₁, s₂, s₃` take any residual
//!    `(v, a)` with `j = 0` to exactly `(V, 0, 0)`:
//!    `v₃ = v + 3a + s₁`, `a₃ = a + 2s₁ + s₂`, `j₃ = s₁ + s₂ + s₃`. The matrix
//!    `[[1,0,0],[2,1,0],[1,1,1]]` has determinant 1, so the integer solution
//!    `s₁ = V − v − 3a`, `s₂ = −a − 2s₁`, `s₃ = −s₁ − s₂` always exists and is as small as the
//!    residual. The position moves by a few residuals: far below half an output LSB.
//!
//! The result is checked, not assumed: the final state must be exactly the requested one and
//! the position in the target cell, and the exact per-tick peaks of every segment
//! ([`check_limits`]) must stay within the limits.

use crate::chain::{binomial, ChainState};
use crate::program::{Program, Segment};

/// Largest number of free levels.
pub const MAX_FREE: usize = 4;

/// Largest number of pieces (two transitions of three, the cruise, the settle).
pub const MAX_PIECES: usize = 8;

/// A value affine in the free levels: `c + Σ k[i]·p[i]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Affine {
    c: f64,
    k: [f64; MAX_FREE],
}

impl Affine {
    fn constant(c: f64) -> Self {
        Affine {
            c,
            ..Default::default()
        }
    }

    fn param(i: usize) -> Self {
        let mut a = Affine::default();
        a.k[i] = 1.0;
        a
    }

    fn add(&self, o: &Affine, m: f64) -> Affine {
        let mut r = *self;
        r.c += m * o.c;
        for i in 0..MAX_FREE {
            r.k[i] += m * o.k[i];
        }
        r
    }

    fn sub(&self, o: &Affine) -> Affine {
        self.add(o, -1.0)
    }
}

/// A state whose registers are affine in the free levels.
#[derive(Clone, Copy, Debug, Default)]
struct AffineState {
    x: Affine,
    v: Affine,
    a: Affine,
    j: Affine,
}

impl AffineState {
    /// `n ≥ 1` ticks with the jerk held at `level` from the first tick (snap `level − j` on the
    /// first tick, zero after).
    fn jerk_piece(&self, level: &Affine, n: u64) -> AffineState {
        // First tick: every register from the previous tick's values.
        let s = AffineState {
            x: self.x.add(&self.v, 1.0),
            v: self.v.add(&self.a, 1.0),
            a: self.a.add(&self.j, 1.0),
            j: *level,
        };
        let m = n - 1;
        let c = |k| binomial(m, k) as f64;
        AffineState {
            x: s.x.add(&s.v, c(1)).add(&s.a, c(2)).add(&s.j, c(3)),
            v: s.v.add(&s.a, c(1)).add(&s.j, c(2)),
            a: s.a.add(&s.j, c(1)),
            j: s.j,
        }
    }
}

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
    pub pieces: Vec<DPiece>,
    /// Number of free levels.
    pub free: usize,
    /// Conditions (as many as free levels).
    pub conditions: Vec<Condition>,
    /// End velocity (raw per tick).
    pub v_end: i128,
    /// Side the end velocity is approached from: `+1` from below (a rising last transition),
    /// `−1` from above.
    pub approach: i128,
    /// Position the end of the tail must reach (raw: the centre of the target cell).
    pub x_centre: f64,
    /// Initial guess of the free levels (from the continuous profile).
    pub guess: [f64; MAX_FREE],
    /// Index of the cruise piece (position targets).
    pub cruise: Option<usize>,
}

/// The real solution of the level equations (step 2), before rounding: what the planner
/// checks against the limits before it asks for integers.
#[derive(Clone, Copy, Debug)]
pub struct Linear {
    /// The end conditions' matrix (rows: conditions, columns: free levels).
    m: [[f64; MAX_FREE]; MAX_FREE],
    /// The real levels.
    pub levels: [f64; MAX_FREE],
    /// The velocity of the cruise piece at these levels (raw per tick), if there is one.
    pub cruise_v: Option<f64>,
    /// The acceleration at the end of each piece at these levels (raw per tick²).
    pub piece_a: [f64; MAX_PIECES],
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

/// The jerk-level pieces of a problem, affine in the levels: order 3 as given; order 2 turns
/// each acceleration level `A` into a jerk impulse `A − A_prev` on its first tick.
fn jerk_pieces(p: &Problem, start: &ChainState) -> Vec<(u64, Affine, usize)> {
    let level = |d: &DPiece| d.free.map_or(Affine::default(), Affine::param);
    let mut out = Vec::with_capacity(p.pieces.len() * 2);
    if p.order == 2 {
        // The acceleration of the first tick is already decided: a + j.
        let mut prev = Affine::constant((start.a + start.j) as f64);
        for d in &p.pieces {
            let l = level(d);
            out.push((1, l.sub(&prev), d.cap));
            if d.ticks > 1 {
                out.push((d.ticks - 1, Affine::default(), d.cap));
            }
            prev = l;
        }
    } else {
        for d in &p.pieces {
            out.push((d.ticks, level(d), d.cap));
        }
    }
    out
}

/// Solves the square system `m·x = r` (n ≤ 4) by Gaussian elimination with partial pivoting.
fn solve(m: &mut [[f64; MAX_FREE]; MAX_FREE], r: &mut [f64; MAX_FREE], n: usize) -> Option<()> {
    for col in 0..n {
        let piv = (col..n).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col] == 0.0 || !m[piv][col].is_finite() {
            return None;
        }
        m.swap(col, piv);
        r.swap(col, piv);
        for row in col + 1..n {
            let f = m[row][col] / m[col][col];
            let pivot_row = m[col];
            for (x, p) in m[row][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *x -= f * p;
            }
            r[row] -= f * r[col];
        }
    }
    for col in (0..n).rev() {
        let mut s = r[col];
        for k in col + 1..n {
            s -= m[col][k] * r[k];
        }
        r[col] = s / m[col][col];
        if !r[col].is_finite() {
            return None;
        }
    }
    Some(())
}

/// The program for integer levels `lv` (order 3: jerks; order 2: accelerations), without the
/// tail, and the exact states at the end of every piece.
fn integer_program(
    p: &Problem,
    start: &ChainState,
    lv: &[i128; MAX_FREE],
    out: &mut Program,
    caps_of: &mut Vec<usize>,
    ends: &mut Vec<ChainState>,
) -> Result<(), ExactFailure> {
    out.segments.clear();
    caps_of.clear();
    ends.clear();
    let level = |d: &DPiece| d.free.map_or(0, |i| lv[i]);
    let mut s = *start;
    let mut push = |out: &mut Program, s: &mut ChainState, ticks: u64, snap: i128, cap: usize| {
        let mut left = ticks;
        let mut snap = snap;
        while left > 0 {
            let n = left.min(u64::from(u32::MAX));
            *s = s.checked_advance(snap, n).ok_or(ExactFailure::Overflow)?;
            out.segments.push(Segment {
                ticks: n as u32,
                snap,
            });
            caps_of.push(cap);
            left -= n;
            snap = 0;
        }
        Ok(())
    };
    // Jerk levels per piece (order 2: the impulse `A − A_prev` then zero), played as one
    // snap impulse to the level and zero snap for the rest of the piece.
    let mut prev = start.a.checked_add(start.j).ok_or(ExactFailure::Overflow)?;
    for d in &p.pieces {
        let l = level(d);
        let parts: [(u64, i128); 2] = if p.order == 2 {
            let jump = l.checked_sub(prev).ok_or(ExactFailure::Overflow)?;
            prev = l;
            [(1, jump), (d.ticks - 1, 0)]
        } else {
            [(d.ticks, l), (0, 0)]
        };
        for (ticks, jerk) in parts {
            if ticks == 0 {
                continue;
            }
            let snap = jerk.checked_sub(s.j).ok_or(ExactFailure::Overflow)?;
            push(out, &mut s, 1, snap, d.cap)?;
            push(out, &mut s, ticks - 1, 0, d.cap)?;
        }
        ends.push(s);
    }
    Ok(())
}

/// The residual of the conditions for the exact states `ends` (goal minus actual).
fn residual(p: &Problem, aim: &Aim, ends: &[ChainState], r: &mut [f64; MAX_FREE]) {
    let last = ends[ends.len() - 1];
    for (i, c) in p.conditions.iter().enumerate() {
        r[i] = match *c {
            Condition::A(k) => -(ends[k].a as f64),
            Condition::V => (aim.v - last.v) as f64,
            Condition::X => aim.x - last.x as f64,
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
    x: f64,
}

fn aim(p: &Problem) -> Aim {
    let n: u64 = p.pieces.iter().map(|d| d.ticks).sum();
    let n = i128::from(n.min(1 << 40));
    let m = 2 * n * n + (1 << 20);
    let v = p.v_end - p.approach * m;
    Aim {
        v,
        x: p.x_centre - 3.0 * v as f64,
    }
}

/// Rounds real levels to integers (`None` if one is not finite or too large).
fn round_levels(l: &[f64; MAX_FREE], n: usize) -> Option<[i128; MAX_FREE]> {
    let mut out = [0i128; MAX_FREE];
    for i in 0..n {
        let r = crate::planner::fmath::round(l[i]);
        if !r.is_finite() || r.abs() >= 1.6e38 {
            return None;
        }
        out[i] = r as i128;
    }
    Some(out)
}

/// Step 2 of the module documentation: the real levels that meet the end conditions with the
/// tick counts of `p`, from `start`.
pub fn linearise(p: &Problem, start: &ChainState) -> Result<Linear, ExactFailure> {
    if p.pieces.len() > MAX_PIECES {
        return Err(ExactFailure::Singular);
    }
    let n = p.free;
    let aim = aim(p);
    // 2. The linear map, in f64: F₀ from the start, columns from rest.
    let pieces = jerk_pieces(p, start);
    let mut st = AffineState {
        x: Affine::constant(start.x as f64),
        v: Affine::constant(start.v as f64),
        a: Affine::constant(start.a as f64),
        j: Affine::constant(start.j as f64),
    };
    let mut piece_end_a = Vec::with_capacity(p.pieces.len());
    let mut piece_end_v = Vec::with_capacity(p.pieces.len());
    // Map jerk pieces back to problem pieces: order 2 emits one or two per piece.
    let mut k = 0;
    for d in &p.pieces {
        let parts = if p.order == 2 && d.ticks > 1 { 2 } else { 1 };
        for _ in 0..parts {
            let (ticks, level, _) = &pieces[k];
            st = st.jerk_piece(level, *ticks);
            k += 1;
        }
        piece_end_a.push(st.a);
        piece_end_v.push(st.v);
    }
    let row = |c: &Condition| -> Affine {
        match *c {
            Condition::A(i) => piece_end_a[i],
            Condition::V => st.v,
            Condition::X => st.x,
        }
    };
    let mut m = [[0.0; MAX_FREE]; MAX_FREE];
    for (i, c) in p.conditions.iter().enumerate() {
        m[i][..n].copy_from_slice(&row(c).k[..n]);
    }
    // The real levels: the continuous guess corrected so that the conditions hold.
    let mut levels = p.guess;
    let mut r = [0.0; MAX_FREE];
    for (i, c) in p.conditions.iter().enumerate() {
        let f = row(c);
        let val = f.c
            + f.k[..n]
                .iter()
                .zip(&levels[..n])
                .map(|(k, l)| k * l)
                .sum::<f64>();
        r[i] = match *c {
            Condition::A(_) => -val,
            Condition::V => aim.v as f64 - val,
            Condition::X => aim.x - val,
        };
    }
    let mut mm = m;
    solve(&mut mm, &mut r, n).ok_or(ExactFailure::Singular)?;
    for q in 0..n {
        levels[q] += r[q];
    }
    let value = |f: &Affine| {
        f.c + f.k[..n]
            .iter()
            .zip(&levels[..n])
            .map(|(k, l)| k * l)
            .sum::<f64>()
    };
    let cruise_v = p.cruise.map(|c| value(&piece_end_v[c]));
    let mut piece_a = [0.0; MAX_PIECES];
    for (out, a) in piece_a.iter_mut().zip(&piece_end_a) {
        *out = value(a);
    }
    Ok(Linear {
        m,
        levels,
        cruise_v,
        piece_a,
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
    let aim = aim(p);
    let (m, levels) = (lin.m, lin.levels);
    let mut r = [0.0; MAX_FREE];
    // 3. Integers, played exactly; one refinement on the exact residual.
    let mut caps_of = Vec::with_capacity(24);
    let mut ends = Vec::with_capacity(p.pieces.len());
    let mut lv = round_levels(&levels, n).ok_or(ExactFailure::Overflow)?;
    for _ in 0..2 {
        integer_program(p, start, &lv, out, &mut caps_of, &mut ends)?;
        residual(p, &aim, &ends, &mut r);
        let mut mm = m;
        solve(&mut mm, &mut r, n).ok_or(ExactFailure::Singular)?;
        // The correction is small: rounded on its own and added in integers, so the levels
        // keep every bit (an f64 level above 2^53 would not).
        let d = round_levels(&r, n).ok_or(ExactFailure::Overflow)?;
        for q in 0..n {
            lv[q] = lv[q].checked_add(d[q]).ok_or(ExactFailure::Overflow)?;
        }
    }
    integer_program(p, start, &lv, out, &mut caps_of, &mut ends)?;
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
        fin = fin.checked_advance(s, 1).ok_or(ov)?;
        out.segments.push(Segment { ticks: 1, snap: s });
        caps_of.push(2);
    }
    check_limits(out, start, caps, &caps_of)?;
    Ok(fin)
}

/// Checks every tick of `program` from `start` against the caps (segment `i` has cap index
/// `caps_of[i]`), exactly. A segment of zero snap has a constant jerk, so its acceleration is
/// linear in the tick: split where the acceleration changes sign, each part has its
/// acceleration's extremes at its ends and a monotone velocity, whose extremes are at its ends
/// too, and its acceleration cap follows the direction ([`Caps::a_cap`]). A segment that
/// applies snap on more than one tick (the planner makes none) is checked tick by tick.
pub fn check_limits(
    program: &Program,
    start: &ChainState,
    caps: &Caps,
    caps_of: &[usize],
) -> Result<(), ExactFailure> {
    let mut s = *start;
    for (seg, &cap) in program.segments.iter().zip(caps_of) {
        let n = u64::from(seg.ticks);
        let at = |k: u64| s.checked_advance(seg.snap, k).ok_or(ExactFailure::Overflow);
        if seg.snap != 0 && n > 1 {
            for k in 1..=n {
                let t = at(k)?;
                check_ticks(caps, cap, &t, &t)?;
            }
        } else {
            let (first, end) = (at(1)?, at(n)?);
            if first.a.signum() * end.a.signum() < 0 {
                // Zero snap after the first tick: a(k) = first.a + (k − 1)·first.j. The last
                // tick on the first one's side of zero, estimated and then made exact.
                let a = |k: u64| {
                    i128::from(k - 1)
                        .checked_mul(first.j)
                        .and_then(|x| x.checked_add(first.a))
                        .ok_or(ExactFailure::Overflow)
                };
                let side = first.a.signum();
                let est = (-(first.a as f64) / first.j as f64).floor() + 1.0;
                let mut k = if est.is_finite() {
                    (est.max(1.0) as u64).min(n)
                } else {
                    1
                };
                while k > 1 && a(k)?.signum() == -side {
                    k -= 1;
                }
                while k < n && a(k + 1)?.signum() != -side {
                    k += 1;
                }
                check_ticks(caps, cap, &first, &at(k)?)?;
                check_ticks(caps, cap, &at(k + 1)?, &end)?;
            } else {
                check_ticks(caps, cap, &first, &end)?;
            }
        }
        s = at(n)?;
    }
    Ok(())
}

/// Checks the ticks from `p` to `q` of one segment, across which the acceleration keeps its
/// sign (so the velocity is monotone): every register's extremes are at the two ends.
fn check_ticks(
    caps: &Caps,
    cap: usize,
    p: &ChainState,
    q: &ChainState,
) -> Result<(), ExactFailure> {
    let v = (p.v.min(q.v), p.v.max(q.v));
    let a = (p.a.min(q.a), p.a.max(q.a));
    let mag = |r: (i128, i128)| r.0.saturating_abs().max(r.1.saturating_abs());
    let over = p.j.abs().max(q.j.abs()) > caps.j
        || mag(a) > caps.a_cap(v, a, q.v.saturating_add(q.a), cap)
        || mag(v) > caps.v;
    if over {
        Err(ExactFailure::Limit)
    } else {
        Ok(())
    }
}
