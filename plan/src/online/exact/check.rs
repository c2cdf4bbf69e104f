//! The exact checks of a program against the caps: the segment-level reference
//! ([`check_limits`]) and the per-run pieces it shares with the piece-level check.

use super::*;

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
    let ov = ExactFailure::Overflow;
    let mut s = *start;
    for (seg, &cap) in program.segments.iter().zip(caps_of) {
        let n = u64::from(seg.ticks);
        if n == 0 {
            continue;
        }
        let first = one_tick(&s, seg.snap).ok_or(ov)?;
        if n == 1 {
            check_ticks(caps, cap, &first, &first)?;
            s = first;
            continue;
        }
        if seg.snap != 0 {
            let mut t = first;
            check_ticks(caps, cap, &t, &t)?;
            for _ in 1..n {
                t = one_tick(&t, seg.snap).ok_or(ov)?;
                check_ticks(caps, cap, &t, &t)?;
            }
            s = t;
            continue;
        }
        let end = zero_snap(&s, n).ok_or(ov)?;
        check_run(caps, cap, &s, &end, n)?;
        s = end;
    }
    Ok(())
}

/// Checks the `n` ticks of one zero-snap segment played from `s` and ending in `end`: split
/// where the acceleration changes sign (it is linear in the tick), each part has a monotone
/// velocity and its extremes at its ends; a part whose velocity changes sign is split there too
/// ([`check_part`]).
pub(super) fn check_run(
    caps: &Caps,
    cap: usize,
    s: &ChainState,
    end: &ChainState,
    n: u64,
) -> Result<(), ExactFailure> {
    let first = one_tick(s, 0).ok_or(ExactFailure::Overflow)?;
    check_from(caps, cap, &first, end, n)
}

/// [`check_run`] given the state after the run's first tick, `first` (a zero-snap run from
/// there on: a piece whose first tick set its jerk is one).
pub(super) fn check_from(
    caps: &Caps,
    cap: usize,
    first: &ChainState,
    end: &ChainState,
    n: u64,
) -> Result<(), ExactFailure> {
    let ov = ExactFailure::Overflow;
    let first = *first;
    // The state k ticks in: `first` advanced k − 1, the ends and their neighbours directly
    // (the last tick but one is the end stepped back: a − j, then v − a, then x − v).
    let at = |k: u64| -> Result<ChainState, ExactFailure> {
        if k == 1 {
            Ok(first)
        } else if k == n {
            Ok(*end)
        } else if k + 1 == n {
            let a = end.a.checked_sub(end.j).ok_or(ov)?;
            let v = end.v.checked_sub(a).ok_or(ov)?;
            let x = end.x.checked_sub(v).ok_or(ov)?;
            Ok(ChainState { x, v, a, j: end.j })
        } else {
            zero_snap(&first, k - 1).ok_or(ov)
        }
    };
    if first.a.signum() * end.a.signum() >= 0 {
        return check_part(caps, cap, &at, (1, &first), (n, end));
    }
    // a(k) = first.a + (k − 1)·first.j. The last tick on the first one's side of zero,
    // estimated and then made exact.
    let a = |k: u64| {
        i128::from(k - 1)
            .checked_mul(first.j)
            .and_then(|x| x.checked_add(first.a))
            .ok_or(ov)
    };
    let side = first.a.signum();
    let est = (-to_f64(first.a) / to_f64(first.j)).floor() + 1.0;
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
    check_part(caps, cap, &at, (1, &first), (k, &at(k)?))?;
    check_part(caps, cap, &at, (k + 1, &at(k + 1)?), (n, end))
}

/// Checks ticks `k₀..=k₁` of a zero-snap segment (`at(k)` the state `k` ticks in; `p`, `q` the
/// states at the two ends), across which the acceleration keeps its sign, so the velocity is
/// monotone. Where the velocity passes through zero the limit that applies changes: the ticks
/// before, whose acceleration shrinks |v|, have the deceleration limit; the tick whose
/// acceleration takes the velocity through zero counts as both (the smaller limit); the ticks
/// after, where |v| grows, the acceleration limit. So the part is split around that tick,
/// estimated from the velocity's quadratic in the tick and then made exact: where one check
/// of the whole part would apply the smaller limit to every tick.
pub(super) fn check_part(
    caps: &Caps,
    cap: usize,
    at: &impl Fn(u64) -> Result<ChainState, ExactFailure>,
    (k0, p): (u64, &ChainState),
    (k1, q): (u64, &ChainState),
) -> Result<(), ExactFailure> {
    let side = p.v.signum();
    let after = q.v.saturating_add(q.a);
    if side == 0 || (q.v.signum() == side && after.signum() == side) {
        // No crossing in the part, nor right after it.
        return check_ticks(caps, cap, p, q);
    }
    // The crossing tick: the last on p's side of zero. The velocity m ticks after p is
    // `v + m·a + C(m,2)·j` (monotone here): its root estimated in f64, then made exact.
    let crossing = if q.v.signum() == side {
        k1
    } else {
        let (v, a, j) = (to_f64(p.v), to_f64(p.a), to_f64(p.j));
        let m = if j == 0.0 {
            -v / a
        } else {
            // (j/2)·m² + (a − j/2)·m + v = 0: the root between the part's ends.
            let (qa, qb) = (0.5 * j, a - 0.5 * j);
            let disc = (qb * qb - 4.0 * qa * v).max(0.0).sqrt();
            let (r1, r2) = ((-qb + disc) / (2.0 * qa), (-qb - disc) / (2.0 * qa));
            let span = (k1 - k0) as f64;
            if (0.0..=span).contains(&r1) {
                r1
            } else {
                r2
            }
        };
        let on_side = |k: u64| at(k).map(|s| s.v.signum() == side);
        let mut k = if m.is_finite() {
            (k0 + m.max(0.0) as u64).clamp(k0, k1 - 1)
        } else {
            k0
        };
        while k > k0 && !on_side(k)? {
            k -= 1;
        }
        while k + 1 < k1 && on_side(k + 1)? {
            k += 1;
        }
        k
    };
    let c = at(crossing)?;
    if crossing > k0 {
        check_ticks(caps, cap, p, &at(crossing - 1)?)?;
    }
    check_ticks(caps, cap, &c, &c)?;
    if crossing < k1 {
        check_ticks(caps, cap, &at(crossing + 1)?, q)?;
    }
    Ok(())
}

/// Checks the ticks from `p` to `q` of one segment, across which the acceleration keeps its
/// sign (so the velocity is monotone): every register's extremes are at the two ends.
pub(super) fn check_ticks(
    caps: &Caps,
    cap: usize,
    p: &ChainState,
    q: &ChainState,
) -> Result<(), ExactFailure> {
    let v = (p.v.min(q.v), p.v.max(q.v));
    let a = (p.a.min(q.a), p.a.max(q.a));
    let mag = |r: (i128, i128)| r.0.saturating_abs().max(r.1.saturating_abs());
    let against = (caps.heading > 0 && v.0 < 0) || (caps.heading < 0 && v.1 > 0);
    let over = p.j.abs().max(q.j.abs()) > caps.j
        || mag(a) > caps.a_cap(v, a, q.v.saturating_add(q.a), cap)
        || mag(v) > caps.v
        || against;
    if over {
        Err(ExactFailure::Limit)
    } else {
        Ok(())
    }
}
