//! The Verilated step/dir generator against its model, every output on every clock, and its
//! lines as a drive sees them (needs Verilator; the README's test command installs it).

use snapgen_sim::build::build_step_dir;
use snapgen_sim::step_dir::{run, PortFault, STEP_DIR_OUTPUTS};

#[test]
fn fabric_model_and_drive_agree() {
    let lib = build_step_dir(false).expect("the generator builds");
    let r = run(&lib.library, 5_000_000, 1, None).expect("runs");
    eprintln!("{r:?}");
    assert_eq!(r.mismatch, None);
    assert_eq!(r.violation, None);
    assert_eq!(r.false_overruns, 0, "within the limit no overrun");
    assert!(r.checked >= 50 && r.pulses > 10_000, "{r:?}");
    // Over the limit, the generator falls behind and says so (a run whose target is near may
    // end before it is a whole step behind).
    assert!(r.over > 0 && 2 * r.flagged >= r.over, "{r:?}");
}

#[test]
fn a_one_bit_fault_in_any_output_is_found() {
    let lib = build_step_dir(false).expect("the generator builds");
    for (port, p) in STEP_DIR_OUTPUTS.iter().enumerate() {
        let fault = PortFault {
            clock: 40_123,
            port,
            bit: p.bits - 1,
        };
        let r = run(&lib.library, 200_000, 2, Some(fault)).expect("runs");
        let m = r.mismatch.unwrap_or_else(|| panic!("{} not found", p.name));
        assert_eq!((m.clock, m.port), (40_123, p.name));
        assert_eq!(m.expected ^ m.actual, 1 << (p.bits - 1));
    }
}
