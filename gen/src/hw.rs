//! `snapgen verilog` and `snapgen cosim`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use snapgen_sim::cosim::{self, CosimConfig, CosimReport};

/// Files `snapgen verilog` writes.
pub struct VerilogFiles {
    /// The motion core.
    pub verilog: PathBuf,
    /// The I/O top (UART command interface, motion core, encoder, PWM) for 125 MHz.
    pub io_top: PathBuf,
    /// The Verilator waiver file.
    pub waivers: PathBuf,
}

/// Writes the motion core's Verilog (`top.v`), the I/O top (`io_top.v`) and their Verilator
/// waivers (`verilator.vlt`).
pub fn write_verilog(out: &Path) -> anyhow::Result<VerilogFiles> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let verilog = out.join("top.v");
    let io_top = out.join("io_top.v");
    let waivers = out.join("verilator.vlt");
    std::fs::write(
        &io_top,
        snapgen_hdl::verilog::io_top_verilog(snapgen_hdl::io_top::IoTopConfig::default()),
    )
    .with_context(|| format!("cannot write {}", io_top.display()))?;
    std::fs::write(&verilog, snapgen_hdl::verilog::motion_core_verilog())
        .with_context(|| format!("cannot write {}", verilog.display()))?;
    std::fs::write(&waivers, snapgen_sim::build::WAIVERS_VLT)
        .with_context(|| format!("cannot write {}", waivers.display()))?;
    Ok(VerilogFiles {
        verilog,
        io_top,
        waivers,
    })
}

/// Runs a co-simulation and prints its report; returns it.
pub fn cosim(cfg: &CosimConfig, bench: bool) -> anyhow::Result<CosimReport> {
    let verilog = snapgen_hdl::verilog::motion_core_verilog();
    let r = cosim::run(&verilog, cfg)?;
    println!(
        "co-simulation: {} moves ({} aborted midway, {} with a controlled stop, {} skipped), {} ticks in {} clocks compared, {} mismatches{}",
        r.moves,
        r.stopped,
        r.soft_stopped,
        r.skipped,
        r.ticks,
        r.clocks,
        u32::from(r.mismatch.is_some()),
        if r.cached_build { " (cached Verilator build)" } else { "" }
    );
    println!(
        "throughput: {:.1} M ticks/s ({:.3} s)",
        r.ticks_per_second() / 1e6,
        r.seconds
    );
    if let Some(m) = &r.mismatch {
        println!("{m}");
    }
    if r.planner_disagreements > 0 {
        println!(
            "{} moves ended where the planner did not predict",
            r.planner_disagreements
        );
    }
    if let Some(v) = &r.vcd {
        println!("waves: {}", v.display());
    }
    if bench {
        let m = cosim::run_model_only(cfg);
        println!(
            "model alone: {:.1} M ticks/s; co-sim / model throughput ratio: {:.3}",
            m.ticks_per_second() / 1e6,
            r.ticks_per_second() / m.ticks_per_second()
        );
    }
    Ok(r)
}
