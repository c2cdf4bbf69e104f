//! `snapgen synth`: the board top and the motion core synthesised with Yosys — resources,
//! share of the device, logic-only timing; exit 1 if the motion core is over its budget. With
//! `--routed`, the same design also placed and routed here on an ECP5-85F (the ULX3S's pins,
//! the open flow of `snapgen build`) at the design's clock, and its routed Fmax printed next to
//! the logic-only figure: Vivado's routing of a Xilinx part is not available here.

use crate::args::{BoardArgs, TimingArgs};

/// Synthesise with Yosys.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    board: BoardArgs,
    /// Also place and route the same design on an ECP5-85F (the ULX3S's pins; Yosys
    /// synth_ecp5 and nextpnr-ecp5, a few minutes) at the design's clock and print its routed
    /// Fmax, closing or not.
    #[arg(long)]
    routed: bool,
    #[command(flatten)]
    timing: TimingArgs,
}

/// The built-in board the routed figure is measured on.
const ROUTED_ON: &str = "ulx3s";

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let b = a.board.load()?;
    let (t, d) = a
        .timing
        .resolve(Some(b.fabric_clock_hz()), b.input_polarity)?;
    let r = crate::fpga::synth(&b, &t, &d)?;
    print!("{}", r.table());
    if a.routed {
        let ecp5 = crate::board_spec::builtin(ROUTED_ON)
            .map_err(|e| crate::error::InputError::Board(e.to_string()))?;
        let plan = crate::fpga::build_plan(&ecp5, &t, &d)?;
        let crate::fpga::Runner::Ecp5 { steps, clock_hz } = &plan.runner else {
            anyhow::bail!("the {ROUTED_ON} build is not the open flow");
        };
        let dir = std::env::temp_dir().join(format!("snapgen-synth-routed-{}", std::process::id()));
        plan.write(&dir)?;
        let routed = crate::ecp5::route_report(steps, &dir, *clock_hz)?;
        println!(
            "routed: the same design on the {} (speed {}, the {} board's pins and PLL, nextpnr seed {}) at the design's {:.2} MHz: Fmax {:.2} MHz, {} ({:+.0} % of the period); logic-only on the {} (Yosys sta, no routing): {:.2} ns ({:.1} MHz); Vivado's routed timing of the {} is not available here (nextpnr's log: {})",
            ecp5.device,
            ecp5.speed_grade,
            ecp5.name,
            crate::ecp5::SEED,
            routed.target_mhz,
            routed.fmax_mhz,
            if routed.pass { "closes" } else { "does not close" },
            100.0 * routed.margin(),
            b.device,
            r.full.path_ns,
            1e3 / r.full.path_ns,
            b.device,
            dir.join("nextpnr.log").display()
        );
    }
    let v = r.violations();
    if !v.is_empty() {
        anyhow::bail!("synthesis check failed: {}", v.join("; "));
    }
    println!("motion core within budget");
    Ok(())
}
