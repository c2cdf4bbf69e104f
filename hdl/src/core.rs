//! The motion core: tick divider, program memory (two banks), sequencer, stop unit and
//! integrator chain, with the bank control that lets the next program load while one plays.
//!
//! Writes (`write_*`, `count_*`) always go to the *standby* bank. A start, accepted only while
//! idle and not stopping, makes the standby bank active and plays it; the bank that was active
//! becomes standby with its segment count cleared, so a second start without a new upload
//! plays nothing.
//!
//! `swap` arms a program swap ([`crate::swap_timer`]): on the tick that takes the time base
//! `ticks` from `swap_last` (its low 32 bits) to `swap_last + 1`, the standby program takes
//! over from the chain's registers as they are, banks swapping as on a start. A stop request or an abort disarms it;
//! a start is not taken while one is armed.
//!
//! `stop` requests a controlled stop ([`crate::stop_unit`]): the unit latches `stop_jerk` and
//! `stop_accel` and prepares while the move plays on, the next tick after that takes the stop
//! (the program is cut there), then the unit feeds the chain until it is at rest, within those
//! limits. `abort_move` is the emergency stop:
//! velocity, acceleration and jerk are zeroed at once (the position holds) and a stop in
//! progress is cancelled; the I/O top asserts it only with the amplifier disabled.
//! `aborted` (the last program was cut short, by either) stays set until the next start or
//! reset. Timing and every rule: `snapgen_model::CoreModel`, which co-simulation compares with
//! this core on every clock.

use rust_hdl::prelude::*;

use crate::chain::SnapChain;
use crate::program_memory::ProgramMemory;
use crate::sequencer::Sequencer;
use crate::sign_extend::CellCentre;
use crate::stop_unit::StopUnit;
use crate::swap_timer::{SwapTimer, SWAP_BITS};
use crate::tick_divider::TickDivider;
use crate::{block_with_ports, FRAC, INDEX_BITS, POSITION_BITS};

const _: () = assert!(FRAC == 80, "update the literal in MotionCore::update");

snapgen_spec::with_motion_core_ports!(block_with_ports! {
    /// The motion core (the top level of `snapgen verilog`); its ports are the spec's
    /// `with_motion_core_ports!` list.
    pub struct MotionCore() {
        divider: TickDivider = Default::default(),
        swap_timer: SwapTimer = Default::default(),
        memory: ProgramMemory = Default::default(),
        sequencer: Sequencer = Default::default(),
        chain: SnapChain = Default::default(),
        cell_centre: CellCentre = Default::default(),
        stop_unit: StopUnit = Default::default(),
        bank: DFF<Bit> = Default::default(),
        /// A copy of `bank` for the memory's read port and segment-0 select (toggled from its
        /// own value, so synthesis keeps it apart): the 104-bit reads do not share a net with
        /// the bank control.
        read_bank: DFF<Bit> = Default::default(),
        count0: DFF<Bits<INDEX_BITS>> = Default::default(),
        count1: DFF<Bits<INDEX_BITS>> = Default::default(),
        aborted_reg: DFF<Bit> = Default::default(),
        ticks_reg: DFF<Bits<64>> = Default::default(),
        /// The low bits of `ticks + 1`, a register beside the time base: the swap timer's lead
        /// and last-tick compare follow no 64-bit adder.
        ticks_after: DFFWithInit<Bits<SWAP_BITS>> = DFFWithInit::new(1.into()),
        engage: Signal<Local, Bit> = Default::default(),
        ticks_next: Signal<Local, Bits<64>> = Default::default(),
        count_zero: Constant<Bits<INDEX_BITS>> = Constant::new(0.into()),
        ticks_zero: Constant<Bits<64>> = Constant::new(0.into()),
        ticks_one: Constant<Bits<64>> = Constant::new(1.into()),
        swap_one: Constant<Bits<SWAP_BITS>> = Constant::new(1.into()),
    }
});

