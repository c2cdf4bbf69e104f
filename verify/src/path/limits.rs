//! Each axis's velocity, acceleration and jerk, and the path's speed, over a trace of positions.
//!
//! From the positions alone, as the machine sees them: an axis's velocity on tick `k` is
//! `pₖ − pₖ₋₁`, its acceleration the difference of two velocities, its jerk the difference of
//! two accelerations (units of the positions per tick, tick², tick³); the path's speed is the
//! Euclidean length of the tick's step, compared squared (exact). The trace runs from rest to
//! rest: before its first point and after its last the axes stand still, so a trace that
//! starts or ends at speed shows the jerk of standing still at once.

use ethnum::I256;

/// The limits of one axis (magnitudes; units of the positions per tick, tick², tick³).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisLimits {
    /// Velocity.
    pub velocity: i128,
    /// Acceleration.
    pub acceleration: i128,
    /// Jerk.
    pub jerk: i128,
}

/// Which quantity went past its limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// An axis's velocity.
    Velocity,
    /// An axis's acceleration.
    Acceleration,
    /// An axis's jerk.
    Jerk,
    /// The path's speed (every axis together).
    PathSpeed,
}

/// The first quantity over its limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Exceeded {
    /// The tick: the step from point `tick − 1` to point `tick` (before the first point the
    /// axes stand at it; the three ticks after the last hold the last point).
    pub tick: usize,
    /// The axis (None: the path's speed).
    pub axis: Option<usize>,
    /// What.
    pub quantity: Quantity,
    /// Its value there (for the path's speed, its square).
    pub value: I256,
    /// The limit (for the path's speed, its square).
    pub limit: I256,
}

/// The largest magnitudes found, per axis (velocity, acceleration, jerk), and the largest
/// squared path speed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Peaks {
    /// Per axis: `[|v|, |a|, |j|]`.
    pub axes: Vec<[I256; 3]>,
    /// Largest squared step length.
    pub path_speed_squared: I256,
}

/// Checks `trace` (one point per tick, every point with `limits.len()` axes) against each
/// axis's `limits` and the path's `speed` (None: unchecked). Returns the peaks, or the first
/// quantity over its limit (in tick order; at one tick, axes in order, velocity first, the
/// path's speed last).
pub fn check(
    trace: &[Vec<i128>],
    limits: &[AxisLimits],
    speed: Option<i128>,
) -> Result<Peaks, Exceeded> {
    let n = limits.len();
    let mut peaks = Peaks {
        axes: vec![[I256::ZERO; 3]; n],
        path_speed_squared: I256::ZERO,
    };
    let (Some(first), Some(last)) = (trace.first(), trace.last()) else {
        return Ok(peaks);
    };
    // At rest before the first point (the registers x = first, v = a = j = 0), and for three
    // points after the last: the jerk of reaching rest.
    let mut prev: Vec<[I256; 3]> = first
        .iter()
        .map(|&x| [I256::from(x), I256::ZERO, I256::ZERO])
        .collect();
    let points = trace.iter().chain(std::iter::repeat_n(last, 3));
    for (tick, p) in points.enumerate() {
        let mut step2 = I256::ZERO;
        for (i, lim) in limits.iter().enumerate() {
            let [x0, v0, a0] = prev[i];
            let x = I256::from(p[i]);
            let v = x - x0;
            let a = v - v0;
            let j = a - a0;
            prev[i] = [x, v, a];
            let checks = [
                (Quantity::Velocity, v, lim.velocity),
                (Quantity::Acceleration, a, lim.acceleration),
                (Quantity::Jerk, j, lim.jerk),
            ];
            for (r, (quantity, value, limit)) in checks.into_iter().enumerate() {
                let m = value.abs();
                peaks.axes[i][r] = peaks.axes[i][r].max(m);
                if m > I256::from(limit) {
                    return Err(Exceeded {
                        tick,
                        axis: Some(i),
                        quantity,
                        value: m,
                        limit: I256::from(limit),
                    });
                }
            }
            step2 += v * v;
        }
        peaks.path_speed_squared = peaks.path_speed_squared.max(step2);
        if let Some(s) = speed {
            let s2 = I256::from(s) * I256::from(s);
            if step2 > s2 {
                return Err(Exceeded {
                    tick,
                    axis: None,
                    quantity: Quantity::PathSpeed,
                    value: step2,
                    limit: s2,
                });
            }
        }
    }
    Ok(peaks)
}

