//! Verilog generation: rust-hdl's output made into files a hardware engineer can drop into a
//! project.
//!
//! rust-hdl 0.46 names the top module `top`, every submodule `top$child$grandchild` and every
//! child port signal `child$port`, and routes each child's clock through the parent's
//! combinational block. Two generated files therefore cannot be read together (both define
//! `top` and the same `top$…` modules), and `$` needs escaping in XDC and TCL. [`emit`] turns
//! that output into one self-contained file per design:
//!
//! * every module is named after the design (`snapgen_core`, `snapgen_core_sequencer`, …):
//!   the top `top` becomes the design's prefix, `top$a$b` becomes `PREFIX_a_b`, and every
//!   other `$` in a name becomes `_` (the renaming is checked to be one-to-one);
//! * clocks are wired directly ([`direct_clocks`]);
//! * `` `default_nettype none`` holds over the design (and `wire` is restored after it);
//! * the few lint waivers and scheduling hints the design needs are written into the file next
//!   to the declaration they concern, each with its reason, so `verilator --lint-only -Wall`
//!   is clean on the files alone, with no configuration file.
//!
//! (Workarounds for rust-hdl 0.46, which is frozen; see docs/HDL.md.)

use rust_hdl::prelude::*;

/// Why generated Verilog could not be finished.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VerilogError {
    /// Two different rust-hdl names would get the same Verilog name.
    #[error("the names {first:?} and {second:?} would both become {name:?}: rename one of the rust-hdl fields")]
    NameCollision {
        /// One original name.
        first: String,
        /// The other.
        second: String,
        /// The name both map to.
        name: String,
    },
    /// A lint waiver names a declaration the design does not have (stale waiver).
    #[error("waiver {rule} for {signal:?} in module *{module}: no such declaration")]
    StaleWaiver {
        /// Rule.
        rule: &'static str,
        /// Module path (after the prefix).
        module: &'static str,
        /// Signal.
        signal: &'static str,
    },
    /// rust-hdl produced clock routing of a shape [`direct_clocks`] does not know.
    #[error("rust-hdl clock routing of an unknown shape survived direct_clocks")]
    ClockRouting,
    /// rust-hdl's output has a shape the netlist passes do not know.
    #[error("the generated Verilog has an unexpected shape: {0}")]
    Netlist(&'static str),
    /// The I/O top's motion core is not the motion core's design.
    #[error("the I/O top's copy of {module} differs from snapgen_core.v's: {line}")]
    CopyDiffers {
        /// The module.
        module: String,
        /// The first line that differs.
        line: String,
    },
}

/// What is written next to one declaration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Note {
    /// `verilator lint_off RULE` before the declaration and `lint_on` after it.
    LintOff(&'static str),
    /// `/* verilator isolate_assignments */` on the declaration: a scheduling hint that makes
    /// Verilator give the signal's assignments blocks of their own. Optional: a design without
    /// the signal is fine.
    IsolateAssignments,
}

/// A waiver or hint for one declaration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Waiver {
    /// The module: its path below the design's top (`"core_sequencer"`, `""` for the top);
    /// any module whose name ends in `_PATH` (or equals it) matches.
    pub module: &'static str,
    /// The declared signal (after renaming).
    pub signal: &'static str,
    /// What to write.
    pub note: Note,
    /// Why, written into the file.
    pub reason: &'static str,
}

