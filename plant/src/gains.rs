//! The controller's gains, derived from the plant by pole placement (docs/PLANT.md, "Gains").
//!
//! With the armature's inductance neglected (its time constant, 0.29 ms for the default motor,
//! is far below the loop's), the plant from voltage to angle is
//!
//! ```text
//! G(s) = K / (s (τ s + 1)),   K = Kt / (R b + Kt Ke) (rad/s per V),   τ = J R / (R b + Kt Ke)
//! ```
//!
//! and with the PID `C(s) = Kp + Ki/s + Kd s` the closed loop's characteristic polynomial is
//! `τ s³ + (1 + K Kd) s² + K Kp s + K Ki`. Placing its roots at `(s + ω)(s² + 2ζω s + ω²)` —
//! a real pole and a pair of damping `ζ`, all at the bandwidth `ω` — gives
//!
//! ```text
//! Kd = ((2ζ + 1) ω τ − 1) / K      Kp = (2ζ + 1) ω² τ / K      Ki = ω³ τ / K
//! ```
//!
//! (a negative `Kd` — a bandwidth below the plant's own `1 / ((2ζ+1) τ)` — is taken as 0).
//! The feed-forward inverts the plant's model along the reference: `Kv = 1/K` (the back-EMF and
//! the viscous friction at the reference velocity) and `Ka = J R / Kt` (the inertia at the
//! reference acceleration), in volts per rad/s and per rad/s²; Coulomb friction is left to the
//! integrator. The bandwidth is capped at a twentieth of the sample rate (the loop's delay,
//! a sample and a PWM period, then costs about 20° of phase).
//!
//! The derivative acts on an error that changes in whole encoder counts: its filter
//! (`D_FILTER = k`, a low-pass of about `2^k` samples) gets the cutoff nearest to
//! `d_filter_ratio` times the bandwidth, `f_s / (2π·2^k)`.
//!
//! With a current-mode drive (torque mode: docs/PLANT.md) the plant is `K_c / (s (J s + b))`
//! from the command to the angle and the same placement gives
//! `Kd = ((2ζ + 1) ω A − B)`, `Kp = (2ζ + 1) ω² A`, `Ki = ω³ A` with `A = J/K_c`, `B = b/K_c`
//! ([`plant_terms`]; the H-bridge's are the same with `A = τ/K`, `B = 1/K`).
//!
//! The volts become PWM clocks (`period / Vs` per volt), radians encoder counts, seconds
//! samples (Ki, Kd) or ticks (Kv, Ka), and those the fabric's integers
//! (`snapgen_model::io::servo::ServoConfig::from_physical`).

use std::f64::consts::PI;

use snapgen_model::io::servo::{GainError, PhysicalGains, ServoConfig, E_FRAC, GAIN_BITS};

use crate::params::{Drive, Physical};

/// What the loop should do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopDesign {
    /// Closed-loop bandwidth (Hz), capped at a twentieth of the sample rate.
    pub bandwidth_hz: f64,
    /// Damping of the complex pole pair.
    pub damping: f64,
    /// Velocity and acceleration feed-forward on.
    pub feed_forward: bool,
    /// Integral action (a PID); without it a PD whose two poles are placed at the bandwidth,
    /// `(s² + 2ζω s + ω²)`: `Kp = A ω²`, `Kd = 2ζω A − B`.
    pub integrator: bool,
    /// Following-error limit (rad).
    pub following_limit_rad: f64,
    /// Share of the supply the integrator may command (its anti-windup bound).
    pub integral_share: f64,
    /// The derivative filter's cutoff over the bandwidth.
    pub d_filter_ratio: f64,
}

impl Default for LoopDesign {
    fn default() -> Self {
        LoopDesign {
            bandwidth_hz: 20.0,
            damping: 0.7,
            feed_forward: true,
            integrator: true,
            following_limit_rad: 1.0,
            integral_share: 0.25,
            d_filter_ratio: 10.0,
        }
    }
}

/// The fabric's timing the gains are for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopTiming {
    /// Tick (s).
    pub ts: f64,
    /// Ticks per sample.
    pub servo_period: u16,
    /// PWM period (clocks).
    pub pwm_period: u16,
}

impl LoopTiming {
    /// The sample period (s).
    pub fn sample_s(&self) -> f64 {
        self.ts * f64::from(self.servo_period)
    }
}

