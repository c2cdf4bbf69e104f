//! The motion core: tick divider, program memory (two banks), sequencer and integrator chain,
//! with the bank control that lets the next program load while one plays.
//!
//! Writes (`write_*`, `count_*`) always go to the *standby* bank. A start, accepted only while
//! idle, makes the standby bank active and plays it; the bank that was active becomes standby
//! with its segment count cleared, so a second start without a new upload plays nothing.
//! `stop` (abort) stops the sequencer and zeroes velocity, acceleration and jerk at once (the
//! position holds); `aborted` stays set until the next start or reset.

use rust_hdl::prelude::*;

use crate::chain::SnapChain;
use crate::program_memory::ProgramMemory;
use crate::sequencer::Sequencer;
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
    /// Start the standby program (one-clock pulse; ignored while busy).
    pub start: Signal<In, Bit>,
    /// Stop now: sequencer idle, v = a = j = 0, position holds.
    pub stop: Signal<In, Bit>,
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
    /// Cruise segment of the standby program, set with the count (63: none).
    pub cruise_value: Signal<In, Bits<INDEX_BITS>>,
    /// Controlled stop: end the cruise early and decelerate as planned.
    pub soft_stop: Signal<In, Bit>,
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
    /// The last program was aborted.
    pub aborted: Signal<Out, Bit>,
    /// Ticks since the start.
    pub tick_count: Signal<Out, Bits<TICK_BITS>>,
    /// The tick enable (one clock wide).
    pub tick: Signal<Out, Bit>,
    /// Bank that plays (the other one is written).
    pub active_bank: Signal<Out, Bit>,
    /// Segment count of the standby program (0: nothing to start).
    pub standby_count: Signal<Out, Bits<INDEX_BITS>>,
    divider: TickDivider,
    memory: ProgramMemory,
    sequencer: Sequencer,
    chain: SnapChain,
    bank: DFF<Bit>,
    count0: DFF<Bits<INDEX_BITS>>,
    count1: DFF<Bits<INDEX_BITS>>,
    cruise0: DFF<Bits<INDEX_BITS>>,
    cruise1: DFF<Bits<INDEX_BITS>>,
    aborted_reg: DFF<Bit>,
    read_bank: Signal<Local, Bit>,
    count_zero: Constant<Bits<INDEX_BITS>>,
}

impl Default for MotionCore {
    fn default() -> Self {
        MotionCore {
            clock: Default::default(),
            reset: Default::default(),
            tick_div: Default::default(),
            start: Default::default(),
            stop: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_ticks: Default::default(),
            write_snap: Default::default(),
            count_enable: Default::default(),
            count_value: Default::default(),
            cruise_value: Default::default(),
            soft_stop: Default::default(),
            x: Default::default(),
            v: Default::default(),
            a: Default::default(),
            j: Default::default(),
            position: Default::default(),
            segment: Default::default(),
            busy: Default::default(),
            done: Default::default(),
            aborted: Default::default(),
            tick_count: Default::default(),
            tick: Default::default(),
            active_bank: Default::default(),
            standby_count: Default::default(),
            divider: Default::default(),
            memory: Default::default(),
            sequencer: Default::default(),
            chain: Default::default(),
            bank: Default::default(),
            count0: Default::default(),
            count1: Default::default(),
            cruise0: Default::default(),
            cruise1: Default::default(),
            aborted_reg: Default::default(),
            read_bank: Default::default(),
            count_zero: Constant::new(0.into()),
        }
    }
}

impl Logic for MotionCore {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, divider, memory, sequencer, chain);
        dff_setup!(
            self,
            clock,
            bank,
            count0,
            count1,
            cruise0,
            cruise1,
            aborted_reg
        );
        self.divider.reset.next = self.reset.val();
        self.divider.divisor.next = self.tick_div.val();
        // While playing, read the active bank; while idle, the standby bank (the next start's).
        self.read_bank.next = self.bank.q.val() ^ !self.sequencer.busy.val();
        self.memory.read_bank.next = self.read_bank.val();
        self.memory.read_address.next = self.sequencer.address.val();
        if self.read_bank.val() {
            self.sequencer.count.next = self.count1.q.val();
            self.sequencer.cruise.next = self.cruise1.q.val();
        } else {
            self.sequencer.count.next = self.count0.q.val();
            self.sequencer.cruise.next = self.cruise0.q.val();
        }
        // Writes go to the standby bank.
        self.memory.write_bank.next = !self.bank.q.val();
        self.memory.write_address.next = self.write_address.val();
        self.memory.write_enable.next = self.write_enable.val() & !self.reset.val();
        self.memory.write_ticks.next = self.write_ticks.val();
        self.memory.write_snap.next = self.write_snap.val();
        self.sequencer.reset.next = self.reset.val();
        self.sequencer.tick.next = self.divider.tick.val();
        self.sequencer.start.next = self.start.val();
        self.sequencer.stop.next = self.stop.val();
        self.sequencer.soft_stop.next = self.soft_stop.val();
        self.sequencer.entry_ticks.next = self.memory.read_ticks.val();
        self.sequencer.entry_snap.next = self.memory.read_snap.val();
        self.chain.reset.next = self.reset.val();
        self.chain.halt.next = self.stop.val();
        self.chain.tick.next = self.divider.tick.val();
        self.chain.snap.next = self.sequencer.snap.val();
        if self.reset.val() {
            self.bank.d.next = false;
            self.count0.d.next = self.count_zero.val();
            self.count1.d.next = self.count_zero.val();
            self.cruise0.d.next = self.count_zero.val();
            self.cruise1.d.next = self.count_zero.val();
            self.aborted_reg.d.next = false;
        } else if self.sequencer.started.val() {
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
                self.cruise0.d.next = self.cruise_value.val();
            } else {
                self.count1.d.next = self.count_value.val();
                self.cruise1.d.next = self.cruise_value.val();
            }
        }
        if self.stop.val() & !self.reset.val() {
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
        self.tick_count.next = self.sequencer.tick_count.val();
        self.tick.next = self.divider.tick.val();
        self.active_bank.next = self.bank.q.val();
        if self.bank.q.val() {
            self.standby_count.next = self.count0.q.val();
        } else {
            self.standby_count.next = self.count1.q.val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_core_is_synthesizable() {
        let mut uut = MotionCore::default();
        uut.connect_all();
        let v = generate_verilog(&uut);
        yosys_validate("motion_core", &v).unwrap();
        crate::synth_check::synth_xilinx("motion_core", &v);
    }
}
