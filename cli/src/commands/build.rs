//! `snapgen build`: a board build written for a board — board top, I/O top, motion core and
//! the toolchain's files. An ECP5 board's open flow (Yosys, nextpnr-ecp5, ecppack) runs here
//! and writes the `.bit`, failing when routed timing does not close (`--files-only` skips it);
//! a Xilinx board's Vivado build (XDC, TCL, Makefile) runs with `--run`. With `--host ps` a
//! Zynq board's build is the one in which its ARM is the host over AXI4-Lite ([`crate::zynq`]).

use std::path::PathBuf;

use crate::args::{BoardArgs, TimingArgs};
use crate::board_spec::Toolchain;

/// Write a board build.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    board: BoardArgs,
    /// Output directory [default: out/BOARD].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run a Vivado build (Xilinx boards; needs Vivado, $VIVADO or on the PATH). An ECP5
    /// board's open flow runs without it.
    #[arg(long)]
    run: bool,
    /// Write an ECP5 board's files only, without running its flow.
    #[arg(long)]
    files_only: bool,
    /// Where the host runs: `uart`, a PC on the fabric's UART (the UART top); `ps`, the Zynq's
    /// own ARM over AXI4-Lite (the AXI top in a Vivado block design with the PS7, a device-tree
    /// overlay for the UIO driver; boards with a [ps] table).
    #[arg(long, value_enum, default_value = "uart")]
    host: Host,
    #[command(flatten)]
    timing: TimingArgs,
}

/// Where the host runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Host {
    /// A PC on the fabric's UART.
    Uart,
    /// The Zynq's processing system, over AXI4-Lite.
    Ps,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let b = a.board.load()?;
    let ps = match (a.host, &b.ps) {
        (Host::Uart, _) => None,
        (Host::Ps, Some(ps)) => Some(ps),
        (Host::Ps, None) => {
            return Err(crate::error::InputError::Board(format!(
                "--host ps: the {} has no processing system (no [ps] table in its board file): use a Zynq board, e.g. --board zybo-z7-10, or drop --host ps",
                b.name
            ))
            .into())
        }
    };
    let clock = ps.map_or(b.fabric_clock_hz(), |ps| ps.fclk_hz);
    let (t, d) = a.timing.resolve(Some(clock), b.input_polarity)?;
    let run = match (b.toolchain(), a.run, a.files_only) {
        (Toolchain::Vivado, _, true) => {
            return Err(crate::error::InputError::Board(format!(
                "--files-only: the {} is built by Vivado, which runs only with --run: drop --files-only",
                b.name
            ))
            .into())
        }
        (Toolchain::OpenEcp5, true, _) => {
            return Err(crate::error::InputError::Board(format!(
                "--run: the {} is built here with the open toolchain, which runs by default (--files-only writes the files alone): drop --run",
                b.name
            ))
            .into())
        }
        (Toolchain::Vivado, run, _) => run,
        (Toolchain::OpenEcp5, _, files_only) => !files_only,
    };
    let out = a.out.unwrap_or_else(|| {
        PathBuf::from("out").join(match ps {
            Some(_) => format!("{}-ps", b.name),
            None => b.name.clone(),
        })
    });
    let plan = match ps {
        Some(ps) => crate::zynq::build_plan(&b, ps, &t, &d)?,
        None => crate::fpga::build_plan(&b, &t, &d)?,
    };
    for f in plan.write(&out)? {
        println!("wrote {}", f.display());
    }
    if !run {
        let needs = match (b.toolchain(), ps) {
            (Toolchain::Vivado, Some(_)) => "Vivado with its bootgen, and dtc",
            (Toolchain::Vivado, None) => "Vivado",
            (Toolchain::OpenEcp5, _) => "Yosys, nextpnr-ecp5 and ecppack",
        };
        println!("run it with: make -C {} (needs {needs})", out.display());
        return Ok(());
    }
    if let Some(r) = plan.run(&out)? {
        let top = b.top_name();
        let used = match (r.luts, r.ffs) {
            (Some(l), Some(f)) => format!(
                "; {} of {} LUT4 ({:.1} %), {} of {} FF",
                l.0,
                l.1,
                100.0 * l.0 as f64 / l.1 as f64,
                f.0,
                f.1
            ),
            _ => String::new(),
        };
        println!(
            "wrote {}: routed Fmax {:.2} MHz for the {:.2} MHz fabric clock on the {} (speed {}, nextpnr seed {}): closes, {:.0} % of the period spare{used}",
            out.join(format!("{top}.bit")).display(),
            r.fmax_mhz,
            r.target_mhz,
            b.device,
            b.speed_grade,
            crate::ecp5::SEED,
            100.0 * r.margin(),
        );
    }
    Ok(())
}
