//! Clock-accurate models of the I/O blocks (`snapgen_hdl`'s `quadrature`, `pwm`, `uart_rx`,
//! `uart_tx`, `byte_fifo`, `frame_rx`, `executor`, `reply_queue`, `reply_tx`). Each has a `clock` method that takes one clock's inputs and returns
//! the outputs after the rising edge, with exactly the hardware's rules, so that the HDL can be
//! compared with it clock by clock.

pub mod axi;
pub mod config;
pub mod executor;
pub mod fifo;
pub mod frame_rx;
pub mod pwm;
pub mod quadrature;
pub mod reply_queue;
pub mod reply_tx;
pub mod servo;
pub mod step_dir;
pub mod uart;

/// One input through a two-flop synchroniser and a glitch filter: a new level is accepted
/// once the synchronised input has differed from the filtered level on `filter + 1`
/// consecutive clocks (`filter = 0`: accepted on the first clock).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilteredInput {
    s1: bool,
    s2: bool,
    /// The filtered level.
    pub level: bool,
    count: u16,
}

impl FilteredInput {
    /// A filtered input resting at `level`.
    pub fn new(level: bool) -> Self {
        FilteredInput {
            s1: level,
            s2: level,
            level,
            count: 0,
        }
    }

    /// One clock; `filter` is the programmed length.
    #[inline]
    pub fn clock(&mut self, input: bool, filter: u16) {
        let (s2, level, count) = (self.s2, self.level, self.count);
        if s2 == level {
            self.count = 0;
        } else if count >= filter {
            self.level = s2;
            self.count = 0;
        } else {
            self.count = count + 1;
        }
        self.s2 = self.s1;
        self.s1 = input;
    }
}
