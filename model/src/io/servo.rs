//! The position controller (`snapgen_hdl::servo::Servo`), clock by clock: PID on the following
//! error with velocity and acceleration feed-forward from the chain's exact registers,
//! integrator anti-windup, output saturation and a following-error limit.
//!
//! # The law, once per sample (docs/MODEL.md, "The position controller")
//!
//! All integers; `count` is the encoder's 32-bit count, `x`, `v`, `a` the chain's registers
//! (output LSB = one encoder count, so the reference and the encoder share their unit). The
//! count `n` stands for the centre of output cell `n` (`x = n·2^80 + 2^79`), where the chain
//! rests: an axis at rest on its target has no following error.
//!
//! ```text
//! e48 = wrap48(x[111:64] − (count·2^16 + 2^15))   following error, counts · 2^-16
//! fault  = |e48| > FOLLOWING_LIMIT · 2^16
//! e   = sat32(e48)                                 (±32 768 counts)
//! Δ   = e − e_prev        (0 on the first sample after the amplifier is enabled)
//! F   = F + Δ − (F >> k)   the derivative's filter, k = D_FILTER (48-bit state)
//! D   = F >> k             (with the new F)
//! I   = clamp(I + e, ±INTEGRAL_LIMIT)   unless the last output saturated in e's direction
//! vs  = v >> 48                                    counts/tick · 2^-32
//! as  = a >> 40                                    counts/tick² · 2^-40
//! sum = KP·e + KI·I + KD·D + KV·vs + KA·as         exact (< 2^113)
//! u   = (sum + 2^47) >> 48                         rounded to nearest, halves up
//! duty = clamp(u, ±OUTPUT_LIMIT)                   PWM clocks, sign = direction
//! ```
//!
//! The derivative filter is a first-order low-pass of time constant about `2^k` samples (its
//! gain at rest is 1; `k = 0` is no filter, `D = Δ`); `>>` is the arithmetic shift (rounding
//! toward −∞).
//!
//! So a gain's integer is its physical value times a fixed power of two: `KP = Kp·2^32` with
//! `Kp` in PWM clocks per count, `KI = Ki·2^32` (per count·sample), `KD = Kd·2^32` (per count
//! per sample), `KV = Kv·2^16` (per count/tick), `KA = Ka·2^8` (per count/tick²)
//! ([`ServoConfig::from_physical`]). Gains are 0 ..= 2^47 − 1.
//!
//! # Timing
//!
//! A sample is taken on every `SERVO_PERIOD`-th tick, from the registers, the count and the
//! configuration as they stand on the clock of that tick (before it). The fabric computes serially (one 48 × 64-bit
//! product per term, 16 bits of the gain per clock): the following-error check answers on the
//! next clock ([`ServoOutputs::fault`]), the new duty stands [`LATENCY`] (27) clocks after the sample.
//! A sample due while the last one is still computing is skipped and reported
//! ([`ServoOutputs::overrun`]). While the amplifier is off everything clears (duty 0, integrator
//! 0, the divider restarts); the peak error holds until the next START or reset.

use crate::chain::wrap;

/// Fractional bits of the following error below one count (the status block's unit).
pub const E_FRAC: u32 = snapgen_spec::widths::E_FRAC;
/// `vs = v >> V_SHIFT`: velocity in counts per tick with 32 fractional bits.
pub const V_SHIFT: u32 = 48;
/// `as = a >> A_SHIFT`: acceleration in counts per tick² with 40 fractional bits.
pub const A_SHIFT: u32 = 40;
/// `u = sum >> OUT_SHIFT`, rounded.
pub const OUT_SHIFT: u32 = 48;
/// Gains are below `2^GAIN_BITS` (their registers hold `snapgen_spec::widths::GAIN_BITS`
/// bits, two's complement).
pub const GAIN_BITS: u32 = snapgen_spec::widths::GAIN_BITS - 1;
/// Clocks from a sample to its duty: 1 to check the error and update the integrator, 5 per
/// term (3 gain digits of 16 bits through a registered multiplier, the last product's
/// addition, the sum), 1 to round and saturate.
pub const LATENCY: u32 = 1 + 5 * 5 + 1;

pub use crate::io::config::ServoConfig;

