//! The tables of docs/PROTOCOL.md, written between markers:
//!
//! ```text
//! <!-- spec:commands -->
//! | code | command | … |
//! <!-- /spec:commands -->
//! ```
//!
//! [`update`] rewrites every marked block of a page from the tables; a page is current when
//! `update(page) == page` (the test of docs/PROTOCOL.md). `snapgen spec --update-docs` writes it.

use crate::codes::{reply_spec, AxisState, ErrorId, Reason, COMMANDS, FLAGS, REPLIES};
use crate::fields::{Field, CONFIG_FIELDS, IDENTITY_FIELDS, STATE_FIELDS, STATUS_FIELDS};
use crate::params::{Reset, PARAMS};
use crate::refusals::REFUSALS;
use crate::text::{expand, UnknownConstant};

/// Why a page cannot be updated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DocError {
    /// A marker names no table.
    UnknownBlock(String),
    /// A block is opened and never closed.
    Unclosed(String),
    /// A table's prose names an unknown constant.
    Constant(UnknownConstant),
}

impl std::fmt::Display for DocError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DocError::UnknownBlock(b) => write!(
                f,
                "<!-- spec:{b} --> names no generated table (known: {})",
                BLOCKS.join(", ")
            ),
            DocError::Unclosed(b) => write!(f, "<!-- spec:{b} --> has no <!-- /spec:{b} -->"),
            DocError::Constant(c) => c.fmt(f),
        }
    }
}

impl std::error::Error for DocError {}

impl From<UnknownConstant> for DocError {
    fn from(e: UnknownConstant) -> Self {
        DocError::Constant(e)
    }
}

/// Every block a page may mark.
pub const BLOCKS: [&str; 15] = [
    "commands",
    "refusals",
    "states",
    "errors",
    "params",
    "replies",
    "reasons",
    "identity",
    "status",
    "flags",
    "state",
    "config",
    "examples",
    "board_pins",
    "axi_registers",
];

/// The pages under docs/ with generated blocks.
pub const PAGES: [&str; 3] = ["PROTOCOL.md", "BOARDS.md", "AXI.md"];

fn row(cells: &[String]) -> String {
    format!("| {} |\n", cells.join(" | "))
}

fn table(header: &[&str], rows: Vec<Vec<String>>) -> String {
    let mut s = row(&header.iter().map(|h| h.to_string()).collect::<Vec<_>>());
    s.push_str(&format!("|{}\n", "---|".repeat(header.len())));
    for r in rows {
        s.push_str(&row(&r));
    }
    s
}

/// A field's type as the command table writes it.
fn field_type(f: &Field) -> String {
    match (f.bytes, f.signed) {
        (1, false) => "u8".into(),
        (2, false) => "u16".into(),
        (4, false) => "u32".into(),
        (8, false) => "u64".into(),
        (n, _) => format!("{n} bytes"),
    }
}

fn layout(fields: &[Field], extra: &[(&str, String)]) -> Result<String, DocError> {
    let mut rows = Vec::new();
    for f in fields {
        rows.push(vec![
            f.offset.to_string(),
            f.bytes.to_string(),
            f.name.to_string(),
            expand(f.meaning, extra)?,
        ]);
    }
    Ok(table(&["offset", "bytes", "field", "meaning"], rows))
}

fn max_text(bits: u32, signed: bool) -> String {
    if signed {
        format!("2^{} − 1", bits - 1)
    } else {
        ((1u128 << bits) - 1).to_string()
    }
}

