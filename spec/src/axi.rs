//! The AXI4-Lite register map of `snapgen_axi` (issue 23): the same command executor as the
//! UART, behind memory-mapped registers (one behaviour, two transports).
//!
//! A host writes a command frame (docs/PROTOCOL.md: start byte, header, payload, CRC) one byte
//! at a time to [`COMMAND`](REGISTERS) and reads its reply one byte at a time from `REPLY`;
//! the station executes it exactly as a frame from the UART. Besides the command stream the map
//! gives what a host polls without a frame: `SNAPSHOT` latches, on the clock of its write, the
//! status block and the chain's registers (x, v, a, j and the absolute tick) into
//! `STATUS`/`TICKS`/`X`/`V`/`A`/`J`, so that a read of several words is one moment; and an
//! interrupt on a program's end, a fault, a swap and a waiting reply.
//!
//! Every register is one or more 32-bit words at consecutive offsets, in table order;
//! [`offset`] derives each offset. The Verilog slave, the model, the host's UIO link, the C
//! header, the JSON description and the docs all read this table.

use crate::codes::flag;
use crate::fields::{field, STATUS_BITS, STATUS_FIELDS};
use crate::widths::{A_BITS, J_BITS, TIME_BITS, V_BITS, X_BITS};

/// Address bits of the slave (bytes): a 256-byte window.
pub const ADDR_BITS: u32 = 8;
/// The `ID` register's value: "snap" in ASCII, first letter in the top byte.
pub const ID_MAGIC: u32 = 0x736E_6170;
/// The register map's version (the `VERSION` register's low 16 bits; its high 16 bits are the
/// protocol's version).
pub const MAP_VERSION: u32 = 1;
/// The AXI response codes the slave gives.
pub const RESP_OKAY: u8 = 0;
/// Slave error: no such register, or the wrong direction (a write to a read-only register,
/// a read of a write-only one). Nothing is changed.
pub const RESP_SLVERR: u8 = 2;

/// How software may use a register.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// Read only (a write answers SLVERR and changes nothing).
    ReadOnly,
    /// Write only (a read answers SLVERR and data 0).
    WriteOnly,
    /// Read and write.
    ReadWrite,
    /// Read; writing 1 to a bit clears it.
    WriteOneToClear,
    /// Read only; a read takes what it returns (a FIFO's head).
    ReadTakes,
}

impl Access {
    /// As the docs and the C header write it.
    pub const fn name(self) -> &'static str {
        match self {
            Access::ReadOnly => "RO",
            Access::WriteOnly => "WO",
            Access::ReadWrite => "RW",
            Access::WriteOneToClear => "RW1C",
            Access::ReadTakes => "RO (read takes)",
        }
    }

    /// A read is answered with data.
    pub const fn readable(self) -> bool {
        !matches!(self, Access::WriteOnly)
    }

    /// A write is accepted.
    pub const fn writable(self) -> bool {
        matches!(
            self,
            Access::WriteOnly | Access::ReadWrite | Access::WriteOneToClear
        )
    }
}

/// A field of a register: bits `lsb .. lsb + bits`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BitField {
    /// Name (upper case).
    pub name: &'static str,
    /// Lowest bit.
    pub lsb: u32,
    /// Width.
    pub bits: u32,
    /// Meaning.
    pub doc: &'static str,
}

/// One register: `words` consecutive 32-bit words (the first at [`offset`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Register {
    /// Name (upper case).
    pub name: &'static str,
    /// 32-bit words (word `k` at offset + 4k holds bits `32k ..` of the value).
    pub words: u32,
    /// Access.
    pub access: Access,
    /// Value after reset (every word).
    pub reset: u32,
    /// Fields (empty: the whole word or value).
    pub fields: &'static [BitField],
    /// Meaning.
    pub doc: &'static str,
    /// What `SNAPSHOT` latches into it, if anything.
    pub snap: Option<Snap>,
}

/// A value `SNAPSHOT` latches: the station's output port of that name, widened to whole words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Snap {
    /// The station's output port (`snapgen_spec::ports::STATION`).
    pub port: &'static str,
    /// Two's complement: widened by sign extension (otherwise by zeros).
    pub signed: bool,
}

/// The interrupt causes: bits of `IRQ_STATUS` and `IRQ_ENABLE`.
pub const IRQ_FIELDS: [BitField; 4] = [
    BitField {
        name: "DONE",
        lsb: 0,
        bits: 1,
        doc: "the flag DONE rose: a program ran to its end (latched; write 1 to clear)",
    },
    BitField {
        name: "FAULT",
        lsb: 1,
        bits: 1,
        doc: "the axis entered ErrorStop (latched; write 1 to clear)",
    },
    BitField {
        name: "SWAP",
        lsb: 2,
        bits: 1,
        doc: "the flag SWAP_PENDING fell: an armed swap took place or was dropped by a stop (latched; write 1 to clear)",
    },
    BitField {
        name: "REPLY",
        lsb: 3,
        bits: 1,
        doc: "a reply byte waits in REPLY (a level: it clears when the replies are read; writing it does nothing)",
    },
];
/// `IRQ_ENABLE`'s fields: one enable per cause, at the cause's bit of `IRQ_STATUS`.
pub const IRQ_ENABLE_FIELDS: [BitField; 4] = [
    enable(IRQ_FIELDS[0], "DONE raises irq"),
    enable(IRQ_FIELDS[1], "FAULT raises irq"),
    enable(IRQ_FIELDS[2], "SWAP raises irq"),
    enable(
        IRQ_FIELDS[3],
        "REPLY raises irq (the host's UIO link enables this one alone)",
    ),
];

