//! A 4-byte FIFO with the head byte visible on `data` (model:
//! `snapgen_model::io::fifo::ByteFifo`). A write when full and a read when empty are ignored;
//! a read and a write on the same clock both happen.

use rust_hdl::prelude::*;

/// The FIFO.
#[derive(LogicBlock)]
pub struct ByteFifo {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Write `write_data`.
    pub write: Signal<In, Bit>,
    /// Byte to write.
    pub write_data: Signal<In, Bits<8>>,
    /// Drop the head byte.
    pub read: Signal<In, Bit>,
    /// Head byte.
    pub data: Signal<Out, Bits<8>>,
    /// Nothing held.
    pub empty: Signal<Out, Bit>,
    /// Four bytes held.
    pub full: Signal<Out, Bit>,
    slot0: DFF<Bits<8>>,
    slot1: DFF<Bits<8>>,
    slot2: DFF<Bits<8>>,
    slot3: DFF<Bits<8>>,
    head: DFF<Bits<2>>,
    tail: DFF<Bits<2>>,
    count: DFF<Bits<3>>,
    do_write: Signal<Local, Bit>,
    do_read: Signal<Local, Bit>,
    pointer0: Constant<Bits<2>>,
    pointer1: Constant<Bits<2>>,
    pointer2: Constant<Bits<2>>,
    pone: Constant<Bits<2>>,
    count0: Constant<Bits<3>>,
    count1: Constant<Bits<3>>,
    count4: Constant<Bits<3>>,
}

impl Default for ByteFifo {
    fn default() -> Self {
        ByteFifo {
            clock: Default::default(),
            write: Default::default(),
            write_data: Default::default(),
            read: Default::default(),
            data: Default::default(),
            empty: Default::default(),
            full: Default::default(),
            slot0: Default::default(),
            slot1: Default::default(),
            slot2: Default::default(),
            slot3: Default::default(),
            head: Default::default(),
            tail: Default::default(),
            count: Default::default(),
            do_write: Default::default(),
            do_read: Default::default(),
            pointer0: Constant::new(0.into()),
            pointer1: Constant::new(1.into()),
            pointer2: Constant::new(2.into()),
            pone: Constant::new(1.into()),
            count0: Constant::new(0.into()),
            count1: Constant::new(1.into()),
            count4: Constant::new(4.into()),
        }
    }
}

impl Logic for ByteFifo {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, slot0, slot1, slot2, slot3, head, tail, count);
        self.do_write.next = self.write.val() & (self.count.q.val() < self.count4.val());
        self.do_read.next = self.read.val() & (self.count.q.val() > self.count0.val());
        if self.do_write.val() {
            if self.tail.q.val() == self.pointer0.val() {
                self.slot0.d.next = self.write_data.val();
            } else if self.tail.q.val() == self.pointer1.val() {
                self.slot1.d.next = self.write_data.val();
            } else if self.tail.q.val() == self.pointer2.val() {
                self.slot2.d.next = self.write_data.val();
            } else {
                self.slot3.d.next = self.write_data.val();
            }
            self.tail.d.next = self.tail.q.val() + self.pone.val();
        }
        if self.do_read.val() {
            self.head.d.next = self.head.q.val() + self.pone.val();
        }
        if self.do_write.val() & !self.do_read.val() {
            self.count.d.next = self.count.q.val() + self.count1.val();
        }
        if self.do_read.val() & !self.do_write.val() {
            self.count.d.next = self.count.q.val() - self.count1.val();
        }
        if self.head.q.val() == self.pointer0.val() {
            self.data.next = self.slot0.q.val();
        } else if self.head.q.val() == self.pointer1.val() {
            self.data.next = self.slot1.q.val();
        } else if self.head.q.val() == self.pointer2.val() {
            self.data.next = self.slot2.q.val();
        } else {
            self.data.next = self.slot3.q.val();
        }
        self.empty.next = self.count.q.val() == self.count0.val();
        self.full.next = self.count.q.val() == self.count4.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_fifo_is_synthesizable() {
        crate::synth_check::synth_block("byte_fifo", ByteFifo::default());
    }
}
