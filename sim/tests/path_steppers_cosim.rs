//! The Verilated path steppers (the sequencer, the interpolator and a step/dir generator per
//! axis) against their model, every output on every clock, and each axis's lines counted as
//! its drive counts them (needs Verilator; the README's test command installs it).

use snapgen_sim::build::{build_path_steppers, build_path_steppers_from, Opt};
use snapgen_sim::path_steppers::{run, PathSteppersConfig, PortFault, PATH_STEPPERS_OUTPUTS};

fn config(axes: u8, clocks: u64, seed: u64) -> PathSteppersConfig {
    PathSteppersConfig {
        axes,
        clocks,
        seed,
        fault: None,
    }
}

#[test]
fn fabric_model_and_drives_agree() {
    for (axes, clocks) in [(3, 6_000_000), (1, 2_000_000), (8, 4_000_000)] {
        let lib = build_path_steppers(axes, false).expect("the stage builds");
        let r = run(&lib.library, &config(axes, clocks, 10 + u64::from(axes))).expect("runs");
        eprintln!("{axes} axes: {r:?}");
        assert_eq!(r.mismatch, None);
        assert_eq!(r.violation, None);
        // Every run within the rate is checked (the last may be cut short by the clocks).
        assert!(
            r.checked + r.fast + 1 >= r.runs && r.steps > 10_000,
            "{r:?}"
        );
        // Faster than the pulses follow, an axis says so.
        assert!(r.fast > 0 && r.must > 0 && r.flagged == r.must, "{r:?}");
    }
}

#[test]
fn a_one_bit_fault_in_any_output_is_found() {
    let lib = build_path_steppers(2, false).expect("the stage builds");
    for (port, p) in PATH_STEPPERS_OUTPUTS.iter().enumerate() {
        let clock = 20_011 + port as u64;
        let fault = PortFault {
            clock,
            port,
            bit: (port as u32 * 5) % p.bits,
        };
        let cfg = PathSteppersConfig {
            fault: Some(fault),
            ..config(2, 60_000, 4)
        };
        let r = run(&lib.library, &cfg).expect("runs");
        let m = r.mismatch.unwrap_or_else(|| panic!("{} not found", p.name));
        assert_eq!((m.clock, m.port), (clock, p.name));
        assert_eq!(m.expected ^ m.actual, 1 << fault.bit);
    }
}

/// The stream reaches the stage's own logic: one line of its Verilog altered (the overrun
/// flag raised without a commit, a write taken by the wrong axis) is found.
#[test]
fn an_altered_line_of_the_verilog_is_found() {
    let good = snapgen_hdl::path_steppers::path_steppers_sources_text(3);
    for (from, to) in [
        (
            "else if (commit && due_k) behind <= 1'b1;",
            "else if (due_k) behind <= 1'b1;",
        ),
        (
            "if (ip_out_write && ip_out_axis == K) next_x <= ip_out_value;",
            "if (ip_out_write && ip_out_axis == ~K) next_x <= ip_out_value;",
        ),
    ] {
        assert_eq!(good.matches(from).count(), 1, "{from}");
        let bad = good.replace(from, to);
        let lib = build_path_steppers_from(&bad, false, Opt::BuildTime)
            .expect("the altered design builds");
        let r = run(&lib.library, &config(3, 2_000_000, 6)).expect("runs");
        assert!(r.mismatch.is_some(), "{to:?} was not found: {r:?}");
    }
}
