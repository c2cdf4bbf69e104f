//! The segment sequencer: once started, plays the program one snap value per tick.
//!
//! It holds the current segment (`index`, ticks `left` including this one, `snap`) and reads
//! the next one from the asynchronous program memory at `address = index + 1`, so a segment
//! may last a single tick. On the last tick of the last segment it drops the snap to 0 and
//! raises `done`. A start is accepted only while idle; an abort stops it at once. The first
//! program tick is the first tick strictly after the clock that accepted the start.
//!
//! A program swap (`swap`, on a tick, from [`crate::swap_timer`]) loads segment 0 of the
//! next program (the standby bank's, `first_*`) in place of the tick's usual step,
//! busy or not, so the next tick is the new program's first.
//!
//! When a controlled stop is taken (`engage`, on a tick) a program playing is cut there: busy
//! falls (`done` is left as it is: false while a program plays, true if it ended before the
//! stop was taken) and the snap drops to 0 (the stop unit feeds the chain from the next tick). The
//! tick counter counts every tick while a program plays or a stop runs (`stopping`).

use rust_hdl::prelude::*;

use crate::{ADDR_BITS, D_BITS, INDEX_BITS, TICK_BITS};

/// Plays a program.
#[derive(LogicBlock)]
pub struct Sequencer {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Tick enable.
    pub tick: Signal<In, Bit>,
    /// Start the program (ignored while busy).
    pub start: Signal<In, Bit>,
    /// Stop now.
    pub abort_move: Signal<In, Bit>,
    /// A program swap is due on this clock's tick: load the next program's segment 0
    /// (`first_*`).
    pub swap: Signal<In, Bit>,
    /// A controlled stop is taken on this clock's tick: cut the program.
    pub engage: Signal<In, Bit>,
    /// A controlled stop runs (its ticks are counted).
    pub stopping: Signal<In, Bit>,
    /// Segments in the program playing (the active bank's).
    pub count: Signal<In, Bits<INDEX_BITS>>,
    /// Memory read data at `address` (the program playing's next segment): tick count.
    pub entry_ticks: Signal<In, Bits<TICK_BITS>>,
    /// Memory read data at `address`: snap.
    pub entry_snap: Signal<In, Bits<D_BITS>>,
    /// Segments in the next program (the standby bank's), which a start or a swap takes.
    pub first_count: Signal<In, Bits<INDEX_BITS>>,
    /// The next program's segment 0: tick count (read on a port of its own).
    pub first_ticks: Signal<In, Bits<TICK_BITS>>,
    /// The next program's segment 0: snap.
    pub first_snap: Signal<In, Bits<D_BITS>>,
    /// Memory read address within the bank: the next segment (`index + 1`; the core reads
    /// segment 0 of the next program on a port of its own).
    pub address: Signal<Out, Bits<ADDR_BITS>>,
    /// Snap for this tick (0 while idle).
    pub snap: Signal<Out, Bits<D_BITS>>,
    /// A program is playing.
    pub busy: Signal<Out, Bit>,
    /// The last program ran to its end (cleared by the next start).
    pub done: Signal<Out, Bit>,
    /// Index of the segment playing (equals the count once done).
    pub index: Signal<Out, Bits<INDEX_BITS>>,
    /// Ticks played since the start.
    pub tick_count: Signal<Out, Bits<TICK_BITS>>,
    /// High on the clock that accepts a start.
    pub started: Signal<Out, Bit>,
    busy_reg: DFF<Bit>,
    done_reg: DFF<Bit>,
    index_reg: DFF<Bits<INDEX_BITS>>,
    /// `index + 1`, a register beside the index: the end-of-program compare follows no adder.
    index_after: DFFWithInit<Bits<INDEX_BITS>>,
    /// `index + 1` (low bits), a register beside the index (meaningful while busy).
    address_reg: DFF<Bits<ADDR_BITS>>,
    left: DFF<Bits<TICK_BITS>>,
    snap_reg: DFF<Bits<D_BITS>>,
    tick_count_reg: DFF<Bits<TICK_BITS>>,
    next_index: Signal<Local, Bits<INDEX_BITS>>,
    /// The address after `address` (while busy `address` is `index + 1`).
    address_after: Signal<Local, Bits<ADDR_BITS>>,
    // Sized constants (rust-hdl emits bare literals as 32-bit: WIDTH warnings).
    index_zero: Constant<Bits<INDEX_BITS>>,
    index_one: Constant<Bits<INDEX_BITS>>,
    address_one: Constant<Bits<ADDR_BITS>>,
    ticks_zero: Constant<Bits<TICK_BITS>>,
    ticks_one: Constant<Bits<TICK_BITS>>,
    snap_zero: Constant<Bits<D_BITS>>,
}

