//! Verilog templates: the hand-written Verilog of a block rust-hdl cannot express lives in a
//! file of its own under `hdl/verilog/`, plain Verilog a reader can follow, with two kinds of
//! holes the generator fills from the contract:
//!
//! * `{{NAME}}` inside a line: a value (a width, a constant of the design);
//! * a line `//@ NAME` (indented as the code around it): a block of lines (a case table over
//!   the commands, one register per parameter, …), each written with the marker's indentation.
//!
//! [`fill`] refuses a hole it is not given and a value it is given that no hole uses, so a
//! template and its generator cannot drift apart silently.

use std::collections::BTreeMap;

/// What goes into a template's holes.
#[derive(Clone, Debug, Default)]
pub struct Holes {
    values: BTreeMap<&'static str, String>,
    blocks: BTreeMap<&'static str, String>,
}

impl Holes {
    /// No holes filled yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// `{{name}}` becomes `value`.
    pub fn value(mut self, name: &'static str, value: impl ToString) -> Self {
        self.values.insert(name, value.to_string());
        self
    }

    /// The line `//@ name` becomes `lines` (one per line of the text).
    pub fn block(mut self, name: &'static str, lines: impl Into<String>) -> Self {
        self.blocks.insert(name, lines.into());
        self
    }
}

/// Why a template could not be filled (a bug in the generator or the template: the tests of
/// every block fill its template).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TemplateError {
    /// A hole no value or block was given for.
    #[error("template {template}: no value for the hole {name}")]
    Unfilled {
        /// The template.
        template: &'static str,
        /// The hole.
        name: String,
    },
    /// A value or block given for a hole the template does not have.
    #[error("template {template}: {name} fills no hole")]
    Unused {
        /// The template.
        template: &'static str,
        /// The value's name.
        name: &'static str,
    },
}

/// `template` (called `name` in errors) with its holes filled.
pub fn fill(name: &'static str, template: &str, holes: &Holes) -> Result<String, TemplateError> {
    let mut used_values = std::collections::BTreeSet::new();
    let mut used_blocks = std::collections::BTreeSet::new();
    let mut out = String::with_capacity(template.len() * 2);
    for line in template.lines() {
        let t = line.trim_start();
        if let Some(block) = t.strip_prefix("//@ ") {
            let key = block.trim();
            let (&k, text) =
                holes
                    .blocks
                    .get_key_value(key)
                    .ok_or_else(|| TemplateError::Unfilled {
                        template: name,
                        name: key.to_string(),
                    })?;
            used_blocks.insert(k);
            let indent = &line[..line.len() - t.len()];
            for l in text.lines() {
                if l.is_empty() {
                    out.push('\n');
                } else {
                    out.push_str(indent);
                    out.push_str(l);
                    out.push('\n');
                }
            }
            continue;
        }
        let mut rest = line;
        while let Some(open) = rest.find("{{") {
            out.push_str(&rest[..open]);
            let after = &rest[open + 2..];
            // A hole is `{{NAME}}` with NAME in capitals; anything else (Verilog's
            // replication `{{N{1'b0}}, x}`) is text.
            let key = after.find("}}").map(|close| &after[..close]).filter(|k| {
                !k.is_empty()
                    && k.chars()
                        .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
            });
            let Some(key) = key else {
                out.push_str("{{");
                rest = after;
                continue;
            };
            let close = key.len();
            let (&k, v) =
                holes
                    .values
                    .get_key_value(key)
                    .ok_or_else(|| TemplateError::Unfilled {
                        template: name,
                        name: key.to_string(),
                    })?;
            used_values.insert(k);
            out.push_str(v);
            rest = &after[close + 2..];
        }
        out.push_str(rest);
        out.push('\n');
    }
    if let Some(k) = holes.values.keys().find(|k| !used_values.contains(*k)) {
        return Err(TemplateError::Unused {
            template: name,
            name: k,
        });
    }
    if let Some(k) = holes.blocks.keys().find(|k| !used_blocks.contains(*k)) {
        return Err(TemplateError::Unused {
            template: name,
            name: k,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_blocks_are_filled_and_checked() {
        let t = "reg [{{W}}-1:0] r;\n   //@ cases\nend\n";
        let h = Holes::new().value("W", 8).block("cases", "a;\nb;");
        assert_eq!(
            fill("t", t, &h).unwrap(),
            "reg [8-1:0] r;\n   a;\n   b;\nend\n"
        );
        assert_eq!(
            fill("t", t, &Holes::new().value("W", 8)),
            Err(TemplateError::Unfilled {
                template: "t",
                name: "cases".into()
            })
        );
        assert_eq!(
            fill("t", t, &h.clone().value("X", 1)),
            Err(TemplateError::Unused {
                template: "t",
                name: "X"
            })
        );
    }
}