#[cfg(test)]
mod tests {
    use super::*;

    const WIDE: AxisLimits = AxisLimits {
        velocity: 1 << 60,
        acceleration: 1 << 60,
        jerk: 1 << 60,
    };

    /// The positions of the integer chain `j += d; a += j; v += a; x += v` under the snaps
    /// `snaps`, from rest at 0 (a different route to the same numbers).
    fn chain(snaps: &[i128]) -> Vec<i128> {
        let (mut x, mut v, mut a, mut j) = (0, 0, 0, 0);
        snaps
            .iter()
            .map(|d| {
                j += d;
                a += j;
                v += a;
                x += v;
                x
            })
            .collect()
    }

    #[test]
    fn an_s_curve_peaks_where_the_chain_does() {
        // Jerk 1 for 3 ticks, 0 for 4, −1 for 3: the acceleration up to 3 and back to 0, a
        // velocity of 21; then the same mirrored, back to rest.
        let mut snaps = vec![0; 16];
        snaps[0] = 1;
        snaps[3] = -1;
        snaps[7] = -1;
        snaps[10] = 1;
        let mut both = snaps.clone();
        both.extend(snaps.iter().map(|d| -d));
        let mut x = vec![0];
        x.extend(chain(&both));
        let trace: Vec<Vec<i128>> = x.iter().map(|&p| vec![p]).collect();
        let p = check(&trace, &[WIDE], None).unwrap();
        assert_eq!(p.axes[0], [21, 3, 1].map(I256::from));
        let tight = AxisLimits { jerk: 0, ..WIDE };
        let e = check(&trace, &[tight], None).unwrap_err();
        assert_eq!((e.tick, e.quantity, e.axis), (1, Quantity::Jerk, Some(0)));
        let slow = AxisLimits {
            velocity: 20,
            ..WIDE
        };
        let e = check(&trace, &[slow], None).unwrap_err();
        assert_eq!((e.quantity, e.value), (Quantity::Velocity, I256::from(21)));
        // Cut at full speed (21 per tick, no acceleration): standing still at once after it
        // is an acceleration of −21 and jerks of −21 and 21.
        let cut = &trace[..14];
        let p = check(cut, &[WIDE], None).unwrap();
        assert_eq!(p.axes[0], [21, 21, 21].map(I256::from));
    }

    #[test]
    fn the_path_speed_is_euclidean() {
        // Steps of (3, 4): speed 5 on every tick between the ends.
        let trace: Vec<Vec<i128>> = (0..10).map(|k| vec![3 * k, 4 * k]).collect();
        let p = check(&trace, &[WIDE, WIDE], Some(5)).unwrap();
        assert_eq!(p.path_speed_squared, I256::from(25));
        let e = check(&trace, &[WIDE, WIDE], Some(4)).unwrap_err();
        assert_eq!((e.tick, e.axis, e.quantity), (1, None, Quantity::PathSpeed));
        // Per axis, 4 per tick is over a velocity limit of 3 on the second axis only.
        let v3 = AxisLimits {
            velocity: 3,
            ..WIDE
        };
        assert!(check(&trace, &[v3, WIDE], None).is_ok());
        let e = check(&trace, &[WIDE, v3], None).unwrap_err();
        assert_eq!((e.tick, e.axis), (1, Some(1)));
    }

    #[test]
    fn standing_still_is_within_any_limit() {
        let trace = vec![vec![7, -3]; 5];
        let zero = AxisLimits {
            velocity: 0,
            acceleration: 0,
            jerk: 0,
        };
        assert!(check(&trace, &[zero, zero], Some(0)).is_ok());
    }
}