/// Rewrites `NAME$clock` clock routing into direct `.clock(clock)` connections.
///
/// rust-hdl routes every sub-block's clock through the parent's combinational `always @(*)`
/// block (`chain$clock = clock;` then `.clock(chain$clock)`). That is legal, but it makes the
/// clock a combinationally derived signal: Verilator re-evaluates all combinational logic on
/// both clock edges and schedules the flip-flops after it settles, which made co-simulation
/// several times slower, and it is not how a reader expects a clock to be wired. This drops the
/// intermediate signals; nothing else in the text changes.
pub fn direct_clocks(verilog: &str) -> Result<String, VerilogError> {
    let is_name = |s: &str| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
    };
    let mut out = String::with_capacity(verilog.len());
    for line in verilog.lines() {
        let t = line.trim();
        // Declaration `reg  NAME$clock;` and assignment `NAME$clock = clock;`: dropped.
        if let Some(rest) = t.strip_prefix("reg") {
            if let Some(name) = rest.trim().strip_suffix("$clock;") {
                if is_name(name) {
                    continue;
                }
            }
        }
        if let Some(name) = t.strip_suffix("$clock = clock;") {
            if is_name(name) {
                continue;
            }
        }
        // Connection `.clock(NAME$clock)`: the port directly.
        if let (Some(start), true) = (
            line.find(".clock("),
            t.ends_with("$clock),") || t.ends_with("$clock)"),
        ) {
            let tail = if t.ends_with(',') { ")," } else { ")" };
            out.push_str(&line[..start]);
            out.push_str(".clock(clock");
            out.push_str(tail);
            out.push('\n');
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    if out.contains("$clock") {
        return Err(VerilogError::ClockRouting);
    }
    Ok(out)
}

/// The Verilog name of a rust-hdl name in a design with module prefix `prefix`.
fn verilog_name(name: &str, prefix: &str) -> String {
    if name == "top" {
        prefix.to_string()
    } else if let Some(rest) = name.strip_prefix("top$") {
        format!("{prefix}_{}", rest.replace('$', "_"))
    } else {
        name.replace('$', "_")
    }
}

/// Renames every identifier (see the module documentation); fails if two names of one scope
/// would merge: module names across the file, signal names within their module.
fn rename(verilog: &str, prefix: &str) -> Result<String, VerilogError> {
    use std::collections::HashMap;
    // New name → the original it came from, to prove the renaming one-to-one.
    let mut modules: HashMap<String, String> = HashMap::new();
    let mut signals: HashMap<String, String> = HashMap::new();
    let check = |map: &mut HashMap<String, String>, new: &str, name: &str| match map.get(new) {
        Some(first) if first != name => Err(VerilogError::NameCollision {
            first: first.clone(),
            second: name.to_string(),
            name: new.to_string(),
        }),
        Some(_) => Ok(()),
        None => {
            map.insert(new.to_string(), name.to_string());
            Ok(())
        }
    };
    let mut out = String::with_capacity(verilog.len());
    let bytes = verilog.as_bytes();
    let mut i = 0;
    let start_char = |b: u8| b.is_ascii_alphabetic() || b == b'_';
    let name_char = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'$';
    while i < bytes.len() {
        let b = bytes[i];
        // Comments are copied as they are (a comment's word "top" is not the design's top).
        let comment_end = if verilog[i..].starts_with("//") {
            Some(verilog[i..].find('\n').map_or(bytes.len(), |k| i + k))
        } else if verilog[i..].starts_with("/*") {
            Some(verilog[i..].find("*/").map_or(bytes.len(), |k| i + k + 2))
        } else {
            None
        };
        if let Some(end) = comment_end {
            let comment = &verilog[i..end];
            let line_so_far = out.rsplit('\n').next().unwrap_or("");
            match comment.strip_prefix("// ") {
                // `endmodule // NAME` names the module: renamed with it.
                Some(name) if line_so_far.trim() == "endmodule" => {
                    out.push_str(&format!("// {}", verilog_name(name.trim(), prefix)));
                }
                _ => out.push_str(comment),
            }
            i = end;
            continue;
        }
        // A system task (`$signed`) or a sized literal's base (`32'h50`) is not a name.
        let after_quote_or_dollar = i > 0 && matches!(bytes[i - 1], b'\'' | b'$');
        if start_char(b) && after_quote_or_dollar {
            let begin = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push_str(&verilog[begin..i]);
        } else if start_char(b) {
            let begin = i;
            while i < bytes.len() && name_char(bytes[i]) {
                i += 1;
            }
            let name = &verilog[begin..i];
            if name == "module" {
                // A new module: a new scope for signal names.
                signals.clear();
            }
            let new = verilog_name(name, prefix);
            // `.port(` names a port of the instantiated module: checked in that module.
            let port_of_child = out.trim_end().ends_with('.');
            if name == "top" || name.starts_with("top$") {
                check(&mut modules, &new, name)?;
            } else if !port_of_child {
                check(&mut signals, &new, name)?;
            }
            out.push_str(&new);
        } else {
            // Copy one whole character (comments may hold non-ASCII text).
            let ch = verilog[i..].chars().next().expect("in bounds");
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    Ok(out)
}

/// The module a `module NAME(` line declares.
fn module_name(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix("module ")?;
    let end = rest.find(['(', ' ', ';'])?;
    Some(&rest[..end])
}

/// The signal a declaration line (`wire [3:0] name;`, `output reg x;`, …) declares.
fn declared(line: &str) -> Option<&str> {
    let t = line.trim();
    let first = t.split_whitespace().next()?;
    if !matches!(first, "wire" | "reg" | "input" | "output" | "localparam") {
        return None;
    }
    let body = t.strip_suffix(';')?;
    body.rsplit([' ', ']']).next()
}

fn module_matches(module: &str, path: &str, prefix: &str) -> bool {
    if path.is_empty() {
        module == prefix
    } else {
        module == path || module.ends_with(&format!("_{path}"))
    }
}

/// Modules synthesis keeps as blocks of their own (`(* keep_hierarchy = "yes" *)`, honoured by
/// Yosys and Vivado), by the path below the design's top, with the reason.
pub const KEPT_MODULES: [(&str, &str); 1] = [(
    "stop_unit",
    "its word-serial engine reads the chain registers through one operand mux: flattened \
     into the core, Yosys merged that mux with the chain's logic (1 700 -> 2 200 LUTs)",
)];

/// Writes each waiver and hint next to its declaration, and the kept modules' attribute.
fn annotate(verilog: &str, prefix: &str, waivers: &[Waiver]) -> Result<String, VerilogError> {
    let mut used = vec![false; waivers.len()];
    let mut out = String::with_capacity(verilog.len() + 64 * waivers.len());
    let mut module = "";
    for line in verilog.lines() {
        if let Some(m) = module_name(line) {
            module = m;
            if let Some((_, why)) = KEPT_MODULES
                .iter()
                .find(|(path, _)| module_matches(m, path, prefix))
            {
                out.push_str(&format!("// Kept as a block in synthesis: {why}.\n"));
                out.push_str("(* keep_hierarchy = \"yes\" *)\n");
            }
        }
        let hits: Vec<usize> = match declared(line) {
            Some(sig) => waivers
                .iter()
                .enumerate()
                .filter(|(_, w)| w.signal == sig && module_matches(module, w.module, prefix))
                .map(|(k, _)| k)
                .collect(),
            None => Vec::new(),
        };
        if hits.is_empty() {
            out.push_str(line);
            out.push('\n');
            continue;
        }
        let indent = &line[..line.len() - line.trim_start().len()];
        let mut decl = line.to_string();
        let mut after = Vec::new();
        for &k in &hits {
            used[k] = true;
            let w = &waivers[k];
            match w.note {
                Note::LintOff(rule) => {
                    out.push_str(&format!(
                        "{indent}/* verilator lint_off {rule} */ // {}\n",
                        w.reason
                    ));
                    after.push(format!("{indent}/* verilator lint_on {rule} */\n"));
                }
                Note::IsolateAssignments => {
                    let semi = decl.rfind(';').expect("a declaration ends in ';'");
                    decl.insert_str(semi, " /* verilator isolate_assignments */");
                    decl.push_str(&format!(" // {}", w.reason));
                }
            }
        }
        out.push_str(&decl);
        out.push('\n');
        for a in after {
            out.push_str(&a);
        }
    }
    for (w, used) in waivers.iter().zip(used) {
        if let (Note::LintOff(rule), false) = (w.note, used) {
            return Err(VerilogError::StaleWaiver {
                rule,
                module: w.module,
                signal: w.signal,
            });
        }
    }
    Ok(out)
}

/// rust-hdl's Verilog of a design under `prefix`: clocks wired directly, names renamed,
/// register modules inlined ([`crate::netlist`]); no waivers or header yet.
pub(crate) fn netlist_of(raw: &str, prefix: &str) -> Result<String, VerilogError> {
    crate::netlist::inline_registers(&rename(&direct_clocks(raw)?, prefix)?)
}

/// A design's netlist finished: the waivers and hints, `` `default_nettype none`` and a header
/// (`header`: comment lines, without `//`).
pub(crate) fn finish(
    body: &str,
    prefix: &str,
    header: &[String],
    waivers: &[Waiver],
) -> Result<String, VerilogError> {
    let body = annotate(body, prefix, waivers)?;
    let mut out = String::new();
    for h in header {
        out.push_str(&format!("// {h}\n"));
    }
    out.push_str(&format!(
        "// Generated by snapgen {} from rust-hdl 0.46. Do not edit: regenerate it.\n\
         // Modules: {prefix} and its submodules {prefix}_*.\n\n\
         /* verilator lint_off DECLFILENAME */ // the file holds the design's submodules too\n\
         `default_nettype none\n",
        env!("CARGO_PKG_VERSION"),
    ));
    out.push_str(body.trim_start_matches('\n'));
    out.push_str("`default_nettype wire\n/* verilator lint_on DECLFILENAME */\n");
    Ok(out)
}

/// Finishes rust-hdl's Verilog for a design: direct clocks, names under `prefix`, register
/// modules inlined, the waivers and hints, `` `default_nettype none`` and a header (`header`:
/// comment lines, without `//`).
pub fn emit(
    raw: &str,
    prefix: &str,
    header: &[String],
    waivers: &[Waiver],
) -> Result<String, VerilogError> {
    finish(&netlist_of(raw, prefix)?, prefix, header, waivers)
}

/// Any block's Verilog under `prefix` (its own tests: lint and synthesis).
pub fn block_verilog<U: Block>(
    mut uut: U,
    prefix: &str,
    waivers: &[Waiver],
) -> Result<String, VerilogError> {
    uut.connect_all();
    emit(&generate_verilog(&uut), prefix, &[], waivers)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renaming_is_checked_one_to_one() {
        let v = "module top(a$b, a_b);\nendmodule\nmodule top$c(a_b);\nendmodule\n";
        assert!(matches!(
            rename(v, "p"),
            Err(VerilogError::NameCollision { .. })
        ));
        // The same name in two modules is two names.
        assert!(rename(
            "module top(a$b);\nendmodule\nmodule top$c(a_b);\nendmodule\n",
            "p"
        )
        .is_ok());
        // Two modules that would merge.
        assert!(rename(
            "module top$a$b();\nendmodule\nmodule top$a_b();\nendmodule\n",
            "p"
        )
        .is_err());
        assert_eq!(
            rename("module top$x$y(q$d); $signed(q$d) 32'h50\n", "p").unwrap(),
            "module p_x_y(q_d); $signed(q_d) 32'h50\n"
        );
        // Comments keep their words.
        assert_eq!(
            rename("// on top of top$a\ntop$a x; /* top */\n", "p").unwrap(),
            "// on top of top$a\np_a x; /* top */\n"
        );
    }

    #[test]
    fn a_stale_waiver_is_an_error() {
        let w = Waiver {
            module: "",
            signal: "missing",
            note: Note::LintOff("UNUSEDSIGNAL"),
            reason: "test",
        };
        let v = "module top(a);\n    input wire a;\nendmodule\n";
        assert_eq!(
            annotate(v, "top", &[w]),
            Err(VerilogError::StaleWaiver {
                rule: "UNUSEDSIGNAL",
                module: "",
                signal: "missing"
            })
        );
    }
}
