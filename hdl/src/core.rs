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
use crate::{
    ADDR_BITS, A_BITS, D_BITS, FRAC, INDEX_BITS, J_BITS, POSITION_BITS, TICK_BITS, V_BITS, X_BITS,
};

const _: () = assert!(FRAC == 80, "update the literal in MotionCore::update");

/// The motion core (the top level of `snapgen verilog`).
#[derive(LogicBlock)]
pub struct MotionCore {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset, active high.
    pub reset: Signal<In, Bit>,
    /// Clocks per tick minus one (0: a tick every clock).
    pub tick_div: Signal<In, Bits<TICK_BITS>>,
    /// Start the standby program (one-clock pulse; ignored while busy or stopping).
    pub start: Signal<In, Bit>,
    /// Emergency stop: sequencer idle, v = a = j = 0 now, position holds, stop cancelled.
    pub abort_move: Signal<In, Bit>,
    /// Controlled stop: taken on the next tick, ends at rest within the stop limits.
    pub stop: Signal<In, Bit>,
    /// The reference takes the encoder's position: x at the centre of cell `load_position`,
    /// v = a = j = 0 (raised by the I/O top only at rest, with no program playing).
    pub load: Signal<In, Bit>,
    /// The cell for `load` (the encoder count).
    pub load_position: Signal<In, Bits<POSITION_BITS>>,
    /// The controlled stop's jerk limit, raw (> 0; latched when a stop is taken).
    pub stop_jerk: Signal<In, Bits<D_BITS>>,
    /// The controlled stop's acceleration limit, raw (≥ `stop_jerk`; latched likewise).
    pub stop_accel: Signal<In, Bits<D_BITS>>,
    /// Write one segment of the standby program.
    pub write_enable: Signal<In, Bit>,
    /// Segment address to write.
    pub write_address: Signal<In, Bits<ADDR_BITS>>,
    /// Segment tick count to write (≥ 1).
    pub write_ticks: Signal<In, Bits<TICK_BITS>>,
    /// Segment snap to write (two's complement).
    pub write_snap: Signal<In, Bits<D_BITS>>,
    /// Set the standby program's segment count.
    pub count_enable: Signal<In, Bit>,
    /// Segment count to set.
    pub count_value: Signal<In, Bits<INDEX_BITS>>,
    /// Arm a program swap (one-clock pulse; see [`crate::swap_timer`]).
    pub swap: Signal<In, Bit>,
    /// The low 32 bits of the time base on the old program's last tick: the registers at
    /// `swap_last + 1` are the new program's start.
    pub swap_last: Signal<In, Bits<SWAP_BITS>>,
    /// Position register, raw.
    pub x: Signal<Out, Bits<X_BITS>>,
    /// Velocity register, raw.
    pub v: Signal<Out, Bits<V_BITS>>,
    /// Acceleration register, raw.
    pub a: Signal<Out, Bits<A_BITS>>,
    /// Jerk register, raw.
    pub j: Signal<Out, Bits<J_BITS>>,
    /// Position in whole output LSBs (`x >> FRAC`, low 32 bits).
    pub position: Signal<Out, Bits<POSITION_BITS>>,
    /// Segment playing.
    pub segment: Signal<Out, Bits<INDEX_BITS>>,
    /// A program is playing.
    pub busy: Signal<Out, Bit>,
    /// The last program ran to its end.
    pub done: Signal<Out, Bit>,
    /// The last program was cut short (by a stop or an abort).
    pub aborted: Signal<Out, Bit>,
    /// A controlled stop is requested or running.
    pub stopping: Signal<Out, Bit>,
    /// The last stop began outside its limits (and landed regardless of them).
    pub stop_over: Signal<Out, Bit>,
    /// Ticks since the start, while a program plays or a stop runs.
    pub tick_count: Signal<Out, Bits<TICK_BITS>>,
    /// Ticks since reset: the board's time base.
    pub ticks: Signal<Out, Bits<64>>,
    /// The axis heads forward (registered): on the last clock the first non-zero of v, a, j
    /// was positive.
    pub heading_pos: Signal<Out, Bit>,
    /// The axis heads backward (registered).
    pub heading_neg: Signal<Out, Bit>,
    /// The chain is at rest: v = a = j = 0.
    pub at_rest: Signal<Out, Bit>,
    /// The tick enable (one clock wide).
    pub tick: Signal<Out, Bit>,
    /// Bank that plays (the other one is written).
    pub active_bank: Signal<Out, Bit>,
    /// Segment count of the standby program (0: nothing to start).
    pub standby_count: Signal<Out, Bits<INDEX_BITS>>,
    /// A program swap is armed.
    pub swap_pending: Signal<Out, Bit>,
    divider: TickDivider,
    swap_timer: SwapTimer,
    memory: ProgramMemory,
    sequencer: Sequencer,
    chain: SnapChain,
    cell_centre: CellCentre,
    stop_unit: StopUnit,
    bank: DFF<Bit>,
    count0: DFF<Bits<INDEX_BITS>>,
    count1: DFF<Bits<INDEX_BITS>>,
    aborted_reg: DFF<Bit>,
    ticks_reg: DFF<Bits<64>>,
    read_bank: Signal<Local, Bit>,
    engage: Signal<Local, Bit>,
    ticks_next: Signal<Local, Bits<64>>,
    count_zero: Constant<Bits<INDEX_BITS>>,
    ticks_zero: Constant<Bits<64>>,
    ticks_one: Constant<Bits<64>>,
}

