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
        return Bits::<N>::from(v as u64);
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
}
