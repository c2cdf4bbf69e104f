//! Fitting the tick counts to the levels (docs/MODEL.md §11): rounding every piece up to whole
//! ticks changes the distance a profile covers, and where a piece is short the level solve can
//! then ask it for more than its limit. Before any integer is played, the real solution is
//! checked and the ticks are changed where it asks too much:
//!
//! * [`shift`] — a free level beyond its limit in a position profile: the distance the
//!   rounding added or lost is taken up by whole ticks of the cruise (or, when the cruise
//!   cannot lose enough, of the first transition, [`trim`]) instead of by the levels;
//! * otherwise a piece whose level (or a hold whose acceleration) is over its limit is given
//!   more ticks, taken from a hold beside it or from the cruise where one can lend them.

use arrayvec::ArrayVec;

use snapgen_model::chain::ChainState;

use super::exact::{linearise, to_f64, Caps, ExactFailure, Linear, Problem};

/// Rounds of [`fit`].
const FIT_ROUNDS: usize = 24;

/// Ticks [`fit`] may add to a plan beyond those it takes from holds and the cruise: this many,
/// and [`FIT_GROWTH_SHARE`] of the plan's ticks.
const FIT_GROWTH: u64 = 24;

/// The share of a plan's ticks [`fit`] may add (1/256: 0.4 %).
const FIT_GROWTH_SHARE: u64 = 256;

/// Fits the tick counts to the levels (docs/MODEL.md §11, "Fitting the ticks to the levels"),
/// on the real solution of the level equations:
///
/// * a free level beyond its limit in a position profile is first brought within by whole
///   ticks of the cruise or the first transition ([`shift`]);
/// * otherwise a free piece whose level exceeds its limit by a ratio `r` (order 3: the jerk;
///   order 2: the acceleration) is lengthened by `n·(√r − 1) + 1` ticks (order 3: a jerk
///   piece's velocity change grows with `n²`) or `n·(r − 1) + 1` (order 2);
/// * a hold (order 3) whose acceleration exceeds its limit by `r` is lengthened by
///   `(n + m)·(r − 1) + 1`, `m` the ticks of the jerk pieces beside it (its velocity change
///   grows with `n + m`);
///
/// the ticks taken (a jerk piece) from the hold beside it, else from the cruise where there
/// is one, and the levels solved again. Ticks nobody lends lengthen the plan, at most
/// [`FIT_GROWTH`] and [`FIT_GROWTH_SHARE`] in all. Returns the real solution of the last solve
/// (the limits are checked on the integers afterwards).
pub(super) fn fit(
    p: &mut Problem,
    start: &ChainState,
    caps: &Caps,
) -> Result<Linear, ExactFailure> {
    let mut grown = 0u64;
    let total: u64 = p.pieces.iter().map(|d| d.ticks).sum();
    let allowed = FIT_GROWTH + total / FIT_GROWTH_SHARE;
    let mut lin = linearise(p, start)?;
    for _ in 0..FIT_ROUNDS {
        let mut changed = false;
        for i in 0..p.pieces.len() {
            let d = p.pieces[i];
            // The planned sign of a piece's level or acceleration: the guess of its level, or
            // (a hold) of the acceleration it holds. The other sign gets the smaller limit.
            let a_limit = |value: f64, planned: f64| {
                if value.signum() != planned.signum() {
                    caps.acc.min(caps.dec) as f64
                } else {
                    caps.a[d.cap] as f64
                }
            };
            let grow = match d.free {
                Some(k) => {
                    let level = lin.levels[k];
                    let limit = if p.order == 3 {
                        caps.j as f64
                    } else {
                        a_limit(level, p.guess[k])
                    };
                    let ratio = level.abs() / limit;
                    if !ratio.is_finite() {
                        return Err(ExactFailure::Overflow);
                    }
                    if ratio <= 1.0 - 1e-9 {
                        continue;
                    }
                    let factor = if p.order == 3 { ratio.sqrt() } else { ratio };
                    let grow = (d.ticks as f64 * (factor - 1.0)).ceil().min(1e12) as u64 + 1;
                    if let Some(l) = shift(p, start, &lin, k, limit, grow, &mut grown)? {
                        lin = l;
                        changed = true;
                        break;
                    }
                    grow
                }
                None if p.order == 3 && is_hold(p, i) && i > 0 => {
                    let a = lin.piece_a[i];
                    let planned = if d.held != 0 { f64::from(d.held) } else { a };
                    let ratio = a.abs() / a_limit(a, planned);
                    if !ratio.is_finite() {
                        return Err(ExactFailure::Overflow);
                    }
                    if ratio <= 1.0 - 1e-9 {
                        continue;
                    }
                    let span = d.ticks + jerk_ticks(p, i - 1) + jerk_ticks(p, i + 1);
                    (span as f64 * (ratio - 1.0)).ceil().min(1e12) as u64 + 1
                }
                None => continue,
            };
            let hold_beside = [i + 1, i.wrapping_sub(1)]
                .into_iter()
                .find(|&j| is_hold(p, j) && p.pieces[j].cap == d.cap);
            p.pieces[i].ticks += grow;
            let donor = if d.free.is_some() {
                hold_beside.or(p.cruise)
            } else {
                p.cruise
            };
            let lent = donor.map_or(0, |j| {
                let t = grow.min(p.pieces[j].ticks.saturating_sub(1));
                p.pieces[j].ticks -= t;
                t
            });
            grown += grow - lent;
            changed = true;
        }
        if grown > allowed {
            return Err(ExactFailure::Limit);
        }
        if !changed {
            return Ok(lin);
        }
        lin = linearise(p, start)?;
    }
    Ok(lin)
}

