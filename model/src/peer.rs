//! The world around a board, clock by clock: a host on the UART line (its transmitter sends the
//! bytes it is given, its receiver collects what the board sends), an encoder that follows the
//! reference position as an ideal motor would (one count per output LSB) or a count set from
//! outside (a simulated motor: [`Peer::drive_encoder`]), at most one quadrature step per
//! clock, with an index pulse once per turn, and the limit and emergency-stop inputs. It produces the pins
//! for each clock and reads the board's outputs after each edge, so the same peer drives the
//! device model, the Verilated I/O top, or both in lockstep.

use std::collections::VecDeque;

use crate::device::{IoInputs, IoOutputs};
use crate::io::uart::{UartRx, UartTx};

/// The host, encoder and switches around a board.
#[derive(Clone, Debug)]
pub struct Peer {
    divisor: u16,
    host_tx: UartTx,
    host_rx: UartRx,
    queue: VecDeque<u8>,
    sending: bool,
    received: Vec<u8>,
    /// Clocks of reset still to give.
    pub reset_clocks: u32,
    encoder: i64,
    target: i64,
    /// The count comes from [`Peer::drive_encoder`].
    driven: bool,
    /// Whether the encoder follows the reference position (otherwise it holds, or goes where
    /// [`Peer::drive_encoder`] says).
    pub follow: bool,
    /// Counts per turn of the encoder: the index pin is high on the counts that are a multiple
    /// of it (0: no index).
    pub index_period: u32,
    /// Positive limit switch active.
    pub limit_positive: bool,
    /// Negative limit switch active.
    pub limit_negative: bool,
    /// Emergency stop pressed.
    pub emergency_stop: bool,
    /// How the switches are wired: bit 0 limit+, bit 1 limit−, bit 2 the emergency stop
    /// normally closed (the pin is low when active); 0: all active high.
    pub wiring: u8,
    /// Force the UART line low (a break) while set.
    pub line_break: bool,
}

impl Peer {
    /// A peer at `divisor` clocks per UART bit, resetting the board for 4 clocks first.
    pub fn new(divisor: u16) -> Self {
        Peer {
            divisor,
            host_tx: UartTx::new(),
            host_rx: UartRx::new(),
            queue: VecDeque::new(),
            sending: false,
            received: Vec::new(),
            reset_clocks: 4,
            encoder: 0,
            target: 0,
            driven: false,
            follow: true,
            index_period: 0,
            limit_positive: false,
            limit_negative: false,
            emergency_stop: false,
            wiring: 0,
            line_break: false,
        }
    }

    /// Bytes for the host to send, in order.
    pub fn send(&mut self, bytes: &[u8]) {
        self.queue.extend(bytes);
    }

    /// True while bytes wait or one is on the line.
    pub fn sending(&self) -> bool {
        self.sending || !self.queue.is_empty()
    }

    /// Bytes the host received.
    pub fn take_received(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.received)
    }

    /// A motor's shaft: the encoder heads for `count` (one quadrature step per clock) and stops
    /// following the reference position.
    pub fn drive_encoder(&mut self, count: i64) {
        self.follow = false;
        self.driven = true;
        self.target = count;
    }

    /// The count on the encoder's pins now.
    pub fn encoder(&self) -> i64 {
        self.encoder
    }

    /// Quadrature levels (A, B) of an encoder count: Gray order 00 → 01 → 11 → 10.
    pub fn levels(count: i64) -> (bool, bool) {
        match count.rem_euclid(4) {
            0 => (false, false),
            1 => (false, true),
            2 => (true, true),
            _ => (true, false),
        }
    }

    /// The pins for this clock.
    pub fn inputs(&mut self) -> IoInputs {
        let next = self.queue.front().copied();
        let o = self.host_tx.clock(
            next.is_some() && !self.sending,
            next.unwrap_or(0),
            self.divisor,
        );
        if !self.sending && next.is_some() && o.busy {
            self.queue.pop_front();
        }
        self.sending = o.busy;
        if self.follow || self.driven {
            if self.encoder < self.target {
                self.encoder += 1;
            } else if self.encoder > self.target {
                self.encoder -= 1;
            }
        }
        let (a, b) = Self::levels(self.encoder);
        let reset = self.reset_clocks > 0;
        self.reset_clocks = self.reset_clocks.saturating_sub(1);
        IoInputs {
            reset,
            uart_rx: o.tx && !self.line_break,
            enc_a: a,
            enc_b: b,
            enc_i: self.index_period != 0
                && self.encoder.rem_euclid(i64::from(self.index_period)) == 0,
            limit_pos: self.limit_positive ^ (self.wiring & 1 != 0),
            limit_neg: self.limit_negative ^ (self.wiring & 2 != 0),
            estop: self.emergency_stop ^ (self.wiring & 4 != 0),
        }
    }

    /// The board's outputs after the edge.
    pub fn observe(&mut self, o: &IoOutputs) {
        let r = self.host_rx.clock(o.uart_tx, self.divisor);
        if r.valid {
            self.received.push(r.data);
        }
        self.observe_status(&o.status);
    }

    /// The board's status block after the edge, for a board without a UART (the AXI top):
    /// the encoder follows its position.
    pub fn observe_status(&mut self, status: &snapgen_spec::Status) {
        if self.follow {
            self.target = i64::from(status.position);
        }
    }
}
