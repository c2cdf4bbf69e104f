//! The protocol's tables (`snapgen_model::protocol`) as Verilog `localparam`s, for the blocks
//! that write their own Verilog (executor, reply transmitter, status block): command and
//! reply codes, payload lengths, NAK reasons, parameters, axis states, error identifiers and
//! reply kinds are written from the one Rust table, never typed again.
//!
//! A block writes its body with the names below and [`with_params`] puts in front of it the
//! `localparam`s the body uses (Verilator's `-Wall` reports unused ones).

use snapgen_model::io::executor::ReplyKind;
use snapgen_model::protocol::{code, AxisState, ErrorId, Param, Reason, COMMANDS, START};
use snapgen_model::protocol::{ERRORS, PARAMS, REASONS, STATES};

/// One `localparam`: its name, width and value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LocalParam {
    /// Name.
    pub name: String,
    /// Width in bits.
    pub bits: u32,
    /// Value.
    pub value: u64,
}

fn p(name: impl Into<String>, bits: u32, value: u64) -> LocalParam {
    LocalParam {
        name: name.into(),
        bits,
        value,
    }
}

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
/// Width of an axis state.
pub const STATE_BITS: u32 = 3;
/// Width of an error identifier.
pub const ERROR_BITS: u32 = 3;

const _: () = {
    assert!(STATES.len() <= 1 << STATE_BITS);
    assert!(ERRORS.len() <= 1 << ERROR_BITS);
    assert!(REPLY_KINDS.len() <= 1 << KIND_BITS);
};

/// Every protocol constant a block may use.
pub fn all() -> Vec<LocalParam> {
    let mut v = vec![p("START_BYTE", 8, u64::from(START))];
    for c in COMMANDS {
        v.push(p(format!("CMD_{}", c.name), 8, u64::from(c.code)));
        v.push(p(format!("LEN_{}", c.name), 8, u64::from(c.len)));
    }
    for (c, name) in [
        (code::IDENTITY, "IDENTITY"),
        (code::STATUS, "STATUS"),
        (code::STATE, "STATE"),
        (code::CONFIG, "CONFIG"),
        (code::ACK, "ACK"),
        (code::NAK, "NAK"),
        (code::TELEMETRY, "TELEMETRY"),
    ] {
        v.push(p(format!("RC_{name}"), 8, u64::from(c)));
    }
    for (r, name) in REASONS {
        v.push(p(format!("R_{name}"), 8, r as u64));
    }
    for (param, name) in PARAMS {
        v.push(p(format!("P_{name}"), 8, param as u64));
    }
    for (s, name) in STATES {
        v.push(p(format!("S_{name}"), STATE_BITS, s as u64));
    }
    for (e, name) in ERRORS {
        v.push(p(format!("E_{name}"), ERROR_BITS, e as u64));
    }
    for (k, name) in REPLY_KINDS {
        v.push(p(format!("K_{name}"), KIND_BITS, k as u64));
    }
    v
}

/// True when `name` appears in `body` as a whole identifier.
fn uses(body: &str, name: &str) -> bool {
    body.match_indices(name).any(|(at, _)| {
        let before = body[..at].chars().next_back();
        let after = body[at + name.len()..].chars().next();
        let ident = |c: Option<char>| c.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
        !ident(before) && !ident(after)
    })
}

/// `body` with the `localparam`s of `params` it uses in front of it.
pub fn with_params(params: &[LocalParam], body: &str) -> String {
    let mut out = String::new();
    for q in params.iter().filter(|q| uses(body, &q.name)) {
        out.push_str(&format!(
            "localparam [{}:0] {} = {}'d{};\n",
            q.bits - 1,
            q.name,
            q.bits,
            q.value
        ));
    }
    out.push_str(body);
    out
}

/// The constants of a state, an error, a reason and a parameter, by their Rust values (for
/// blocks that name them in code).
pub fn state_name(s: AxisState) -> String {
    format!("S_{}", s.name())
}

/// `E_*` of an error identifier.
pub fn error_name(e: ErrorId) -> String {
    format!("E_{}", e.name())
}

/// `R_*` of a reason.
pub fn reason_name(r: Reason) -> String {
    format!("R_{}", r.name())
}

/// `P_*` of a parameter.
pub fn param_name(q: Param) -> String {
    format!("P_{}", q.name())
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
    fn only_used_params_are_written() {
        let body = "x = CMD_PING; y = R_BAD_CRC_X;";
        let v = with_params(&all(), body);
        assert!(v.contains("localparam [7:0] CMD_PING = 8'd1;"));
        assert!(!v.contains("R_BAD_CRC ="), "a longer name is not a use");
    }

    #[test]
    fn names_are_unique() {
        let a = all();
        let mut names: Vec<&str> = a.iter().map(|q| q.name.as_str()).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n);
    }

    #[test]
    fn received_fields_by_hand() {
        // A 3-byte payload a, b, c arrives newest first: c at 7:0, b at 15:8, a at 23:16.
        assert_eq!(received_field("p", 3, 0, 1), "p[23:16]");
        assert_eq!(received_field("p", 3, 1, 2), "{p[7:0], p[15:8]}");
    }
}
