//! The plant clock by clock: the H-bridge reads the fabric's `pwm`, `dir` and `amplifier` pins
//! on every clock, the motor is integrated every `step_clocks` clocks with the bridge's voltage
//! averaged over exactly those clocks, and the encoder's count follows the shaft.
//!
//! # The bridge (sign-magnitude, with synchronous rectification)
//!
//! * Enabled, `dir` low: the motor sees `+Vs` while `pwm` is high and 0 V (both low sides on)
//!   while it is low; `dir` high: `−Vs` and 0 V.
//! * Dead time: for `dead_time` after each change of `pwm` or `dir`, the switching leg's two
//!   transistors are off and its free-wheeling diode sets the voltage, by the current's
//!   sign: a current the bridge drives loses that time at each turn-on (and a regenerating
//!   one gains it), the well-known dead-time distortion.
//! * Current limit: while |i| is at the limit, clocks that would drive it further are
//!   replaced by 0 V (the bridge chops, cycle by cycle).
//! * Disabled: every transistor off. A current decays through the diodes against the supply
//!   (`−Vs·sign(i)`) and stops at zero; then the terminals float (no current, no torque).
//!
//! # A current-mode drive (`amplifier.kind = "current"`)
//!
//! A servo drive in torque mode, as seed 001's is usually run: the pins' average over each
//! step (`+1` while `pwm` is high with `dir` low, `−1` with `dir` high) through the drive's
//! first-order input filter is its command, full scale the current limit; its PI current loop
//! sets the motor's voltage within the supply ([`Plant`]'s `current_drive`). No dead time: the
//! drive's own bridge is inside its loop. Disabled, it is off as the bridge is.
//!
//! # The encoder
//!
//! `count = round(θ / Δ)` with `Δ = 2π / (4 · lines)`: count 0 spans `±Δ/2` around the angle
//! at reset, as the chain's position LSB is centred in its cell. The index is high while
//! `count mod (4 · lines) = 0`. The pins (A, B) of a count are the model's
//! (`snapgen_model::peer::Peer::levels`).

use crate::motor::{step, MotorState};
use crate::params::{Drive, Physical};

/// The fabric's outputs to the power stage, on one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BridgePins {
    /// PWM.
    pub pwm: bool,
    /// Direction (high: negative voltage).
    pub dir: bool,
    /// Amplifier enable.
    pub enable: bool,
}

/// The plant.
#[derive(Clone, Debug)]
pub struct Plant {
    p: Physical,
    clock_period: f64,
    step_clocks: u32,
    state: MotorState,
    // The step being gathered.
    clocks: u32,
    volt_seconds: f64,
    disabled: bool,
    // The bridge.
    last: BridgePins,
    dead_left: f64,
    limiting: bool,
    // The last step's average voltage.
    volts: f64,
    time: f64,
    // A current-mode drive: the step's commanded volt-seconds (the pins alone, no dead time),
    // its command filter's output (−1..1) and its current loop's integrator (V).
    command_seconds: f64,
    command: f64,
    loop_integral: f64,
}

/// A step that is not a whole number of clocks, or none.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("a plant step of {step_s} s is {clocks} clocks of a {clock_hz} Hz clock: give a step of at least one clock (and at most 1 ms)")]
pub struct StepError {
    /// The step asked for.
    pub step_s: f64,
    /// The clock.
    pub clock_hz: f64,
    /// Clocks it would be.
    pub clocks: f64,
}

impl Plant {
    /// A plant at rest at angle 0, stepped every `round(step_s · clock_hz)` clocks.
    pub fn new(p: &Physical, clock_hz: f64, step_s: f64) -> Result<Self, StepError> {
        let clocks = (step_s * clock_hz).round();
        if !(clocks >= 1.0 && step_s <= 1e-3 && clock_hz.is_finite()) {
            return Err(StepError {
                step_s,
                clock_hz,
                clocks,
            });
        }
        Ok(Plant {
            p: *p,
            clock_period: 1.0 / clock_hz,
            step_clocks: clocks as u32,
            state: MotorState::default(),
            clocks: 0,
            volt_seconds: 0.0,
            disabled: false,
            last: BridgePins::default(),
            dead_left: 0.0,
            limiting: false,
            volts: 0.0,
            time: 0.0,
            command_seconds: 0.0,
            command: 0.0,
            loop_integral: 0.0,
        })
    }

