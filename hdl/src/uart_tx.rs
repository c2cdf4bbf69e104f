//! UART transmitter, 8N1 (model: `snapgen_model::io::uart::UartTx`): when idle and `start` is
//! high it takes `data` and sends a start bit, 8 data bits LSB first and a stop bit, each
//! `divisor` clocks long (`divisor ≥ 1`); `busy` meanwhile. The line idles high.

use rust_hdl::prelude::*;

/// The transmitter.
#[derive(LogicBlock)]
pub struct UartTx {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Send `data` (taken when not busy).
    pub start: Signal<In, Bit>,
    /// Byte to send.
    pub data: Signal<In, Bits<8>>,
    /// Clocks per bit.
    pub divisor: Signal<In, Bits<16>>,
    /// The line.
    pub tx: Signal<Out, Bit>,
    /// Sending.
    pub busy: Signal<Out, Bit>,
    busy_reg: DFF<Bit>,
    timer: DFF<Bits<16>>,
    bit_index: DFF<Bits<4>>,
    shift: DFF<Bits<8>>,
    line: DFFWithInit<Bit>,
    div_m1: Signal<Local, Bits<16>>,
    last: Constant<Bits<4>>,
    stop_index: Constant<Bits<4>>,
    bit_one: Constant<Bits<4>>,
    bit_zero: Constant<Bits<4>>,
    zero: Constant<Bits<16>>,
    one: Constant<Bits<16>>,
}

impl Default for UartTx {
    fn default() -> Self {
        UartTx {
            clock: Default::default(),
            start: Default::default(),
            data: Default::default(),
            divisor: Default::default(),
            tx: Default::default(),
            busy: Default::default(),
            busy_reg: Default::default(),
            timer: Default::default(),
            bit_index: Default::default(),
            shift: Default::default(),
            line: DFFWithInit::new(true),
            div_m1: Default::default(),
            last: Constant::new(9.into()),
            stop_index: Constant::new(8.into()),
            bit_one: Constant::new(1.into()),
            bit_zero: Constant::new(0.into()),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
        }
    }
}

impl Logic for UartTx {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, busy_reg, timer, bit_index, shift, line);
        if self.divisor.val() == self.zero.val() {
            self.div_m1.next = self.zero.val();
        } else {
            self.div_m1.next = self.divisor.val() - self.one.val();
        }
        if !self.busy_reg.q.val() {
            if self.start.val() {
                // Bit 0 is the start bit (low); bits 1..=8 the data LSB first; bit 9 the stop bit.
                self.shift.d.next = self.data.val();
                self.busy_reg.d.next = true;
                self.bit_index.d.next = self.bit_zero.val();
                self.timer.d.next = self.div_m1.val();
                self.line.d.next = false;
            }
        } else if self.timer.q.val() == self.zero.val() {
            if self.bit_index.q.val() == self.last.val() {
                self.busy_reg.d.next = false;
                self.line.d.next = true;
            } else {
                self.bit_index.d.next = self.bit_index.q.val() + self.bit_one.val();
                if self.bit_index.q.val() == self.stop_index.val() {
                    self.line.d.next = true;
                } else {
                    self.line.d.next = self.shift.q.val().get_bit(0);
                    self.shift.d.next = self.shift.q.val() >> 1;
                }
                self.timer.d.next = self.div_m1.val();
            }
        } else {
            self.timer.d.next = self.timer.q.val() - self.one.val();
        }
        self.tx.next = self.line.q.val();
        self.busy.next = self.busy_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uart_tx_is_synthesizable() {
        crate::synth_check::synth_block("uart_tx", UartTx::default());
    }
}
