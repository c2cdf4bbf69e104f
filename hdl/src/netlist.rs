//! Text passes over rust-hdl's Verilog that make it a netlist a reader can follow: one
//! register per `always` line instead of one wrapper module per register, and a design that
//! instantiates another design's top (the I/O top's motion core) instead of carrying a
//! renamed copy of it.
//!
//! rust-hdl 0.46 writes every `DFF` instance as a module of its own (`d`, `q`, `clock`, an
//! `initial` and one `always`), and `DFFWithInit` as a module around one of those (the stored
//! value XORed with the initial value). [`inline_registers`] replaces each instance of such a
//! module with the register itself, declared with its initial value where the parent declared
//! the `q` wire, and drops the modules no longer used. The behaviour is the same on every
//! clock (the co-simulations compare the result with the model); the passes check every
//! pattern they rely on and fail rather than guess.

use std::collections::BTreeMap;

use crate::emit::VerilogError;

/// One module of a file: its name and its lines (from `module` to `endmodule`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Module {
    /// Its name.
    pub name: String,
    /// Its text, `module …` to `endmodule …` with the newline.
    pub text: String,
}

/// A file split into its modules; text between modules (comments, directives) is kept with
/// the module that follows it, and what follows the last module in `tail`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Netlist {
    /// Each module with the text before it.
    pub modules: Vec<(String, Module)>,
    /// Text after the last module.
    pub tail: String,
}

impl Netlist {
    /// Splits `verilog` into its modules.
    pub fn parse(verilog: &str) -> Result<Self, VerilogError> {
        let mut n = Netlist::default();
        let mut before = String::new();
        let mut current: Option<Module> = None;
        for line in verilog.split_inclusive('\n') {
            let t = line.trim_start();
            if let Some(m) = current.as_mut() {
                m.text.push_str(line);
                if t.starts_with("endmodule") {
                    n.modules
                        .push((std::mem::take(&mut before), current.take().expect("open")));
                }
            } else if let Some(rest) = t.strip_prefix("module ") {
                let end = rest
                    .find(['(', ' ', ';'])
                    .ok_or(VerilogError::Netlist("a module line without a name"))?;
                current = Some(Module {
                    name: rest[..end].to_string(),
                    text: line.to_string(),
                });
            } else {
                before.push_str(line);
            }
        }
        if current.is_some() {
            return Err(VerilogError::Netlist("a module without endmodule"));
        }
        n.tail = before;
        Ok(n)
    }

    /// The file again.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for (before, m) in &self.modules {
            s.push_str(before);
            s.push_str(&m.text);
        }
        s.push_str(&self.tail);
        s
    }

    /// The module called `name`.
    pub fn module(&self, name: &str) -> Option<&Module> {
        self.modules.iter().map(|(_, m)| m).find(|m| m.name == name)
    }
}

/// What a register module stores: its width (as written in `[w:0]`, empty for one bit) and its
/// initial value (a Verilog constant).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Register {
    range: String,
    init: String,
}

/// The body lines of a module (trimmed, without blanks and comments).
fn body(m: &Module) -> Vec<&str> {
    m.text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .collect()
}

/// `m` as a plain register: `module N(d,q,clock)`, an `initial` of `q`, one `always` that
/// copies `d` into `q`, nothing else.
fn plain_register(m: &Module) -> Option<Register> {
    let b = body(m);
    let header = format!("module {}(d,q,clock);", m.name);
    let range = b
        .get(2)?
        .strip_prefix("output reg")?
        .trim()
        .strip_suffix("q;")?
        .trim();
    let init = b.get(5)?.strip_prefix("q = ")?.strip_suffix(';')?;
    let want = [
        header.as_str(),
        "input wire  d;",
        "",
        "input wire  clock;",
        "initial begin",
        "",
        "end",
        "always @(posedge clock) begin",
        "q <= d;",
        "end",
    ];
    if b.len() != 11 || !b[10].starts_with("endmodule") {
        return None;
    }
    for (k, w) in want.iter().enumerate() {
        if w.is_empty() {
            continue;
        }
        // The input's width is the output's.
        let w = if k == 1 && !range.is_empty() {
            format!("input wire  {range} d;")
        } else {
            w.to_string()
        };
        if b[k] != w {
            return None;
        }
    }
    Some(Register {
        range: range.to_string(),
        init: init.to_string(),
    })
}

