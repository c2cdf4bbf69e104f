//! One input pin through a two-flop synchroniser and a programmable glitch filter (the model
//! is `snapgen_model::io::FilteredInput`): a new level is accepted once the synchronised input
//! has differed from the filtered level on `filter + 1` consecutive clocks.

use rust_hdl::prelude::*;

/// Synchroniser and glitch filter.
#[derive(LogicBlock)]
pub struct InputFilter {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// The raw pin.
    pub pin: Signal<In, Bit>,
    /// Filter length in clocks.
    pub filter: Signal<In, Bits<16>>,
    /// The filtered level.
    pub level: Signal<Out, Bit>,
    sync1: DFFWithInit<Bit>,
    sync2: DFFWithInit<Bit>,
    level_reg: DFFWithInit<Bit>,
    count: DFF<Bits<16>>,
    zero: Constant<Bits<16>>,
    one: Constant<Bits<16>>,
}

impl InputFilter {
    /// A filter whose pin rests at `idle` (low for encoders, high for a UART line).
    pub fn new(idle: bool) -> Self {
        InputFilter {
            clock: Default::default(),
            pin: Default::default(),
            filter: Default::default(),
            level: Default::default(),
            sync1: DFFWithInit::new(idle),
            sync2: DFFWithInit::new(idle),
            level_reg: DFFWithInit::new(idle),
            count: Default::default(),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
        }
    }
}

impl Logic for InputFilter {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, sync1, sync2, level_reg, count);
        self.sync1.d.next = self.pin.val();
        self.sync2.d.next = self.sync1.q.val();
        if self.sync2.q.val() == self.level_reg.q.val() {
            self.count.d.next = self.zero.val();
        } else if self.count.q.val() >= self.filter.val() {
            self.level_reg.d.next = self.sync2.q.val();
            self.count.d.next = self.zero.val();
        } else {
            self.count.d.next = self.count.q.val() + self.one.val();
        }
        self.level.next = self.level_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_filter_is_synthesizable() {
        crate::synth_check::synth_block("input_filter", InputFilter::new(true));
    }
}
