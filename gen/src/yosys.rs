//! Runs Yosys `synth_xilinx -family xc7` on generated Verilog and reads its cell counts.
//! `$SNAPGEN_YOSYS` overrides the `yosys` binary.

use std::collections::BTreeMap;
use std::path::Path;
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

/// Synthesises `verilog_file` (top module `top`) for the 7 series and returns its cells.
pub fn synth_xilinx(verilog_file: &Path) -> anyhow::Result<Resources> {
    let yosys = std::env::var("SNAPGEN_YOSYS").unwrap_or_else(|_| "yosys".into());
    let script = format!(
        "read_verilog {}; synth_xilinx -family xc7 -top top -flatten -noiopad; stat",
        verilog_file.display()
    );
    let out = Command::new(&yosys)
        .args(["-q", "-p", &format!("{script}; tee -q -o /dev/stdout stat")])
        .output()
        .with_context(|| {
            format!(
                "{yosys} was not found: install Yosys (Debian/Ubuntu: apt-get install yosys) or point SNAPGEN_YOSYS at it"
            )
        })?;
    if !out.status.success() {
        bail!(
            "yosys failed on {}:\n{}",
            verilog_file.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    parse_stat(&String::from_utf8_lossy(&out.stdout))
        .with_context(|| format!("reading Yosys' statistics for {}", verilog_file.display()))
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
