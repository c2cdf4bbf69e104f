//! The contract as Verilog `localparam`s, for the blocks whose Verilog is written from a
//! template (the executor, the reply transmitter, the status block): command and reply codes,
//! payload lengths, NAK reasons, parameters, axis states and error identifiers. A block's body
//! names them; [`with_localparams`] puts in front of it the ones it uses (Verilator's `-Wall`
//! reports unused ones).

use crate::codes::{AxisState, ErrorId, Reason, COMMANDS, REPLIES};
use crate::params::PARAMS;
use crate::widths::STATE_BITS;
use crate::wire::START;

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

impl LocalParam {
    /// A `localparam` called `name` of `bits` bits.
    pub fn new(name: impl Into<String>, bits: u32, value: u64) -> Self {
        LocalParam {
            name: name.into(),
            bits,
            value,
        }
    }
}

/// A name that two of `params` share, if any (the first such in alphabetical order) (a Verilog module may not declare a
/// `localparam` twice).
pub fn repeated_name(params: &[LocalParam]) -> Option<&str> {
    let mut names: Vec<&str> = params.iter().map(|q| q.name.as_str()).collect();
    names.sort_unstable();
    names.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// Every protocol constant: `START_BYTE`, `CMD_*` and `LEN_*` of each command, `RC_*` of
/// each reply, `R_*` of each reason, `P_*` of each parameter, `S_*` of each axis state and
/// `E_*` of each error identifier.
pub fn localparams() -> Vec<LocalParam> {
    let mut v = vec![LocalParam::new("START_BYTE", 8, u64::from(START))];
    for c in COMMANDS {
        v.push(LocalParam::new(
            format!("CMD_{}", c.name),
            8,
            u64::from(c.code),
        ));
        v.push(LocalParam::new(
            format!("LEN_{}", c.name),
            8,
            u64::from(c.len),
        ));
    }
    for r in REPLIES {
        v.push(LocalParam::new(
            format!("RC_{}", r.name),
            8,
            u64::from(r.code),
        ));
    }
    for r in Reason::ALL {
        v.push(LocalParam::new(format!("R_{}", r.name()), 8, r as u64));
    }
    for p in PARAMS {
        v.push(LocalParam::new(format!("P_{}", p.name), 8, p.param as u64));
    }
    for s in AxisState::ALL {
        v.push(LocalParam::new(
            format!("S_{}", s.name()),
            STATE_BITS,
            s as u64,
        ));
    }
    for e in ErrorId::ALL {
        v.push(LocalParam::new(
            format!("E_{}", e.name()),
            STATE_BITS,
            e as u64,
        ));
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
pub fn with_localparams(params: &[LocalParam], body: &str) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_used_params_are_written() {
        let body = "x = CMD_PING; y = R_BAD_CRC_X;";
        let v = with_localparams(&localparams(), body);
        assert!(v.contains("localparam [7:0] CMD_PING = 8'd1;"));
        assert!(!v.contains("R_BAD_CRC ="), "a longer name is not a use");
    }

    #[test]
    fn names_are_unique() {
        assert_eq!(repeated_name(&localparams()), None);
        let twice = [LocalParam::new("A", 1, 0), LocalParam::new("A", 2, 1)];
        assert_eq!(repeated_name(&twice), Some("A"));
    }
}
