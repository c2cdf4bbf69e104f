//! The Verilated path core (the motion core on the path length driving the path steppers)
//! against its model, every output on every clock, and each axis's lines counted as its drive
//! counts them (needs Verilator; the README's test command installs it).

use snapgen_sim::build::{build_path_core, build_path_core_from, Opt};
use snapgen_sim::path_core::{run, PathCoreConfig, PortFault, PATH_CORE_OUTPUTS};

fn config(axes: u8, clocks: u64, seed: u64) -> PathCoreConfig {
    PathCoreConfig {
        axes,
        clocks,
        seed,
        fault: None,
    }
}

#[test]
fn fabric_model_and_drives_agree() {
    for (axes, clocks) in [(3, 10_000_000), (1, 2_000_000), (8, 5_000_000)] {
        let lib = build_path_core(axes, false).expect("the path core builds");
        let r = run(&lib.library, &config(axes, clocks, 20 + u64::from(axes))).expect("runs");
        eprintln!("{axes} axes: {r:?}");
        assert_eq!(r.mismatch, None);
        assert_eq!(r.violation, None);
        // Most runs are within the rate and checked; group stops and aborts are reached.
        assert!(
            r.runs > 3 && 2 * r.checked > r.runs && r.steps > 1_000,
            "{r:?}"
        );
        assert!(r.stops > 0 && r.swaps > 0, "{r:?}");
    }
}

#[test]
fn a_one_bit_fault_in_any_output_is_found() {
    let lib = build_path_core(2, false).expect("the path core builds");
    for (port, p) in PATH_CORE_OUTPUTS.iter().enumerate() {
        let clock = 30_011 + port as u64;
        let fault = PortFault {
            clock,
            port,
            bit: (port as u32 * 5) % p.bits,
        };
        let cfg = PathCoreConfig {
            fault: Some(fault),
            ..config(2, 60_000, 4)
        };
        let r = run(&lib.library, &cfg).expect("runs");
        let m = r.mismatch.unwrap_or_else(|| panic!("{} not found", p.name));
        assert_eq!((m.clock, m.port), (clock, p.name));
        assert_eq!(m.expected ^ m.actual, 1 << fault.bit);
    }
}

/// The stream reaches the path core's own wiring: the steppers ticked with the core's tick
/// (a clock early, at the position before the step), or never, is found.
#[test]
fn an_altered_line_of_the_verilog_is_found() {
    let good = snapgen_hdl::path_core::path_core_sources_text(2);
    for (from, to) in [
        (".tick(tick_q)", ".tick(c_tick | (tick_q & reset))"),
        (
            "tick_q <= c_tick & ~reset;",
            "tick_q <= c_tick & ~reset & 1'b0;",
        ),
    ] {
        assert_eq!(good.matches(from).count(), 1, "{from}");
        let bad = good.replace(from, to);
        let lib =
            build_path_core_from(&bad, false, Opt::BuildTime).expect("the altered design builds");
        let r = run(&lib.library, &config(2, 1_000_000, 6)).expect("runs");
        assert!(r.mismatch.is_some(), "{to:?} was not found: {r:?}");
    }
}

/// The path core as a board's core: a line written into its ring and a move of the path
/// length played on its chain; each axis's steps on its line follow the rule at the fabric's
/// path length on every tick, and end on the line's end. With steps too short for the speed
/// the lines fall behind, and the check says so.
#[test]
fn the_board_reads_the_axes_from_its_step_lines() {
    use snapgen_model::path::interp::{Path, Segment, Shape};
    use snapgen_model::{ChainState, CoreInputs, Format, FRAC_BITS};
    use snapgen_plan::{plan_from, Method, MoveRequest};
    use snapgen_sim::cosim::CoreSide;
    use snapgen_sim::path_board::PathCoreBoard;

    const ONE: i128 = 1 << 62;
    let cell = 1i128 << FRAC_BITS;
    let lib = build_path_core(2, false).expect("the path core builds");
    let format = Format::with_ts(1e-4);
    let lsb = format.position_lsb;
    // 3000 LSB along X and 4000 along Y: 5000 of path.
    let path = Path {
        segments: vec![Segment {
            length: 5000 * cell,
            shape: Shape::Line {
                from: vec![0, 0],
                dir: vec![ONE * 3 / 5, ONE * 4 / 5],
            },
        }],
    };
    let tick_div = PathCoreBoard::tick_div(2);
    for (lsb_per_tick, short_steps) in [(300.0, false), (2000.0, true)] {
        let mut board = PathCoreBoard::open(&lib.library, 2, &format).expect("opens");
        let home = board.core().chain();
        let step = if short_steps {
            1
        } else {
            PathCoreBoard::step_for(2, lsb_per_tick).unwrap()
        };
        board
            .load_path(&path, home.x, step, (lsb_per_tick as i128) << FRAC_BITS)
            .unwrap();
        let v = lsb_per_tick * lsb / format.ts;
        let request = MoveRequest {
            distance: 5001.0 * lsb,
            method: Method::Order3 {
                vmax: v,
                amax: v / format.ts / 10.0,
                jmax: v / format.ts / format.ts / 50.0,
            },
        };
        let plan = plan_from(&request, &format, ChainState { ..home }).unwrap();
        let idle = CoreInputs {
            tick_div,
            stop_jerk: 1,
            stop_accel: 1,
            ..Default::default()
        };
        let mut queue: std::collections::VecDeque<CoreInputs> = plan
            .program
            .segments
            .iter()
            .enumerate()
            .map(|(k, s)| CoreInputs {
                write_enable: true,
                write_address: k as u8,
                write_ticks: s.ticks,
                write_snap: s.snap,
                ..idle
            })
            .collect();
        queue.push_back(CoreInputs {
            count_enable: true,
            count_value: plan.program.segments.len() as u8,
            ..idle
        });
        queue.push_back(CoreInputs {
            start: true,
            ..idle
        });
        let per_tick = u64::from(tick_div) + 1;
        // The ring goes in and the drives follow, then the move and 10 ticks more.
        board
            .run(6 * per_tick, &mut |_| idle)
            .expect("fabric and model agree");
        board
            .run((plan.ticks_total() + 10) * per_tick, &mut |_| {
                queue.pop_front().unwrap_or(idle)
            })
            .expect("fabric and model agree");
        let view = board.fabric_view();
        eprintln!("{lsb_per_tick} LSB/tick, step {step}: {view:?}");
        assert!(view.ticks > plan.ticks_total(), "{view:?}");
        if short_steps {
            assert!(view.differing > 0 && view.flags.is_some(), "{view:?}");
        } else {
            assert_eq!((view.differing, &view.flags), (0, &None), "{view:?}");
            // The line's end, by its own numbers: (3000, 4000) LSB, to the step.
            let s = i64::from(step);
            assert_eq!(view.end, vec![3000 / s * s, 4000 / s * s], "{view:?}");
            assert!(view.steps > 0);
        }
    }
}