/// `m` as rust-hdl's register with an initial value: a plain register of initial value 0
/// holding `d ^ init`, its output `q ^ init`.
fn init_register(m: &Module, plain: &BTreeMap<String, Register>) -> Option<Register> {
    let b = body(m);
    let header = format!("module {}(d,q,clock);", m.name);
    if b.first()? != &header.as_str() {
        return None;
    }
    let range = b
        .get(2)?
        .strip_prefix("output reg")?
        .trim()
        .strip_suffix("q;")?
        .trim();
    let init = b
        .get(4)?
        .strip_prefix("localparam  init = ")?
        .strip_suffix(';')?;
    let child = b.get(7)?.strip_suffix(" dff(")?;
    let inner = plain.get(child)?;
    let zero = inner.init.split('\'').nth(1).is_some_and(|v| {
        v.trim_start_matches(['h', 'b', 'd'])
            .chars()
            .all(|c| c == '0')
    });
    let sp = |r: &str| {
        if r.is_empty() {
            String::new()
        } else {
            format!("{r} ")
        }
    };
    let want = [
        format!("input wire  {}d;", sp(range)),
        format!("reg  {}dff_d;", sp(range)),
        format!("wire  {}dff_q;", sp(range)),
        ".d(dff_d),".to_string(),
        ".q(dff_q),".to_string(),
        ".clock(clock)".to_string(),
        ");".to_string(),
        "always @(*) begin".to_string(),
        "q = dff_q ^ init;".to_string(),
        "dff_d = d ^ init;".to_string(),
        "end".to_string(),
    ];
    let got = [
        b[1], b[5], b[6], b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15],
    ];
    if !zero || inner.range != range || b.len() != 17 || got.iter().zip(&want).any(|(g, w)| g != w)
    {
        return None;
    }
    Some(Register {
        range: range.to_string(),
        init: init.to_string(),
    })
}

/// Every instance of a register module replaced by the register it holds (see the module
/// documentation); the register modules no longer instantiated are dropped.
pub fn inline_registers(verilog: &str) -> Result<String, VerilogError> {
    let mut n = Netlist::parse(verilog)?;
    let mut plain = BTreeMap::new();
    for (_, m) in &n.modules {
        if let Some(r) = plain_register(m) {
            plain.insert(m.name.clone(), r);
        }
    }
    let mut registers = plain.clone();
    for (_, m) in &n.modules {
        if let Some(r) = init_register(m, &plain) {
            registers.insert(m.name.clone(), r);
        }
    }
    for (_, m) in n.modules.iter_mut() {
        if registers.contains_key(&m.name) {
            continue;
        }
        m.text = inline_in(&m.text, &registers)?;
    }
    // Drop the register modules nothing instantiates any more.
    let used = |name: &str, n: &Netlist| {
        n.modules.iter().any(|(_, m)| {
            m.text
                .lines()
                .any(|l| l.trim_start().starts_with(&format!("{name} ")))
        })
    };
    let mut k = 0;
    while k < n.modules.len() {
        let name = n.modules[k].1.name.clone();
        if registers.contains_key(&name) && !used(&name, &n) {
            let (before, _) = n.modules.remove(k);
            // Keep what stood before the dropped module (blank lines go with it).
            if let Some((b, _)) = n.modules.get_mut(k) {
                let trimmed = before.trim_matches('\n');
                if !trimmed.is_empty() {
                    b.insert_str(0, &before);
                }
            }
        } else {
            k += 1;
        }
    }
    Ok(n.text())
}

/// One module's text with its register instances inlined.
fn inline_in(text: &str, registers: &BTreeMap<String, Register>) -> Result<String, VerilogError> {
    let lines: Vec<&str> = text.lines().collect();
    // Instance name → (register, d signal, q signal).
    let mut found: Vec<(String, Register, String, String, String)> = Vec::new();
    let mut out: Vec<String> = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let t = lines[k].trim();
        let inst = t.split_once(' ').and_then(|(module, rest)| {
            let reg = registers.get(module)?;
            let name = rest.strip_suffix('(')?;
            Some((reg.clone(), name.to_string()))
        });
        if let Some((reg, name)) = inst {
            let port = |l: Option<&&str>, p: &str| -> Option<String> {
                let s = l?.trim().strip_prefix(&format!(".{p}("))?;
                Some(s.trim_end_matches(',').strip_suffix(')')?.to_string())
            };
            let d = port(lines.get(k + 1), "d");
            let q = port(lines.get(k + 2), "q");
            let c = port(lines.get(k + 3), "clock");
            let end = lines.get(k + 4).map(|l| l.trim());
            let (Some(d), Some(q), Some(c), Some(");")) = (d, q, c, end) else {
                return Err(VerilogError::Netlist(
                    "a register instance of an unknown shape",
                ));
            };
            let indent = &lines[k][..lines[k].len() - lines[k].trim_start().len()];
            out.push(format!(
                "{indent}always @(posedge {c}) {q} <= {d};   // register {name}"
            ));
            found.push((name, reg, d, q, c));
            k += 5;
            continue;
        }
        out.push(lines[k].to_string());
        k += 1;
    }
    // The q signals become registers with their initial values.
    for (_, reg, _, q, _) in &found {
        let sp = if reg.range.is_empty() {
            String::new()
        } else {
            format!("{} ", reg.range)
        };
        let decl = format!("wire  {sp}{q};");
        let at = out
            .iter()
            .position(|l| l.trim() == decl)
            .ok_or(VerilogError::Netlist(
                "a register's q is not declared as a wire",
            ))?;
        let indent = out[at][..out[at].len() - out[at].trim_start().len()].to_string();
        out[at] = format!("{indent}reg  {sp}{q} = {};", reg.init);
    }
    let mut s = out.join("\n");
    s.push('\n');
    Ok(s)
}