impl Default for Sequencer {
    fn default() -> Self {
        Sequencer {
            clock: Default::default(),
            reset: Default::default(),
            tick: Default::default(),
            start: Default::default(),
            abort_move: Default::default(),
            swap: Default::default(),
            engage: Default::default(),
            stopping: Default::default(),
            count: Default::default(),
            entry_ticks: Default::default(),
            entry_snap: Default::default(),
            first_count: Default::default(),
            first_ticks: Default::default(),
            first_snap: Default::default(),
            address: Default::default(),
            snap: Default::default(),
            busy: Default::default(),
            done: Default::default(),
            index: Default::default(),
            tick_count: Default::default(),
            started: Default::default(),
            busy_reg: Default::default(),
            done_reg: Default::default(),
            index_reg: Default::default(),
            index_after: DFFWithInit::new(1.into()),
            address_reg: Default::default(),
            left: Default::default(),
            snap_reg: Default::default(),
            tick_count_reg: Default::default(),
            next_index: Default::default(),
            address_after: Default::default(),
            index_zero: Constant::new(0.into()),
            index_one: Constant::new(1.into()),
            address_one: Constant::new(1.into()),
            ticks_zero: Constant::new(0.into()),
            ticks_one: Constant::new(1.into()),
            snap_zero: Constant::new(0.into()),
        }
    }
}

impl Logic for Sequencer {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            busy_reg,
            done_reg,
            index_reg,
            index_after,
            address_reg,
            left,
            snap_reg,
            tick_count_reg
        );
        self.next_index.next = self.index_after.q.val();
        self.address_after.next = self.address_reg.q.val() + self.address_one.val();
        self.address.next = self.address_reg.q.val();
        self.started.next = false;
        if self.reset.val() {
            self.busy_reg.d.next = false;
            self.done_reg.d.next = false;
            self.index_reg.d.next = self.index_zero.val();
            self.index_after.d.next = self.index_one.val();
            self.address_reg.d.next = self.address_one.val();
            self.left.d.next = self.ticks_zero.val();
            self.snap_reg.d.next = self.snap_zero.val();
            self.tick_count_reg.d.next = self.ticks_zero.val();
        } else if self.abort_move.val() {
            self.busy_reg.d.next = false;
            self.snap_reg.d.next = self.snap_zero.val();
        } else if self.start.val() & !self.busy_reg.q.val() {
            self.started.next = true;
            self.index_reg.d.next = self.index_zero.val();
            self.index_after.d.next = self.index_one.val();
            self.address_reg.d.next = self.address_one.val();
            self.tick_count_reg.d.next = self.ticks_zero.val();
            if self.first_count.val() == self.index_zero.val() {
                self.done_reg.d.next = true;
                self.snap_reg.d.next = self.snap_zero.val();
            } else {
                self.busy_reg.d.next = true;
                self.done_reg.d.next = false;
                self.left.d.next = self.first_ticks.val();
                self.snap_reg.d.next = self.first_snap.val();
            }
        } else if self.tick.val() {
            if self.busy_reg.q.val() | self.stopping.val() {
                self.tick_count_reg.d.next = self.tick_count_reg.q.val() + self.ticks_one.val();
            }
            if self.swap.val() {
                self.index_reg.d.next = self.index_zero.val();
                self.index_after.d.next = self.index_one.val();
                self.address_reg.d.next = self.address_one.val();
                self.tick_count_reg.d.next = self.ticks_zero.val();
                if self.first_count.val() == self.index_zero.val() {
                    self.busy_reg.d.next = false;
                    self.done_reg.d.next = true;
                    self.snap_reg.d.next = self.snap_zero.val();
                } else {
                    self.busy_reg.d.next = true;
                    self.done_reg.d.next = false;
                    self.left.d.next = self.first_ticks.val();
                    self.snap_reg.d.next = self.first_snap.val();
                }
            } else if self.engage.val() {
                // `done` is left: false while a program plays, and a program that ended before
                // the stop was taken did run to its end.
                self.busy_reg.d.next = false;
                self.snap_reg.d.next = self.snap_zero.val();
            } else if self.busy_reg.q.val() {
                if self.left.q.val() == self.ticks_one.val() {
                    self.index_reg.d.next = self.next_index.val();
                    self.index_after.d.next = self.next_index.val() + self.index_one.val();
                    self.address_reg.d.next = self.address_after.val();
                    if self.next_index.val() == self.count.val() {
                        self.busy_reg.d.next = false;
                        self.done_reg.d.next = true;
                        self.snap_reg.d.next = self.snap_zero.val();
                    } else {
                        self.left.d.next = self.entry_ticks.val();
                        self.snap_reg.d.next = self.entry_snap.val();
                    }
                } else {
                    self.left.d.next = self.left.q.val() - self.ticks_one.val();
                }
            }
        }
        self.snap.next = self.snap_reg.q.val();
        self.busy.next = self.busy_reg.q.val();
        self.done.next = self.done_reg.q.val();
        self.index.next = self.index_reg.q.val();
        self.tick_count.next = self.tick_count_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequencer_is_synthesizable() {
        crate::synth_check::synth_block("sequencer", Sequencer::default());
    }
}
