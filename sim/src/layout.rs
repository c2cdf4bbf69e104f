//! Word layouts between the Rust side of a co-simulation and its C++ harness: one table of a
//! design's ports (name, width) is the single source of the harness's C++ (generated into the
//! build as `snapgen_layout.h`), the wrapper's Verilog ports and the Rust encoders and
//! decoders.
//!
//! Ports wider than 32 bits take whole 32-bit words of their own (low word first); narrower
//! ones are packed, in table order, into shared words from bit 0 up. [`Slot::get`] and
//! [`Slot::put`] handle ports of up to 128 bits; wider ones are read word by word.

/// A port of the design under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Port {
    /// Its Verilog name (and the Verilated C++ member's).
    pub name: &'static str,
    /// Its width.
    pub bits: u32,
}

/// A model port value as a port's raw bits and back (`bits`: the port's width; signed values
/// are two's complement and sign-extended when read).
pub trait PortValue: Copy {
    /// The raw bits (the slot keeps the port's width of them).
    fn to_word(self) -> u128;
    /// From a port's raw bits.
    fn from_word(v: u128, bits: u32) -> Self;
    /// Writes the value into its slot of `w` (a port wider than 128 bits writes its words
    /// itself).
    #[inline(always)]
    fn put_into(self, slot: &Slot, w: &mut [u32]) {
        slot.put(w, self.to_word());
    }
}

/// The status block (240 bits): its bytes from the slot's first word up, byte 0 in bits 7:0.
/// `to_word`/`from_word` carry its first 16 bytes only; [`PortValue::put_into`] writes it
/// whole, and [`first_difference`] compares a wide port word by word.
impl PortValue for snapgen_spec::Status {
    fn to_word(self) -> u128 {
        let mut bytes = [0u8; 16];
        let mut all = [0u8; snapgen_spec::Status::BYTES];
        self.write_payload(&mut all);
        bytes.copy_from_slice(&all[..16]);
        u128::from_le_bytes(bytes)
    }
    fn from_word(v: u128, _: u32) -> Self {
        let mut all = [0u8; snapgen_spec::Status::BYTES];
        all[..16].copy_from_slice(&v.to_le_bytes());
        snapgen_spec::Status::from_payload(&all).expect("the status block's length")
    }
    fn put_into(self, slot: &Slot, w: &mut [u32]) {
        let mut bytes = [0u8; snapgen_spec::Status::BYTES];
        self.write_payload(&mut bytes);
        for (k, b) in bytes.into_iter().enumerate() {
            let word = slot.word + k / 4;
            let shift = 8 * (k % 4);
            w[word] = (w[word] & !(0xFF << shift)) | (u32::from(b) << shift);
        }
    }
}

impl PortValue for bool {
    #[inline(always)]
    fn to_word(self) -> u128 {
        u128::from(self)
    }
    #[inline(always)]
    fn from_word(v: u128, _: u32) -> Self {
        v & 1 == 1
    }
}

macro_rules! unsigned_port_value {
    ($($t:ty),*) => {$(
        impl PortValue for $t {
            #[inline(always)]
            fn to_word(self) -> u128 {
                self as u128
            }
            #[inline(always)]
            fn from_word(v: u128, _: u32) -> Self {
                v as $t
            }
        }
    )*};
}

unsigned_port_value!(u8, u16, u32, u64, u128);

impl PortValue for i128 {
    #[inline(always)]
    fn to_word(self) -> u128 {
        self as u128
    }
    #[inline(always)]
    fn from_word(v: u128, bits: u32) -> Self {
        snapgen_model::chain::wrap(v as i128, bits)
    }
}

/// Where a port's bits are in the word array.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Slot {
    /// First word.
    pub word: usize,
    /// Bit offset within it (0 for wide ports).
    pub shift: u32,
    /// Width.
    pub bits: u32,
}

impl Slot {
    /// Mask of a narrow port within its word (shifted down).
    pub const fn mask(&self) -> u32 {
        if self.bits >= 32 {
            u32::MAX
        } else {
            (1 << self.bits) - 1
        }
    }

    /// Words it takes.
    pub const fn words(&self) -> usize {
        if self.bits > 32 {
            self.bits.div_ceil(32) as usize
        } else {
            1
        }
    }

