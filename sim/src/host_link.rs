//! The host's [`Link`] to a [`VirtualBoard`]: commands go over the board's UART at its baud
//! rate, byte by byte, and time is the board's own (its clocks), so a latency measured here is
//! the one the design's UART gives, to the clock.

use snapgen_host::axis::driver::{Link, LinkError};
use snapgen_host::protocol::{Command, Decoded, Decoder, Reply};

use crate::board::VirtualBoard;

/// Clocks run between looks at the board's output.
const CHUNK: u64 = 32;

/// A link to a virtual board.
pub struct BoardLink {
    board: VirtualBoard,
    decoder: Decoder,
    seq: u8,
    /// Clocks a reply may take (a second of board time).
    timeout: u64,
}

impl BoardLink {
    /// A link to `board`.
    pub fn new(board: VirtualBoard) -> Self {
        let timeout = u64::from(board.design().clock_hz);
        BoardLink {
            board,
            decoder: Decoder::new(),
            seq: 0,
            timeout,
        }
    }

    /// The board.
    pub fn board(&self) -> &VirtualBoard {
        &self.board
    }

    /// The board, to change its world (switches) or inject a fault.
    pub fn board_mut(&mut self) -> &mut VirtualBoard {
        &mut self.board
    }

    fn tick_clocks(&self) -> u64 {
        u64::from(self.board.design().dividers.tick_div) + 1
    }
}

impl Link for BoardLink {
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError> {
        self.seq = self.seq.wrapping_add(1).max(1);
        let seq = self.seq;
        let format = self.board.design().format;
        self.board.receive(&c.to_frame(seq, &format).to_bytes());
        let mut waited = 0;
        while waited < self.timeout {
            self.board.run(CHUNK);
            waited += CHUNK;
            for b in self.board.take_output() {
                if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
                    if f.seq == seq {
                        if let Some(r) = Reply::from_frame(&f) {
                            return Ok(r);
                        }
                    }
                }
            }
        }
        Err(LinkError(format!(
            "no reply to {c:?} within {} clocks",
            self.timeout
        )))
    }

    fn wait(&mut self, ticks: u64) {
        self.board.run(ticks * self.tick_clocks());
    }

    fn byte_ticks(&self) -> f64 {
        10.0 * f64::from(self.board.design().dividers.uart_divisor) / self.tick_clocks() as f64
    }

    fn host_ticks(&self) -> f64 {
        self.board.clocks() as f64 / self.tick_clocks() as f64
    }
}
