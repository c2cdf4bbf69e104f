//! The swap timer: holds a program swap armed for a tick of the time base and says on which
//! tick it is due (docs/PROTOCOL.md, SWAP_AT; the reference, clock for clock, is
//! `snapgen_model::CoreModel`).
//!
//! The swap is armed with `last`, the low 32 bits of the time base on the old program's last
//! tick: the tick that takes `ticks` from `last` to `last + 1` loads the standby program
//! (`due`), so the next tick is the new program's first and the registers at `last + 1` are
//! its start. An arm is taken only when `last − (ticks + 1) − 1`, modulo 2^32, is below 2^31
//! (the new program's start lies 3 to 2^31 + 2 ticks after `ticks`; the executor refuses
//! farther ones), when no swap is armed and no stop is requested or runs; otherwise it changes
//! nothing. `cancel` (a stop request, an abort) and `reset` disarm it.
//!
//! Timing: `due` feeds the program memory's read address, so it must not wait for a
//! comparison. On every tick the timer compares the time base after that tick (the core's
//! `ticks + 1`) with `last` into a register; on the next tick `due` is that register ANDed
//! with `pending` and `tick`. (That is why an arm needs three ticks of lead: the register is
//! first computed on a tick after the arm, and the acceptance test assumes the arming clock
//! ticks, so it needs no tick in its path.)

use rust_hdl::prelude::*;

/// Bits of the time base the timer compares.
pub const SWAP_BITS: usize = 32;

// rust-hdl workaround: `#[hdl_gen]` copies a const name into the Verilog verbatim, so the sign
// bit of `lead` is a literal in `update`; this ties it to SWAP_BITS.
const _: () = assert!(SWAP_BITS == 32, "update the literal in SwapTimer::update");

/// Arms and fires a program swap at a tick of the time base.
#[derive(LogicBlock, Default)]
pub struct SwapTimer {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset: disarms.
    pub reset: Signal<In, Bit>,
    /// Disarm (a stop request or an abort); also holds `due` low.
    pub cancel: Signal<In, Bit>,
    /// A stop runs: an arm is not taken.
    pub stopping: Signal<In, Bit>,
    /// Arm for the tick after `arm_last`.
    pub arm: Signal<In, Bit>,
    /// The low bits of the time base on the old program's last tick.
    pub arm_last: Signal<In, Bits<SWAP_BITS>>,
    /// The tick enable.
    pub tick: Signal<In, Bit>,
    /// The low bits of `ticks + 1` (the core's incrementer, shared).
    pub ticks_next: Signal<In, Bits<SWAP_BITS>>,
    /// A swap is armed.
    pub pending: Signal<Out, Bit>,
    /// The armed swap happens on this clock's tick (combinational).
    pub due: Signal<Out, Bit>,
    pending_reg: DFF<Bit>,
    last_reg: DFF<Bits<SWAP_BITS>>,
    /// The next tick is the armed one's last (meaningful while pending).
    next_is_last: DFF<Bit>,
    lead: Signal<Local, Bits<SWAP_BITS>>,
}

impl Logic for SwapTimer {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, pending_reg, last_reg, next_is_last);
        self.due.next = self.pending_reg.q.val()
            & self.tick.val()
            & self.next_is_last.q.val()
            & !self.cancel.val()
            & !self.reset.val();
        // arm_last − (ticks + 1) − 1.
        self.lead.next = self.arm_last.val() + !self.ticks_next.val();
        if self.reset.val() | self.cancel.val() | self.due.val() {
            self.pending_reg.d.next = false;
            self.next_is_last.d.next = false;
        } else if self.arm.val()
            & !self.pending_reg.q.val()
            & !self.stopping.val()
            & !self.lead.val().get_bit(31)
        {
            self.pending_reg.d.next = true;
            self.last_reg.d.next = self.arm_last.val();
            self.next_is_last.d.next = false;
        } else if self.tick.val() {
            self.next_is_last.d.next = self.ticks_next.val() == self.last_reg.q.val();
        }
        self.pending.next = self.pending_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swap_timer_is_synthesizable() {
        crate::synth_check::synth_block("swap_timer", SwapTimer::default());
    }
}