impl Default for MotionCore {
    fn default() -> Self {
        MotionCore {
            clock: Default::default(),
            reset: Default::default(),
            tick_div: Default::default(),
            start: Default::default(),
            abort_move: Default::default(),
            stop: Default::default(),
            load: Default::default(),
            load_position: Default::default(),
            stop_jerk: Default::default(),
            stop_accel: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_ticks: Default::default(),
            write_snap: Default::default(),
            count_enable: Default::default(),
            count_value: Default::default(),
            swap: Default::default(),
            swap_last: Default::default(),
            x: Default::default(),
            v: Default::default(),
            a: Default::default(),
            j: Default::default(),
            position: Default::default(),
            segment: Default::default(),
            busy: Default::default(),
            done: Default::default(),
            aborted: Default::default(),
            stopping: Default::default(),
            stop_over: Default::default(),
            tick_count: Default::default(),
            ticks: Default::default(),
            heading_pos: Default::default(),
            heading_neg: Default::default(),
            at_rest: Default::default(),
            tick: Default::default(),
            active_bank: Default::default(),
            standby_count: Default::default(),
            swap_pending: Default::default(),
            divider: Default::default(),
            swap_timer: Default::default(),
            memory: Default::default(),
            sequencer: Default::default(),
            chain: Default::default(),
            cell_centre: Default::default(),
            stop_unit: Default::default(),
            bank: Default::default(),
            count0: Default::default(),
            count1: Default::default(),
            aborted_reg: Default::default(),
            ticks_reg: Default::default(),
            read_bank: Default::default(),
            engage: Default::default(),
            ticks_next: Default::default(),
            count_zero: Constant::new(0.into()),
            ticks_zero: Constant::new(0.into()),
            ticks_one: Constant::new(1.into()),
        }
    }
}

impl Logic for MotionCore {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, divider, memory, sequencer, chain, stop_unit, swap_timer);
        dff_setup!(self, clock, bank, count0, count1, aborted_reg, ticks_reg);
        self.ticks_next.next = self.ticks_reg.q.val() + self.ticks_one.val();
        self.divider.reset.next = self.reset.val();
        self.divider.divisor.next = self.tick_div.val();
        // A due tick waits while the stop unit computes the next tick's snap.
        self.divider.hold.next = self.stop_unit.computing.val();
        // The stop is taken on the first tick after the unit has prepared it.
        self.engage.next = self.divider.tick.val()
            & self.stop_unit.armed.val()
            & !self.reset.val()
            & !self.abort_move.val();
        // The swap timer: a stop request or an abort disarms it.
        self.swap_timer.reset.next = self.reset.val();
        self.swap_timer.cancel.next = self.abort_move.val() | self.stop.val();
        self.swap_timer.stopping.next = self.stop_unit.active.val();
        self.swap_timer.arm.next = self.swap.val();
        self.swap_timer.arm_last.next = self.swap_last.val();
        self.swap_timer.tick.next = self.divider.tick.val();
        self.swap_timer.ticks_next.next = self.ticks_next.val().get_bits::<SWAP_BITS>(0);
        self.sequencer.swap.next = self.swap_timer.due.val();
        // While playing, read the active bank; while idle or swapping, the standby bank (the
        // next program's).
        self.read_bank.next =
            self.bank.q.val() ^ (!self.sequencer.busy.val() | self.swap_timer.due.val());
        self.memory.read_bank.next = self.read_bank.val();
        self.memory.read_address.next = self.sequencer.address.val();
        if self.read_bank.val() {
            self.sequencer.count.next = self.count1.q.val();
        } else {
            self.sequencer.count.next = self.count0.q.val();
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
        self.sequencer.entry_ticks.next = self.memory.read_ticks.val();
        self.sequencer.entry_snap.next = self.memory.read_snap.val();
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
        } else if self.divider.tick.val() {
            self.ticks_reg.d.next = self.ticks_next.val();
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
