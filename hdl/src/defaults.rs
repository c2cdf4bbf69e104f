//! The design the blocks are built with when nothing else is said (the Zybo Z7-10's timing:
//! 125 MHz, 115 200 baud, Ts = 10 µs; the default format): what a block's `Default` and its
//! tests use.

use snapgen_model::device::Design;
use snapgen_model::timing::{Dividers, Timing};

/// The dividers for 125 MHz, 115 200 baud and Ts = 10 µs (the Zybo Z7-10 defaults).
pub fn default_dividers() -> Dividers {
    Timing::default()
        .dividers()
        .expect("the default timing is valid")
}

/// The default design (the Zybo Z7-10's timing, the default format), with design hash 0:
/// [`crate::verilog::io_design`] computes a design's real hash.
pub fn default_design() -> Design {
    let t = Timing::default();
    Design {
        format: snapgen_model::DEFAULT_FORMAT,
        dividers: default_dividers(),
        clock_hz: t.clock_hz as u32,
        baud: t.baud,
        design_hash: 0,
        input_polarity: 0,
    }
}