/// Piece `j` is a hold: a zero-jerk piece of a transition (not the cruise).
fn is_hold(p: &Problem, j: usize) -> bool {
    p.pieces
        .get(j)
        .is_some_and(|h| h.slack && h.free.is_none() && Some(j) != p.cruise)
}

/// The ticks of piece `j` when it is a free (jerk) piece, else 0.
fn jerk_ticks(p: &Problem, j: usize) -> u64 {
    p.pieces
        .get(j)
        .filter(|q| q.free.is_some())
        .map_or(0, |q| q.ticks)
}

/// A position profile whose rounded ticks carry the axis further or shorter than its levels
/// can make up (free level `k` solved beyond `limit`): the distance taken up by whole ticks
/// instead. A tick of the cruise at speed `v_c` carries the axis `v_c` and sets no level; the
/// solve turns a change `Δx` of where the ticks lead into a level change `−s·Δx`
/// (`s = ∂p_k/∂x`, [`Linear::position_sensitivity`]). So the cruise gains or loses the fewest
/// ticks that bring the level within its limit; where it cannot lose enough (a peak profile,
/// whose cruise is one tick), the first transition is shortened ([`trim`]). A profile without
/// a cruise (a partial release) takes the ticks from its longest piece, at that piece's
/// speed: a tick there changes its transition's velocity by a part in its length, which the
/// levels take up. Ticks are added only when fewer than the `grow` the level's own piece
/// would need. `None` when nothing applies (the level then gets more ticks in [`fit`]);
/// ticks added count in `grown`.
fn shift(
    p: &mut Problem,
    start: &ChainState,
    lin: &Linear,
    k: usize,
    limit: f64,
    grow: u64,
    grown: &mut u64,
) -> Result<Option<Linear>, ExactFailure> {
    let Some(sens) = lin.position_sensitivity(p) else {
        return Ok(None);
    };
    // The piece whose whole ticks carry the distance, and its speed.
    let settle = p.pieces.len() - 1;
    let (donor, speed) = match (p.cruise, lin.cruise_v) {
        (Some(c), Some(vc)) => (c, vc),
        _ => {
            // Not the level's own piece: its ticks move its level too much.
            let Some(d) = (0..settle)
                .filter(|&i| p.pieces[i].free != Some(k))
                .max_by_key(|&i| p.pieces[i].ticks)
            else {
                return Ok(None);
            };
            let before = if d == 0 {
                to_f64(start.v)
            } else {
                lin.piece_v[d - 1]
            };
            (d, 0.5 * (before + lin.piece_v[d]))
        }
    };
    let (level, per_tick) = (lin.levels[k], -sens[k] * speed);
    if !(per_tick.is_finite() && per_tick != 0.0) {
        return Ok(None);
    }
    let against = level.signum() == -p.guess[k].signum();
    // m donor ticks move the level by m·per_tick: the m nearest zero that lands it within.
    let inside = 1.0 - 1e-6;
    let (a, b) = (
        (-inside * limit - level) / per_tick,
        (inside * limit - level) / per_tick,
    );
    let (lo, hi) = (a.min(b), a.max(b));
    let m = if lo > 0.0 { lo.ceil() } else { hi.floor() };
    if !(m >= lo && m <= hi && m.abs() < 1e12) {
        // No whole number of ticks lands within: the level is too sensitive to them.
        return if hi < 0.0 && against {
            trim(p, start, k, limit)
        } else {
            Ok(None)
        };
    }
    let n = p.pieces[donor].ticks;
    if m >= 1.0 && m < grow as f64 {
        p.pieces[donor].ticks += m as u64;
        *grown += m as u64;
    } else if m < 0.0 && ((-m) as u64) < n {
        p.pieces[donor].ticks -= (-m) as u64;
    } else if m < 0.0 && against {
        return trim(p, start, k, limit);
    } else {
        return Ok(None);
    }
    Ok(Some(linearise(p, start)?))
}

