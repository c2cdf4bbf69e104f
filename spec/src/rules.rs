//! The protocol's rules that are numbers: the program swap's lead and reach, the reply queue's
//! depth, the watchdog's unit, and the retry policy every host uses.

use crate::widths::SWAP_BITS;

/// A SWAP_AT is refused with LATE unless its tick lies at least this many ticks beyond the
/// time base on the clock before the one that executes it (a signed 64-bit difference).
pub const SWAP_MIN_LEAD: i64 = 5;
/// A SWAP_AT whose tick lies this many ticks or more beyond the time base is refused with
/// BAD_ARGUMENT: the core compares the low [`SWAP_BITS`] bits of the time base.
pub const SWAP_REACH: i64 = 1 << (SWAP_BITS - 1);
/// Replies a device holds while it sends; a host keeps at most this many commands
/// unanswered (a frame arriving with the queue full is neither executed nor answered, and
/// raises the REPLY_OVERFLOW flag).
pub const REPLY_QUEUE: usize = 16;

/// How long a host waits for a reply before it sends the same frame again (seconds): more
/// than the device's inter-byte timeout after a NAK BAD_CRC, and far more than the longest
/// reply takes at the slowest rate a board is built for.
pub const HOST_REPLY_TIMEOUT_S: f64 = 0.3;
/// How many times a host sends a frame again (same `SEQ`) before it gives up.
pub const HOST_RETRIES: u32 = 3;

const _: () = assert!(HOST_REPLY_TIMEOUT_S > crate::wire::FRAME_TIMEOUT_S);
