//! Quadrature encoder decoder (model: `snapgen_model::io::quadrature`): filtered A, B and
//! index, 4× decoding into a signed `N`-bit count, a 16-bit counter of illegal double
//! transitions, and the count latched on each rising edge of the index.
//!
//! The decoder compares the filtered levels with their values one clock earlier. Gray order
//! 00 → 01 → 11 → 10 counts up: a step is forward when the new A equals the old B and the new B
//! differs from the old A; backward when the new B equals the old A and the new A differs from
//! the old B; an error when both channels changed.

use rust_hdl::prelude::*;

use crate::input_filter::InputFilter;

/// The decoder, with an `N`-bit count.
#[derive(LogicBlock)]
pub struct QuadratureDecoder<const N: usize> {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Channel A pin.
    pub a: Signal<In, Bit>,
    /// Channel B pin.
    pub b: Signal<In, Bit>,
    /// Index pin (tie low when absent).
    pub index: Signal<In, Bit>,
    /// Glitch filter length in clocks.
    pub filter: Signal<In, Bits<16>>,
    /// Synchronous clear of the count, the errors and the index latch.
    pub clear: Signal<In, Bit>,
    /// Position count, two's complement.
    pub count: Signal<Out, Bits<N>>,
    /// Illegal transitions (wraps).
    pub errors: Signal<Out, Bits<16>>,
    /// Count at the last index edge.
    pub index_count: Signal<Out, Bits<N>>,
    /// An index edge was seen since the last clear.
    pub index_seen: Signal<Out, Bit>,
    filter_a: InputFilter,
    filter_b: InputFilter,
    filter_index: InputFilter,
    prev_a: DFF<Bit>,
    prev_b: DFF<Bit>,
    prev_z: DFF<Bit>,
    count_reg: DFF<Bits<N>>,
    errors_reg: DFF<Bits<16>>,
    index_count_reg: DFF<Bits<N>>,
    index_seen_reg: DFF<Bit>,
    count_one: Constant<Bits<N>>,
    count_zero: Constant<Bits<N>>,
    errors_one: Constant<Bits<16>>,
    errors_zero: Constant<Bits<16>>,
}

impl<const N: usize> Default for QuadratureDecoder<N> {
    fn default() -> Self {
        QuadratureDecoder {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            index: Default::default(),
            filter: Default::default(),
            clear: Default::default(),
            count: Default::default(),
            errors: Default::default(),
            index_count: Default::default(),
            index_seen: Default::default(),
            filter_a: InputFilter::new(false),
            filter_b: InputFilter::new(false),
            filter_index: InputFilter::new(false),
            prev_a: Default::default(),
            prev_b: Default::default(),
            prev_z: Default::default(),
            count_reg: Default::default(),
            errors_reg: Default::default(),
            index_count_reg: Default::default(),
            index_seen_reg: Default::default(),
            count_one: Constant::new(1.into()),
            count_zero: Constant::new(0.into()),
            errors_one: Constant::new(1.into()),
            errors_zero: Constant::new(0.into()),
        }
    }
}

impl<const N: usize> Logic for QuadratureDecoder<N> {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, filter_a, filter_b, filter_index);
        dff_setup!(
            self,
            clock,
            prev_a,
            prev_b,
            prev_z,
            count_reg,
            errors_reg,
            index_count_reg,
            index_seen_reg
        );
        self.filter_a.pin.next = self.a.val();
        self.filter_b.pin.next = self.b.val();
        self.filter_index.pin.next = self.index.val();
        self.filter_a.filter.next = self.filter.val();
        self.filter_b.filter.next = self.filter.val();
        self.filter_index.filter.next = self.filter.val();
        self.prev_a.d.next = self.filter_a.level.val();
        self.prev_b.d.next = self.filter_b.level.val();
        self.prev_z.d.next = self.filter_index.level.val();
        if self.clear.val() {
            self.count_reg.d.next = self.count_zero.val();
            self.errors_reg.d.next = self.errors_zero.val();
            self.index_count_reg.d.next = self.count_zero.val();
            self.index_seen_reg.d.next = false;
        } else {
            if (self.filter_a.level.val() == self.prev_b.q.val())
                & (self.filter_b.level.val() != self.prev_a.q.val())
            {
                self.count_reg.d.next = self.count_reg.q.val() + self.count_one.val();
            }
            if (self.filter_b.level.val() == self.prev_a.q.val())
                & (self.filter_a.level.val() != self.prev_b.q.val())
            {
                self.count_reg.d.next = self.count_reg.q.val() - self.count_one.val();
            }
            if (self.filter_a.level.val() != self.prev_a.q.val())
                & (self.filter_b.level.val() != self.prev_b.q.val())
            {
                self.errors_reg.d.next = self.errors_reg.q.val() + self.errors_one.val();
            }
            if self.filter_index.level.val() & !self.prev_z.q.val() {
                self.index_count_reg.d.next = self.count_reg.q.val();
                self.index_seen_reg.d.next = true;
            }
        }
        self.count.next = self.count_reg.q.val();
        self.errors.next = self.errors_reg.q.val();
        self.index_count.next = self.index_count_reg.q.val();
        self.index_seen.next = self.index_seen_reg.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_decoder_is_synthesizable() {
        crate::synth_check::synth_block("quadrature", QuadratureDecoder::<32>::default());
    }
}
