//! The brushed DC motor with its load: armature circuit and shaft, integrated with a fixed-step
//! fourth-order Runge–Kutta method over steps of constant terminal voltage.
//!
//! ```text
//! L di/dt = V − R i − Ke ω
//! J dω/dt = Kt i − b ω − Tc sign(ω)
//!   dθ/dt = ω
//! ```
//!
//! Coulomb friction: a shaft at rest stays at rest while the motor's torque is within `Tc`
//! (only the armature circuit moves); a moving shaft feels `Tc` against its motion, taken
//! constant over a step, and a step that would carry the speed through zero ends at rest.
//!
//! The step (docs/PLANT.md, "The integrator"): 1 µs by default. It must resolve the armature's
//! time constant `L/R` (0.29 ms for the default motor: RK4's error per step is then about
//! `(h·R/L)^5 / 120 ≈ 10^-15`), the PWM period (50 µs at 20 kHz: the current's ripple is
//! followed in 50 steps) and the encoder's counts (one every 22 µs at 35 rad/s): the plant is
//! stepped every `round(h · clock)` fabric clocks, with the bridge's voltage averaged over
//! exactly those clocks.

use crate::params::Physical;

/// The motor's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotorState {
    /// Shaft angle (rad).
    pub theta: f64,
    /// Shaft speed (rad/s).
    pub omega: f64,
    /// Armature current (A).
    pub current: f64,
}

/// `(dθ, dω, di)` at `s` with terminal voltage `v` and Coulomb torque `friction` (signed).
fn derivatives(p: &Physical, s: &MotorState, v: f64, friction: f64) -> [f64; 3] {
    [
        s.omega,
        (p.kt * s.current - p.b * s.omega - friction) / p.j,
        (v - p.r * s.current - p.ke * s.omega) / p.l,
    ]
}

/// One RK4 step of `f` from `y`.
fn rk4(y: [f64; 3], h: f64, f: impl Fn([f64; 3]) -> [f64; 3]) -> [f64; 3] {
    let add =
        |a: [f64; 3], b: [f64; 3], k: f64| [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]];
    let k1 = f(y);
    let k2 = f(add(y, k1, h / 2.0));
    let k3 = f(add(y, k2, h / 2.0));
    let k4 = f(add(y, k3, h));
    [
        y[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
        y[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        y[2] + h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
    ]
}

/// `s` after `h` seconds at terminal voltage `v`.
pub fn step(p: &Physical, s: MotorState, v: f64, h: f64) -> MotorState {
    let state = |y: [f64; 3]| MotorState {
        theta: y[0],
        omega: y[1],
        current: y[2],
    };
    if s.omega == 0.0 && (p.kt * s.current).abs() < p.tc {
        // Stuck: the armature circuit alone (ω = 0).
        let y = rk4([s.theta, 0.0, s.current], h, |y| {
            [0.0, 0.0, (v - p.r * y[2]) / p.l]
        });
        return state(y);
    }
    let dir = if s.omega != 0.0 {
        s.omega.signum()
    } else {
        (p.kt * s.current).signum()
    };
    let y = rk4([s.theta, s.omega, s.current], h, |y| {
        derivatives(p, &state(y), v, p.tc * dir)
    });
    let mut n = state(y);
    if n.omega * dir < 0.0 {
        // Friction stopped it within the step.
        n.omega = 0.0;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlantParams;

    /// The linear motor (no Coulomb friction) from rest under a voltage step, exactly:
    /// `(s² + (R/L + b/J) s + (R b + Kt Ke)/(L J)) ω = Kt V/(L J)`, two real poles.
    fn exact(p: &Physical, v: f64, t: f64) -> MotorState {
        let a1 = p.r / p.l + p.b / p.j;
        let a0 = (p.r * p.b + p.kt * p.ke) / (p.l * p.j);
        let disc = (a1 * a1 - 4.0 * a0).sqrt();
        let (s1, s2) = ((-a1 + disc) / 2.0, (-a1 - disc) / 2.0);
        let w_ss = p.kt * v / (p.r * p.b + p.kt * p.ke);
        // ω = w_ss (1 + (s2 e^{s1 t} − s1 e^{s2 t}) / (s1 − s2)), ω(0) = ω'(0) = 0.
        let omega = w_ss * (1.0 + (s2 * (s1 * t).exp() - s1 * (s2 * t).exp()) / (s1 - s2));
        let theta = w_ss
            * (t + (s2 / s1 * ((s1 * t).exp() - 1.0) - s1 / s2 * ((s2 * t).exp() - 1.0))
                / (s1 - s2));
        // i from J ω' + b ω = Kt i.
        let domega = w_ss * s1 * s2 * ((s1 * t).exp() - (s2 * t).exp()) / (s1 - s2);
        MotorState {
            theta,
            omega,
            current: (p.j * domega + p.b * omega) / p.kt,
        }
    }

    #[test]
    fn the_integrator_follows_the_analytic_step_response() {
        // The default motor without Coulomb friction, with some viscous friction.
        let p = Physical {
            tc: 0.0,
            b: 2e-5,
            ..PlantParams::default_plant().physical()
        };
        let (v, h) = (6.0, 1e-6);
        let mut s = MotorState::default();
        let mut worst = [0.0f64; 3];
        for k in 1..=200_000 {
            s = step(&p, s, v, h);
            if k % 1000 == 0 {
                let e = exact(&p, v, k as f64 * h);
                let scale = exact(&p, v, 0.2);
                worst[0] = worst[0].max((s.theta - e.theta).abs() / scale.theta);
                worst[1] = worst[1].max((s.omega - e.omega).abs() / scale.omega);
                worst[2] = worst[2].max((s.current - e.current).abs() / 0.1);
            }
        }
        // 0.2 s (five loaded time constants) at 1 µs steps: the error is rounding's alone
        // (measured ~1e-12 here; RK4's error falls as h⁴ down to that floor).
        assert!(worst.iter().all(|&w| w < 1e-9), "{worst:?}");
        // Ten times the step: still far below what the encoder resolves (the error scales as h⁴).
        let mut s = MotorState::default();
        for _ in 0..20_000 {
            s = step(&p, s, v, 10.0 * h);
        }
        let e = exact(&p, v, 0.2);
        assert!((s.theta - e.theta).abs() < 1e-7, "{} {}", s.theta, e.theta);
    }

    #[test]
    fn coulomb_friction_holds_below_breakaway_and_stops_the_shaft() {
        let p = PlantParams::default_plant().physical();
        // Below R·Tc/Kt the shaft does not move.
        let v = 0.9 * p.r * p.tc / p.kt;
        let mut s = MotorState::default();
        for _ in 0..100_000 {
            s = step(&p, s, v, 1e-6);
        }
        assert_eq!((s.theta, s.omega), (0.0, 0.0));
        // Above it, it turns; without voltage (the terminals shorted) it comes to rest and stays.
        let mut s = MotorState::default();
        for _ in 0..100_000 {
            s = step(&p, s, 2.0, 1e-6);
        }
        assert!(s.omega > 10.0);
        for _ in 0..400_000 {
            s = step(&p, s, 0.0, 1e-6);
        }
        let at = s.theta;
        for _ in 0..10_000 {
            s = step(&p, s, 0.0, 1e-6);
        }
        assert_eq!((s.omega, s.theta), (0.0, at));
    }
}