/// The gains in volts and radians (the method's own units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VoltGains {
    /// V per rad.
    pub kp: f64,
    /// V per rad·s.
    pub ki: f64,
    /// V per rad/s.
    pub kd: f64,
    /// V per rad/s of reference velocity.
    pub kv: f64,
    /// V per rad/s² of reference acceleration.
    pub ka: f64,
}

/// Derived gains, at every stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// The bandwidth used (Hz), after the cap.
    pub bandwidth_hz: f64,
    /// The plant's gain `K` (rad/s per V) and time constant `τ` (s).
    pub plant_k: f64,
    /// `τ`.
    pub plant_tau: f64,
    /// In volts and radians.
    pub volts: VoltGains,
    /// In PWM clocks, counts, samples and ticks.
    pub physical: PhysicalGains,
    /// What CONFIGURE writes.
    pub config: ServoConfig,
}

/// Why no gains.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DesignError {
    /// A design value out of range.
    #[error("{what} = {value}: {fix}")]
    Bad {
        /// Which.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What to change.
        fix: &'static str,
    },
    /// A gain the fabric cannot hold.
    #[error(transparent)]
    Gain(#[from] GainError),
}

/// The plant's `(A, B)` of `A θ'' + B θ' = u` (u in volts): with the H-bridge `A = J R / Kt`,
/// `B = (R b + Kt Ke) / Kt` (`τ/K` and `1/K`); with a current-mode drive, whose full command
/// (`Vs` "volts") is the full-scale current `I`, `A = J Vs / (Kt I)` and `B = b Vs / (Kt I)`
/// (the back-EMF and the resistance are the drive's to overcome). Coulomb friction is left to
/// the integrator.
pub fn plant_terms(p: &Physical) -> (f64, f64) {
    match p.drive {
        Drive::Voltage => (p.j * p.r / p.kt, (p.r * p.b + p.kt * p.ke) / p.kt),
        Drive::Current { .. } => {
            let per_volt = p.kt * p.i_limit / p.vs;
            (p.j / per_volt, p.b / per_volt)
        }
    }
}

