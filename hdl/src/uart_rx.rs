//! UART receiver, 8N1 (model: `snapgen_model::io::uart::UartRx`): two-flop synchroniser;
//! start bit checked `divisor / 2` clocks after the falling edge, then the 8 data bits (LSB
//! first) and the stop bit sampled every `divisor` clocks at mid-bit. A low stop bit pulses
//! `framing_error`, drops the byte and waits for the line to return high. `divisor ≥ 1`.

use rust_hdl::prelude::*;

/// The receiver.
#[derive(LogicBlock)]
pub struct UartRx {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// The line (idles high).
    pub rx: Signal<In, Bit>,
    /// Clocks per bit.
    pub divisor: Signal<In, Bits<16>>,
    /// The byte received.
    pub data: Signal<Out, Bits<8>>,
    /// One-clock pulse: a byte arrived.
    pub valid: Signal<Out, Bit>,
    /// One-clock pulse: a low stop bit.
    pub framing_error: Signal<Out, Bit>,
    sync1: DFFWithInit<Bit>,
    sync2: DFFWithInit<Bit>,
    state: DFF<Bits<3>>,
    timer: DFF<Bits<16>>,
    bit_index: DFF<Bits<3>>,
    shift: DFF<Bits<8>>,
    data_reg: DFF<Bits<8>>,
    valid_reg: DFF<Bit>,
    error_reg: DFF<Bit>,
    div_m1: Signal<Local, Bits<16>>,
    idle: Constant<Bits<3>>,
    start: Constant<Bits<3>>,
    bits: Constant<Bits<3>>,
    stop: Constant<Bits<3>>,
    wait_high: Constant<Bits<3>>,
    last_bit: Constant<Bits<3>>,
    bit_one: Constant<Bits<3>>,
    bit_zero: Constant<Bits<3>>,
    zero: Constant<Bits<16>>,
    one: Constant<Bits<16>>,
    msb: Constant<Bits<8>>,
}

impl Default for UartRx {
    fn default() -> Self {
        UartRx {
            clock: Default::default(),
            rx: Default::default(),
            divisor: Default::default(),
            data: Default::default(),
            valid: Default::default(),
            framing_error: Default::default(),
            sync1: DFFWithInit::new(true),
            sync2: DFFWithInit::new(true),
            state: Default::default(),
            timer: Default::default(),
            bit_index: Default::default(),
            shift: Default::default(),
            data_reg: Default::default(),
            valid_reg: Default::default(),
            error_reg: Default::default(),
            div_m1: Default::default(),
            idle: Constant::new(0.into()),
            start: Constant::new(1.into()),
            bits: Constant::new(2.into()),
            stop: Constant::new(3.into()),
            wait_high: Constant::new(4.into()),
            last_bit: Constant::new(7.into()),
            bit_one: Constant::new(1.into()),
            bit_zero: Constant::new(0.into()),
            zero: Constant::new(0.into()),
            one: Constant::new(1.into()),
            msb: Constant::new(0x80.into()),
        }
    }
}

impl Logic for UartRx {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, sync1, sync2, state, timer, bit_index, shift, data_reg, valid_reg,
            error_reg
        );
        self.sync1.d.next = self.rx.val();
        self.sync2.d.next = self.sync1.q.val();
        if self.divisor.val() == self.zero.val() {
            self.div_m1.next = self.zero.val();
        } else {
            self.div_m1.next = self.divisor.val() - self.one.val();
        }
        self.valid_reg.d.next = false;
        self.error_reg.d.next = false;
        if self.state.q.val() == self.idle.val() {
            if !self.sync2.q.val() {
                self.state.d.next = self.start.val();
                self.timer.d.next = self.divisor.val() >> 1;
            }
        } else if self.state.q.val() == self.start.val() {
            if self.timer.q.val() == self.zero.val() {
                if self.sync2.q.val() {
                    self.state.d.next = self.idle.val();
                } else {
                    self.state.d.next = self.bits.val();
                    self.timer.d.next = self.div_m1.val();
                    self.bit_index.d.next = self.bit_zero.val();
                }
            } else {
                self.timer.d.next = self.timer.q.val() - self.one.val();
            }
        } else if self.state.q.val() == self.bits.val() {
            if self.timer.q.val() == self.zero.val() {
                if self.sync2.q.val() {
                    self.shift.d.next = (self.shift.q.val() >> 1) | self.msb.val();
                } else {
                    self.shift.d.next = self.shift.q.val() >> 1;
                }
                self.timer.d.next = self.div_m1.val();
                if self.bit_index.q.val() == self.last_bit.val() {
                    self.state.d.next = self.stop.val();
                } else {
                    self.bit_index.d.next = self.bit_index.q.val() + self.bit_one.val();
                }
            } else {
                self.timer.d.next = self.timer.q.val() - self.one.val();
            }
        } else if self.state.q.val() == self.stop.val() {
            if self.timer.q.val() == self.zero.val() {
                if self.sync2.q.val() {
                    self.data_reg.d.next = self.shift.q.val();
                    self.valid_reg.d.next = true;
                    self.state.d.next = self.idle.val();
                } else {
                    self.error_reg.d.next = true;
                    self.state.d.next = self.wait_high.val();
                }
            } else {
                self.timer.d.next = self.timer.q.val() - self.one.val();
            }
        } else if self.sync2.q.val() {
            self.state.d.next = self.idle.val();
        }
        self.data.next = self.data_reg.q.val();
        self.valid.next = self.valid_reg.q.val();
        self.framing_error.next = self.error_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uart_rx_is_synthesizable() {
        crate::synth_check::synth_block("uart_rx", UartRx::default());
    }
}