const fn enable(cause: BitField, doc: &'static str) -> BitField {
    BitField { doc, ..cause }
}

/// `IRQ_STATUS`/`IRQ_ENABLE` bit: a program ran to its end.
pub const IRQ_DONE: u32 = 1 << IRQ_FIELDS[0].lsb;
/// `IRQ_STATUS`/`IRQ_ENABLE` bit: the axis entered ErrorStop.
pub const IRQ_FAULT: u32 = 1 << IRQ_FIELDS[1].lsb;
/// `IRQ_STATUS`/`IRQ_ENABLE` bit: an armed swap took place or was dropped.
pub const IRQ_SWAP: u32 = 1 << IRQ_FIELDS[2].lsb;
/// `IRQ_STATUS`/`IRQ_ENABLE` bit: a reply byte waits.
pub const IRQ_REPLY: u32 = 1 << IRQ_FIELDS[3].lsb;
/// Every cause.
pub const IRQ_ALL: u32 = IRQ_DONE | IRQ_FAULT | IRQ_SWAP | IRQ_REPLY;
/// The latched causes (the others are levels).
pub const IRQ_LATCHED: u32 = IRQ_DONE | IRQ_FAULT | IRQ_SWAP;

/// `REPLY`'s fields.
pub const REPLY_FIELDS: [BitField; 2] = [
    BitField {
        name: "BYTE",
        lsb: 0,
        bits: 8,
        doc: "the reply stream's next byte (valid when VALID is set)",
    },
    BitField {
        name: "VALID",
        lsb: 8,
        bits: 1,
        doc: "a byte was waiting: BYTE is it, and the read took it",
    },
];
/// `REPLY`: the bit that says the read took a byte.
pub const REPLY_VALID: u32 = 1 << REPLY_FIELDS[1].lsb;

/// `COMMAND`'s field.
pub const COMMAND_FIELDS: [BitField; 1] = [BitField {
    name: "BYTE",
    lsb: 0,
    bits: 8,
    doc: "the command stream's next byte (taken when write strobe 0 is set; bits 31:8 are ignored)",
}];

/// `VERSION`'s fields.
pub const VERSION_FIELDS: [BitField; 2] = [
    BitField {
        name: "MAP",
        lsb: 0,
        bits: 16,
        doc: "this register map's version",
    },
    BitField {
        name: "PROTOCOL",
        lsb: 16,
        bits: 16,
        doc: "the command protocol's version (docs/PROTOCOL.md)",
    },
];

/// Words of a register of `bits` bits.
const fn words(bits: u32) -> u32 {
    bits.div_ceil(32)
}

/// The register map, in address order.
pub const REGISTERS: [Register; 14] = [
    Register {
        name: "ID",
        words: 1,
        access: Access::ReadOnly,
        reset: ID_MAGIC,
        fields: &[],
        snap: None,
        doc: "\"snap\" in ASCII: the slave is a snapgen station",
    },
    Register {
        name: "VERSION",
        words: 1,
        access: Access::ReadOnly,
        reset: MAP_VERSION | (crate::wire::PROTOCOL_VERSION as u32) << 16,
        fields: &VERSION_FIELDS,
        snap: None,
        doc: "the register map's and the protocol's versions",
    },
    Register {
        name: "COMMAND",
        words: 1,
        access: Access::WriteOnly,
        reset: 0,
        fields: &COMMAND_FIELDS,
        snap: None,
        doc: "a byte of a command frame (docs/PROTOCOL.md), executed as the UART's: write a frame's bytes in order; at most one byte every other clock reaches the station, which the handshake guarantees",
    },
    Register {
        name: "REPLY",
        words: 1,
        access: Access::ReadTakes,
        reset: 0,
        fields: &REPLY_FIELDS,
        snap: None,
        doc: "a byte of the reply stream (replies and telemetry frames, as on the UART)",
    },
    Register {
        name: "IRQ_STATUS",
        words: 1,
        access: Access::WriteOneToClear,
        reset: 0,
        fields: &IRQ_FIELDS,
        snap: None,
        doc: "interrupt causes, enabled or not",
    },
    Register {
        name: "IRQ_ENABLE",
        words: 1,
        access: Access::ReadWrite,
        reset: 0,
        fields: &IRQ_ENABLE_FIELDS,
        snap: None,
        doc: "the causes that raise `irq` (bits as IRQ_STATUS)",
    },
    Register {
        name: "SNAPSHOT",
        words: 1,
        access: Access::WriteOnly,
        reset: 0,
        fields: &[],
        snap: None,
        doc: "any write latches, on its clock, the status block into STATUS and the chain's registers into TICKS, X, V, A, J",
    },
    Register {
        name: "RESERVED",
        words: 1,
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: None,
        doc: "reads 0 (keeps the snapshot 8-word aligned)",
    },
    Register {
        name: "STATUS",
        words: words(STATUS_BITS as u32),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "status", signed: false }),
        doc: "the status block at the last SNAPSHOT (docs/PROTOCOL.md, \"Status block\"): its byte k in bits 8(k mod 4) of word k/4",
    },
    Register {
        name: "TICKS",
        words: words(TIME_BITS),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "ticks", signed: false }),
        doc: "ticks since reset (the board's time base) at the last SNAPSHOT, unsigned",
    },
    Register {
        name: "X",
        words: words(X_BITS),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "x", signed: true }),
        doc: "the position register at the last SNAPSHOT, raw, two's complement sign-extended to the words' width",
    },
    Register {
        name: "V",
        words: words(V_BITS),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "v", signed: true }),
        doc: "the velocity register at the last SNAPSHOT (as X)",
    },
    Register {
        name: "A",
        words: words(A_BITS),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "a", signed: true }),
        doc: "the acceleration register at the last SNAPSHOT (as X)",
    },
    Register {
        name: "J",
        words: words(J_BITS),
        access: Access::ReadOnly,
        reset: 0,
        fields: &[],
        snap: Some(Snap { port: "j", signed: true }),
        doc: "the jerk register at the last SNAPSHOT (as X)",
    },
];

