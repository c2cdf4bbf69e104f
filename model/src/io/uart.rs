//! UART, 8N1, LSB first, with a programmable baud divisor (clocks per bit; 125 MHz / 115 200
//! baud = 1085).
//!
//! Receiver: two-flop synchroniser; in idle it waits for the line low; it samples the start
//! bit `divisor / 2` clocks later (a high line there is a false start), then every `divisor`
//! clocks the 8 data bits and the stop bit at mid-bit. A low stop bit is a framing error: the
//! byte is dropped, `framing_error` pulses, and the receiver waits for the line to return
//! high. A good byte pulses `valid` with `data`.
//!
//! Transmitter: when idle and `start` is high it takes `data`, sends a start bit, 8 data bits
//! and a stop bit, each `divisor` clocks long; `busy` is high meanwhile. The line idles high.

/// Default baud divisor for 115 200 baud from 125 MHz.
pub const DIVISOR_115200_AT_125MHZ: u16 = 1085;

/// Receiver outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RxOutputs {
    /// The byte received (valid when `valid` pulses).
    pub data: u8,
    /// One-clock pulse: a byte arrived.
    pub valid: bool,
    /// One-clock pulse: a low stop bit.
    pub framing_error: bool,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum RxState {
    #[default]
    Idle,
    Start,
    Data,
    Stop,
    WaitHigh,
}

/// The receiver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UartRx {
    s1: bool,
    s2: bool,
    state: RxState,
    timer: u16,
    bit: u8,
    shift: u8,
    out: RxOutputs,
}

impl Default for UartRx {
    fn default() -> Self {
        UartRx {
            s1: true,
            s2: true,
            state: RxState::Idle,
            timer: 0,
            bit: 0,
            shift: 0,
            out: RxOutputs::default(),
        }
    }
}

impl UartRx {
    /// A receiver on an idle (high) line.
    pub fn new() -> Self {
        Self::default()
    }

    /// One clock with the raw line level `rx`.
    #[inline]
    pub fn clock(&mut self, rx: bool, divisor: u16) -> RxOutputs {
        let line = self.s2;
        self.out.valid = false;
        self.out.framing_error = false;
        match self.state {
            RxState::Idle => {
                if !line {
                    self.state = RxState::Start;
                    self.timer = divisor / 2;
                }
            }
            RxState::Start => {
                if self.timer == 0 {
                    if line {
                        self.state = RxState::Idle;
                    } else {
                        self.state = RxState::Data;
                        self.timer = divisor.saturating_sub(1);
                        self.bit = 0;
                    }
                } else {
                    self.timer -= 1;
                }
            }
            RxState::Data => {
                if self.timer == 0 {
                    self.shift = (self.shift >> 1) | (u8::from(line) << 7);
                    self.timer = divisor.saturating_sub(1);
                    if self.bit == 7 {
                        self.state = RxState::Stop;
                    } else {
                        self.bit += 1;
                    }
                } else {
                    self.timer -= 1;
                }
            }
            RxState::Stop => {
                if self.timer == 0 {
                    if line {
                        self.out.data = self.shift;
                        self.out.valid = true;
                        self.state = RxState::Idle;
                    } else {
                        self.out.framing_error = true;
                        self.state = RxState::WaitHigh;
                    }
                } else {
                    self.timer -= 1;
                }
            }
            RxState::WaitHigh => {
                if line {
                    self.state = RxState::Idle;
                }
            }
        }
        self.s2 = self.s1;
        self.s1 = rx;
        self.out
    }
}

/// Transmitter outputs after a clock edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TxOutputs {
    /// The line.
    pub tx: bool,
    /// Sending.
    pub busy: bool,
}

/// The transmitter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UartTx {
    busy: bool,
    timer: u16,
    bit: u8,
    shift: u16,
    line: bool,
}

impl Default for UartTx {
    fn default() -> Self {
        UartTx {
            busy: false,
            timer: 0,
            bit: 0,
            shift: 0,
            line: true,
        }
    }
}

impl UartTx {
    /// An idle transmitter.
    pub fn new() -> Self {
        Self::default()
    }

    /// True while a byte is being sent.
    pub fn busy(&self) -> bool {
        self.busy
    }

    /// One clock: `start` with `data` begins a byte when idle.
    #[inline]
    pub fn clock(&mut self, start: bool, data: u8, divisor: u16) -> TxOutputs {
        if !self.busy {
            if start {
                // Frame: start bit 0, data LSB first, stop bit 1 (bit 0 goes out first).
                self.shift = (u16::from(data) << 1) | (1 << 9);
                self.busy = true;
                self.bit = 0;
                self.timer = divisor.saturating_sub(1);
                self.line = false;
            }
        } else if self.timer == 0 {
            if self.bit == 9 {
                self.busy = false;
                self.line = true;
            } else {
                self.bit += 1;
                self.line = (self.shift >> self.bit) & 1 == 1;
                self.timer = divisor.saturating_sub(1);
            }
        } else {
            self.timer -= 1;
        }
        TxOutputs {
            tx: self.line,
            busy: self.busy,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// TX (bit time `divisor`) into RX (expecting `rx_divisor`): a baud rate error.
    fn loopback(bytes: &[u8], divisor: u16, rx_divisor: u16) -> Vec<u8> {
        let mut tx = UartTx::new();
        let mut rx = UartRx::new();
        let mut got = Vec::new();
        let mut queue = bytes.iter().copied().peekable();
        let mut busy = false;
        for _ in 0..(bytes.len() as u32 + 2) * 12 * u32::from(divisor) {
            let next = queue.peek().copied();
            let o = tx.clock(next.is_some(), next.unwrap_or(0), divisor);
            if !busy && next.is_some() {
                queue.next(); // accepted on this clock
            }
            busy = o.busy;
            let r = rx.clock(o.tx, rx_divisor);
            if r.valid {
                got.push(r.data);
            }
            assert!(!r.framing_error);
        }
        got
    }

    #[test]
    fn bytes_loop_back_at_nominal_and_two_percent_off() {
        let data = [0x00, 0xFF, 0xA5, 0x5A, 0x01, 0x80];
        assert_eq!(loopback(&data, 100, 100), data);
        assert_eq!(loopback(&data, 100, 98), data);
        assert_eq!(loopback(&data, 100, 102), data);
    }

    #[test]
    fn low_stop_bit_is_a_framing_error() {
        let mut rx = UartRx::new();
        let d = 16u16;
        let mut errors = 0;
        // Start bit, 8 zero bits, a low stop bit, then idle.
        for k in 0..(11 * u32::from(d)) {
            let level = k >= 10 * u32::from(d);
            let o = rx.clock(level, d);
            errors += u32::from(o.framing_error);
            assert!(!o.valid);
        }
        assert_eq!(errors, 1);
    }
}
