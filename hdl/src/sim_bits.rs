//! Conversions between rust-hdl's `Bits<N>` and Rust integers, for the blocks that write their
//! own Verilog and run their model in rust-hdl's simulator (`Bits<N>` wider than 64 bits has
//! no integer conversion of its own).

use rust_hdl::prelude::*;

/// The unsigned value of the low 128 bits of `b`.
pub fn to_u128<const N: usize>(b: Bits<N>) -> u128 {
    if N <= 64 {
        return u128::from(b.to_u64());
    }
    (0..N.min(128)).fold(0u128, |v, k| v | (u128::from(b.get_bit(k)) << k))
}

/// The two's-complement value of `b`, sign-extended (N ≤ 128).
pub fn to_i128<const N: usize>(b: Bits<N>) -> i128 {
    let s = 128 - N as u32;
    ((to_u128(b) as i128) << s) >> s
}

/// The low N bits of `v` (zero-extended past 128).
pub fn from_u128<const N: usize>(v: u128) -> Bits<N> {
    if N <= 64 {
        // (rust-hdl panics on a value wider than the vector: its low N bits.)
        let mask = if N == 64 { u64::MAX } else { (1u64 << N) - 1 };
        return Bits::<N>::from(v as u64 & mask);
    }
    (0..N.min(128)).fold(Bits::<N>::default(), |b, k| {
        if (v >> k) & 1 == 1 {
            b.replace_bit(k, true)
        } else {
            b
        }
    })
}

/// The low N bits of a two's-complement value.
pub fn from_i128<const N: usize>(v: i128) -> Bits<N> {
    from_u128(v as u128)
}

/// An input port's value as the model's port type (the spec's Rust type of the port).
pub trait Sample<T> {
    /// The value on the port.
    fn sample(&self) -> T;
}

/// A model's output value onto an output port.
pub trait Drive<T> {
    /// Drives the port with `v` (its low bits).
    fn drive(&mut self, v: T);
}

impl Sample<bool> for Signal<In, Bit> {
    fn sample(&self) -> bool {
        self.val()
    }
}

impl Drive<bool> for Signal<Out, Bit> {
    fn drive(&mut self, v: bool) {
        self.next = v;
    }
}

macro_rules! unsigned_ports {
    ($($t:ty),*) => {$(
        impl<const N: usize> Sample<$t> for Signal<In, Bits<N>> {
            fn sample(&self) -> $t {
                to_u128(self.val()) as $t
            }
        }
        impl<const N: usize> Drive<$t> for Signal<Out, Bits<N>> {
            fn drive(&mut self, v: $t) {
                self.next = from_u128(v as u128);
            }
        }
    )*};
}

unsigned_ports!(u8, u16, u32, u64, u128);

impl<const N: usize> Sample<i128> for Signal<In, Bits<N>> {
    fn sample(&self) -> i128 {
        to_i128(self.val())
    }
}

impl<const N: usize> Drive<i128> for Signal<Out, Bits<N>> {
    fn drive(&mut self, v: i128) {
        self.next = from_i128(v);
    }
}

impl<const N: usize> Drive<snapgen_spec::Status> for Signal<Out, Bits<N>> {
    fn drive(&mut self, v: snapgen_spec::Status) {
        // The status block's bytes, byte 0 in bits 7:0.
        let mut bytes = [0u8; snapgen_spec::Status::BYTES];
        v.write_payload(&mut bytes);
        self.next = bytes
            .iter()
            .enumerate()
            .fold(Bits::<N>::default(), |b, (k, &byte)| {
                (0..8).fold(b, |b, i| b.replace_bit(8 * k + i, (byte >> i) & 1 == 1))
            });
    }
}

/// For a block that writes its own Verilog and runs its model (its field `_sim`) in rust-hdl's
/// simulator, from the spec's port list (called through its `with_*_ports!` macro): its
/// `Logic`, whose `update` clocks the model with every input port (into the model's input
/// struct `$ins`) and drives every output port from its outputs (`$outs`), and whose `hdl` is
/// the Verilog body `$body` makes of the block, so that no port is copied by hand.
macro_rules! model_ports {
    (
        $block:ident, $ins:ident, $outs:ident, $body:expr;
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        impl $block {
            /// The model's inputs: every input port's value.
            fn model_inputs(&self) -> $ins {
                $ins {
                    $($( $i: $crate::sim_bits::Sample::<$it>::sample(&self.$i), )*)*
                }
            }

            /// Every output port driven from the model's outputs `o`.
            fn drive_outputs(&mut self, o: &$outs) {
                $($( $crate::sim_bits::Drive::<$ot>::drive(&mut self.$o, o.$o); )*)*
            }

        }

        impl Logic for $block {
            fn update(&mut self) {
                if self.clock.pos_edge() {
                    let i = self.model_inputs();
                    self._sim.clock(&i);
                }
                let o = self._sim.outputs();
                self.drive_outputs(&o);
            }

            fn connect(&mut self) {
                $($( self.$o.connect(); )*)*
            }

            fn hdl(&self) -> Verilog {
                let body: fn(&$block) -> String = $body;
                Verilog::Custom(body(self))
            }
        }
    };
}
pub(crate) use model_ports;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips() {
        for v in [
            0i128,
            1,
            -1,
            5,
            -(1 << 103),
            (1 << 103) - 1,
            12_345_678_901_234,
        ] {
            assert_eq!(to_i128(from_i128::<104>(v)), v);
        }
        assert_eq!(to_u128(from_u128::<16>(0xBEEF)), 0xBEEF);
        assert_eq!(to_i128(from_u128::<8>(0xFF)), -1);
        assert_eq!(to_u128(from_u128::<144>(u128::MAX)), u128::MAX);
        assert!(!from_u128::<144>(u128::MAX).get_bit(130));
    }

    #[test]
    fn a_port_samples_and_drives_the_models_types() {
        // An output driven with a model's value reads back the same through an input of
        // that width (two's complement wraps to the port, as in the fabric).
        fn through<const N: usize, T: Copy>(v: T) -> T
        where
            Signal<Out, Bits<N>>: Drive<T>,
            Signal<In, Bits<N>>: Sample<T>,
        {
            let mut out = Signal::<Out, Bits<N>>::default();
            out.drive(v);
            let mut inp = Signal::<In, Bits<N>>::default();
            inp.next = out.next;
            inp.update_all();
            inp.sample()
        }
        assert_eq!(through::<112, i128>(-(1 << 100) - 3), -(1 << 100) - 3);
        assert_eq!(through::<128, i128>(i128::MIN + 7), i128::MIN + 7);
        assert_eq!(through::<128, u128>(u128::MAX - 5), u128::MAX - 5);
        assert_eq!(through::<64, u64>(u64::MAX), u64::MAX);
        assert_eq!(through::<3, u8>(0b1101), 0b101, "the port's width");
        assert_eq!(through::<16, u16>(0xBEEF), 0xBEEF);
        let mut bit = Signal::<Out, Bit>::default();
        bit.drive(true);
        assert!(bit.next);
    }
}
