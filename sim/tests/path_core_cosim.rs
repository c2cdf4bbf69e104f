//! The Verilated path core (the motion core on the path length driving the path steppers)
//! against its model, every output on every clock, and each axis's lines counted as its drive
//! counts them (needs Verilator; the README's test command installs it).

use snapgen_sim::build::{build_path_core, build_path_core_from};
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
        assert!(r.stops > 0, "{r:?}");
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
        let lib = build_path_core_from(&bad, false).expect("the altered design builds");
        let r = run(&lib.library, &config(2, 1_000_000, 6)).expect("runs");
        assert!(r.mismatch.is_some(), "{to:?} was not found: {r:?}");
    }
}
