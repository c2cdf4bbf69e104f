//! A [`Transport`] to a [`VirtualBoard`]: bytes go over the board's UART at its baud rate,
//! and time is the board's own (its clocks), so a latency measured here is the one the
//! design's UART gives, to the clock. The host's [`FramedLink`] over it is the same code, with
//! the same retry policy, as over a serial port.

use snapgen_host::link::{FramedLink, LinkError, RetryPolicy, Transport};

use crate::board::VirtualBoard;

/// Clocks run between looks at the board's output.
const CHUNK: u64 = 32;

/// A virtual board as a byte medium.
pub struct BoardTransport {
    board: VirtualBoard,
    clock_hz: f64,
}

impl BoardTransport {
    /// `board` as a transport.
    pub fn new(board: VirtualBoard) -> Self {
        let clock_hz = f64::from(board.design().clock_hz);
        BoardTransport { board, clock_hz }
    }

    /// The board.
    pub fn board(&self) -> &VirtualBoard {
        &self.board
    }

    /// The board, to change its world (switches) or inject a fault.
    pub fn board_mut(&mut self) -> &mut VirtualBoard {
        &mut self.board
    }

    fn clocks_of(&self, seconds: f64) -> u64 {
        (seconds.max(0.0) * self.clock_hz).round() as u64
    }
}

impl Transport for BoardTransport {
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.board.receive(bytes);
        Ok(())
    }

    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
        let mut left = self.clocks_of(wait).max(1);
        while left > 0 {
            let n = left.min(CHUNK);
            self.board.run(n);
            left -= n;
            let got = self.board.take_output();
            if !got.is_empty() {
                out.extend_from_slice(&got);
                return Ok(());
            }
        }
        Ok(())
    }

    fn now(&self) -> f64 {
        self.board.clocks() as f64 / self.clock_hz
    }

    fn sleep(&mut self, seconds: f64) {
        let n = self.clocks_of(seconds);
        self.board.run(n);
    }

    fn byte_time(&self) -> f64 {
        10.0 * f64::from(self.board.design().dividers.uart_divisor) / self.clock_hz
    }
}

/// The host's link to `board`: the framed protocol with the one retry policy, sequence
/// numbers from 0 (a simulation repeats).
pub fn board_link(board: VirtualBoard) -> FramedLink<BoardTransport> {
    FramedLink::new(BoardTransport::new(board), RetryPolicy::default(), 0)
}