impl Default for MotionCore {
    fn default() -> Self {
        MotionCore::build()
    }
}

impl Logic for MotionCore {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, divider, memory, sequencer, chain, stop_unit, swap_timer);
        dff_setup!(
            self,
            clock,
            bank,
            read_bank,
            count0,
            count1,
            aborted_reg,
            ticks_reg,
            ticks_after
        );
        self.ticks_next.next = self.ticks_reg.q.val() + self.ticks_one.val();
        self.divider.reset.next = self.reset.val();
        self.divider.divisor.next = self.tick_div.val();
        // A due tick waits while the stop unit computes the next tick's snap (the tick is a
        // register: it is told what the unit does after this edge).
        self.divider.hold_next.next = self.stop_unit.computing_next.val();
        // The stop is taken on the first tick after the unit has prepared it. (A reset or an
        // abort on that clock wins where engage is read — the sequencer's and the stop unit's
        // phases, `aborted` — so neither is in engage's path.)
        self.engage.next = self.divider.tick.val() & self.stop_unit.armed.val();
        // The swap timer: a stop request or an abort disarms it.
        self.swap_timer.reset.next = self.reset.val();
        self.swap_timer.cancel.next = self.abort_move.val() | self.stop.val();
        self.swap_timer.stopping.next = self.stop_unit.active.val();
        self.swap_timer.arm.next = self.swap.val();
        self.swap_timer.arm_last.next = self.swap_last.val();
        self.swap_timer.tick.next = self.divider.tick.val();
        self.swap_timer.ticks_next.next = self.ticks_after.q.val();
        self.sequencer.swap.next = self.swap_timer.due.val();
        // The sequencer reads the active bank's next segment and, for a start or a swap,
        // segment 0 of the standby bank (the next program's), both from registers' addresses:
        // the swap's decision on a tick chooses between them in the sequencer, after the reads.
        self.memory.read_bank.next = self.read_bank.q.val();
        self.memory.read_address.next = self.sequencer.address.val();
        self.memory.first_bank.next = !self.read_bank.q.val();
        self.sequencer.entry_ticks.next = self.memory.read_ticks.val();
        self.sequencer.entry_snap.next = self.memory.read_snap.val();
        self.sequencer.first_ticks.next = self.memory.first_ticks.val();
        self.sequencer.first_snap.next = self.memory.first_snap.val();
        if self.bank.q.val() {
            self.sequencer.count.next = self.count1.q.val();
            self.sequencer.first_count.next = self.count0.q.val();
        } else {
            self.sequencer.count.next = self.count0.q.val();
            self.sequencer.first_count.next = self.count1.q.val();
        }
        // Writes go to the standby bank.
        self.memory.write_bank.next = !self.bank.q.val();
        self.memory.write_address.next = self.write_address.val();
        self.memory.write_enable.next = self.write_enable.val() & !self.reset.val();
        self.memory.write_ticks.next = self.write_ticks.val();
        self.memory.write_snap.next = self.write_snap.val();
        self.sequencer.reset.next = self.reset.val();
        self.sequencer.tick.next = self.divider.tick.val();
        // No start while a stop is requested or runs, or a swap is armed.
        self.sequencer.start.next =
            self.start.val() & !self.stop_unit.active.val() & !self.swap_timer.pending.val();
        self.sequencer.abort_move.next = self.abort_move.val();
        self.sequencer.engage.next = self.engage.val();
        // Its ticks count once the stop is taken.
        self.sequencer.stopping.next = self.stop_unit.computing.val() | self.stop_unit.ready.val();
        self.stop_unit.reset.next = self.reset.val();
        self.stop_unit.cancel.next = self.abort_move.val();
        self.stop_unit.request.next = self.stop.val();
        self.stop_unit.engage.next = self.engage.val();
        self.stop_unit.tick.next = self.divider.tick.val();
        self.stop_unit.v.next = self.chain.v.val();
        self.stop_unit.a.next = self.chain.a.val();
        self.stop_unit.j.next = self.chain.j.val();
        self.stop_unit.jerk_limit.next = self.stop_jerk.val();
        self.stop_unit.accel_limit.next = self.stop_accel.val();
        self.chain.reset.next = self.reset.val();
        self.chain.halt.next = self.abort_move.val();
        self.chain.load.next = self.load.val();
        self.cell_centre.position.next = self.load_position.val();
        self.chain.load_x.next = self.cell_centre.out.val();
        self.chain.tick.next = self.divider.tick.val();
        // The stop unit's snap once it has one; the program's otherwise.
        if self.stop_unit.ready.val() {
            self.chain.snap.next = self.stop_unit.snap.val();
        } else {
            self.chain.snap.next = self.sequencer.snap.val();
        }
        if self.reset.val() {
            self.ticks_reg.d.next = self.ticks_zero.val();
            self.ticks_after.d.next = self.swap_one.val();
        } else if self.divider.tick.val() {
            self.ticks_reg.d.next = self.ticks_next.val();
            self.ticks_after.d.next = self.ticks_after.q.val() + self.swap_one.val();
        }
        if self.reset.val() {
            self.read_bank.d.next = false;
        } else if self.sequencer.started.val() | self.swap_timer.due.val() {
            self.read_bank.d.next = !self.read_bank.q.val();
        }
        if self.reset.val() {
            self.bank.d.next = false;
            self.count0.d.next = self.count_zero.val();
            self.count1.d.next = self.count_zero.val();
            self.aborted_reg.d.next = false;
        } else if self.sequencer.started.val() | self.swap_timer.due.val() {
            // Swap: the standby bank plays; the old active bank becomes standby, emptied.
            self.bank.d.next = !self.bank.q.val();
            self.aborted_reg.d.next = false;
            if self.bank.q.val() {
                self.count1.d.next = self.count_zero.val();
            } else {
                self.count0.d.next = self.count_zero.val();
            }
        } else if self.count_enable.val() {
            if self.bank.q.val() {
                self.count0.d.next = self.count_value.val();
            } else {
                self.count1.d.next = self.count_value.val();
            }
        }
        if (self.abort_move.val() | self.engage.val())
            & self.sequencer.busy.val()
            & !self.reset.val()
        {
            self.aborted_reg.d.next = true;
        }
        self.x.next = self.chain.x.val();
        self.v.next = self.chain.v.val();
        self.a.next = self.chain.a.val();
        self.j.next = self.chain.j.val();
        // rust-hdl workaround: `#[hdl_gen]` copies a const name into the Verilog verbatim, so
        // the bit index is a literal; the assertion below ties it to FRAC.
        self.position.next = self.chain.x.val().get_bits::<POSITION_BITS>(80);
        self.segment.next = self.sequencer.index.val();
        self.busy.next = self.sequencer.busy.val();
        self.done.next = self.sequencer.done.val();
        self.aborted.next = self.aborted_reg.q.val();
        self.stopping.next = self.stop_unit.active.val();
        self.stop_over.next = self.stop_unit.over.val();
        self.tick_count.next = self.sequencer.tick_count.val();
        self.ticks.next = self.ticks_reg.q.val();
        self.heading_pos.next = self.stop_unit.heading_pos.val();
        self.heading_neg.next = self.stop_unit.heading_neg.val();
        self.at_rest.next = self.stop_unit.at_rest.val();
        self.tick.next = self.divider.tick.val();
        self.active_bank.next = self.bank.q.val();
        if self.bank.q.val() {
            self.standby_count.next = self.count0.q.val();
        } else {
            self.standby_count.next = self.count1.q.val();
        }
        self.swap_pending.next = self.swap_timer.pending.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_core_is_synthesizable() {
        crate::synth_check::synth_block("motion_core", MotionCore::default());
    }
}
