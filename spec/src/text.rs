//! Constants named in the tables' prose: a meaning may say `{FRAC_BITS}` where the docs
//! should print 80, so that no number is typed a second time in a sentence.

use crate::rules::{REPLY_QUEUE, SWAP_MIN_LEAD, SWAP_REACH};
use crate::widths::{D_BITS, E_FRAC, FRAC_BITS, MAX_SEGMENTS, SWAP_BITS, V_BITS, X_BITS};
use crate::wire::{DEVICE_MAX_PAYLOAD, PROTOCOL_VERSION};

/// Every constant the tables' prose may name, with its value.
pub fn constants() -> Vec<(&'static str, String)> {
    vec![
        ("FRAC_BITS", FRAC_BITS.to_string()),
        ("X_BITS", X_BITS.to_string()),
        ("V_BITS", V_BITS.to_string()),
        ("D_BITS", D_BITS.to_string()),
        ("MAX_SEGMENTS", MAX_SEGMENTS.to_string()),
        ("LAST_SEGMENT", (MAX_SEGMENTS - 1).to_string()),
        ("E_FRAC", E_FRAC.to_string()),
        ("VELOCITY_SHIFT", (V_BITS - 32).to_string()),
        ("PROTOCOL_VERSION", PROTOCOL_VERSION.to_string()),
        ("SWAP_MIN_LEAD", SWAP_MIN_LEAD.to_string()),
        ("SWAP_REACH_LOG2", SWAP_REACH.trailing_zeros().to_string()),
        ("SWAP_BITS", SWAP_BITS.to_string()),
        ("REPLY_QUEUE", REPLY_QUEUE.to_string()),
        ("DEVICE_MAX_PAYLOAD", DEVICE_MAX_PAYLOAD.to_string()),
    ]
}

/// A placeholder no table defines.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownConstant(pub String);

impl std::fmt::Display for UnknownConstant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the placeholder {{{}}} names no constant: add it to spec::text::constants or to the design facts",
            self.0
        )
    }
}

impl std::error::Error for UnknownConstant {}

/// `text` with every `{NAME}` replaced by its value, from [`constants`] or from `extra`
/// (facts of a design the spec does not know, e.g. a block's latency in clocks).
pub fn expand(text: &str, extra: &[(&str, String)]) -> Result<String, UnknownConstant> {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    let known = constants();
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        let Some(close) = after.find('}') else {
            out.push_str(&rest[open..]);
            return Ok(out);
        };
        let name = &after[..close];
        let is_name = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
        if !is_name {
            out.push('{');
            rest = after;
            continue;
        }
        let value = known
            .iter()
            .chain(extra.iter())
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v.clone())
            .ok_or_else(|| UnknownConstant(name.to_string()))?;
        out.push_str(&value);
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expands_known_names_and_refuses_unknown_ones() {
        assert_eq!(expand("shift {FRAC_BITS}", &[]).unwrap(), "shift 80");
        assert_eq!(
            expand("{X} and {LAST_SEGMENT}", &[("X", "7".into())]).unwrap(),
            "7 and 31"
        );
        assert_eq!(expand("{not a name}", &[]).unwrap(), "{not a name}");
        assert_eq!(expand("{NOPE}", &[]), Err(UnknownConstant("NOPE".into())));
    }
}