    /// True when bit `bit` of word `word` is one of its bits.
    pub const fn covers(&self, word: usize, bit: u32) -> bool {
        if word < self.word || word >= self.word + self.words() {
            return false;
        }
        let index = (word - self.word) as u32 * 32 + bit;
        index >= self.shift && index < self.shift + self.bits
    }

    /// Its value in `w` (ports of at most 128 bits).
    #[inline(always)]
    pub fn get(&self, w: &[u32]) -> u128 {
        debug_assert!(self.bits <= 128, "get: a port wider than 128 bits");
        if self.bits <= 32 {
            u128::from((w[self.word] >> self.shift) & self.mask())
        } else {
            let mut v = 0u128;
            for k in 0..self.words() {
                v |= u128::from(w[self.word + k]) << (32 * k);
            }
            v & (u128::MAX >> (128 - self.bits))
        }
    }

    /// Flips bit `bit` (modulo its width) of the port in `w` (any width).
    pub fn flip(&self, w: &mut [u32], bit: u32) {
        let at = self.shift + bit % self.bits;
        w[self.word + (at / 32) as usize] ^= 1 << (at % 32);
    }

    /// The words of a wide port (more than 32 bits), in `w`.
    pub fn words_in<'a>(&self, w: &'a [u32]) -> &'a [u32] {
        &w[self.word..self.word + self.words()]
    }

    /// Writes `v` (its low `bits` bits) into `w` (ports of at most 128 bits).
    #[inline(always)]
    pub fn put(&self, w: &mut [u32], v: u128) {
        debug_assert!(self.bits <= 128, "put: a port wider than 128 bits");
        if self.bits <= 32 {
            let m = self.mask() << self.shift;
            w[self.word] = (w[self.word] & !m) | (((v as u32) << self.shift) & m);
        } else {
            let v = v & (u128::MAX >> (128 - self.bits));
            for k in 0..self.words() {
                w[self.word + k] = (v >> (32 * k)) as u32;
            }
        }
    }
}

/// A deliberate one-bit error in a block's outputs (a test hook of every lockstep), to show
/// that a difference is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortFault {
    /// The clock.
    pub clock: u64,
    /// The output port (an index into the block's output table).
    pub port: usize,
    /// The bit (modulo the port's width).
    pub bit: u32,
}

impl PortFault {
    /// Flips its bit in `got`, a batch of clocks of `slots.len()` ports' output words
    /// (`words` a clock) beginning at clock `first`, when its clock is in the batch.
    pub fn apply(&self, slots: &[Slot], words: usize, first: u64, got: &mut [u32]) {
        let clocks = (got.len() / words) as u64;
        if self.clock >= first && self.clock < first + clocks {
            let at = (self.clock - first) as usize * words;
            slots[self.port % slots.len()].flip(&mut got[at..at + words], self.bit);
        }
    }
}

/// The first output that differs between a fabric and its model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PortMismatch {
    /// Clock (from 0).
    pub clock: u64,
    /// The output port.
    pub port: &'static str,
    /// The model's bits (of a port wider than 128 bits, its first differing 32-bit word).
    pub expected: u128,
    /// The fabric's bits (likewise).
    pub actual: u128,
}

impl std::fmt::Display for PortMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "first mismatch at clock {}: {} expected {:#x} got {:#x}",
            self.clock, self.port, self.expected, self.actual
        )
    }
}

/// The first clock and port where a batch of the fabric's output words (`got`) differs from
/// the model's (`want`): clocks of `words` words beginning at clock `first`, the ports of
/// `ports` at `slots` (ports of at most 128 bits).
pub fn first_difference(
    ports: &[Port],
    slots: &[Slot],
    words: usize,
    first: u64,
    got: &[u32],
    want: &[u32],
) -> Option<PortMismatch> {
    got.chunks(words)
        .zip(want.chunks(words))
        .enumerate()
        .find_map(|(c, (g, w))| {
            ports.iter().zip(slots).find_map(|(p, s)| {
                if s.bits > 128 {
                    // A wide port: its first differing word.
                    let (g, w) = (s.words_in(g), s.words_in(w));
                    let k = g.iter().zip(w).position(|(a, b)| a != b)?;
                    return Some(PortMismatch {
                        clock: first + c as u64,
                        port: p.name,
                        expected: u128::from(w[k]),
                        actual: u128::from(g[k]),
                    });
                }
                let (actual, expected) = (s.get(g), s.get(w));
                (actual != expected).then_some(PortMismatch {
                    clock: first + c as u64,
                    port: p.name,
                    expected,
                    actual,
                })
            })
        })
}

