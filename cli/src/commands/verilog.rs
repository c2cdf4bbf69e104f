//! `snapgen verilog`: the motion core (`snapgen_core.v`) and the I/O top (`snapgen_io.v`,
//! which instantiates it) for a clock, baud rate and Ts; with `--interpolator AXES` also the
//! path interpolator (`snapgen_interpolator.v`) and the path sequencer that drives it
//! (`snapgen_path_sequencer.v`), with `--step-dir` the step/dir generator
//! (`snapgen_step_dir.v`), with `--steppers AXES` the N-axis output stage for stepper drives
//! that instantiates them (`snapgen_path_steppers.v` and the three blocks' files), with
//! `--path-core AXES` the motion core on the path length driving that stage
//! (`snapgen_path_core.v` with the stage's files): issue 22's blocks, not yet in a board's
//! design; with `--axi` the AXI4-Lite top (`snapgen_axi.v`, issue 23).

use std::path::{Path, PathBuf};

use anyhow::Context;
use snapgen_model::device::Design;

use crate::args::TimingArgs;

/// Write the Verilog.
#[derive(clap::Args)]
pub struct Args {
    /// Output directory.
    #[arg(long, default_value = "out/verilog")]
    out: PathBuf,
    #[command(flatten)]
    timing: TimingArgs,
    /// Also write the path interpolator and the path sequencer for this many axes (1 to 8) as
    /// `snapgen_interpolator.v` and `snapgen_path_sequencer.v` (blocks of their own: no
    /// design instantiates them yet; the sequencer's `interpolator` outputs are the
    /// interpolator's inputs of the same names).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=8))]
    interpolator: Option<u8>,
    /// Also write the path steppers for this many axes (1 to 8), the N-axis output stage for
    /// stepper drives, with the blocks it instantiates: `snapgen_path_steppers.v`,
    /// `snapgen_path_sequencer.v`, `snapgen_interpolator.v`, `snapgen_step_dir.v` (not yet
    /// in a board's design).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=8), conflicts_with_all = ["interpolator", "step_dir"])]
    steppers: Option<u8>,
    /// Also write the path core for this many axes (1 to 8): the motion core on the path
    /// length driving the path steppers, `snapgen_path_core.v`, with the steppers' four files
    /// (it instantiates `snapgen_core`, written anyway; not yet in a board's design).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=8), conflicts_with_all = ["interpolator", "step_dir", "steppers"])]
    path_core: Option<u8>,
    /// Also write the step/dir generator of one axis as `snapgen_step_dir.v` (a block of its
    /// own: no design instantiates it yet).
    #[arg(long)]
    step_dir: bool,
    /// Also write the AXI4-Lite top, `snapgen_axi.v`: the station of `snapgen_io.v` behind an
    /// AXI4-Lite slave (register map: docs/AXI.md), for a host on a Zynq's ARM.
    #[arg(long)]
    axi: bool,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let (t, d) = a.timing.resolve(None, 0)?;
    let files = write_verilog(&a.out, &d)?;
    println!(
        "wrote {} and {} (clock {} Hz, {} baud = {} clocks per bit ({} baud), Ts {} s = {} clocks, design hash {:#010x})",
        files.core.display(),
        files.io_top.display(),
        t.clock_hz,
        t.baud,
        d.dividers.uart_divisor,
        d.baud,
        t.ts,
        u64::from(d.dividers.tick_div) + 1,
        d.design_hash
    );
    if let Some(axes) = a.interpolator {
        let prefix = snapgen_hdl::interpolator::INTERPOLATOR_PREFIX;
        let file = a.out.join(format!("{prefix}.v"));
        std::fs::write(&file, snapgen_hdl::interpolator::interpolator_verilog(axes))
            .with_context(|| format!("cannot write {}", file.display()))?;
        println!("wrote {} ({axes} axes)", file.display());
        let prefix = snapgen_hdl::path_sequencer::PATH_SEQUENCER_PREFIX;
        let file = a.out.join(format!("{prefix}.v"));
        std::fs::write(
            &file,
            snapgen_hdl::path_sequencer::path_sequencer_verilog(axes),
        )
        .with_context(|| format!("cannot write {}", file.display()))?;
        println!("wrote {} ({axes} axes)", file.display());
    }
    if let Some(axes) = a.steppers {
        for (name, text) in snapgen_hdl::path_steppers::path_steppers_sources(axes) {
            let file = a.out.join(&name);
            std::fs::write(&file, text)
                .with_context(|| format!("cannot write {}", file.display()))?;
            println!("wrote {} ({axes} axes)", file.display());
        }
    }
    if let Some(axes) = a.path_core {
        for (name, text) in snapgen_hdl::path_core::path_core_sources(axes) {
            if name == files.core.file_name().unwrap_or_default().to_string_lossy() {
                continue; // written above
            }
            let file = a.out.join(&name);
            std::fs::write(&file, text)
                .with_context(|| format!("cannot write {}", file.display()))?;
            println!("wrote {} ({axes} axes)", file.display());
        }
    }
    if a.axi {
        let file = a
            .out
            .join(format!("{}.v", snapgen_hdl::axi_top::AXI_PREFIX));
        std::fs::write(&file, snapgen_hdl::axi_top::axi_top_verilog(&d))
            .with_context(|| format!("cannot write {}", file.display()))?;
        println!(
            "wrote {} (AXI4-Lite top; read it with {} and {})",
            file.display(),
            files.core.display(),
            files.io_top.display()
        );
    }
    if a.step_dir {
        let file = a
            .out
            .join(format!("{}.v", snapgen_hdl::step_dir::STEP_DIR_PREFIX));
        std::fs::write(&file, snapgen_hdl::step_dir::step_dir_verilog())
            .with_context(|| format!("cannot write {}", file.display()))?;
        println!("wrote {}", file.display());
    }
    Ok(())
}

/// Files `snapgen verilog` writes.
pub struct VerilogFiles {
    /// The motion core (`snapgen_core.v`).
    pub core: PathBuf,
    /// The I/O top (`snapgen_io.v`: UART command interface, position controller, encoder, PWM, around `snapgen_core`).
    pub io_top: PathBuf,
}

/// Writes the motion core's Verilog (`snapgen_core.v`) and the I/O top of `design`
/// (`snapgen_io.v`, which instantiates `snapgen_core`). Each file carries its own lint
/// waivers; the I/O top needs both.
pub fn write_verilog(out: &Path, design: &Design) -> anyhow::Result<VerilogFiles> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let core = out.join(format!("{}.v", snapgen_hdl::verilog::CORE_PREFIX));
    let io_top = out.join(format!("{}.v", snapgen_hdl::verilog::IO_PREFIX));
    std::fs::write(&io_top, snapgen_hdl::verilog::io_top_verilog(design))
        .with_context(|| format!("cannot write {}", io_top.display()))?;
    std::fs::write(&core, snapgen_hdl::verilog::motion_core_verilog())
        .with_context(|| format!("cannot write {}", core.display()))?;
    Ok(VerilogFiles { core, io_top })
}