/// The byte offset of register `index` of [`REGISTERS`].
pub const fn offset(index: usize) -> u32 {
    let mut at = 0;
    let mut k = 0;
    while k < index {
        at += 4 * REGISTERS[k].words;
        k += 1;
    }
    at
}

/// The index in [`REGISTERS`] of the register called `name` (a compile error in a `const` when
/// there is none).
pub const fn index(name: &str) -> usize {
    let mut k = 0;
    while k < REGISTERS.len() {
        if eq(REGISTERS[k].name, name) {
            return k;
        }
        k += 1;
    }
    panic!("no such register")
}

/// The byte offset of the register called `name`.
pub const fn offset_of(name: &str) -> u32 {
    offset(index(name))
}

const fn eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut k = 0;
    while k < a.len() {
        if a[k] != b[k] {
            return false;
        }
        k += 1;
    }
    true
}

/// The status block's bit (in the station's `status` port, byte 0 in bits 7:0) where its
/// `state` field starts: the FAULT cause is this byte equal to ErrorStop.
pub const STATUS_STATE_LSB: u32 = 8 * field(&STATUS_FIELDS, "state").offset as u32;
/// The bit of the flag DONE in the station's `status` port.
pub const STATUS_DONE_BIT: u32 =
    8 * field(&STATUS_FIELDS, "flags").offset as u32 + flag_bit(flag::DONE);
/// The bit of the flag SWAP_PENDING in the station's `status` port.
pub const STATUS_SWAP_PENDING_BIT: u32 =
    8 * field(&STATUS_FIELDS, "flags").offset as u32 + flag_bit(flag::SWAP_PENDING);

const fn flag_bit(mask: u16) -> u32 {
    mask.trailing_zeros()
}

/// Bytes the map spans.
pub const SPAN: u32 = offset(REGISTERS.len());

/// The register (and its word) at byte offset `addr` (low two bits ignored), if any.
pub fn at(addr: u32) -> Option<(&'static Register, u32)> {
    let word = addr / 4;
    let mut first = 0;
    for r in &REGISTERS {
        if word >= first && word < first + r.words {
            return Some((r, word - first));
        }
        first += r.words;
    }
    None
}

const _: () = {
    assert!(SPAN <= 1 << ADDR_BITS, "the map fits the slave's window");
    assert!(offset_of("STATUS") % 32 == 0);
    assert!(IRQ_ALL == 0xF && IRQ_LATCHED == 0x7);
    assert!(field(&STATUS_FIELDS, "state").bytes == 1);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_are_consecutive_words_and_names_unique() {
        let mut names: Vec<&str> = REGISTERS.iter().map(|r| r.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), REGISTERS.len());
        assert_eq!(offset_of("ID"), 0);
        assert_eq!(offset_of("COMMAND"), 8);
        assert_eq!(offset_of("STATUS"), 0x20);
        assert_eq!(offset_of("TICKS"), 0x40);
        assert_eq!(offset_of("J"), 0x78);
        assert_eq!(SPAN, 0x88);
        assert_eq!(at(0x44).map(|(r, w)| (r.name, w)), Some(("TICKS", 1)));
        assert_eq!(at(0x47).map(|(r, w)| (r.name, w)), Some(("TICKS", 1)));
        assert!(at(SPAN).is_none());
        for r in &REGISTERS {
            for f in r.fields {
                assert!(f.lsb + f.bits <= 32, "{}.{}", r.name, f.name);
            }
        }
    }
}
