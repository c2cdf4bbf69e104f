//! What the lockstep compares and reports: the core's output registers (the spec's port
//! list, in the harness's word layout), a deliberate fault to prove a comparison fails, and
//! the first difference found.

use crate::fabric::{CORE_OUTPUTS, OUTPUT_BITS, OUT_SLOTS};
use snapgen_model::CoreOutputs;

/// A compared output: an index into [`CORE_OUTPUTS`] (the spec's port list), which gives its
/// name and width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Register(usize);

impl Register {
    /// Every register, in comparison order.
    pub fn all() -> impl Iterator<Item = Register> {
        (0..CORE_OUTPUTS.len()).map(Register)
    }

    /// The register called `name` (its Verilog port).
    pub fn named(name: &str) -> Option<Register> {
        CORE_OUTPUTS
            .iter()
            .position(|p| p.name == name)
            .map(Register)
    }

    /// Its name (as the Verilog port).
    pub fn name(self) -> &'static str {
        CORE_OUTPUTS[self.0].name
    }

    /// Its width in bits.
    pub fn bits(self) -> u32 {
        CORE_OUTPUTS[self.0].bits
    }

    /// Its raw bits in `o`, as an unsigned pattern of its width.
    #[inline(always)]
    pub fn bits_of(self, o: &CoreOutputs) -> u128 {
        OUTPUT_BITS[self.0](o) & (u128::MAX >> (128 - self.bits()))
    }

    /// Its bits in a clock's output words.
    pub fn bits_in(self, words: &[u32]) -> u128 {
        OUT_SLOTS[self.0].get(words)
    }

    /// Flips bit `bit` (modulo its width) of this register in a clock's output words.
    pub fn flip(self, words: &mut [u32], bit: u32) {
        OUT_SLOTS[self.0].flip(words, bit);
    }
}

impl std::str::FromStr for Register {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Register::named(s).ok_or_else(|| {
            let names: Vec<&str> = CORE_OUTPUTS.iter().map(|p| p.name).collect();
            format!("unknown register {s:?} (one of {})", names.join(", "))
        })
    }
}

/// A deliberate one-bit error in the captured fabric stream, to prove the comparison fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    /// Clock at which to flip.
    pub clock: u64,
    /// Register to flip.
    pub register: Register,
    /// Bit to flip.
    pub bit: u32,
}

/// The first difference between fabric and model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// Parallel session that found it (each session is its own core and move stream).
    pub session: usize,
    /// Clock (rising edges since power-up of that session's core, from 0).
    pub clock: u64,
    /// Move being played (0-based).
    pub move_index: usize,
    /// Register that differs.
    pub register: Register,
    /// Model's bits.
    pub expected: u128,
    /// Fabric's bits.
    pub actual: u128,
    /// Width of the register.
    pub bits: u32,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let digits = self.bits.div_ceil(4) as usize;
        write!(
            f,
            "first mismatch in session {} at clock {} (move {}): register {} expected {:#0w$x} got {:#0w$x} (differing bits {:#x})",
            self.session,
            self.clock,
            self.move_index,
            self.register.name(),
            self.expected,
            self.actual,
            self.expected ^ self.actual,
            w = digits + 2
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabric::{decode, encode_outputs, OUT_WORDS};

    /// Outputs with every port's bits drawn from `seed` (random words, decoded).
    fn outputs(seed: u64) -> CoreOutputs {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let words: Vec<u32> = (0..OUT_WORDS).map(|_| rng.gen()).collect();
        decode(&words)
    }

    /// A flip of any bit a register occupies is found in a register, and only those: the
    /// lockstep compares whole words, then names the register that differs.
    #[test]
    fn the_comparison_sees_every_bit_of_every_word() {
        for seed in 0..64 {
            let m = outputs(seed);
            let words = encode_outputs(&m);
            assert_eq!(decode(&words), m, "layout round trip, seed {seed}");
            for k in 0..OUT_WORDS {
                for bit in 0..32 {
                    let mut bad = words;
                    bad[k] ^= 1 << bit;
                    let found = Register::all().any(|r| r.bits_of(&m) != r.bits_in(&bad));
                    let used = OUT_SLOTS.iter().any(|s| s.covers(k, bit));
                    assert_eq!(found, used, "word {k} bit {bit}, seed {seed}");
                }
            }
        }
    }
}