/// The gains and limits in physical units, per the controller's units: PWM clocks (duty),
/// encoder counts, ticks and samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhysicalGains {
    /// Duty clocks per count of following error.
    pub kp: f64,
    /// Duty clocks per count·sample of integrated error.
    pub ki: f64,
    /// Duty clocks per count/sample of error change.
    pub kd: f64,
    /// Duty clocks per count/tick of reference velocity.
    pub kv: f64,
    /// Duty clocks per count/tick² of reference acceleration.
    pub ka: f64,
}

/// A gain that does not fit the controller's integers.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "gain {name} = {value} ({units}) is {raw:.3e} as an integer, outside 0 ..= 2^47 − 1: {fix}"
)]
pub struct GainError {
    /// Which.
    pub name: &'static str,
    /// Its physical value.
    pub value: f64,
    /// Its units.
    pub units: &'static str,
    /// As an integer.
    pub raw: f64,
    /// What to change.
    pub fix: &'static str,
}

impl ServoConfig {
    /// The gains' integers (rounded to nearest) for `g`, the rest of `self` kept.
    pub fn from_physical(self, g: &PhysicalGains) -> Result<ServoConfig, GainError> {
        let max = ((1i64 << GAIN_BITS) - 1) as f64;
        let conv = |name, value: f64, shift: i32, units| {
            let raw = (value * 2f64.powi(shift)).round();
            if !(raw.is_finite() && (0.0..=max).contains(&raw)) {
                return Err(GainError {
                    name,
                    value,
                    units,
                    raw,
                    fix: if raw < 0.0 || raw.is_nan() {
                        "gains are not negative (check the motor's or the encoder's polarity instead)"
                    } else {
                        "lower the bandwidth or raise the loop rate"
                    },
                });
            }
            Ok(raw as i64)
        };
        Ok(ServoConfig {
            kp: conv("KP", g.kp, 32, "duty clocks per count")?,
            ki: conv("KI", g.ki, 32, "duty clocks per count·sample")?,
            kd: conv("KD", g.kd, 32, "duty clocks per count/sample")?,
            kv: conv("KV", g.kv, 16, "duty clocks per count/tick")?,
            ka: conv("KA", g.ka, 8, "duty clocks per count/tick²")?,
            ..self
        })
    }
}

/// The law's state between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ServoLaw {
    /// The integrator.
    pub integral: i128,
    /// The last sample's (saturated) error.
    pub e_prev: i128,
    /// The derivative filter's state `F` (48-bit).
    pub d_state: i128,
    /// A sample has been taken since the amplifier was enabled.
    pub primed: bool,
    /// The last output was above `OUTPUT_LIMIT`.
    pub sat_high: bool,
    /// ... below `−OUTPUT_LIMIT`.
    pub sat_low: bool,
}

/// One sample's result.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sample {
    /// The following error, counts · 2^-16 (48-bit, before saturation).
    pub error: i128,
    /// The error is beyond the following-error limit.
    pub fault: bool,
    /// The new duty, PWM clocks.
    pub duty: i16,
}

/// The following error of the registers `x` against the encoder count (48-bit, counts·2^-16):
/// the count `n` stands for the centre of cell `n`.
pub fn following_error(x: i128, count: i64) -> i128 {
    let r = wrap(x >> 64, 48);
    wrap(
        r - ((i128::from(count as i32) << E_FRAC) + (1 << (E_FRAC - 1))),
        48,
    )
}

impl ServoLaw {
    /// One sample (the module documentation's law).
    pub fn sample(&mut self, c: &ServoConfig, x: i128, v: i128, a: i128, count: i64) -> Sample {
        let e48 = following_error(x, count);
        let fault = e48.abs() > i128::from(c.following_limit) << E_FRAC;
        let e = e48.clamp(-(1 << 31), (1 << 31) - 1);
        let delta = if self.primed { e - self.e_prev } else { 0 };
        let k = u32::from(c.d_filter.min(15));
        self.d_state = wrap(self.d_state + delta - (self.d_state >> k), 48);
        let d = self.d_state >> k;
        let hold = (self.sat_high && e > 0) || (self.sat_low && e < 0);
        if !hold {
            let lim = i128::from(c.integral_limit);
            self.integral = (self.integral + e).clamp(-lim, lim);
        }
        self.e_prev = e;
        self.primed = true;
        let sum = i128::from(c.kp) * e
            + i128::from(c.ki) * self.integral
            + i128::from(c.kd) * d
            + i128::from(c.kv) * (v >> V_SHIFT)
            + i128::from(c.ka) * (a >> A_SHIFT);
        let u = (sum + (1 << (OUT_SHIFT - 1))) >> OUT_SHIFT;
        let lim = i128::from(c.output_limit);
        self.sat_high = u > lim;
        self.sat_low = u < -lim;
        Sample {
            error: e48,
            fault,
            duty: u.clamp(-lim, lim) as i16,
        }
    }
}

