//! PWM generator for an H-bridge or a servo amplifier's PWM/DIR input.
//!
//! A counter runs 0 .. period−1. The signed duty is latched when the counter restarts (so a
//! change never makes a runt pulse) as a magnitude saturated to the period and a direction;
//! `pwm` is high while `counter < magnitude`; both outputs are forced low at once when
//! disabled or on fault: `enable` and `fault` gate them combinationally, so the outputs after
//! an edge follow the gating inputs as they are after it ([`Pwm::outputs`]).

/// Inputs for one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PwmInputs {
    /// Period in clocks (0: output stays low).
    pub period: u16,
    /// Signed duty in clocks (−period ..= period; saturated).
    pub duty: i16,
    /// Enable.
    pub enable: bool,
    /// Fault (forces the outputs off).
    pub fault: bool,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PwmOutputs {
    /// PWM line.
    pub pwm: bool,
    /// Direction (high for a negative duty).
    pub dir: bool,
}

/// The generator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pwm {
    counter: u16,
    magnitude: u16,
    negative: bool,
}

impl Pwm {
    /// A generator at rest.
    pub fn new() -> Self {
        Self::default()
    }

    /// One clock; the outputs after it with the gating inputs of `i` held.
    #[inline]
    pub fn clock(&mut self, i: &PwmInputs) -> PwmOutputs {
        let wrap = self.counter.wrapping_add(1) >= i.period;
        if wrap {
            self.counter = 0;
            let m = i.duty.unsigned_abs();
            self.magnitude = m.min(i.period);
            self.negative = i.duty < 0;
        } else {
            self.counter += 1;
        }
        self.outputs(i.enable, i.fault)
    }

    /// The outputs for the current state, gated by `enable` and `fault` as they are now.
    pub fn outputs(&self, enable: bool, fault: bool) -> PwmOutputs {
        let on = enable && !fault;
        PwmOutputs {
            pwm: on && self.counter < self.magnitude,
            dir: on && self.negative,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duty_sets_the_high_time_and_saturates() {
        for (duty, want_high, dir) in [
            (3i16, 3usize, false),
            (-7, 7, true),
            (50, 10, false),
            (0, 0, false),
        ] {
            let mut p = Pwm::new();
            let i = PwmInputs {
                period: 10,
                duty,
                enable: true,
                fault: false,
            };
            for _ in 0..10 {
                p.clock(&i);
            }
            let mut high = 0;
            let mut d = false;
            for _ in 0..10 {
                let o = p.clock(&i);
                high += usize::from(o.pwm);
                d = o.dir;
            }
            assert_eq!((high, d), (want_high, dir), "duty {duty}");
        }
    }

    #[test]
    fn fault_forces_off() {
        let mut p = Pwm::new();
        let i = PwmInputs {
            period: 4,
            duty: -4,
            enable: true,
            fault: true,
        };
        for _ in 0..8 {
            assert_eq!(p.clock(&i), PwmOutputs::default());
        }
    }
}
