//! Runs Yosys `synth_xilinx` on generated Verilog: cell counts and the logic-only critical path.
//! `$SNAPGEN_YOSYS` overrides the `yosys` binary.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

use anyhow::{bail, Context};

/// Cell counts after synthesis (flattened).
#[derive(Clone, Debug, Default)]
pub struct Resources {
    /// Every cell type and its count.
    pub cells: BTreeMap<String, u64>,
}

impl Resources {
    fn sum(&self, pred: impl Fn(&str) -> bool) -> u64 {
        self.cells
            .iter()
            .filter(|(k, _)| pred(k))
            .map(|(_, v)| v)
            .sum()
    }
    /// LUT1..LUT6 (logic LUTs; LUT RAM is counted in `lutram`).
    pub fn luts(&self) -> u64 {
        self.sum(|k| k.starts_with("LUT"))
    }
    /// Flip-flops (FDRE, FDSE, FDCE, FDPE).
    pub fn ffs(&self) -> u64 {
        self.sum(|k| k.starts_with("FD"))
    }
    /// CARRY4.
    pub fn carry4(&self) -> u64 {
        self.sum(|k| k == "CARRY4")
    }
    /// DSP48E1.
    pub fn dsp(&self) -> u64 {
        self.sum(|k| k.starts_with("DSP48"))
    }
    /// Distributed RAM cells (RAM32M, RAM64M, RAM32X1D, …).
    pub fn lutram(&self) -> u64 {
        self.sum(|k| k.starts_with("RAM") && !k.starts_with("RAMB"))
    }
    /// Block RAM cells (RAMB18E1, RAMB36E1).
    pub fn bram(&self) -> u64 {
        self.sum(|k| k.starts_with("RAMB"))
    }
    /// Block RAM in 36 kb units (a RAMB18 counts one half, rounded up).
    pub fn bram36(&self) -> u64 {
        self.sum(|k| k.starts_with("RAMB36")) + self.sum(|k| k.starts_with("RAMB18")).div_ceil(2)
    }
    /// Latches (must be 0).
    pub fn latches(&self) -> u64 {
        self.sum(|k| k.starts_with("LD"))
    }
    /// One line for people.
    pub fn summary(&self) -> String {
        format!(
            "{} LUT, {} FF, {} CARRY4, {} DSP48E1, {} LUT-RAM cells, {} BRAM, {} latches",
            self.luts(),
            self.ffs(),
            self.carry4(),
            self.dsp(),
            self.lutram(),
            self.bram(),
            self.latches()
        )
    }
}

/// Synthesis results of one design.
#[derive(Clone, Debug)]
pub struct SynthReport {
    /// Cells of the whole design.
    pub resources: Resources,
    /// Its logic-only critical path (ns), from Yosys `sta`: the longest of its blocks.
    pub path_ns: f64,
    /// Each block synthesis keeps apart (the flattened top, and every module marked
    /// `keep_hierarchy`), by module name: its own cells and critical path.
    pub modules: BTreeMap<String, ModuleReport>,
}

/// One block of a synthesised design.
#[derive(Clone, Debug, Default)]
pub struct ModuleReport {
    /// Its own cells (not those of the blocks kept apart inside it).
    pub resources: Resources,
    /// Its logic-only critical path (ns).
    pub path_ns: f64,
}

/// Runs Yosys on `files` with top `top`: cell counts and the logic-only critical path.
pub fn synth(files: &[PathBuf], top: &str, family: &str) -> anyhow::Result<SynthReport> {
    let yosys = std::env::var("SNAPGEN_YOSYS").unwrap_or_else(|_| "yosys".into());
    let reads: Vec<String> = files
        .iter()
        .map(|f| format!("read_verilog {}", f.display()))
        .collect();
    let script = format!(
        "{}; synth_xilinx -family {family} -top {top} -flatten -noiopad; tee -q -o /dev/stdout stat; \
         read_verilog -lib -specify +/xilinx/cells_sim.v; tee -q -o /dev/stdout sta",
        reads.join("; ")
    );
    let out = Command::new(&yosys)
        .args(["-q", "-p", &script])
        .output()
        .with_context(|| {
            format!("{yosys} was not found: install Yosys (Debian/Ubuntu: apt-get install yosys) or point SNAPGEN_YOSYS at it")
        })?;
    if !out.status.success() {
        bail!("yosys failed:\n{}", String::from_utf8_lossy(&out.stderr));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let resources = parse_stat(&text)?;
    let mut modules = parse_modules(&text)?;
    // One arrival time per block: "Latest arrival time in 'MODULE' is PS:".
    for l in text.lines() {
        let Some(rest) = l.trim().strip_prefix("Latest arrival time in '") else {
            continue;
        };
        let Some((name, tail)) = rest.split_once('\'') else {
            continue;
        };
        let ps: f64 = tail
            .rsplit(' ')
            .next()
            .and_then(|v| v.trim_end_matches(':').parse().ok())
            .context("an arrival time Yosys printed could not be read")?;
        modules.entry(name.to_string()).or_default().path_ns = ps / 1000.0;
    }
    let path_ns = modules
        .values()
        .map(|m| m.path_ns)
        .reduce(f64::max)
        .context("Yosys sta printed no arrival time")?;
    Ok(SynthReport {
        resources,
        path_ns,
        modules,
    })
}

/// The cells of every module block (`=== NAME ===`) of Yosys' `stat`, without the design
/// hierarchy's totals.
fn parse_modules(text: &str) -> anyhow::Result<BTreeMap<String, ModuleReport>> {
    let mut out = BTreeMap::new();
    for block in text.split("=== ").skip(1) {
        let Some((name, body)) = block.split_once(" ===") else {
            continue;
        };
        if name == "design hierarchy" {
            continue;
        }
        out.insert(
            name.to_string(),
            ModuleReport {
                resources: parse_stat(body)?,
                path_ns: 0.0,
            },
        );
    }
    Ok(out)
}

/// The cell counts of the last `stat` block in Yosys' output.
pub fn parse_stat(text: &str) -> anyhow::Result<Resources> {
    let mut r = Resources::default();
    // The last "Number of cells" block lists the flattened design's cells.
    let block = text.rsplit("Number of cells:").next().unwrap_or("");
    for line in block.lines().skip(1) {
        let mut it = line.split_whitespace();
        match (it.next(), it.next(), it.next()) {
            (Some(name), Some(n), None) => {
                if let Ok(n) = n.parse::<u64>() {
                    r.cells.insert(name.to_string(), n);
                }
            }
            _ => {
                if !r.cells.is_empty() && line.trim().is_empty() {
                    break;
                }
            }
        }
    }
    if r.cells.is_empty() {
        bail!("no cell counts in Yosys' output");
    }
    Ok(r)
}