/// A position profile whose first transition is short and whose rounded ticks carry the axis
/// further than the transition's levels can take back (free level `k` of it solved against its
/// planned sign, beyond `limit`): its jerk pieces shortened by the fewest whole ticks that
/// bring that level back within. A tick of a transition at speed `v` carries the axis `v`, its
/// levels only what their small velocity change makes of the rest of the move, so whole ticks
/// take back the distance and the levels the rest (their sign against the plan shrinks as
/// ticks are removed). `None` when no number of ticks does (the transition too short).
fn trim(
    p: &mut Problem,
    start: &ChainState,
    k: usize,
    limit: f64,
) -> Result<Option<Linear>, ExactFailure> {
    let Some(cruise) = p.cruise else {
        return Ok(None);
    };
    let firsts: ArrayVec<usize, 3> = (0..cruise)
        .filter(|&i| p.pieces[i].free.is_some())
        .collect();
    if !firsts.iter().any(|&i| p.pieces[i].free == Some(k)) {
        return Ok(None);
    }
    let orig: ArrayVec<u64, 3> = firsts.iter().map(|&i| p.pieces[i].ticks).collect();
    let pieces = firsts.len() as u64;
    let most = (orig.iter().min().copied().unwrap_or(1) - 1) * pieces;
    let sign = p.guess[k].signum();
    // The level against its plan, in units of the limit (−1 is the limit), with `cut` ticks
    // taken from the pieces in turn (a tick of travel a step).
    let against = |p: &mut Problem, cut: u64| -> Result<(f64, Linear), ExactFailure> {
        for (m, (&i, &n)) in firsts.iter().zip(&orig).enumerate() {
            let m = m as u64;
            p.pieces[i].ticks = n - cut / pieces - u64::from(cut % pieces > m);
        }
        let lin = linearise(p, start)?;
        Ok((lin.levels[k] * sign / limit, lin))
    };
    if most == 0 || against(p, most)?.0 < -1.0 {
        against(p, 0)?;
        return Ok(None);
    }
    // The fewest ticks with the level within: `lo` is over, `hi` within.
    let (mut lo, mut hi) = (0, most);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if against(p, mid)?.0 < -1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(against(p, hi)?.1))
}
