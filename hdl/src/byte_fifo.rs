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
    m0: DFF<Bits<8>>,
    m1: DFF<Bits<8>>,
    m2: DFF<Bits<8>>,
    m3: DFF<Bits<8>>,
    head: DFF<Bits<2>>,
    tail: DFF<Bits<2>>,
    count: DFF<Bits<3>>,
    do_write: Signal<Local, Bit>,
    do_read: Signal<Local, Bit>,
    p0: Constant<Bits<2>>,
    p1: Constant<Bits<2>>,
    p2: Constant<Bits<2>>,
    pone: Constant<Bits<2>>,
    c0: Constant<Bits<3>>,
    c1: Constant<Bits<3>>,
    c4: Constant<Bits<3>>,
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
            m0: Default::default(),
            m1: Default::default(),
            m2: Default::default(),
            m3: Default::default(),
            head: Default::default(),
            tail: Default::default(),
            count: Default::default(),
            do_write: Default::default(),
            do_read: Default::default(),
            p0: Constant::new(0.into()),
            p1: Constant::new(1.into()),
            p2: Constant::new(2.into()),
            pone: Constant::new(1.into()),
            c0: Constant::new(0.into()),
            c1: Constant::new(1.into()),
            c4: Constant::new(4.into()),
        }
    }
}

impl Logic for ByteFifo {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, m0, m1, m2, m3, head, tail, count);
        self.do_write.next = self.write.val() & (self.count.q.val() < self.c4.val());
        self.do_read.next = self.read.val() & (self.count.q.val() > self.c0.val());
        if self.do_write.val() {
            if self.tail.q.val() == self.p0.val() {
                self.m0.d.next = self.write_data.val();
            } else if self.tail.q.val() == self.p1.val() {
                self.m1.d.next = self.write_data.val();
            } else if self.tail.q.val() == self.p2.val() {
                self.m2.d.next = self.write_data.val();
            } else {
                self.m3.d.next = self.write_data.val();
            }
            self.tail.d.next = self.tail.q.val() + self.pone.val();
        }
        if self.do_read.val() {
            self.head.d.next = self.head.q.val() + self.pone.val();
        }
        if self.do_write.val() & !self.do_read.val() {
            self.count.d.next = self.count.q.val() + self.c1.val();
        }
        if self.do_read.val() & !self.do_write.val() {
            self.count.d.next = self.count.q.val() - self.c1.val();
        }
        if self.head.q.val() == self.p0.val() {
            self.data.next = self.m0.q.val();
        } else if self.head.q.val() == self.p1.val() {
            self.data.next = self.m1.q.val();
        } else if self.head.q.val() == self.p2.val() {
            self.data.next = self.m2.q.val();
        } else {
            self.data.next = self.m3.q.val();
        }
        self.empty.next = self.count.q.val() == self.c0.val();
        self.full.next = self.count.q.val() == self.c4.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_fifo_is_synthesizable() {
        let mut uut = ByteFifo::default();
        uut.connect_all();
        let v = crate::verilog::direct_clocks(&generate_verilog(&uut));
        yosys_validate("byte_fifo", &v).unwrap();
        crate::synth_check::synth_xilinx("byte_fifo", &v);
    }
}