/// The contents of block `name` (`extra`: facts of the design the spec does not know, named
/// in the tables' prose).
pub fn block(name: &str, extra: &[(&str, String)]) -> Result<String, DocError> {
    let x = |s: &str| expand(s, extra);
    Ok(match name {
        "commands" => {
            let mut rows = Vec::new();
            for c in COMMANDS {
                let payload = if c.fields.is_empty() {
                    "—".to_string()
                } else if let Some(r) = REPLIES.iter().find(|r| r.fields == c.fields) {
                    // A layout a reply shares: described below, with the reply.
                    x(r.meaning)?
                } else {
                    let mut parts = Vec::new();
                    for f in c.fields {
                        parts.push(format!(
                            "`{}` {} ({})",
                            f.name,
                            field_type(f),
                            x(f.meaning)?
                        ));
                    }
                    parts.join(", ")
                };
                rows.push(vec![
                    format!("`{:#04X}`", c.code).replace("0X", "0x"),
                    c.name.to_string(),
                    c.len.to_string(),
                    payload,
                    if c.effect { "yes" } else { "no" }.to_string(),
                    reply_spec(c.reply).map_or("?", |r| r.name).to_string(),
                ]);
            }
            table(
                &[
                    "code",
                    "command",
                    "LEN",
                    "payload",
                    "changes state",
                    "reply",
                ],
                rows,
            )
        }
        "refusals" => {
            let mut rows = Vec::new();
            for r in REFUSALS {
                let reasons: Vec<&str> = r.reasons.iter().map(|q| q.name()).collect();
                rows.push(vec![r.command.to_string(), reasons.join(", "), x(r.when)?]);
            }
            table(&["command", "refused with", "when"], rows)
        }
        "states" => {
            let mut rows = Vec::new();
            for s in AxisState::ALL {
                rows.push(vec![
                    (s as u8).to_string(),
                    s.name().into(),
                    x(s.meaning())?,
                ]);
            }
            table(&["value", "state", "meaning"], rows)
        }
        "errors" => {
            let mut rows = Vec::new();
            for e in ErrorId::ALL {
                rows.push(vec![
                    (e as u8).to_string(),
                    e.name().into(),
                    x(e.meaning())?,
                ]);
            }
            table(&["value", "error", "cause"], rows)
        }
        "reasons" => {
            let mut rows = Vec::new();
            for r in Reason::ALL {
                rows.push(vec![
                    (r as u8).to_string(),
                    r.name().into(),
                    x(r.meaning())?,
                ]);
            }
            table(&["value", "reason", "meaning"], rows)
        }
        "params" => {
            let mut rows = Vec::new();
            for p in PARAMS {
                let default = match p.reset {
                    Reset::Design => "the design's".to_string(),
                    Reset::Max => p.max().to_string(),
                    Reset::Value(v) => v.to_string(),
                };
                rows.push(vec![
                    (p.param as u8).to_string(),
                    p.name.to_string(),
                    default,
                    max_text(p.bits, p.signed),
                    p.settable.name().to_string(),
                    x(p.meaning)?,
                ]);
            }
            table(
                &["param", "name", "default", "maximum", "set", "meaning"],
                rows,
            )
        }
        "replies" => {
            let mut rows = Vec::new();
            for r in REPLIES {
                rows.push(vec![
                    format!("`{:#04X}`", r.code).replace("0X", "0x"),
                    r.name.to_string(),
                    r.len.to_string(),
                    x(r.meaning)?,
                ]);
            }
            table(&["code", "reply", "LEN", "payload"], rows)
        }
        "identity" => layout(&IDENTITY_FIELDS, extra)?,
        "status" => layout(&STATUS_FIELDS, extra)?,
        "state" => layout(&STATE_FIELDS, extra)?,
        "config" => layout(&CONFIG_FIELDS, extra)?,
        "flags" => {
            let mut rows = Vec::new();
            for f in FLAGS {
                rows.push(vec![f.bit.to_string(), f.name.to_string(), x(f.meaning)?]);
            }
            table(&["bit", "flag", "meaning"], rows)
        }
        "examples" => super::examples::markdown(),
        "board_pins" => {
            let rows = crate::ports::board_pins(1)
                .into_iter()
                .map(|p| {
                    let wired = match p.wired {
                        crate::ports::PinUse::Clock => "the clock".to_string(),
                        crate::ports::PinUse::ResetButton => "the reset synchroniser".to_string(),
                        crate::ports::PinUse::Io(name) => format!("`{name}`"),
                    };
                    Ok(vec![
                        format!("`{}`", p.port),
                        match p.dir {
                            crate::ports::Dir::In => "in".to_string(),
                            crate::ports::Dir::Out => "out".to_string(),
                        },
                        wired,
                        x(p.doc)?,
                    ])
                })
                .collect::<Result<Vec<_>, DocError>>()?;
            table(&["port", "direction", "I/O top port", "what"], rows)
        }
        "axi_registers" => table(
            &["offset", "register", "words", "access", "reset", "meaning"],
            crate::emit::axi::markdown_table(),
        ),
        other => return Err(DocError::UnknownBlock(other.to_string())),
    })
}

/// `page` with every marked block rewritten from the tables.
pub fn update(page: &str, extra: &[(&str, String)]) -> Result<String, DocError> {
    let mut out = String::with_capacity(page.len());
    let mut rest = page;
    while let Some(open) = rest.find("<!-- spec:") {
        let after = &rest[open + "<!-- spec:".len()..];
        let Some(end) = after.find(" -->") else {
            break;
        };
        let name = &after[..end];
        let close = format!("<!-- /spec:{name} -->");
        let body_start = open + "<!-- spec:".len() + end + " -->".len();
        let Some(close_at) = rest[body_start..].find(&close) else {
            return Err(DocError::Unclosed(name.to_string()));
        };
        out.push_str(&rest[..body_start]);
        out.push('\n');
        out.push_str(&block(name, extra)?);
        out.push_str(&close);
        rest = &rest[body_start + close_at + close.len()..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_marked_block_is_rewritten_and_the_rest_kept() {
        let page = "# P\n\n<!-- spec:reasons -->\nstale\n<!-- /spec:reasons -->\n\ntail\n";
        let got = update(page, &[]).unwrap();
        assert!(got.starts_with("# P\n\n<!-- spec:reasons -->\n| value | reason | meaning |\n"));
        assert!(got.contains("| 14 | LATE | SWAP_AT for a tick less than 5 ticks ahead"));
        assert!(got.ends_with("<!-- /spec:reasons -->\n\ntail\n"));
        assert_eq!(
            update(&got, &[]).unwrap(),
            got,
            "a current page is a fixed point"
        );
        assert!(matches!(
            update("<!-- spec:nope -->\n<!-- /spec:nope -->", &[]),
            Err(DocError::UnknownBlock(_))
        ));
        assert!(matches!(
            update("<!-- spec:reasons -->\n", &[]),
            Err(DocError::Unclosed(_))
        ));
    }

    #[test]
    fn the_command_table_writes_types_and_ranges() {
        let t = block("commands", &[]).unwrap();
        assert!(t.contains(
            "| `0x02` | LOAD_SEGMENT | 18 | `index` u8 (0–31), `ticks` u32 (≥ 1), `snap` 13 bytes (signed 104-bit) | yes | ACK |"
        ), "{t}");
        let p = block("params", &[]).unwrap();
        assert!(
            p.contains("| 5 | STOP_JERK | 0 | 2^103 − 1 | at rest |"),
            "{p}"
        );
        assert!(
            p.contains("| 1 | TICK_DIVIDER | the design's | 4294967295 | at rest |"),
            "{p}"
        );
        assert!(
            p.contains("| 17 | OUTPUT_LIMIT | 32767 | 2^15 − 1 | any time |"),
            "{p}"
        );
    }
}
