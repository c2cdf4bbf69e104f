//! Seed 002's velocity transitions: from any entry state `(v₀, a₀)` to a set speed `v_s` with
//! zero acceleration, time-optimal under a jerk limit `J` and an acceleration limit.
//!
//! Everything is in tick units (times in ticks, raw register values per tick), as the other
//! planners (docs/MODEL.md §4).
//!
//! Order 3 (the seed's case). The speed at which the entry acceleration can be brought to zero
//! at full jerk is `v_i = v₀ + a₀·|a₀|/(2J)` (seed 002 eqs 31–34, `T_i = |a₀|/J`). If
//! `v_s ≥ v_i` the transition *rises* (its acceleration ends positive-going), otherwise it
//! *falls*; a fall is a rise of the mirrored state, so one function plans both. After mirroring
//! (`σ = ±1`, `v₀ → σv₀`, …) the profile is three pieces: jerk `+J` from `a₀` to a peak `a_p`,
//! a hold at `a_p`, jerk `−J` from `a_p` to zero. The speed it gains,
//! `Δv = (a_p² − a₀²)/(2J) + a_p·t_hold + a_p²/(2J)`, fixes the case:
//!
//! * [`Shape::Acceleration`] — no hold: `a_p = √(J·Δv + a₀²/2)` stays within the limit. This
//!   is seed 002's *acceleration transition* (Fig. 4, eqs 27–30: the concave profile from the
//!   entry state is tangent to the convex one into `v_s`, `a_p = a₀ + J·T_t`); when `a_p`
//!   equals the limit it is the seed's *jerk transition*.
//! * [`Shape::Linear`] — `a_p` is the limit and the hold makes up the rest of `Δv`: the seed's
//!   *linear transition* (S_RISE_LIN / S_FALL_LIN).
//! * [`Shape::Constant`] — already at the set speed with zero acceleration (CONST_SPD).
//!
//! and the entry:
//!
//! * [`Entry::Through`] — `σa₀ < 0`: the entry acceleration points away from the set speed and
//!   is first taken through zero at `v_i` (the seed's *speed transition* to an intermediate
//!   speed, CONVEX_INT / CONCAVE_INT, §6). With jerk held at `J` through zero this is the
//!   seed's two phases, speed transition then S-curve, as one piece.
//! * [`Entry::Beyond`] — `σa₀` exceeds the limit (limits lowered mid-move): the first piece
//!   steps it back within at `−J`, then the profile holds the limit. The velocity keeps moving
//!   toward `v_s` throughout: no undershoot, no reversal.
//! * [`Entry::Within`] — otherwise (the seed's concave / convex entries: the first piece
//!   continues or starts the concave rise).
//!
//! Separate acceleration and deceleration limits (PLCopen's Acceleration and Deceleration): a
//! transition that speeds the axis up (|v| grows all along) uses the acceleration limit, one
//! that slows it down uses the deceleration limit, one that passes through zero speed uses the
//! smaller of the two.
//!
//! Order 2 (trapezoid): the acceleration steps at once, so the transition is one piece at
//! `±A` lasting `|Δv|/A` and the entry acceleration plays no part.

use serde::Serialize;

/// One piece of a continuous profile: the highest limited derivative (jerk for order 3,
/// acceleration for order 2) held at `level` for `t` ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Piece {
    /// Duration (ticks, real).
    pub t: f64,
    /// Level (raw per tick³ or per tick²).
    pub level: f64,
}

/// How a transition's acceleration behaves, in the seed's terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// No change needed (CONST_SPD).
    Constant,
    /// The peak stays within the limit (acceleration / jerk transition).
    Acceleration,
    /// The peak is the limit, held (linear transition).
    Linear,
}

/// How a transition starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Entry {
    /// Entry acceleration toward the set speed, within the limit.
    Within,
    /// Entry acceleration away from the set speed: taken through zero at `v_i` first.
    Through,
    /// Entry acceleration beyond the (new) limit: stepped back within first.
    Beyond,
}

/// One velocity transition, planned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// True when the velocity rises (`v_s ≥ v_i`).
    pub rise: bool,
    /// Entry case.
    pub entry: Entry,
    /// Shape case.
    pub shape: Shape,
    /// The acceleration limit this transition used (raw per tick²).
    pub accel_limit: f64,
    /// Pieces: order 3 uses all three (jerk, hold, jerk), order 2 the first only.
    pub pieces: [Piece; 3],
    /// Number of pieces used.
    pub len: usize,
}

