//! The `localparam`s the template blocks name (the executor, the reply transmitter, the
//! reply queue): the contract's codes, lengths, reasons, parameters, states and errors
//! (`snapgen_spec::emit::verilog`), the reply kinds of the executor's queue
//! (`snapgen_model::io::executor::ReplyKind`) and the register widths, each written from its
//! one table. [`with_localparams`] puts the ones a body uses in front of it.

use snapgen_model::io::executor::ReplyKind;
pub use snapgen_spec::emit::verilog::{with_localparams, LocalParam};
use snapgen_spec::params::PARAMS;
use snapgen_spec::widths;

/// Every reply kind with its Verilog name (`K_*`), in code order.
pub const REPLY_KINDS: [(ReplyKind, &str); 7] = [
    (ReplyKind::Identity, "IDENTITY"),
    (ReplyKind::Ack, "ACK"),
    (ReplyKind::Nak, "NAK"),
    (ReplyKind::Status, "STATUS"),
    (ReplyKind::State, "STATE"),
    (ReplyKind::Config, "CONFIG"),
    (ReplyKind::Telemetry, "TELEMETRY"),
];

/// Width of a reply kind.
pub const KIND_BITS: u32 = 3;

const _: () = assert!(REPLY_KINDS.len() <= 1 << KIND_BITS);

/// Every constant a template block may name: the contract's, the reply kinds (`K_*`), the
/// register widths (`D_BITS`, `TICK_BITS`, …, `KIND_BITS`) and each parameter register's
/// width (`<REGISTER>_BITS`).
pub fn localparams() -> Vec<LocalParam> {
    let mut v = snapgen_spec::emit::verilog::localparams();
    for (k, name) in REPLY_KINDS {
        v.push(LocalParam::new(format!("K_{name}"), KIND_BITS, k as u64));
    }
    for (name, bits) in [
        ("X_BITS", widths::X_BITS),
        ("D_BITS", widths::D_BITS),
        ("TICK_BITS", widths::TICK_BITS),
        ("ADDR_BITS", widths::ADDR_BITS),
        ("INDEX_BITS", widths::INDEX_BITS),
        ("SWAP_BITS", widths::SWAP_BITS),
        ("TIME_BITS", widths::TIME_BITS),
        ("STATE_BITS", widths::STATE_BITS),
        ("KIND_BITS", KIND_BITS),
        ("MAX_SEGMENTS", widths::MAX_SEGMENTS),
    ] {
        v.push(LocalParam::new(name, 32, u64::from(bits)));
    }
    for p in PARAMS {
        v.push(LocalParam::new(
            format!("{}_BITS", p.register.to_uppercase()),
            32,
            u64::from(p.bits),
        ));
    }
    v
}

/// [`localparams`] and a block's own widths (name, value; 32-bit localparams).
pub fn localparams_with(own: &[(&str, u32)]) -> Vec<LocalParam> {
    let mut v = localparams();
    for &(name, bits) in own {
        v.push(LocalParam::new(name, 32, u64::from(bits)));
    }
    v
}

/// A little-endian field of `bytes` bytes at payload byte `at`, for a payload of `n` bytes
/// received into `vector` newest byte first (byte `k` is `vector[8(n-1-k) +: 8]`), as a
/// Verilog concatenation (most significant byte first).
pub fn received_field(vector: &str, n: usize, at: usize, bytes: usize) -> String {
    assert!(at + bytes <= n, "field past the payload");
    let parts: Vec<String> = (at..at + bytes)
        .rev()
        .map(|k| {
            let lo = 8 * (n - 1 - k);
            format!("{vector}[{}:{lo}]", lo + 7)
        })
        .collect();
    if parts.len() == 1 {
        parts[0].clone()
    } else {
        format!("{{{}}}", parts.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique() {
        let params = localparams();
        assert_eq!(snapgen_spec::emit::verilog::repeated_name(&params), None);
    }

    #[test]
    fn received_fields_by_hand() {
        // A 3-byte payload a, b, c arrives newest first: c at 7:0, b at 15:8, a at 23:16.
        assert_eq!(received_field("p", 3, 0, 1), "p[23:16]");
        assert_eq!(received_field("p", 3, 1, 2), "{p[7:0], p[15:8]}");
    }
}
