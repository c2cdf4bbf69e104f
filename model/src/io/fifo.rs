//! A small byte FIFO (depth 4): write and read strobes, `empty`/`full` flags, the head byte
//! visible on `data` (first-word fall-through). A write when full and a read when empty are
//! ignored; a simultaneous read and write both happen.

/// Depth.
pub const DEPTH: usize = 4;

/// The FIFO.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ByteFifo {
    mem: [u8; DEPTH],
    head: u8,
    tail: u8,
    count: u8,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FifoOutputs {
    /// Head byte (meaningless when empty).
    pub data: u8,
    /// No byte held.
    pub empty: bool,
    /// `DEPTH` bytes held.
    pub full: bool,
}

impl ByteFifo {
    /// An empty FIFO.
    pub fn new() -> Self {
        Self::default()
    }

    /// One clock.
    #[inline]
    pub fn clock(&mut self, write: bool, data: u8, read: bool) -> FifoOutputs {
        let do_write = write && usize::from(self.count) < DEPTH;
        let do_read = read && self.count > 0;
        if do_write {
            self.mem[usize::from(self.tail)] = data;
            self.tail = (self.tail + 1) % DEPTH as u8;
        }
        if do_read {
            self.head = (self.head + 1) % DEPTH as u8;
        }
        self.count = self.count + u8::from(do_write) - u8::from(do_read);
        self.outputs()
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> FifoOutputs {
        FifoOutputs {
            data: self.mem[usize::from(self.head)],
            empty: self.count == 0,
            full: usize::from(self.count) == DEPTH,
        }
    }
}
