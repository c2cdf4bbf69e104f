//! The Verilated I/O top (`snapgen_io`), loaded through [`crate::verilated`]: one call runs
//! many clocks with every clock's pins in and every clock's outputs out. Its port tables are the single source of the harness's word
//! layout (`snapgen_layout.h`) and of the Rust encoders and decoders below; its outputs are
//! compared with `snapgen_model::device::Device` on every clock ([`crate::io_cosim`]) and drive
//! the virtual board ([`crate::board`]).

use std::path::Path;

use snapgen_model::device::{IoInputs, IoOutputs};
use snapgen_spec::fields::{Status, STATUS_BITS, STATUS_FIELDS};

use crate::layout::{harness_header, pack, Port, Slot};
use crate::verilated::{abi, VcdWindow, Verilated};
use crate::SimError;

/// The I/O top's port tables, encoders and decoder, from the spec's port list (one slot per
/// port in list order; the status block takes whole words of its own).
macro_rules! io_layout {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        /// The I/O top's inputs, in the harness's word order.
        pub const IO_INPUTS: [Port; [$($(stringify!($i)),*),*].len()] =
            [$($( Port { name: stringify!($i), bits: $ib }, )*)*];

        /// The I/O top's outputs, in the harness's word order (the status block last).
        pub const IO_OUTPUTS: [Port; [$($(stringify!($o)),*),*].len()] =
            [$($( Port { name: stringify!($o), bits: $ob }, )*)*];

        /// A clock's pins in the harness's layout.
        pub fn encode_inputs(i: &IoInputs) -> [u32; IN_WORDS] {
            let mut w = [0u32; IN_WORDS];
            let mut k = 0;
            $($( Packed::pack(i.$i, &IN_SLOTS[k], &mut w); k += 1; )*)*
            debug_assert_eq!(k, IN_SLOTS.len());
            w
        }

        /// A clock's outputs in the harness's layout.
        pub fn encode_outputs(o: &IoOutputs) -> [u32; OUT_WORDS] {
            let mut w = [0u32; OUT_WORDS];
            let mut k = 0;
            $($( Packed::pack(o.$o, &OUT_SLOTS[k], &mut w); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            w
        }

        /// Decodes a clock's output words.
        pub fn decode_outputs(w: &[u32]) -> IoOutputs {
            let mut k = 0;
            $($( let $o = Packed::unpack(&OUT_SLOTS[k], w); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            IoOutputs { $($( $o, )*)* }
        }
    };
}

snapgen_spec::with_io_top_ports!(io_layout! {});

/// A value of an I/O top port in the harness's words: a pin, or the status block (its bytes
/// from the slot's first word up, byte 0 in bits 7:0).
trait Packed: Sized {
    fn pack(self, slot: &Slot, w: &mut [u32]);
    fn unpack(slot: &Slot, w: &[u32]) -> Self;
}

impl Packed for bool {
    fn pack(self, slot: &Slot, w: &mut [u32]) {
        slot.put(w, u128::from(self));
    }
    fn unpack(slot: &Slot, w: &[u32]) -> Self {
        slot.get(w) == 1
    }
}

impl Packed for Status {
    fn pack(self, slot: &Slot, w: &mut [u32]) {
        let mut bytes = [0u8; Status::BYTES];
        self.write_payload(&mut bytes);
        for (k, b) in bytes.into_iter().enumerate() {
            w[slot.word + k / 4] |= u32::from(b) << (8 * (k % 4));
        }
    }
    fn unpack(slot: &Slot, w: &[u32]) -> Self {
        let bytes: Vec<u8> = (0..Status::BYTES)
            .map(|k| (w[slot.word + k / 4] >> (8 * (k % 4))) as u8)
            .collect();
        Status::from_payload(&bytes).expect("the status block's length")
    }
}

const IN_LAYOUT: ([Slot; IO_INPUTS.len()], usize) = pack(&IO_INPUTS);
const OUT_LAYOUT: ([Slot; IO_OUTPUTS.len()], usize) = pack(&IO_OUTPUTS);
/// Where each input is in a clock's input words.
pub const IN_SLOTS: [Slot; IO_INPUTS.len()] = IN_LAYOUT.0;
/// Where each output is in a clock's output words.
pub const OUT_SLOTS: [Slot; IO_OUTPUTS.len()] = OUT_LAYOUT.0;
/// Input words per clock.
pub const IN_WORDS: usize = IN_LAYOUT.1;
/// Output words per clock.
pub const OUT_WORDS: usize = OUT_LAYOUT.1;
/// The status block's port.
const STATUS_PORT: usize = IO_OUTPUTS.len() - 1;
/// Where the status block starts in a clock's output words.
const STATUS_WORD: usize = OUT_SLOTS[STATUS_PORT].word;

const _: () = assert!(IO_OUTPUTS[STATUS_PORT].bits as usize == STATUS_BITS);

/// The harness's generated header (`snapgen_layout.h`).
pub fn io_layout_header() -> String {
    // At rest the UART line idles high (and every other pin is low).
    let idle = IoInputs {
        uart_rx: true,
        ..Default::default()
    };
    harness_header(
        &IO_INPUTS,
        &IO_OUTPUTS,
        abi(IO_TAG, IN_WORDS, OUT_WORDS),
        &encode_inputs(&idle),
    )
}

/// A compared output: a pin, or a field of the status block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoSignal {
    /// One of the one-bit outputs (index into [`IO_OUTPUTS`]).
    Pin(usize),
    /// A field of the status block (index into `STATUS_FIELDS`).
    Status(usize),
}

impl IoSignal {
    /// Every compared signal.
    pub fn all() -> impl Iterator<Item = IoSignal> {
        (0..STATUS_PORT)
            .map(IoSignal::Pin)
            .chain((0..STATUS_FIELDS.len()).map(IoSignal::Status))
    }

    /// Its name (`uart_tx`, …, `status.flags`, …).
    pub fn name(self) -> String {
        match self {
            IoSignal::Pin(k) => IO_OUTPUTS[k].name.to_string(),
            IoSignal::Status(k) => format!("status.{}", STATUS_FIELDS[k].name),
        }
    }

    /// Its width in bits.
    pub fn bits(self) -> u32 {
        match self {
            IoSignal::Pin(_) => 1,
            IoSignal::Status(k) => 8 * STATUS_FIELDS[k].bytes as u32,
        }
    }

    /// Its value in a clock's output words.
    pub fn value(self, w: &[u32]) -> u128 {
        match self {
            IoSignal::Pin(k) => OUT_SLOTS[k].get(w),
            IoSignal::Status(k) => {
                let f = STATUS_FIELDS[k];
                let bytes = status_bytes(w);
                (0..f.bytes).fold(0u128, |v, i| {
                    v | (u128::from(bytes[f.offset + i]) << (8 * i))
                })
            }
        }
    }

    /// The words with this signal's bit `bit` (modulo its width) flipped.
    pub fn flip(self, w: &mut [u32], bit: u32) {
        let bit = bit % self.bits();
        match self {
            IoSignal::Pin(k) => {
                let s = OUT_SLOTS[k];
                s.put(w, s.get(w) ^ 1);
            }
            IoSignal::Status(k) => {
                let at = 8 * STATUS_FIELDS[k].offset as u32 + bit;
                w[STATUS_WORD + (at / 32) as usize] ^= 1 << (at % 32);
            }
        }
    }
}

impl std::str::FromStr for IoSignal {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        IoSignal::all()
            .find(|x| x.name() == s)
            .ok_or_else(|| format!("unknown I/O signal {s:?}"))
    }
}

fn status_bytes(w: &[u32]) -> Vec<u8> {
    (0..STATUS_BITS / 8)
        .map(|k| (w[STATUS_WORD + k / 4] >> (8 * (k % 4))) as u8)
        .collect()
}

/// The first signal whose value differs between the fabric's outputs `got` and the model's
/// `want`: (signal, model's value, fabric's value). Every output bit belongs to a signal
/// (tested), so equal signals mean equal vectors.
pub fn first_difference(got: &[u32], want: &[u32]) -> Option<(IoSignal, u128, u128)> {
    if got == want {
        return None;
    }
    IoSignal::all()
        .find(|s| s.value(got) != s.value(want))
        .map(|s| (s, s.value(want), s.value(got)))
}

/// The I/O top's tag in the harness's ABI word.
const IO_TAG: u32 = 2;

/// One Verilated I/O top.
pub struct FabricIo(Verilated);

impl FabricIo {
    /// Loads `library` and creates one I/O top; with `vcd`, the library must be a trace build.
    pub fn open(library: &Path, vcd: Option<&VcdWindow>) -> Result<Self, SimError> {
        Verilated::open(library, vcd, IO_TAG, IN_WORDS, OUT_WORDS).map(FabricIo)
    }

    /// Runs one clock per entry of `ins`; `outs` receives `OUT_WORDS` words a clock.
    pub fn run(&mut self, ins: &[[u32; IN_WORDS]], outs: &mut Vec<u32>) {
        self.0.run_each(ins.as_flattened(), outs);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_host::protocol::flag;

    #[test]
    fn outputs_round_trip_and_every_bit_is_a_signal() {
        let o = IoOutputs {
            uart_tx: true,
            pwm: false,
            dir: true,
            amplifier: true,
            led_idle: false,
            led_busy: true,
            led_fault: false,
            led_heartbeat: true,
            status: Status {
                state: 5,
                error: 3,
                flags: flag::CUT | flag::AMPLIFIER,
                tick_count: 0xDEAD_BEEF,
                position: -7,
                velocity: 123_456,
                encoder: -99,
                bad_crc: 0x1234,
                bad_frames: 0xFFFF,
                following_peak: 0x8765_4321,
                duty: -1234,
            },
        };
        let w = encode_outputs(&o);
        assert_eq!(decode_outputs(&w), o);
        // A flip of any used bit is seen by exactly one signal.
        for word in 0..OUT_WORDS {
            for bit in 0..32 {
                let mut bad = w;
                bad[word] ^= 1 << bit;
                let seen: Vec<IoSignal> = IoSignal::all()
                    .filter(|s| s.value(&bad) != s.value(&w))
                    .collect();
                let used = OUT_SLOTS.iter().any(|s| s.covers(word, bit));
                assert_eq!(seen.len(), usize::from(used), "word {word} bit {bit}");
            }
        }
        // flip() flips what value() reads.
        for s in IoSignal::all() {
            let mut bad = w;
            s.flip(&mut bad, 3);
            assert_ne!(s.value(&bad), s.value(&w), "{}", s.name());
        }
    }
}