/// Inputs of one clock (registered outputs of other blocks, as they stand before the edge).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServoInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// The amplifier is enabled (otherwise everything clears).
    pub enable: bool,
    /// The core's tick enable.
    pub tick: bool,
    /// A program starts (the peak error clears).
    pub start: bool,
    /// Position register.
    pub x: i128,
    /// Velocity register.
    pub v: i128,
    /// Acceleration register.
    pub a: i128,
    /// Encoder count (32-bit).
    pub count: i64,
    /// The configuration.
    pub config: ServoConfig,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ServoOutputs {
    /// The duty for the PWM, clocks (signed).
    pub duty: i16,
    /// Pulse: the following error exceeded its limit.
    pub fault: bool,
    /// Pulse: a sample was skipped (the last one was still computing).
    pub overrun: bool,
    /// The largest |following error| at a sample since the last START or reset, counts·2^-16
    /// (saturated at 2^31).
    pub peak: u32,
}

/// The controller, clock by clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Servo {
    law: ServoLaw,
    out: ServoOutputs,
    /// Ticks until the next sample.
    divider: u16,
    /// Clocks until the computing sample's duty stands (0: idle).
    countdown: u32,
    pending: Sample,
}

impl Servo {
    /// At rest.
    pub fn new() -> Self {
        Self::default()
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> ServoOutputs {
        self.out
    }

    /// The law's state.
    pub fn law(&self) -> &ServoLaw {
        &self.law
    }

    /// One clock.
    pub fn clock(&mut self, i: &ServoInputs) -> ServoOutputs {
        let c = &i.config;
        self.out.fault = false;
        self.out.overrun = false;
        if i.reset || i.start {
            self.out.peak = 0;
        }
        if i.reset || !i.enable {
            self.law = ServoLaw::default();
            self.out.duty = 0;
            self.divider = 0;
            self.countdown = 0;
            return self.out;
        }
        let busy = self.countdown > 0;
        // The divider counts ticks; a sample on the tick it reaches 0.
        let due = i.tick && c.servo_period != 0 && self.divider == 0;
        if i.tick && c.servo_period != 0 {
            self.divider = if self.divider == 0 {
                c.servo_period - 1
            } else {
                self.divider - 1
            };
        }
        if busy {
            self.countdown -= 1;
            if self.countdown == LATENCY - 1 {
                // The error checked, one clock after the sample.
                self.out.fault = self.pending.fault;
                if !i.start {
                    let mag = self
                        .pending
                        .error
                        .clamp(-(1 << 31), (1 << 31) - 1)
                        .unsigned_abs();
                    self.out.peak = self.out.peak.max(mag as u32);
                }
            }
            if self.countdown == 0 {
                self.out.duty = self.pending.duty;
            }
        }
        if due {
            if busy {
                self.out.overrun = true;
            } else {
                self.pending = self.law.sample(c, i.x, i.v, i.a, i.count);
                self.countdown = LATENCY;
            }
        }
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> ServoConfig {
        ServoConfig {
            servo_period: 1,
            kp: 1 << 32,
            output_limit: 1000,
            following_limit: 100,
            ..Default::default()
        }
    }

    /// `x` for a reference `counts + frac / 2^16` counts from the centre of cell 0.
    fn x_of(counts: i64, frac: i128) -> i128 {
        (i128::from(counts) << 80) + (1 << 79) + (frac << 64)
    }

    #[test]
    fn proportional_rounds_to_nearest_and_saturates() {
        let mut law = ServoLaw::default();
        let c = cfg();
        // 5.5 counts of error at Kp = 1 duty/count: 5.5 rounds up to 6.
        assert_eq!(law.sample(&c, x_of(5, 1 << 15), 0, 0, 0).duty, 6);
        // −5.5 rounds up (toward +∞) to −5.
        assert_eq!(law.sample(&c, x_of(-6, 1 << 15), 0, 0, 0).duty, -5);
        let s = law.sample(&c, x_of(5000, 0), 0, 0, 0);
        assert_eq!(s.duty, 1000);
        assert!(law.sat_high && s.fault);
        // Beyond the following limit: a fault.
        assert!(law.sample(&c, x_of(0, 0), 0, 0, -101).fault);
        assert!(!law.sample(&c, x_of(0, 0), 0, 0, -100).fault);
    }

    #[test]
    fn the_integrator_clamps_and_holds_while_saturated() {
        let c = ServoConfig {
            ki: 1 << 32,
            integral_limit: 10 << 16,
            ..cfg()
        };
        let mut law = ServoLaw::default();
        for _ in 0..20 {
            law.sample(&c, x_of(1, 0), 0, 0, 0);
        }
        assert_eq!(law.integral, 10 << 16);
        // Saturated high with a positive error: the integrator holds.
        let c2 = ServoConfig {
            output_limit: 5,
            ..c
        };
        let mut law = ServoLaw::default();
        law.sample(&c2, x_of(1, 0), 0, 0, 0);
        law.sample(&c2, x_of(100, 0), 0, 0, 0);
        let held = law.integral;
        law.sample(&c2, x_of(100, 0), 0, 0, 0);
        assert_eq!(law.integral, held);
        // A negative error integrates again.
        law.sample(&c2, x_of(-1, 0), 0, 0, 0);
        assert!(law.integral < held);
    }

    #[test]
    fn feed_forward_scales_as_documented() {
        // Kv = 3 duty clocks per count/tick: v of 2 counts/tick gives 6.
        let c = ServoConfig {
            kp: 0,
            kv: 3 << 16,
            ka: 5 << 8,
            ..cfg()
        };
        let mut law = ServoLaw::default();
        let v = 2i128 << 80;
        let a = 1i128 << 79; // half a count per tick²
        assert_eq!(law.sample(&c, x_of(0, 0), v, 0, 0).duty, 6);
        assert_eq!(law.sample(&c, x_of(0, 0), 0, a, 0).duty, 3); // 2.5 rounds up
    }

    #[test]
    fn the_derivative_filter_has_unit_gain() {
        let c = ServoConfig {
            kp: 0,
            kd: 1 << 32,
            d_filter: 3,
            ..cfg()
        };
        let mut law = ServoLaw::default();
        // The error ramps by 16 counts per sample: D (duty) rises to 16, by 2 = 16/8 first.
        let mut duties = Vec::new();
        for k in 0..200 {
            duties.push(law.sample(&c, x_of(16 * k, 0), 0, 0, 0).duty);
        }
        assert_eq!(duties[..3], [0, 2, 4]);
        assert_eq!(*duties.last().unwrap(), 16);
        // Unfiltered: Δ itself.
        let c0 = ServoConfig { d_filter: 0, ..c };
        let mut law = ServoLaw::default();
        let d: Vec<i16> = (0..4)
            .map(|k| law.sample(&c0, x_of(16 * k, 0), 0, 0, 0).duty)
            .collect();
        assert_eq!(d, [0, 16, 16, 16]);
    }

    #[test]
    fn timing_latency_overrun_and_clear() {
        let mut s = Servo::new();
        let c = cfg();
        let i = |tick, enable| ServoInputs {
            enable,
            tick,
            x: x_of(7, 0),
            count: 0,
            config: c,
            ..Default::default()
        };
        // A sample on the first tick; its duty stands LATENCY clocks later.
        s.clock(&i(true, true));
        for k in 1..LATENCY {
            let o = s.clock(&i(false, true));
            assert_eq!(o.duty, 0, "clock {k}");
            assert_eq!(o.peak, if k >= 1 { 7 << 16 } else { 0 });
        }
        assert_eq!(s.clock(&i(false, true)).duty, 7);
        // Two ticks LATENCY/2 apart: the second is skipped and reported.
        s.clock(&i(true, true));
        for _ in 0..LATENCY / 2 {
            s.clock(&i(false, true));
        }
        assert!(s.clock(&i(true, true)).overrun);
        // The amplifier off: everything clears but the peak.
        let o = s.clock(&i(false, false));
        assert_eq!((o.duty, o.peak), (0, 7 << 16));
        assert_eq!(*s.law(), ServoLaw::default());
    }
}
