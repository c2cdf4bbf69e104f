//! `snapgen demo`: the main job on built-in defaults.
//!
//! Plans seed 001's Table 1 move (12π rad in 1.8 s, γ = 0.4, φ = 0.25) and, from where it ends,
//! Table 3's move back to 0; then a seed 000 move in which every limit is active. Prints the
//! plans, checks that each lands exactly on its target at rest, and writes one plot per move.
//! Then generates the core's Verilog, builds it with Verilator, plays the three moves on it
//! clock by clock against the model, and prints the mismatch count and Yosys' resource counts.

use std::f64::consts::PI;
use std::path::Path;

use anyhow::{ensure, Context};
use snapgen_model::{plan, plan_from, Format, Method, MoveRequest, Plan, DEFAULT_FORMAT};
use snapgen_sim::cosim::CosimConfig;
use snapgen_sim::moves::MoveSpec;

use crate::plot;
use crate::report::PlanReport;

fn show(name: &str, p: &Plan, out: &Path) -> anyhow::Result<()> {
    println!("== {name}");
    print!("{}", PlanReport::new(p).human());
    ensure!(
        p.final_state.is_at_rest() && p.final_error_lsb() == 0,
        "{name}: the model did not end exactly on target at rest"
    );
    let svg = out.join(format!("{name}.svg"));
    plot::write_svg(p, name, &svg).map_err(|e| anyhow::anyhow!("{}: {e}", svg.display()))?;
    println!("  plot: {}\n", svg.display());
    Ok(())
}

/// Runs the demo, writing plots into `out`.
pub fn run(out: &Path) -> anyhow::Result<()> {
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
        back.final_state.x == f.home_raw(),
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
    let files = crate::hw::write_verilog(&out.join("verilog"))?;
    println!(
        "  Verilog: {} (Verilator waivers and hints {})",
        files.verilog.display(),
        files.waivers.display()
    );
    let spec = |distance: f64, method: Method, ts: f64| MoveSpec {
        request: MoveRequest { distance, method },
        ts,
        tick_div: 0,
        stop_after: None,
        soft_stop_after: None,
    };
    let moves = vec![
        spec(12.0 * PI, seed001, f.ts),
        spec(-12.0 * PI, seed001, f.ts),
        spec(0.5, seed000.request.method, f.ts),
    ];
    let verilog = std::fs::read_to_string(&files.verilog)?;
    let mut cfg = CosimConfig::fixed(moves);
    cfg.mismatch_vcd = out.join("cosim-mismatch.vcd");
    let r = snapgen_sim::cosim::run(&verilog, &cfg)?;
    println!(
        "  Verilator co-simulation: {} moves, {} ticks ({} clocks), {} mismatches{}",
        r.moves,
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
        r.planner_disagreements == 0,
        "the core did not end where the planner said"
    );
    let res = crate::yosys::synth_xilinx(&files.verilog)?;
    println!("  Yosys synth_xilinx (xc7, flattened): {}", res.summary());
    ensure!(res.latches() == 0, "the core synthesised with latches");
    Ok(())
}
