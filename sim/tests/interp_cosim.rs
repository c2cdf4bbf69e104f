//! The Verilated path interpolator against its model, every output on every clock, under the
//! random stream of `snapgen_sim::interp` (needs Verilator; the README's test command installs
//! it): at every number of axes, with no difference and every undisturbed computation of
//! a planner's segment equal to the rule; and a one-bit fault in any output is found at its
//! clock (that shows the comparison and its report work; that the stream reaches the logic is
//! shown by the disturbance counts and by the rule checks).

use snapgen_sim::build::{build_interpolator, build_interpolator_from, Opt};
use snapgen_sim::interp::{run, InterpConfig, PortFault, INTERP_OUTPUTS};

fn config(axes: u8, clocks: u64, seed: u64) -> InterpConfig {
    InterpConfig {
        axes,
        clocks,
        seed,
        fault: None,
    }
}

#[test]
fn fabric_and_model_agree_on_every_clock() {
    // 10^7 clocks in all, most at three axes and eight; every other count too.
    for (axes, clocks) in [
        (1, 1_000_000),
        (2, 200_000),
        (3, 5_000_000),
        (4, 200_000),
        (5, 200_000),
        (6, 200_000),
        (7, 200_000),
        (8, 3_000_000),
    ] {
        let lib = build_interpolator(axes, false).expect("the interpolator builds");
        let r = run(&lib.library, &config(axes, clocks, u64::from(axes))).expect("runs");
        assert_eq!(r.mismatch, None, "{axes} axes");
        assert_eq!(r.clocks, clocks);
        assert_eq!(r.rule_errors, 0, "{axes} axes: the model against the rule");
        assert!(r.checked > clocks / 2_000, "{axes} axes: {r:?}");
        assert!(
            r.computations > r.checked && r.segments > 100,
            "{axes} axes: {r:?}"
        );
        // Every kind of disturbance happened (in the long runs; they are rare), and segments
        // of random bits.
        assert!(
            (clocks < 1_000_000 || r.disturbances.iter().all(|&n| n > 0)) && r.random_segments > 0,
            "{axes} axes: {r:?}"
        );
        eprintln!("{axes} axes: {r:?}");
    }
}

#[test]
fn a_one_bit_fault_in_any_output_is_found() {
    let lib = build_interpolator(3, false).expect("the interpolator builds");
    for (port, p) in INTERP_OUTPUTS.iter().enumerate() {
        for (clock, bit) in [(1_234, 0), (57_001, p.bits - 1)] {
            let mut cfg = config(3, 60_000, 9);
            cfg.fault = Some(PortFault { clock, port, bit });
            let r = run(&lib.library, &cfg).expect("runs");
            let m = r
                .mismatch
                .unwrap_or_else(|| panic!("{} bit {bit} not found", p.name));
            assert_eq!((m.clock, m.port), (clock, p.name));
            assert_eq!(m.expected ^ m.actual, 1 << (bit % p.bits));
        }
    }
}

/// The stream reaches the logic: a fabric with one line of its Verilog altered (a carry
/// dropped, an arithmetic shift made logical, a prefetched share read from the axis after)
/// disagrees with the model within the suite's clocks.
#[test]
fn an_altered_line_of_the_verilog_is_found() {
    let good = snapgen_hdl::interpolator::interpolator_verilog(3);
    for (from, to) in [
        (
            "+ {{(T_BITS-SPLIT-1){1'b0}}, carry};",
            "+ {(T_BITS-SPLIT){1'b0}};",
        ),
        (
            "cy_shift <= $signed(cy) >>> step;",
            "cy_shift <= cy >> step;",
        ),
        (
            "next_share <= seg_share[next_q[2:0]];",
            "next_share <= seg_share[next_q[2:0] + 3'd1];",
        ),
    ] {
        assert_eq!(
            good.matches(from).count(),
            if from.starts_with("next") { 2 } else { 1 }
        );
        let bad = good.replace(from, to);
        let lib = build_interpolator_from(&bad, false, Opt::BuildTime)
            .expect("the altered design builds");
        let r = run(&lib.library, &config(3, 2_000_000, 3)).expect("runs");
        assert!(r.mismatch.is_some(), "{to:?} was not found: {r:?}");
    }
}