    /// The physical parameters.
    pub fn physical(&self) -> &Physical {
        &self.p
    }

    /// The motor's state at the end of the last step.
    pub fn state(&self) -> MotorState {
        self.state
    }

    /// Sets the motor's state (a test's starting point).
    pub fn set_state(&mut self, s: MotorState) {
        self.state = s;
    }

    /// The bridge's average voltage over the last step (V).
    pub fn volts(&self) -> f64 {
        self.volts
    }

    /// Simulated time (s), at the end of the last step.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Clocks per step.
    pub fn step_clocks(&self) -> u32 {
        self.step_clocks
    }

    /// The encoder's count: the shaft angle in counts, rounded to nearest.
    pub fn count(&self) -> i64 {
        (self.state.theta / self.p.rad_per_count()).round() as i64
    }

    /// The index pulse.
    pub fn index(&self) -> bool {
        self.p.index && self.count().rem_euclid(i64::from(self.p.counts_per_rev)) == 0
    }

    /// The voltage the bridge puts on the motor for a whole clock with `pins` (before dead
    /// time), given the current's sign.
    fn commanded(&self, pins: BridgePins) -> f64 {
        if !pins.pwm {
            0.0
        } else if pins.dir {
            -self.p.vs
        } else {
            self.p.vs
        }
    }

    /// The switching leg's voltage while its transistors are both off (the diode's), across
    /// the motor.
    fn free_wheeling(&self, pins: BridgePins) -> f64 {
        let i = self.state.current;
        match (pins.dir, i > 0.0, i < 0.0) {
            // dir low, leg A switches: i > 0 leaves A through its low diode (0 V), i < 0
            // enters through its high diode (+Vs).
            (false, true, _) => 0.0,
            (false, _, true) => self.p.vs,
            // dir high, leg B switches and V = −V_B: i < 0 leaves B (0 V), i > 0 enters (−Vs).
            (true, _, true) => 0.0,
            (true, true, _) => -self.p.vs,
            _ => self.commanded(pins),
        }
    }

    /// One fabric clock with the fabric's pins; the motor steps when a step's clocks are in.
    pub fn clock(&mut self, pins: BridgePins) {
        let dt = self.clock_period;
        if !pins.enable {
            // Off: the diodes return the current to the supply until it is zero.
            let i = self.state.current;
            self.disabled = true;
            self.volt_seconds += if i > 0.0 {
                -self.p.vs
            } else if i < 0.0 {
                self.p.vs
            } else {
                self.p.ke * self.state.omega
            } * dt;
            self.dead_left = 0.0;
        } else {
            let edge = pins.pwm != self.last.pwm || pins.dir != self.last.dir;
            if edge && self.last.enable {
                self.dead_left = self.p.dead_time;
            }
            let mut v = self.commanded(pins);
            if self.limiting && v != 0.0 && v.signum() == self.state.current.signum() {
                v = 0.0;
            }
            let dead = self.dead_left.min(dt);
            self.dead_left -= dead;
            self.volt_seconds += dead * self.free_wheeling(pins) + (dt - dead) * v;
            self.command_seconds += self.commanded(pins) * dt;
        }
        self.last = pins;
        self.clocks += 1;
        if self.clocks == self.step_clocks {
            self.integrate();
        }
    }

    /// `n` clocks with the same pins (what [`Plant::clock`] does `n` times, by whole runs up
    /// to each step's end).
    pub fn hold(&mut self, pins: BridgePins, mut n: u64) {
        while n > 0 {
            let edge = pins.enable
                && self.last.enable
                && (pins.pwm != self.last.pwm || pins.dir != self.last.dir);
            if edge || self.dead_left > 0.0 || pins.enable != self.last.enable {
                self.clock(pins);
                n -= 1;
                continue;
            }
            let m = n.min(u64::from(self.step_clocks - self.clocks));
            let v = if !pins.enable {
                self.disabled = true;
                let i = self.state.current;
                if i > 0.0 {
                    -self.p.vs
                } else if i < 0.0 {
                    self.p.vs
                } else {
                    self.p.ke * self.state.omega
                }
            } else {
                let v = self.commanded(pins);
                self.command_seconds += v * self.clock_period * m as f64;
                if self.limiting && v != 0.0 && v.signum() == self.state.current.signum() {
                    0.0
                } else {
                    v
                }
            };
            self.volt_seconds += v * self.clock_period * m as f64;
            self.clocks += m as u32;
            n -= m;
            if self.clocks == self.step_clocks {
                self.integrate();
            }
        }
    }