/// `io` (a design that contains `core`'s top as a child under the prefix `child_prefix`)
/// with that copy's modules dropped and its instance made an instance of `core_top`. Fails
/// unless every dropped module is, under the other prefix, the module `core` holds.
pub fn use_child_design(
    io: &str,
    child_prefix: &str,
    core: &str,
    core_top: &str,
) -> Result<String, VerilogError> {
    let mut n = Netlist::parse(io)?;
    let c = Netlist::parse(core)?;
    let is_copy =
        |name: &str| name == child_prefix || name.starts_with(&format!("{child_prefix}_"));
    for (_, m) in n.modules.iter().filter(|(_, m)| is_copy(&m.name)) {
        let renamed = m.name.replacen(child_prefix, core_top, 1);
        let want = c.module(&renamed).ok_or(VerilogError::Netlist(
            "the copy has a module the design has not",
        ))?;
        let copy = m.text.replace(child_prefix, core_top);
        if copy != want.text {
            let line = copy
                .lines()
                .zip(want.text.lines())
                .find(|(a, b)| a != b)
                .map_or_else(String::new, |(a, b)| format!("{a:?} against {b:?}"));
            return Err(VerilogError::CopyDiffers {
                module: renamed,
                line,
            });
        }
    }
    let copies = n.modules.iter().filter(|(_, m)| is_copy(&m.name)).count();
    if copies != c.modules.len() {
        return Err(VerilogError::Netlist(
            "the copy and the design differ in modules",
        ));
    }
    n.modules.retain(|(_, m)| !is_copy(&m.name));
    let mut replaced = 0;
    for (_, m) in n.modules.iter_mut() {
        let mut lines: Vec<String> = m.text.lines().map(str::to_string).collect();
        for l in lines.iter_mut() {
            let t = l.trim_start();
            if let Some(rest) = t.strip_prefix(&format!("{child_prefix} ")) {
                let indent = l[..l.len() - t.len()].to_string();
                *l = format!("{indent}{core_top} {rest}");
                replaced += 1;
            }
        }
        m.text = lines.join("\n") + "\n";
    }
    if replaced != 1 {
        return Err(VerilogError::Netlist(
            "the child design is not instantiated exactly once",
        ));
    }
    Ok(n.text())
}

#[cfg(test)]
mod tests {
    use super::*;

    const DFF: &str = "module p_r(d,q,clock);\n    \n    // Module arguments\n    input wire  [3:0] d;\n    output reg  [3:0] q;\n    input wire  clock;\n    \n    // Update code (custom)\n    initial begin\n       q = 4'h5;\n    end\n    \n    always @(posedge clock) begin\n       q <= d;\n    end\n          \nendmodule // p_r\n";

    #[test]
    fn a_register_module_becomes_its_register() {
        let parent = "module p(clock,o);\n    input wire  clock;\n    output reg  [3:0] o;\n    reg  [3:0] r_d;\n    wire  [3:0] r_q;\n    p_r r(\n        .d(r_d),\n        .q(r_q),\n        .clock(clock)\n    );\n    always @(*) begin\n        r_d = r_q + 4'd1;\n        o = r_q;\n    end\nendmodule // p\n";
        let v = format!("{parent}{DFF}");
        let got = inline_registers(&v).unwrap();
        assert!(got.contains("reg  [3:0] r_q = 4'h5;"), "{got}");
        assert!(
            got.contains("always @(posedge clock) r_q <= r_d;   // register r"),
            "{got}"
        );
        assert!(!got.contains("module p_r"), "{got}");
        // A shape it does not know is left alone, never guessed.
        let odd = DFF.replace("q <= d;", "q <= ~d;");
        assert_eq!(
            plain_register(&Netlist::parse(&odd).unwrap().modules[0].1),
            None
        );
    }
}