/// The limits of an online plan in tick units (raw per tick^n), as reals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickLimits {
    /// Velocity limit (> 0).
    pub v: f64,
    /// Acceleration limit when |v| grows (> 0).
    pub acc: f64,
    /// Deceleration limit when |v| shrinks (> 0).
    pub dec: f64,
    /// Jerk limit (> 0; unused by order 2).
    pub j: f64,
}

impl TickLimits {
    /// The acceleration limit of a transition, mirrored so that it accelerates in `+`: its
    /// speeds run from `lo` (the lowest it passes) up to `hi` (the set speed). Positive speeds
    /// grow in magnitude (acceleration), negative ones shrink (deceleration); a transition
    /// across zero speed gets the smaller limit.
    fn for_mirrored(&self, lo: f64, hi: f64) -> f64 {
        if lo >= 0.0 {
            self.acc
        } else if hi <= 0.0 {
            self.dec
        } else {
            self.acc.min(self.dec)
        }
    }
}

impl Transition {
    /// The used pieces.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces[..self.len]
    }

    /// Total duration (ticks, real).
    pub fn duration(&self) -> f64 {
        self.pieces().iter().map(|p| p.t).sum()
    }

    /// Distance covered from entry velocity `v0` and acceleration `a0` (continuous time).
    pub fn distance(&self, order: u8, v0: f64, a0: f64) -> f64 {
        let (mut x, mut v, mut a) = (0.0, v0, a0);
        for p in self.pieces() {
            let t = p.t;
            if order == 2 {
                x += v * t + p.level * t * t / 2.0;
                v += p.level * t;
            } else {
                x += v * t + a * t * t / 2.0 + p.level * t * t * t / 6.0;
                v += a * t + p.level * t * t / 2.0;
                a += p.level * t;
            }
        }
        x
    }
}

/// Seed 002 §6: the speed reached when the entry acceleration is brought to zero at full jerk
/// (eqs 32 and 34: `v_i = v₀ + a₀·T_i − J·T_i²/2`, `T_i = |a₀|/J`).
pub fn intermediate_speed(v0: f64, a0: f64, j: f64) -> f64 {
    v0 + a0 * a0.abs() / (2.0 * j)
}

/// The order-3 transition from `(v0, a0)` to the set speed `vs` (module documentation).
pub fn velocity3(v0: f64, a0: f64, vs: f64, lim: &TickLimits) -> Transition {
    let j = lim.j;
    let vi = intermediate_speed(v0, a0, j);
    let rise = vs >= vi;
    let s = if rise { 1.0 } else { -1.0 };
    let (v0n, a0n, vsn, vin) = (s * v0, s * a0, s * vs, s * vi);
    // Speeds swept (mirrored): from the lowest of the entry and v_i up to v_s.
    let amax = lim.for_mirrored(v0n.min(vin), vsn);
    let dv = vsn - v0n;
    let (entry, shape, t1, l1, ap, hold);
    if a0n > amax {
        // Beyond: step down to the limit, hold it, release. v_s ≥ v_i makes the hold ≥ 0.
        entry = Entry::Beyond;
        shape = Shape::Linear;
        t1 = (a0n - amax) / j;
        l1 = -j;
        ap = amax;
        hold = ((dv - a0n * a0n / (2.0 * j)) / amax).max(0.0);
    } else {
        entry = if a0n < 0.0 {
            Entry::Through
        } else {
            Entry::Within
        };
        l1 = j;
        // Peak without a hold (eq 29 rewritten: a_p = a₀ + J·T_t); v_s ≥ v_i makes it real.
        let peak = (j * dv + a0n * a0n / 2.0).max(0.0).sqrt();
        if peak <= amax {
            shape = if dv == 0.0 && a0n == 0.0 {
                Shape::Constant
            } else {
                Shape::Acceleration
            };
            ap = peak;
            hold = 0.0;
        } else {
            shape = Shape::Linear;
            ap = amax;
            hold = ((dv - (2.0 * amax * amax - a0n * a0n) / (2.0 * j)) / amax).max(0.0);
        }
        t1 = ((ap - a0n) / j).max(0.0);
    }
    Transition {
        rise,
        entry,
        shape,
        accel_limit: amax,
        pieces: [
            Piece {
                t: t1,
                level: s * l1,
            },
            Piece {
                t: hold,
                level: 0.0,
            },
            Piece {
                t: ap / j,
                level: -s * j,
            },
        ],
        len: 3,
    }
}

