//! Co-simulation of the Verilated AXI4-Lite top (`snapgen_axi.v` with the station of
//! `snapgen_io.v`) against its model, clock by clock, under random AXI traffic with random
//! back-pressure (needs Verilator; the README's test command installs it).

use snapgen_sim::axi::AXI_OUTPUTS;
use snapgen_sim::axi_cosim::{run, run_verilog, AxiCosimConfig};
use snapgen_sim::io_cosim::cosim_design;
use snapgen_sim::layout::PortFault;
use snapgen_spec::axi::IRQ_ALL;

fn config(clocks: u64, seed: u64) -> AxiCosimConfig {
    AxiCosimConfig {
        clocks,
        seed,
        fault: None,
    }
}

/// Two hosts of 1.5 million clocks each: every output equal on every clock, no handshake
/// rule broken, and the traffic reached what the map offers.
#[test]
fn random_axi_traffic_matches_bit_for_bit() {
    for seed in [3, 8] {
        let r = run(&cosim_design(), &config(1_500_000, seed)).unwrap();
        eprintln!("seed {seed}: {r:?}");
        assert!(r.passed(), "seed {seed}: {r:?}");
        assert_eq!(r.clocks, 1_500_000);
        assert!(r.replies > 1000 && r.starts_acked > 10 && r.swaps_armed > 5);
        assert!(r.slave_errors > 0 && r.snapshots > 50);
        assert_eq!(r.irq_seen, IRQ_ALL, "every interrupt cause seen");
    }
}

/// A flipped bit of any kind of output is found at its clock.
#[test]
fn an_injected_difference_is_found() {
    for (clock, port, bit) in [
        (40_000u64, "s_axi_rdata", 7u32),
        (50_001, "s_axi_bvalid", 0),
        (60_002, "irq", 0),
        (70_003, "status", 200),
        (80_004, "pwm", 0),
    ] {
        let index = AXI_OUTPUTS.iter().position(|p| p.name == port).unwrap();
        let cfg = AxiCosimConfig {
            fault: Some(PortFault {
                clock,
                port: index,
                bit,
            }),
            ..config(100_000, 5)
        };
        let r = run(&cosim_design(), &cfg).unwrap();
        let m = r.mismatch.unwrap_or_else(|| panic!("{port} not found"));
        assert_eq!((m.clock, m.port), (clock, port));
    }
}

/// A changed line of the slave's Verilog is found by the lockstep.
#[test]
fn an_altered_slave_is_found() {
    let design = cosim_design();
    let text = snapgen_hdl::axi_top::axi_sources_text(&design);
    for (line, altered) in [
        (
            "irq_q <= |(irq_status & irq_enable_q);",
            "irq_q <= |(irq_status);",
        ),
        ("w_lane0_q <= s_axi_wstrb[0];", "w_lane0_q <= 1'b1;"),
        (
            "b_valid_q <= write_fire | (b_valid_q & ~s_axi_bready);",
            "b_valid_q <= write_fire | (b_valid_q & s_axi_bready);",
        ),
    ] {
        assert!(text.contains(line), "{line}");
        let r = run_verilog(&design, &text.replace(line, altered), &config(300_000, 4)).unwrap();
        assert!(!r.passed(), "{altered} not found");
    }
}