/// Where port `k` of `ports` goes, and the words used up to and including it.
const fn place(ports: &[Port], k: usize) -> (Slot, usize) {
    let mut word = 0;
    let mut used = 0; // bits used in `word` by narrow ports
    let mut i = 0;
    let mut slot = Slot {
        word: 0,
        shift: 0,
        bits: 0,
    };
    while i <= k {
        let bits = ports[i].bits;
        assert!(bits >= 1, "a port has at least one bit");
        if bits > 32 {
            if used > 0 {
                word += 1;
                used = 0;
            }
            slot = Slot {
                word,
                shift: 0,
                bits,
            };
            word += bits.div_ceil(32) as usize;
        } else {
            if used + bits > 32 {
                word += 1;
                used = 0;
            }
            slot = Slot {
                word,
                shift: used,
                bits,
            };
            used += bits;
        }
        i += 1;
    }
    (slot, word + if used > 0 { 1 } else { 0 })
}

/// The slots of `ports` and the number of words they take.
pub const fn pack<const N: usize>(ports: &[Port; N]) -> ([Slot; N], usize) {
    let mut slots = [Slot {
        word: 0,
        shift: 0,
        bits: 0,
    }; N];
    let mut k = 0;
    while k < N {
        slots[k] = place(ports, k).0;
        k += 1;
    }
    (slots, if N == 0 { 0 } else { place(ports, N - 1).1 })
}

