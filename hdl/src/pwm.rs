//! PWM generator with direction output (model: `snapgen_model::io::pwm`). A counter runs
//! 0 .. period−1; the signed duty is latched as magnitude (saturated to the period) and sign
//! when the counter restarts; `pwm = counter < magnitude`; both outputs are forced low at once
//! when disabled or on fault.

use rust_hdl::prelude::*;

/// The generator.
#[derive(LogicBlock)]
pub struct PwmGenerator {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Period in clocks.
    pub period: Signal<In, Bits<16>>,
    /// Signed duty (two's complement) in clocks.
    pub duty: Signal<In, Bits<16>>,
    /// Enable.
    pub enable: Signal<In, Bit>,
    /// Fault: outputs off.
    pub fault: Signal<In, Bit>,
    /// PWM line.
    pub pwm: Signal<Out, Bit>,
    /// Direction (high for a negative duty).
    pub dir: Signal<Out, Bit>,
    counter: DFF<Bits<16>>,
    magnitude: DFF<Bits<16>>,
    negative: DFF<Bit>,
    next_count: Signal<Local, Bits<16>>,
    abs_duty: Signal<Local, Bits<16>>,
    zero: Constant<Bits<16>>,
    one: Constant<Bits<16>>,
    sign: Constant<Bits<16>>,
}

impl Default for PwmGenerator {
    fn default() -> Self {
        PwmGenerator {
            clock: Default::default(),
            period: Default::default(),
            duty: Default::default(),
            enable: Default::default(),
            fault: Default::default(),
            pwm: Default::default(),
            dir: Default::default(),
            counter: Default::default(),
            magnitude: Default::default(),
            negative: Default::default(),
            next_count: Default::default(),
            abs_duty: Default::default(),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
            sign: Constant::new(0x8000.into()),
        }
    }
}

impl Logic for PwmGenerator {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, counter, magnitude, negative);
        self.next_count.next = self.counter.q.val() + self.one.val();
        // |duty|: two's complement negation of a negative duty (−32768 gives 32768).
        if self.duty.val() >= self.sign.val() {
            self.abs_duty.next = (!self.duty.val()) + self.one.val();
        } else {
            self.abs_duty.next = self.duty.val();
        }
        if self.next_count.val() >= self.period.val() {
            self.counter.d.next = self.zero.val();
            if self.abs_duty.val() > self.period.val() {
                self.magnitude.d.next = self.period.val();
            } else {
                self.magnitude.d.next = self.abs_duty.val();
            }
            self.negative.d.next = self.duty.val() >= self.sign.val();
        } else {
            self.counter.d.next = self.next_count.val();
        }
        self.pwm.next = (self.enable.val() & !self.fault.val())
            & (self.counter.q.val() < self.magnitude.q.val());
        self.dir.next = (self.enable.val() & !self.fault.val()) & self.negative.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pwm_generator_is_synthesizable() {
        crate::synth_check::synth_block("pwm", PwmGenerator::default());
    }
}
