//! Quadrature encoder decoder: two-flop synchronisers, a programmable glitch filter on A, B and
//! the index, 4× decoding into a signed count of configurable width (wrapping at it, as the
//! hardware register does), and a counter of illegal double
//! transitions (both channels changing on the same clock, after filtering).
//!
//! Direction: the filtered state `(A, B)` read as Gray code 00 → 01 → 11 → 10 → 00 counts up
//! (B leads A); the reverse sequence counts down.

use super::FilteredInput;

/// Inputs for one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QuadInputs {
    /// Channel A (raw pin).
    pub a: bool,
    /// Channel B.
    pub b: bool,
    /// Index (raw pin; tie low when absent).
    pub index: bool,
    /// Glitch filter length in clocks.
    pub filter: u16,
    /// Synchronous clear of count, errors and index latch.
    pub clear: bool,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QuadOutputs {
    /// Position count (4 per line), sign-extended from the counter's width.
    pub count: i64,
    /// Illegal transitions seen (wraps at 2^16).
    pub errors: u16,
    /// The count latched at the last rising edge of the index (as it stood before that clock).
    pub index_count: i64,
    /// An index edge was seen since the last clear.
    pub index_seen: bool,
}

/// The decoder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quadrature {
    a: FilteredInput,
    b: FilteredInput,
    z: FilteredInput,
    // The filtered levels one clock earlier: the decoder compares them with the current ones.
    prev_a: bool,
    prev_b: bool,
    prev_z: bool,
    out: QuadOutputs,
    bits: u32,
}

impl Default for Quadrature {
    fn default() -> Self {
        Quadrature::with_width(32)
    }
}

/// Gray code to position within a cycle: 00 → 0, 01 → 1, 11 → 2, 10 → 3.
fn phase(a: bool, b: bool) -> u8 {
    match (a, b) {
        (false, false) => 0,
        (false, true) => 1,
        (true, true) => 2,
        (true, false) => 3,
    }
}

impl Quadrature {
    /// A decoder whose inputs rest low, with a 32-bit count.
    pub fn new() -> Self {
        Self::default()
    }

    /// A decoder with a `bits`-wide count (2..=64).
    pub fn with_width(bits: u32) -> Self {
        assert!(
            (2..=64).contains(&bits),
            "count width {bits} outside 2..=64"
        );
        Quadrature {
            a: Default::default(),
            b: Default::default(),
            z: Default::default(),
            prev_a: false,
            prev_b: false,
            prev_z: false,
            out: QuadOutputs::default(),
            bits,
        }
    }

    /// One clock.
    #[inline]
    pub fn clock(&mut self, i: &QuadInputs) -> QuadOutputs {
        let old = phase(self.prev_a, self.prev_b);
        let new = phase(self.a.level, self.b.level);
        let o = &mut self.out;
        if i.clear {
            *o = QuadOutputs::default();
        } else {
            // The index latches the count as it stood before this clock's step.
            if self.z.level && !self.prev_z {
                o.index_count = o.count;
                o.index_seen = true;
            }
            match new.wrapping_sub(old) & 3 {
                1 => o.count = wrap(o.count.wrapping_add(1), self.bits),
                3 => o.count = wrap(o.count.wrapping_sub(1), self.bits),
                2 => o.errors = o.errors.wrapping_add(1),
                _ => {}
            }
        }
        self.prev_a = self.a.level;
        self.prev_b = self.b.level;
        self.prev_z = self.z.level;
        self.a.clock(i.a, i.filter);
        self.b.clock(i.b, i.filter);
        self.z.clock(i.index, i.filter);
        self.out
    }
}

/// Sign-extends the low `bits` bits.
fn wrap(v: i64, bits: u32) -> i64 {
    let s = 64 - bits;
    (v << s) >> s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(q: &mut Quadrature, seq: &[(bool, bool)], hold: usize, filter: u16) -> QuadOutputs {
        let mut o = QuadOutputs::default();
        for &(a, b) in seq {
            for _ in 0..hold {
                o = q.clock(&QuadInputs {
                    a,
                    b,
                    filter,
                    ..Default::default()
                });
            }
        }
        o
    }

    #[test]
    fn counts_four_per_cycle_both_ways() {
        let mut q = Quadrature::new();
        // Each state held 4 clocks; the final one 8 more, through the synchroniser and filter.
        let fwd = [(false, true), (true, true), (true, false), (false, false)];
        run(&mut q, &fwd, 4, 1);
        let o = run(&mut q, &[(false, false)], 8, 1);
        assert_eq!(o.count, 4);
        let back = [(true, false), (true, true), (false, true), (false, false)];
        run(&mut q, &back, 4, 1);
        let o = run(&mut q, &[(false, false)], 8, 1);
        assert_eq!((o.count, o.errors), (0, 0));
    }

    #[test]
    fn short_glitches_are_filtered_and_double_steps_counted() {
        let mut q = Quadrature::new();
        // A one-clock glitch on A with a 2-clock filter: ignored.
        let mut o = q.clock(&QuadInputs {
            a: true,
            filter: 2,
            ..Default::default()
        });
        for _ in 0..10 {
            o = q.clock(&QuadInputs {
                filter: 2,
                ..Default::default()
            });
        }
        assert_eq!((o.count, o.errors), (0, 0));
        // Both channels at once: an illegal transition.
        let o = run(&mut q, &[(true, true)], 6, 0);
        assert_eq!((o.count, o.errors), (0, 1));
    }
}