/// The order-2 transition from `v0` to `vs`: one piece at `±A` (module documentation).
pub fn velocity2(v0: f64, vs: f64, lim: &TickLimits) -> Transition {
    let rise = vs >= v0;
    let s = if rise { 1.0 } else { -1.0 };
    let amax = lim.for_mirrored(s * v0, s * vs);
    let dv = vs - v0;
    Transition {
        rise,
        entry: Entry::Within,
        shape: if dv == 0.0 {
            Shape::Constant
        } else {
            Shape::Linear
        },
        accel_limit: amax,
        pieces: [
            Piece {
                t: dv.abs() / amax,
                level: if rise { amax } else { -amax },
            },
            Piece::default(),
            Piece::default(),
        ],
        len: 1,
    }
}

/// The transition of the given order.
pub fn velocity(order: u8, v0: f64, a0: f64, vs: f64, lim: &TickLimits) -> Transition {
    if order == 2 {
        velocity2(v0, vs, lim)
    } else {
        velocity3(v0, a0, vs, lim)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: TickLimits = TickLimits {
        v: 10.0,
        acc: 4.0,
        dec: 3.0,
        j: 1.0,
    };

    /// Integrates the pieces independently with small Euler steps of the jerk.
    fn end_state(t: &Transition, v0: f64, a0: f64) -> (f64, f64, f64) {
        let (mut x, mut v, mut a) = (0.0, v0, a0);
        let mut peak_a: f64 = a0.abs();
        for p in t.pieces() {
            let n = 20_000;
            let dt = p.t / n as f64;
            for _ in 0..n {
                x += v * dt + a * dt * dt / 2.0 + p.level * dt * dt * dt / 6.0;
                v += a * dt + p.level * dt * dt / 2.0;
                a += p.level * dt;
                peak_a = peak_a.max(a.abs());
            }
        }
        let _ = x;
        (v, a, peak_a)
    }

    #[test]
    fn every_case_reaches_the_set_speed_with_zero_acceleration() {
        // (v0, a0, vs, expected entry, expected shape)
        let cases = [
            (0.0, 0.0, 30.0, Entry::Within, Shape::Linear),
            (0.0, 0.0, 2.0, Entry::Within, Shape::Acceleration),
            (0.0, 2.0, 30.0, Entry::Within, Shape::Linear),
            (5.0, 3.0, 4.0, Entry::Through, Shape::Acceleration),
            (5.0, -2.0, 20.0, Entry::Through, Shape::Linear),
            (20.0, 6.0, 50.0, Entry::Beyond, Shape::Linear),
            (20.0, -6.0, -10.0, Entry::Beyond, Shape::Linear),
            (7.0, 0.0, 7.0, Entry::Within, Shape::Constant),
        ];
        for (v0, a0, vs, entry, shape) in cases {
            let t = velocity3(v0, a0, vs, &LIM);
            assert_eq!((t.entry, t.shape), (entry, shape), "{v0} {a0} {vs}");
            let (v, a, peak) = end_state(&t, v0, a0);
            assert!((v - vs).abs() < 1e-6, "{v0} {a0} {vs}: v {v}");
            assert!(a.abs() < 1e-9, "{v0} {a0} {vs}: a {a}");
            assert!(peak <= t.accel_limit.max(a0.abs()) + 1e-9);
        }
    }

    #[test]
    fn speeding_up_uses_acceleration_and_slowing_down_deceleration() {
        assert_eq!(velocity3(0.0, 0.0, 100.0, &LIM).accel_limit, 4.0);
        assert_eq!(velocity3(100.0, 0.0, 0.0, &LIM).accel_limit, 3.0);
        assert_eq!(velocity3(-100.0, 0.0, 0.0, &LIM).accel_limit, 3.0);
        assert_eq!(velocity3(-10.0, 0.0, 10.0, &LIM).accel_limit, 3.0);
        assert_eq!(velocity2(0.0, -100.0, &LIM).accel_limit, 4.0);
    }

    #[test]
    fn the_intermediate_speed_is_seed_002_eq_32_at_eq_34() {
        // a0 = 3, J = 1: T_i = 3, v_i = v0 + 3·3 − 9/2.
        assert!((intermediate_speed(1.0, 3.0, 1.0) - (1.0 + 9.0 - 4.5)).abs() < 1e-12);
    }
}
