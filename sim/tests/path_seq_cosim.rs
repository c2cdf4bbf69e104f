//! The Verilated path sequencer against its model, every output on every clock, and the
//! positions it commits against the rule (needs Verilator; the README's test command installs
//! it).

use snapgen_sim::build::{build_path_sequencer, build_path_sequencer_from, Opt};
use snapgen_sim::path_seq::{run, PathSeqConfig, PortFault, PATH_SEQ_OUTPUTS};

fn config(axes: u8, clocks: u64, seed: u64) -> PathSeqConfig {
    PathSeqConfig {
        axes,
        clocks,
        seed,
        fault: None,
    }
}

#[test]
fn fabric_model_and_rule_agree() {
    for (axes, clocks) in [(3, 10_000_000), (1, 2_000_000), (8, 2_000_000)] {
        let lib = build_path_sequencer(axes, false).expect("the sequencer builds");
        let r = run(&lib.library, &config(axes, clocks, u64::from(axes))).expect("runs");
        eprintln!("{axes} axes: {r:?}");
        assert_eq!(r.mismatch, None);
        assert_eq!(r.rule_error, None);
        assert_eq!(r.false_refusals, 0);
        assert!(
            r.checked * 10 >= r.commits * 8 && r.checked > clocks / 5_000,
            "{r:?}"
        );
        assert!(
            r.wrapped > 0 && r.moves > clocks / 10_000 && r.late_runs > 0,
            "{r:?}"
        );
        assert!(r.probes > 0 && r.refused == r.probes, "{r:?}");
    }
}

#[test]
fn a_one_bit_fault_in_any_output_is_found() {
    let lib = build_path_sequencer(2, false).expect("the sequencer builds");
    for (port, p) in PATH_SEQ_OUTPUTS.iter().enumerate() {
        let clock = 30_011 + port as u64;
        let fault = PortFault {
            clock,
            port,
            bit: (port as u32 * 7) % p.bits,
        };
        let cfg = PathSeqConfig {
            fault: Some(fault),
            ..config(2, 100_000, 4)
        };
        let r = run(&lib.library, &cfg).expect("runs");
        let m = r.mismatch.unwrap_or_else(|| panic!("{} not found", p.name));
        assert_eq!((m.clock, m.port), (clock, p.name));
        assert_eq!(m.expected ^ m.actual, 1 << fault.bit);
    }
}

/// The stream reaches the logic: a fabric with one line of its Verilog altered (a borrow
/// dropped, the clamp a cell before the path's start lost, no step back, the clamp below the
/// oldest segment kept taken as the path's start's) disagrees with the
/// model within the suite's clocks.
#[test]
fn an_altered_line_of_the_verilog_is_found() {
    let good = snapgen_hdl::path_sequencer::path_sequencer_verilog(3);
    for (from, to) in [
        (
            "r <= {s_q[X_BITS-1:SPLIT] - span_start[X_BITS-1:SPLIT] - borrow_in, low};",
            "r <= {s_q[X_BITS-1:SPLIT] - span_start[X_BITS-1:SPLIT], low};",
        ),
        (
            "MINUS_CELL = {{CELL_BITS{1'b1}}, {FRAC_BITS{1'b0}}};",
            "MINUS_CELL = {X_BITS{1'b0}};",
        ),
        ("k <= k - ONE_INDEX;", "k <= k;"),
        (
            "if (under) offset_q <= first ? MINUS_CELL : {X_BITS{1'b0}};",
            "if (under) offset_q <= MINUS_CELL;",
        ),
    ] {
        assert_eq!(good.matches(from).count(), 1, "{from}");
        let bad = good.replace(from, to);
        let lib = build_path_sequencer_from(&bad, false, Opt::BuildTime)
            .expect("the altered design builds");
        let r = run(&lib.library, &config(3, 2_000_000, 5)).expect("runs");
        assert!(r.mismatch.is_some(), "{to:?} was not found: {r:?}");
    }
}