    fn integrate(&mut self) {
        let h = f64::from(self.step_clocks) * self.clock_period;
        let mut v = self.volt_seconds / h;
        if let Drive::Current { .. } = self.p.drive {
            if self.disabled {
                // Off: the drive's loop starts again from rest.
                self.loop_integral = 0.0;
                self.command = 0.0;
            } else {
                v = self.current_drive(h);
            }
        }
        let before = self.state.current;
        let mut s = step(&self.p, self.state, v, h);
        if self.disabled && (s.current * before <= 0.0) {
            // The diodes cannot carry a reversed current: it stopped at zero.
            s.current = 0.0;
        }
        self.state = s;
        self.volts = v;
        self.limiting = s.current.abs() >= self.p.i_limit;
        self.clocks = 0;
        self.volt_seconds = 0.0;
        self.command_seconds = 0.0;
        self.disabled = false;
        self.time += h;
    }

    /// A current-mode drive over the step `h`: the pins' average is its command (through its
    /// first-order input filter), full scale `i_limit`; its PI current loop, `Kp = L·ω_c`,
    /// `Ki = R·ω_c` of the plant file's winding (the zero cancels the armature's pole: the
    /// current follows its reference as `ω_c / (s + ω_c)`, the back-EMF rejected by the
    /// integrator), sets the motor's voltage, within the supply (the integrator holds while the
    /// output is at it). Returns the step's voltage.
    fn current_drive(&mut self, h: f64) -> f64 {
        let Drive::Current {
            filter_rad_s,
            kp,
            ki,
            ..
        } = self.p.drive
        else {
            return self.volt_seconds / h;
        };
        let u = self.command_seconds / (h * self.p.vs);
        self.command += (u - self.command) * (1.0 - (-h * filter_rad_s).exp());
        let error = self.command * self.p.i_limit - self.state.current;
        let v = kp * error + self.loop_integral;
        let clamped = v.clamp(-self.p.vs, self.p.vs);
        if clamped == v {
            self.loop_integral += ki * error * h;
        }
        clamped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlantParams;

    fn run(plant: &mut Plant, clocks: u64, period: u32, duty: u32, dir: bool) {
        for k in 0..clocks {
            let phase = (k % u64::from(period)) as u32;
            plant.clock(BridgePins {
                pwm: phase < duty,
                dir,
                enable: true,
            });
        }
    }

    #[test]
    fn pwm_at_a_duty_drives_the_speed_the_average_voltage_gives() {
        // 10 MHz, 20 kHz PWM (500 clocks), 30 % duty, no dead time: V̄ = 0.3 Vs.
        let mut p = PlantParams::default_plant().physical();
        p.dead_time = 0.0;
        let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
        run(&mut plant, 3_000_000, 500, 150, false);
        let vbar = 0.3 * p.vs;
        // Steady state: V̄ = R ī + Ke ω, Kt ī = Tc + b ω.
        let want = (vbar - p.r * p.tc / p.kt) / (p.ke + p.r * p.b / p.kt);
        let got = plant.state().omega;
        assert!((got / want - 1.0).abs() < 1e-3, "{got} {want}");
        // Backwards with dir.
        let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
        run(&mut plant, 3_000_000, 500, 150, true);
        assert!((plant.state().omega / -want - 1.0).abs() < 1e-3);
    }

    #[test]
    fn dead_time_costs_the_driving_current_one_dead_time_per_period() {
        // A viscous load that keeps the current (3 A) above its PWM ripple (±0.8 A): the
        // current drives through every edge, and each period loses one dead time at turn-on.
        let mut p = PlantParams::default_plant().physical();
        p.b = 1e-3;
        let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
        run(&mut plant, 3_000_000, 500, 150, false);
        // One dead time lost per 50 µs period: V̄ = Vs (0.3 − 0.5 µs / 50 µs).
        let vbar = p.vs * (0.3 - p.dead_time / 50e-6);
        let want = (vbar - p.r * p.tc / p.kt) / (p.ke + p.r * p.b / p.kt);
        let got = plant.state().omega;
        assert!((got / want - 1.0).abs() < 2e-3, "{got} {want}");
    }

    #[test]
    fn the_current_limit_chops_and_disabling_lets_the_current_die() {
        let mut p = PlantParams::default_plant().physical();
        p.i_limit = 3.0;
        let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
        // Full voltage from rest: the stall current would be 42 A.
        let mut peak: f64 = 0.0;
        for _ in 0..200_000 {
            plant.clock(BridgePins {
                pwm: true,
                dir: false,
                enable: true,
            });
            peak = peak.max(plant.state().current);
        }
        assert!(peak < 3.0 + 0.2, "{peak}");
        // Off: the current goes to zero within a few armature time constants and stays there.
        for _ in 0..100_000 {
            plant.clock(BridgePins::default());
        }
        assert_eq!(plant.state().current, 0.0);
        assert!(plant.state().omega > 0.0, "it coasts");
    }

    #[test]
    fn holding_pins_is_clocking_them() {
        let p = PlantParams::default_plant().physical();
        let mut a = Plant::new(&p, 10e6, 1e-6).unwrap();
        let mut b = a.clone();
        let runs = [
            (true, false, true, 137u64),
            (false, false, true, 363),
            (true, true, true, 1001),
            (false, true, false, 77),
            (true, false, true, 20_000),
        ];
        for _ in 0..50 {
            for (pwm, dir, enable, n) in runs {
                let pins = BridgePins { pwm, dir, enable };
                for _ in 0..n {
                    a.clock(pins);
                }
                b.hold(pins, n);
            }
        }
        let (sa, sb) = (a.state(), b.state());
        assert!(
            (sa.theta - sb.theta).abs() < 1e-12 && (sa.current - sb.current).abs() < 1e-12,
            "{sa:?} {sb:?}"
        );
    }

    #[test]
    fn the_encoder_counts_round_to_nearest_with_an_index_per_turn() {
        let p = PlantParams::default_plant().physical();
        let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
        let d = p.rad_per_count();
        for (theta, count) in [
            (0.49 * d, 0),
            (0.51 * d, 1),
            (-0.51 * d, -1),
            (8000.2 * d, 8000),
        ] {
            plant.set_state(MotorState {
                theta,
                ..Default::default()
            });
            assert_eq!(plant.count(), count, "{theta}");
            assert_eq!(plant.index(), count % 8000 == 0);
        }
        assert!(Plant::new(&p, 10e6, 1e-8).is_err());
    }

    /// A current-mode drive at a quarter of its command sets a quarter of its full-scale
    /// current (on average over its PWM periods) while the back-EMF rises, and the shaft
    /// accelerates as `(Kt i − Tc) / J` says; the other direction, the other sign.
    #[test]
    fn a_current_mode_drive_sets_the_current_its_command_asks() {
        let p = PlantParams::parse(
            include_str!("../motors/re40-148877-current-drive.toml"),
            "current-drive",
        )
        .unwrap()
        .physical();
        for dir in [false, true] {
            let mut plant = Plant::new(&p, 10e6, 1e-6).unwrap();
            // 2 ms to settle (the filter and the loop: about 0.1 ms).
            run(&mut plant, 20_000, 500, 125, dir);
            let (w0, t0) = (plant.state().omega, plant.time());
            // 20 ms more (400 PWM periods), the current averaged over every plant step.
            let mut sum = 0.0;
            for k in 0..200_000u32 {
                plant.clock(BridgePins {
                    pwm: k % 500 < 125,
                    dir,
                    enable: true,
                });
                if k % 10 == 9 {
                    sum += plant.state().current;
                }
            }
            let sign = if dir { -1.0 } else { 1.0 };
            let mean = sum / 20_000.0;
            assert!(
                (mean - sign * 0.25 * p.i_limit).abs() < 0.01 * p.i_limit,
                "{mean}"
            );
            let s = plant.state();
            let alpha = sign * (p.kt * 0.25 * p.i_limit - p.tc) / p.j;
            let want_w = w0 + alpha * (plant.time() - t0);
            assert!(
                (s.omega - want_w).abs() < 0.02 * want_w.abs(),
                "{s:?} {want_w}"
            );
        }
    }

    #[test]
    fn current_mode_fields_belong_to_a_current_mode_drive() {
        let text = crate::params::DEFAULT_PLANT.replace(
            "current_limit_a = 12.0",
            "current_limit_a = 12.0\ncurrent_loop_hz = 2000.0",
        );
        let e = PlantParams::parse(&text, "x.toml").unwrap_err().to_string();
        assert!(e.contains("only a current-mode drive has it"), "{e}");
    }
}