/// The gains for plant `p` with `design` at `timing`.
pub fn derive(
    p: &Physical,
    design: &LoopDesign,
    timing: &LoopTiming,
) -> Result<Gains, DesignError> {
    let bad = |what, value: f64, fix| Err(DesignError::Bad { what, value, fix });
    if !(design.bandwidth_hz.is_finite() && design.bandwidth_hz > 0.0) {
        return bad(
            "bandwidth_hz",
            design.bandwidth_hz,
            "give a positive bandwidth in Hz",
        );
    }
    if !(design.damping.is_finite() && (0.1..=5.0).contains(&design.damping)) {
        return bad(
            "damping",
            design.damping,
            "give a damping between 0.1 and 5 (0.7 is usual)",
        );
    }
    if !(design.following_limit_rad.is_finite() && design.following_limit_rad > 0.0) {
        return bad(
            "following_limit_rad",
            design.following_limit_rad,
            "give a positive following-error limit in rad",
        );
    }
    if !(0.0..=1.0).contains(&design.integral_share) {
        return bad(
            "integral_share",
            design.integral_share,
            "give a share of the supply in 0..=1",
        );
    }
    if timing.servo_period == 0
        || timing.pwm_period == 0
        || !(timing.ts.is_finite() && timing.ts > 0.0)
    {
        return bad(
            "servo_period",
            f64::from(timing.servo_period),
            "the loop needs a sample period and a PWM period (both ≥ 1)",
        );
    }
    let t = timing.sample_s();
    let f = design.bandwidth_hz.min(1.0 / (20.0 * t));
    let w = 2.0 * PI * f;
    let z = design.damping;
    // The plant as `θ'' · A + θ' · B = u`: `A = τ/K` volts per rad/s², `B = 1/K` volts per
    // rad/s (for a current-mode drive, a volt is a share `1/Vs` of its full-scale command).
    let (a, b) = plant_terms(p);
    let (k, tau) = (1.0 / b, a / b);
    let (kp, ki, kd) = if design.integrator {
        (
            (2.0 * z + 1.0) * w * w * a,
            w * w * w * a,
            ((2.0 * z + 1.0) * w * a - b).max(0.0),
        )
    } else {
        (w * w * a, 0.0, (2.0 * z * w * a - b).max(0.0))
    };
    let volts = VoltGains {
        kp,
        ki,
        kd,
        kv: if design.feed_forward { b } else { 0.0 },
        ka: if design.feed_forward { a } else { 0.0 },
    };
    // Volts to PWM clocks, radians to counts.
    let duty_per_volt = f64::from(timing.pwm_period) / p.vs;
    let rad = p.rad_per_count();
    let physical = PhysicalGains {
        kp: volts.kp * rad * duty_per_volt,
        ki: volts.ki * t * rad * duty_per_volt,
        kd: volts.kd / t * rad * duty_per_volt,
        kv: volts.kv * rad / timing.ts * duty_per_volt,
        ka: volts.ka * rad / (timing.ts * timing.ts) * duty_per_volt,
    };
    // The integrator may command `integral_share` of the supply: |Ki·I| ≤ share · period.
    let integral_limit = if physical.ki > 0.0 {
        let counts_samples = design.integral_share * f64::from(timing.pwm_period) / physical.ki;
        (counts_samples * f64::from(1u32 << E_FRAC)).min(((1i64 << GAIN_BITS) - 1) as f64) as i64
    } else {
        0
    };
    let following = (design.following_limit_rad / rad).ceil();
    if following > f64::from(i32::MAX) {
        return bad(
            "following_limit_rad",
            design.following_limit_rad,
            "it is more counts than FOLLOWING_LIMIT holds (2^31 − 1)",
        );
    }
    // The derivative filter: cutoff f_s / (2π·2^k) nearest to d_filter_ratio × bandwidth.
    let shift = (1.0 / t / (2.0 * PI * design.d_filter_ratio * f))
        .log2()
        .round()
        .clamp(0.0, 15.0);
    let config = ServoConfig {
        servo_period: timing.servo_period,
        d_filter: if design.d_filter_ratio > 0.0 {
            shift as u8
        } else {
            0
        },
        integral_limit,
        output_limit: timing.pwm_period.min(i16::MAX as u16),
        following_limit: following as u32,
        ..Default::default()
    }
    .from_physical(&physical)?;
    Ok(Gains {
        bandwidth_hz: f,
        plant_k: k,
        plant_tau: tau,
        volts,
        physical,
        config,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlantParams;

    fn timing() -> LoopTiming {
        LoopTiming {
            ts: 1e-5,
            servo_period: 5,
            pwm_period: 500,
        }
    }

    /// The closed loop's characteristic polynomial with the derived gains has the roots asked
    /// for: evaluated at them, it vanishes.
    #[test]
    fn the_poles_land_where_they_were_placed() {
        let p = PlantParams::default_plant().physical();
        let g = derive(&p, &LoopDesign::default(), &timing()).unwrap();
        let (k, tau) = (g.plant_k, g.plant_tau);
        let w = 2.0 * PI * g.bandwidth_hz;
        let z = 0.7;
        let char_poly = |re: f64, im: f64| {
            // τ s³ + (1 + K Kd) s² + K Kp s + K Ki at s = re + i im.
            let (s2r, s2i) = (re * re - im * im, 2.0 * re * im);
            let (s3r, s3i) = (s2r * re - s2i * im, s2r * im + s2i * re);
            let c2 = 1.0 + k * g.volts.kd;
            (
                tau * s3r + c2 * s2r + k * g.volts.kp * re + k * g.volts.ki,
                tau * s3i + c2 * s2i + k * g.volts.kp * im,
            )
        };
        let scale = k * g.volts.ki;
        for (re, im) in [(-w, 0.0), (-z * w, w * (1.0 - z * z).sqrt())] {
            let (r, i) = char_poly(re, im);
            assert!(r.abs() / scale < 1e-9 && i.abs() / scale < 1e-9, "{r} {i}");
        }
        // The feed-forward: Kv·ω and Ka·α are the voltages the model needs at (ω, α).
        let (omega, alpha) = (30.0, 60.0);
        let v = g.volts.kv * omega + g.volts.ka * alpha;
        let i = p.j * alpha / p.kt + p.b * omega / p.kt;
        assert!((v - (p.r * i + p.ke * omega)).abs() < 1e-9);
    }

    #[test]
    fn the_derivative_filter_cuts_off_near_ten_times_the_bandwidth() {
        let p = PlantParams::default_plant().physical();
        let g = derive(&p, &LoopDesign::default(), &timing()).unwrap();
        // 20 kHz samples, 20 Hz: f_s / (2π·2^k) nearest 200 Hz is k = 4 (199 Hz).
        assert_eq!(g.config.d_filter, 4);
        assert!((g.plant_k - p.speed_per_volt()).abs() < 1e-12);
    }

    #[test]
    fn a_slow_loop_caps_the_bandwidth_and_bad_designs_are_refused() {
        let p = PlantParams::default_plant().physical();
        let slow = LoopTiming {
            servo_period: 500,
            ..timing()
        };
        let g = derive(&p, &LoopDesign::default(), &slow).unwrap();
        assert!((g.bandwidth_hz - 10.0).abs() < 1e-9);
        let e = derive(
            &p,
            &LoopDesign {
                damping: 0.0,
                ..Default::default()
            },
            &slow,
        )
        .unwrap_err();
        assert!(e.to_string().contains("damping"), "{e}");
    }

    /// With a current-mode drive: the characteristic polynomial `A s³ + (B + Kd) s² + Kp s + Ki`
    /// of the plant `A θ'' + B θ' = u` (A and B from the drive's full scale, computed here
    /// from J, b, Kt, I and Vs) vanishes at the placed roots; the feed-forward is the command
    /// the inertia and the viscous friction need.
    #[test]
    fn current_mode_poles_land_where_they_were_placed() {
        let p = Physical {
            drive: crate::params::Drive::Current {
                loop_rad_s: 2.0 * PI * 2500.0,
                filter_rad_s: 2.0 * PI * 5000.0,
                kp: 5.0,
                ki: 2e4,
            },
            b: 3e-5,
            ..PlantParams::default_plant().physical()
        };
        let g = derive(&p, &LoopDesign::default(), &timing()).unwrap();
        let per_volt = p.kt * p.i_limit / p.vs;
        let (a, b) = (p.j / per_volt, p.b / per_volt);
        let w = 2.0 * PI * g.bandwidth_hz;
        let z = 0.7;
        let char_poly = |re: f64, im: f64| {
            let (s2r, s2i) = (re * re - im * im, 2.0 * re * im);
            let (s3r, s3i) = (s2r * re - s2i * im, s2r * im + s2i * re);
            let c2 = b + g.volts.kd;
            (
                a * s3r + c2 * s2r + g.volts.kp * re + g.volts.ki,
                a * s3i + c2 * s2i + g.volts.kp * im,
            )
        };
        for (re, im) in [(-w, 0.0), (-z * w, w * (1.0 - z * z).sqrt())] {
            let (r, i) = char_poly(re, im);
            assert!(
                r.abs() / g.volts.ki < 1e-9 && i.abs() / g.volts.ki < 1e-9,
                "{r} {i}"
            );
        }
        // Kv ω + Ka α commands the current J α / Kt + b ω / Kt, in volts of full scale.
        let (omega, alpha) = (30.0, 60.0);
        let command = (g.volts.kv * omega + g.volts.ka * alpha) / p.vs * p.i_limit;
        assert!((command - (p.j * alpha + p.b * omega) / p.kt).abs() < 1e-9);
    }

    /// Without the integrator: `A s² + (B + Kd) s + Kp` vanishes at the placed pair, and no
    /// integral action is left (KI and INTEGRAL_LIMIT 0).
    #[test]
    fn a_pd_places_its_two_poles() {
        let p = PlantParams::default_plant().physical();
        let d = LoopDesign {
            integrator: false,
            bandwidth_hz: 5.0,
            ..Default::default()
        };
        let g = derive(&p, &d, &timing()).unwrap();
        let (a, b) = (p.j * p.r / p.kt, (p.r * p.b + p.kt * p.ke) / p.kt);
        let w = 2.0 * PI * 5.0;
        let (re, im) = (-0.7 * w, w * (1.0f64 - 0.49).sqrt());
        let (s2r, s2i) = (re * re - im * im, 2.0 * re * im);
        let r = a * s2r + (b + g.volts.kd) * re + g.volts.kp;
        let i = a * s2i + (b + g.volts.kd) * im;
        assert!(
            r.abs() / g.volts.kp < 1e-9 && i.abs() / g.volts.kp < 1e-9,
            "{r} {i}"
        );
        assert_eq!((g.config.ki, g.config.integral_limit), (0, 0));
    }
}
