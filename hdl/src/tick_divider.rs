//! The trajectory tick: one clock-wide pulse every `divisor + 1` clocks, so the fabric clock
//! (125 MHz on the Zybo) and the tick `Ts` are independent. `divisor = 0` ticks on every clock.
//! While the stop unit computes the next tick's snap a due tick waits and the count runs on;
//! the tick comes on the first clock it does not compute.
//!
//! The tick is a register (it fans out to every register of the core): on each edge it takes
//! what the next clock's tick is, from the count after the edge, the divisor before it and
//! `hold_next`, the stop unit's "computing" after the edge. So a new divisor counts from the
//! clock after it is written (`snapgen_model::CoreModel` does the same).

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
    /// Hold a due tick on the next clock (the stop unit computes then).
    pub hold_next: Signal<In, Bit>,
    /// High for one clock every `divisor + 1` clocks (registered).
    pub tick: Signal<Out, Bit>,
    /// The count plus one (the count after the next edge when no tick restarts it), kept in
    /// the register instead of the count: the compare below then follows no adder.
    count_plus_one: DFFWithInit<Bits<TICK_BITS>>,
    tick_reg: DFF<Bit>,
    /// The count after the edge (the count plus one) reaches the divisor.
    due_count: Signal<Local, Bit>,
    /// A restarted count (0) reaches it: the divisor is 0.
    due_zero: Signal<Local, Bit>,
    /// The one of the two the restart (a reset or a tick) chooses.
    due: Signal<Local, Bit>,
    zero: Constant<Bits<TICK_BITS>>,
    one: Constant<Bits<TICK_BITS>>,
}

impl Default for TickDivider {
    fn default() -> Self {
        TickDivider {
            clock: Default::default(),
            reset: Default::default(),
            divisor: Default::default(),
            hold_next: Default::default(),
            tick: Default::default(),
            count_plus_one: DFFWithInit::new(1.into()),
            tick_reg: Default::default(),
            due_count: Default::default(),
            due_zero: Default::default(),
            due: Default::default(),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
        }
    }
}

impl Logic for TickDivider {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, count_plus_one, tick_reg);
        self.tick.next = self.tick_reg.q.val();
        // `>=` rather than `==`: lowering the divisor mid-count never waits for a wrap. Both
        // compares, the count's and a restarted count's (0 >= divisor), side by side; the
        // restart chooses between them last, so the reset (a net that reaches every block) and
        // the tick pass one multiplexer, not the 32-bit compare.
        self.due_count.next = self.count_plus_one.q.val() >= self.divisor.val();
        self.due_zero.next = self.divisor.val() == self.zero.val();
        if self.reset.val() | self.tick_reg.q.val() {
            self.due.next = self.due_zero.val();
            self.count_plus_one.d.next = self.one.val();
        } else {
            self.due.next = self.due_count.val();
            self.count_plus_one.d.next = self.count_plus_one.q.val() + self.one.val();
        }
        self.tick_reg.d.next = self.due.val() & !self.hold_next.val();
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