/// A block's port tables, word layouts and encoders from one of the spec's port lists (called
/// through its `with_*_ports!` macro): the tables `$ins` and `$outs` (the harness's word
/// order), `IN_SLOTS`, `OUT_SLOTS`, `IN_WORDS`, `OUT_WORDS`, and `encode_inputs` and
/// `encode_outputs` for the model's port structs `$ity` and `$oty` (one `put` per port with a
/// constant slot: straight-line code).
macro_rules! port_layout {
    (
        $ins:ident, $outs:ident, $ity:ty, $oty:ty;
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        /// The block's inputs, in the harness's word order.
        pub const $ins: [$crate::layout::Port; [$($(stringify!($i)),*),*].len()] =
            [$($( $crate::layout::Port { name: stringify!($i), bits: $ib }, )*)*];

        /// The block's outputs, in the harness's word order.
        pub const $outs: [$crate::layout::Port; [$($(stringify!($o)),*),*].len()] =
            [$($( $crate::layout::Port { name: stringify!($o), bits: $ob }, )*)*];

        const IN_LAYOUT: ([$crate::layout::Slot; $ins.len()], usize) = $crate::layout::pack(&$ins);
        const OUT_LAYOUT: ([$crate::layout::Slot; $outs.len()], usize) = $crate::layout::pack(&$outs);
        /// Where each input is in a clock's input words.
        pub const IN_SLOTS: [$crate::layout::Slot; $ins.len()] = IN_LAYOUT.0;
        /// Where each output is in a clock's output words.
        pub const OUT_SLOTS: [$crate::layout::Slot; $outs.len()] = OUT_LAYOUT.0;
        /// Input words per clock.
        pub const IN_WORDS: usize = IN_LAYOUT.1;
        /// Output words per clock.
        pub const OUT_WORDS: usize = OUT_LAYOUT.1;

        /// A clock's inputs in the harness's word layout.
        #[inline(always)]
        pub fn encode_inputs(i: &$ity) -> [u32; IN_WORDS] {
            let mut w = [0u32; IN_WORDS];
            let mut k = 0;
            $($( $crate::layout::PortValue::put_into(i.$i, &IN_SLOTS[k], &mut w); k += 1; )*)*
            debug_assert_eq!(k, IN_SLOTS.len());
            w
        }

        /// A clock's outputs in the harness's word layout: what the co-simulation compares the
        /// fabric's words with, on every clock.
        #[inline(always)]
        pub fn encode_outputs(o: &$oty) -> [u32; OUT_WORDS] {
            let mut w = [0u32; OUT_WORDS];
            let mut k = 0;
            $($( $crate::layout::PortValue::put_into(o.$o, &OUT_SLOTS[k], &mut w); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            w
        }
    };
}
pub(crate) use port_layout;

/// The C++ type Verilator gives a port of `bits` bits is a wide array (more than 64 bits).
fn wide(bits: u32) -> bool {
    bits > 64
}

/// The harness header: `SNAPGEN_IN_WORDS`, `SNAPGEN_OUT_WORDS`, `snapgen_set(top, in)` (inputs
/// from words) and `snapgen_get(top, out)` (outputs into words), for the Verilated model
/// class `Vtop`.
pub fn harness_header(inputs: &[Port], outputs: &[Port], abi: u32, idle: &[u32]) -> String {
    let pack_dyn = |ports: &[Port]| -> (Vec<Slot>, usize) {
        let slots = (0..ports.len()).map(|k| place(ports, k).0).collect();
        (
            slots,
            ports.len().checked_sub(1).map_or(0, |k| place(ports, k).1),
        )
    };
    let (ins, in_words) = pack_dyn(inputs);
    let (outs, out_words) = pack_dyn(outputs);
    let mut s = String::from(
        "// Generated by snapgen-sim from its port tables (sim/src/layout.rs). Do not edit.\n\
         #pragma once\n#include <cstdint>\n",
    );
    assert_eq!(
        idle.len(),
        in_words,
        "the idle inputs are one clock's words"
    );
    let idle: Vec<String> = idle.iter().map(|w| format!("0x{w:x}u")).collect();
    s.push_str(&format!(
        "#define SNAPGEN_IN_WORDS {in_words}\n#define SNAPGEN_OUT_WORDS {out_words}\n\
         #define SNAPGEN_ABI 0x{abi:x}u\n\
         static const uint32_t SNAPGEN_IDLE[SNAPGEN_IN_WORDS] = {{{}}};\n\n",
        idle.join(", ")
    ));
    s.push_str("static inline void snapgen_set(Vtop* t, const uint32_t* in) {\n");
    for (p, sl) in inputs.iter().zip(&ins) {
        let w = sl.word;
        if wide(p.bits) {
            for k in 0..sl.words() {
                s.push_str(&format!("    t->{}[{k}] = in[{}];\n", p.name, w + k));
            }
        } else if p.bits > 32 {
            s.push_str(&format!(
                "    t->{} = (uint64_t)in[{w}] | ((uint64_t)in[{}] << 32);\n",
                p.name,
                w + 1
            ));
        } else {
            s.push_str(&format!(
                "    t->{} = (in[{w}] >> {}) & 0x{:x}u;\n",
                p.name,
                sl.shift,
                sl.mask()
            ));
        }
    }
    s.push_str("}\n\nstatic inline void snapgen_get(const Vtop* t, uint32_t* out) {\n");
    let mut narrow: Vec<Vec<String>> = vec![Vec::new(); out_words];
    for (p, sl) in outputs.iter().zip(&outs) {
        let w = sl.word;
        if wide(p.bits) {
            for k in 0..sl.words() {
                s.push_str(&format!("    out[{}] = t->{}[{k}];\n", w + k, p.name));
            }
        } else if p.bits > 32 {
            s.push_str(&format!("    out[{w}] = (uint32_t)t->{};\n", p.name));
            s.push_str(&format!(
                "    out[{}] = (uint32_t)(t->{} >> 32);\n",
                w + 1,
                p.name
            ));
        } else {
            narrow[w].push(format!("((uint32_t)t->{} << {})", p.name, sl.shift));
        }
    }
    for (w, terms) in narrow.iter().enumerate() {
        if !terms.is_empty() {
            s.push_str(&format!("    out[{w}] = {};\n", terms.join(" | ")));
        }
    }
    s.push_str("}\n");
    s
}

/// The slot of the port called `name` among `ports` at `slots` (a block's own table: a name
/// it lacks is a bug of the caller's).
pub fn slot_named(ports: &[Port], slots: &[Slot], name: &str) -> Slot {
    ports
        .iter()
        .position(|p| p.name == name)
        .map(|k| slots[k])
        .unwrap_or_else(|| panic!("the block has no output {name}"))
}

/// A lockstep's batch: each clock's input words and the model's output words gathered, then
/// run on the fabric in one call and compared (the lockstep of every block but the core's).
pub struct Batch {
    ports: &'static [Port],
    slots: &'static [Slot],
    words: usize,
    fault: Option<PortFault>,
    /// The clock of the batch's first (from 0).
    pub first: u64,
    ins: Vec<u32>,
    want: Vec<u32>,
    got: Vec<u32>,
}

impl Batch {
    /// An empty batch for the block whose outputs are `ports` at `slots`, `words` words a
    /// clock, with the test hook `fault` applied to the fabric's words.
    pub fn new(
        ports: &'static [Port],
        slots: &'static [Slot],
        words: usize,
        fault: Option<PortFault>,
    ) -> Self {
        Batch {
            ports,
            slots,
            words,
            fault,
            first: 0,
            ins: Vec::new(),
            want: Vec::new(),
            got: Vec::new(),
        }
    }

    /// Adds a clock: its input words and the model's output words after it.
    pub fn push(&mut self, ins: &[u32], want: &[u32]) {
        self.ins.extend_from_slice(ins);
        self.want.extend_from_slice(want);
    }

    /// Clocks gathered.
    pub fn len(&self) -> usize {
        self.want.len() / self.words
    }

    /// No clock gathered.
    pub fn is_empty(&self) -> bool {
        self.want.is_empty()
    }

    /// Runs the gathered clocks on `fabric` and compares them: the first difference, if
    /// any. The fabric's words stay readable ([`Batch::got`]) until [`Batch::next`].
    pub fn run(&mut self, fabric: &mut crate::verilated::Verilated) -> Option<PortMismatch> {
        fabric.run_each(&self.ins, &mut self.got);
        if let Some(f) = self.fault {
            f.apply(self.slots, self.words, self.first, &mut self.got);
        }
        if self.got == self.want {
            return None;
        }
        first_difference(
            self.ports, self.slots, self.words, self.first, &self.got, &self.want,
        )
    }

    /// The fabric's words of the batch just run, a clock at a time.
    pub fn got(&self) -> std::slice::ChunksExact<'_, u32> {
        self.got.chunks_exact(self.words)
    }

    /// Begins the next batch after this one.
    pub fn next(&mut self) {
        self.first += self.len() as u64;
        self.ins.clear();
        self.want.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PORTS: [Port; 5] = [
        Port { name: "a", bits: 1 },
        Port {
            name: "b",
            bits: 104,
        },
        Port {
            name: "c",
            bits: 20,
        },
        Port {
            name: "d",
            bits: 20,
        },
        Port {
            name: "e",
            bits: 64,
        },
    ];

    #[test]
    fn packing_by_hand() {
        let (s, n) = pack(&PORTS);
        assert_eq!(
            s[0],
            Slot {
                word: 0,
                shift: 0,
                bits: 1
            }
        );
        assert_eq!(
            s[1],
            Slot {
                word: 1,
                shift: 0,
                bits: 104
            }
        );
        assert_eq!(
            s[2],
            Slot {
                word: 5,
                shift: 0,
                bits: 20
            }
        );
        assert_eq!(
            s[3],
            Slot {
                word: 6,
                shift: 0,
                bits: 20
            }
        );
        assert_eq!(
            s[4],
            Slot {
                word: 7,
                shift: 0,
                bits: 64
            }
        );
        assert_eq!(n, 9);
        let h = harness_header(&PORTS, &PORTS, 0x1_0909, &[0, 0, 0, 0, 0, 0, 0, 0, 7]);
        assert!(h.contains("#define SNAPGEN_IN_WORDS 9"));
        assert!(h.contains("#define SNAPGEN_ABI 0x10909u"));
        assert!(h.contains("SNAPGEN_IDLE[SNAPGEN_IN_WORDS] = {0x0u, 0x0u, 0x0u, 0x0u, 0x0u, 0x0u, 0x0u, 0x0u, 0x7u};"));
        assert!(h.contains("t->b[3] = in[4];"));
        assert!(h.contains("t->e = (uint64_t)in[7] | ((uint64_t)in[8] << 32);"));
        assert!(h.contains("out[0] = ((uint32_t)t->a << 0);"));
    }

    #[test]
    fn put_then_get() {
        let (s, n) = pack(&PORTS);
        let mut w = vec![0u32; n];
        let vals = [
            1u128,
            (1 << 103) | 12345,
            0xabcde,
            0x12345,
            u128::from(u64::MAX - 7),
        ];
        for (sl, v) in s.iter().zip(vals) {
            sl.put(&mut w, v);
        }
        for (sl, v) in s.iter().zip(vals) {
            assert_eq!(sl.get(&w), v);
        }
    }
}
