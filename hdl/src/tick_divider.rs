//! The trajectory tick: one clock-wide pulse every `divisor + 1` clocks, so the fabric clock
//! (125 MHz on the Zybo) and the tick `Ts` are independent. `divisor = 0` ticks on every clock.
//! While `hold` is high (the stop unit is computing the next tick's snap) a due tick waits and
//! the count runs on; the tick comes on the first clock without `hold`.

use rust_hdl::prelude::*;

use crate::TICK_BITS;

/// Tick enable generator.
#[derive(LogicBlock)]
pub struct TickDivider {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset: restarts the count.
    pub reset: Signal<In, Bit>,
    /// Clocks per tick minus one.
    pub divisor: Signal<In, Bits<TICK_BITS>>,
    /// Hold a due tick.
    pub hold: Signal<In, Bit>,
    /// High for one clock every `divisor + 1` clocks.
    pub tick: Signal<Out, Bit>,
    counter: DFF<Bits<TICK_BITS>>,
    zero: Constant<Bits<TICK_BITS>>,
    one: Constant<Bits<TICK_BITS>>,
}

impl Default for TickDivider {
    fn default() -> Self {
        TickDivider {
            clock: Default::default(),
            reset: Default::default(),
            divisor: Default::default(),
            hold: Default::default(),
            tick: Default::default(),
            counter: Default::default(),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
        }
    }
}

impl Logic for TickDivider {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, counter);
        // `>=` rather than `==`: lowering the divisor mid-count never waits for a wrap.
        self.tick.next = (self.counter.q.val() >= self.divisor.val()) & !self.hold.val();
        if self.reset.val() | self.tick.val() {
            self.counter.d.next = self.zero.val();
        } else {
            self.counter.d.next = self.counter.q.val() + self.one.val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_divider_is_synthesizable() {
        crate::synth_check::synth_block("tick_divider", TickDivider::default());
    }
}
