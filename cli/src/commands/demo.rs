//! `snapgen demo`: the main job on built-in defaults.
//!
//! Plans seed 001's Table 1 move (12π rad in 1.8 s, γ = 0.4, φ = 0.25) and, from where it ends,
//! Table 3's move back to 0; then a seed 000 move in which every limit is active. Prints the
//! plans, checks that each lands exactly on its target at rest, and writes one plot per move.
//! Then generates the core's Verilog, builds it with Verilator, plays the three moves and a
//! fourth cut by the fabric's controlled stop on it clock by clock against the model, runs the
//! I/O top against the device model under random command streams, and prints the mismatch
//! counts and Yosys' resource counts. Then seed 000's Figure 3 online on the fabric, seed
//! 001's experiment on the closed loop, and a small G-code part on the Verilated path core
//! (several axes along one path, the interpolator in fabric).

use std::f64::consts::PI;
use std::path::Path;

use anyhow::{ensure, Context};
use snapgen_model::format::Quantity;
use snapgen_model::stop::StopLimits;
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plan::{plan, plan_from, Method, MoveRequest, Plan};
use snapgen_sim::cosim::CosimConfig;
use snapgen_sim::moves::MoveSpec;

use crate::report::PlanReport;
use crate::svg;

/// The main job on built-in defaults.
#[derive(clap::Args)]
pub struct Args {
    /// Directory for the plots.
    #[arg(long, default_value = "out/demo")]
    out: std::path::PathBuf,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    demo(&a.out)
}

fn show(name: &str, p: &Plan, out: &Path) -> anyhow::Result<()> {
    println!("== {name}");
    let report = PlanReport::new(p);
    print!("{}", report.human());
    // Checked on the program integrated independently of the planner.
    let end = crate::report::integrate_plan(p).end;
    ensure!(
        end.at_rest() && report.final_error_lsb == 0,
        "{name}: the program does not end exactly on target at rest"
    );
    let svg = out.join(format!("{name}.svg"));
    svg::write_svg(p, name, &svg).map_err(|e| anyhow::anyhow!("{}: {e}", svg.display()))?;
    println!("  plot: {}\n", svg.display());
    Ok(())
}

/// Runs the demo, writing plots into `out`.
pub fn demo(out: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let f: Format = DEFAULT_FORMAT;
    println!(
        "snapgen demo: Ts = {} s, output LSB = {} units, registers x/v/a/j/d = {:?} bits\n",
        f.ts,
        f.position_lsb,
        f.widths.as_array()
    );
    let seed001 = Method::Duration {
        duration: 1.8,
        gamma: 0.4,
        phi: 0.25,
    };
    let there = plan(
        &MoveRequest {
            distance: 12.0 * PI,
            method: seed001,
        },
        &f,
    )?;
    show("seed001_table1", &there, out)?;
    let back = plan_from(
        &MoveRequest {
            distance: -12.0 * PI,
            method: seed001,
        },
        &f,
        there.final_state,
    )?;
    show("seed001_table3_return", &back, out)?;
    ensure!(
        crate::report::integrate_plan(&back).end.x == ethnum::I256::from(f.home_raw()),
        "the return move did not come back to exactly the start register"
    );
    println!("  round trip 0 -> 12π -> 0 ends on the start register bit for bit\n");
    let seed000 = plan(
        &MoveRequest {
            distance: 0.5,
            method: Method::Order4 {
                vmax: 1.0,
                amax: 5.0,
                jmax: 50.0,
                dmax: 1000.0,
            },
        },
        &f,
    )?;
    show("seed000_all_limits", &seed000, out)?;

    // The same three moves on the generated core, clock by clock against the model.
    println!("== fabric");
    let design = snapgen_hdl::verilog::io_design(&snapgen_model::device::Design::from_timing(
        &f,
        &snapgen_model::timing::Timing::default(),
    )?);
    let files = super::verilog::write_verilog(&out.join("verilog"), &design)?;
    println!(
        "  Verilog: {} and {}",
        files.core.display(),
        files.io_top.display()
    );
    let spec = |distance: f64, method: Method, ts: f64| {
        MoveSpec::plain(MoveRequest { distance, method }, ts)
    };
    // The seed 000 move once more, stopped by the fabric's controlled stop 20 000 ticks in
    // (mid-move), within the move's own acceleration and jerk limits.
    let raw = |q: Quantity, v: f64| (v * f.scale(q)).floor() as i128;
    let stopped = MoveSpec {
        stop_after: Some(20_000),
        stop_limits: StopLimits {
            jerk: raw(Quantity::Jerk, 50.0),
            accel: raw(Quantity::Acceleration, 5.0),
        },
        ..spec(-0.5, seed000.request.method, f.ts)
    };
    // The seed 000 move back, replanned on the way: program swaps at random ticks, each
    // planned online from the state at its tick (docs/PROTOCOL.md, SWAP_AT).
    let replanned = MoveSpec {
        replans: 4,
        replan_seed: 2026,
        ..spec(-0.5, seed000.request.method, f.ts)
    };
    let moves = vec![
        spec(12.0 * PI, seed001, f.ts),
        spec(-12.0 * PI, seed001, f.ts),
        spec(0.5, seed000.request.method, f.ts),
        stopped,
        replanned,
    ];
    let verilog = std::fs::read_to_string(&files.core)?;
    let mut cfg = CosimConfig::fixed(moves);
    cfg.mismatch_vcd = out.join("cosim-mismatch.vcd");
    let r = snapgen_sim::cosim::run(&verilog, &cfg)?;
    println!(
        "  Verilator co-simulation: {} moves ({} with a controlled stop, {} at rest after it; {} program swaps replanning a move at random ticks), {} ticks ({} clocks), {} mismatches{}",
        r.moves,
        r.stopped,
        r.stopped - r.stops_not_at_rest,
        r.replans,
        r.ticks,
        r.clocks,
        u32::from(r.mismatch.is_some()),
        if r.cached_build {
            " (cached build)"
        } else {
            ""
        }
    );
    if let Some(m) = &r.mismatch {
        anyhow::bail!("{m}; waves in {}", cfg.mismatch_vcd.display());
    }
    ensure!(
        r.planner_disagreements == 0 && r.stops_not_at_rest == 0,
        "the core did not end where the planner said, or a stop did not end at rest"
    );
    ensure!(
        r.replans > 0 && r.swap_faults() == 0,
        "no program swap was played, or the core armed a late swap or refused a timely one"
    );
    // The I/O top (UART command interface, axis state machine, limit switches, emergency
    // stop, watchdog) against the device model, under random command streams.
    let io = snapgen_sim::io_cosim::run(
        &snapgen_sim::io_cosim::cosim_design(),
        &snapgen_sim::io_cosim::IoCosimConfig {
            mismatch_vcd: out.join("io-mismatch.vcd"),
            ..snapgen_sim::io_cosim::IoCosimConfig::new(400_000, 1, 2)
        },
    )?;
    println!(
        "  I/O top against the device model: {}; {} mismatches",
        snapgen_sim::io_cosim::describe(&io),
        u32::from(io.mismatch.is_some())
    );
    if let Some(m) = &io.mismatch {
        anyhow::bail!("{m}; waves in {}", out.join("io-mismatch.vcd").display());
    }
    let res = crate::yosys::synth(
        std::slice::from_ref(&files.core),
        snapgen_hdl::verilog::CORE_PREFIX,
        "xc7",
    )?;
    println!(
        "  Yosys synth_xilinx (xc7, flattened, the stop unit kept apart): {}; logic-only path {:.2} ns",
        res.resources.summary(),
        res.path_ns
    );
    for (name, m) in &res.modules {
        println!(
            "    {name}: {}; logic-only path {:.2} ns",
            m.resources.summary(),
            m.path_ns
        );
    }
    ensure!(
        res.resources.latches() == 0,
        "the core synthesised with latches"
    );

    // Online replanning through the PLCopen host axis: seed 000's Figure 3 on the Verilated I/O
    // top (the device model in lockstep, every output compared), at 125 MHz and 115 200 baud.
    println!("\n== online: seed 000 Figure 3 through the PLCopen host axis on the fabric (`snapgen online --scenario seed000-fig3 --board fabric`)");
    let sc = crate::scenario::Scenario::Seed000Fig3;
    let played = super::online::play(
        sc.script(None)?,
        &super::online::Target {
            board: super::online::BoardKind::Fabric,
            port: None,
            uio: None,
            baud: snapgen_model::timing::DEFAULT_BAUD,
        },
    )?;
    println!("{}", super::online::describe(&played));
    super::online::write_svg(
        &played,
        &sc.title(None),
        &out.join("seed000_fig3_online.svg"),
    )?;
    ensure!(
        played.mismatches == Some(0),
        "the fabric and the model disagreed during the online scenario"
    );
    let r = &played.report;
    let f0 = r.axis.settings.format;
    // Case (a): every block done; case (b): the first block aborted while it moves.
    use snapgen_host::axis::Outcome;
    let outcomes: Vec<_> = r.axis.commands.iter().map(|c| c.outcome.clone()).collect();
    let want = [
        Outcome::Done,
        Outcome::Done,
        Outcome::Done,
        Outcome::CommandAborted,
        Outcome::Done,
    ];
    ensure!(
        outcomes == want
            && f0.output_lsb(r.last.x) == crate::scenario::cell_mm(10.0, &f0)
            && (r.last.v, r.last.a, r.last.j) == (0, 0, 0),
        "the online scenario ended with outcomes {outcomes:?} (want {want:?}) or not at rest on 10 mm"
    );

    // Seed 001's experiment, short form, on the closed loop: the Verilated I/O top drives a
    // simulated maxon RE 40 with the paper's load; the device model compares every clock.
    println!("\n== closed loop: seed 001's experiment (short form: `snapgen experiment seed001` runs it whole)");
    let o = super::experiment::Options {
        board: super::experiment::Board::Fabric,
        plant: snapgen_plant::PlantParams::default_plant(),
        clock_hz: super::experiment::EXPERIMENT_CLOCK_HZ,
        ts: f.ts,
        pwm_hz: 20_000.0,
        loop_hz: 10_000.0,
        design: snapgen_plant::gains::LoopDesign::default(),
        host_loop: true,
        transport_delay_s: 0.0,
        short: true,
        step_s: 1e-6,
        out: Some(out.join("seed001")),
    };
    let r = super::experiment::play(&o)?;
    print!("{}", super::experiment::table(&r));
    ensure!(
        r.mismatches == Some(0),
        "the closed loop's fabric and model disagreed"
    );
    ensure!(
        r.loops
            .iter()
            .all(|l| l.profiles.iter().all(|p| p.landed_exactly)),
        "a closed-loop move did not land on its plan"
    );

    // Several axes along one path (issue 22): a small part played by the axis group through
    // the host axis on the Verilated path core, the interpolator and a step/dir generator per
    // axis in fabric; the axes read from its step lines.
    println!("\n== several axes along one path: a small part on the Verilated path core (`snapgen path --gcode examples/demo_part.ngc --board path-core --lsb 1e-3`)");
    let part = out.join("demo_part.ngc");
    std::fs::write(&part, DEMO_PART).with_context(|| format!("cannot write {}", part.display()))?;
    let svg = out.join("demo_part_path_core.svg");
    let (part, svg) = (part.display().to_string(), svg.display().to_string());
    super::path::run_args(&[
        "--gcode",
        &part,
        "--board",
        "path-core",
        "--lsb",
        "1e-3",
        "--svg",
        &svg,
    ])?;
    Ok(())
}

/// The demo's G-code part (`examples/demo_part.ngc`).
const DEMO_PART: &str = include_str!("../../../examples/demo_part.ngc");
