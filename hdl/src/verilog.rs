//! The design's Verilog files: the motion core (`snapgen_core.v`) and the I/O top
//! (`snapgen_io.v`, which instantiates it), each finished by [`crate::emit`] with its waivers
//! and hints, and the design hash over both.

use rust_hdl::prelude::*;

use crate::core::MotionCore;
use crate::emit::{emit, finish, netlist_of, Note, Waiver};
use crate::io_top::IoTop;
use snapgen_model::device::Design;

/// Module prefix of the motion core design (`snapgen_core.v`).
pub const CORE_PREFIX: &str = "snapgen_core";
/// Module prefix of the I/O top design (`snapgen_io.v`).
pub const IO_PREFIX: &str = "snapgen_io";

/// Hints every design with a sequencer uses.
///
/// rust-hdl emits one `always @(*)` block per module, so the core's block (reads the
/// sequencer's memory address, drives its count and memory-data inputs) and the sequencer's
/// block (reads those, drives the address) form a loop at block granularity only: the address
/// depends on registers alone. Isolating the address (and the next index it comes from) breaks
/// the false loop, so Verilator orders the logic statically instead of re-evaluating it until
/// it settles (co-simulation 41 → 35 ns a clock), and no UNOPTFLAT waiver is needed.
pub const SEQUENCER_HINTS: [Waiver; 2] = [
    Waiver {
        module: "sequencer",
        signal: "address",
        note: Note::IsolateAssignments,
        reason: "depends on registers only: breaks a false block-level loop with the core",
    },
    Waiver {
        module: "sequencer",
        signal: "next_index",
        note: Note::IsolateAssignments,
        reason: "the address is computed from it",
    },
];

/// The swap timer's waiver: `lead` is an adder whose sign bit alone is used.
pub const SWAP_TIMER_WAIVER: Waiver = Waiver {
    module: "swap_timer",
    signal: "lead",
    note: Note::LintOff("UNUSEDSIGNAL"),
    reason: "only its sign bit is used: the arm's acceptance test",
};

/// Every hint and waiver of a design with a motion core.
pub fn core_waivers() -> Vec<Waiver> {
    let mut w = SEQUENCER_HINTS.to_vec();
    w.push(SWAP_TIMER_WAIVER);
    w
}

/// Every waiver and hint of the station with its motion core.
pub fn station_waivers() -> Vec<Waiver> {
    let mut w = core_waivers();
    w.extend_from_slice(&crate::station::WAIVERS);
    w
}

/// Every waiver and hint of the I/O top design (the station's and the UART top's).
pub fn io_top_waivers() -> Vec<Waiver> {
    let mut w = station_waivers();
    w.extend_from_slice(&crate::io_top::WAIVERS);
    w
}

/// The I/O top's own waivers and the station's (the motion core is a design of its own).
fn io_file_waivers() -> Vec<Waiver> {
    let mut w = crate::station::WAIVERS.to_vec();
    w.extend_from_slice(&crate::io_top::WAIVERS);
    w
}

/// The motion core's rust-hdl Verilog.
fn motion_core_raw() -> String {
    let mut uut = MotionCore::default();
    uut.connect_all();
    generate_verilog(&uut)
}

/// The motion core's Verilog: `snapgen_core.v`, top module `snapgen_core`.
pub fn motion_core_verilog() -> String {
    let header = [
        "snapgen motion core: tick divider, two-bank program memory, sequencer, stop unit, snap chain."
            .to_string(),
        format!(
            "Widths: x {}, v/a/j/snap {}, ticks {} bits; {} segments per bank, 2 banks.",
            crate::X_BITS,
            crate::V_BITS,
            crate::TICK_BITS,
            1 << crate::ADDR_BITS
        ),
    ];
    emit(&motion_core_raw(), CORE_PREFIX, &header, &core_waivers())
        .expect("the motion core's names and waivers are checked by its tests")
}

/// The I/O top's Verilog for `design`: `snapgen_io.v`, top module `snapgen_io`, which
/// instantiates `snapgen_core` (`snapgen_core.v`, [`motion_core_verilog`]): the two files
/// together are the design, and no logic is written twice. Its identity (what PING answers)
/// carries `design.design_hash`; [`io_design`] gives a design its hash.
pub fn io_top_verilog(design: &Design) -> String {
    let mut uut = IoTop::new(*design);
    uut.connect_all();
    let d = design.dividers;
    let header = [
        "snapgen I/O top: UART command interface, encoder decoder, PWM, limit switches, emergency"
            .to_string(),
        "stop, amplifier enable, around the motion core snapgen_core (snapgen_core.v: read both files)."
            .to_string(),
        format!(
            "Built for: {} Hz clock, {} baud ({} clocks per bit), tick divider {} after reset, frame timeout {} clocks.",
            design.clock_hz, design.baud, d.uart_divisor, d.tick_div, d.frame_timeout
        ),
        format!(
            "Design hash {:#010x}: FNV-1a (32 bits) of snapgen_core.v then this file, generated with the hash 0.",
            design.design_hash
        ),
    ];
    let io = netlist_of(&generate_verilog(&uut), IO_PREFIX)
        .and_then(|io| {
            let core = netlist_of(&motion_core_raw(), CORE_PREFIX)?;
            crate::netlist::use_child_design(
                &io,
                &format!("{IO_PREFIX}_station_core"),
                &core,
                CORE_PREFIX,
            )
        })
        .and_then(|io| finish(&io, IO_PREFIX, &header, &io_file_waivers()))
        .expect("the I/O top's names, waivers and motion core are checked by its tests");
    io
}

/// Every source file of the I/O top design for `design`: `snapgen_core.v`, then
/// `snapgen_io.v`.
pub fn io_sources(design: &Design) -> [(&'static str, String); 2] {
    [
        ("snapgen_core.v", motion_core_verilog()),
        ("snapgen_io.v", io_top_verilog(design)),
    ]
}

/// The I/O top design's sources as one text (what a simulator or a synthesis run reads).
pub fn io_sources_text(design: &Design) -> String {
    io_sources(design).map(|(_, v)| v).concat()
}

/// `design` with its hash: FNV-1a (32 bits) of its sources (`snapgen_core.v`, then
/// `snapgen_io.v` generated with the hash 0), so a host can tell which design a board runs
/// (docs/HDL.md).
pub fn io_design(design: &Design) -> Design {
    let unhashed = Design {
        design_hash: 0,
        ..*design
    };
    Design {
        design_hash: snapgen_model::device::fnv1a32(io_sources_text(&unhashed).as_bytes()),
        ..*design
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_have_the_prefix_and_no_dollar() {
        let v = motion_core_verilog();
        let no_tasks = v.replace("$signed", "").replace("$unsigned", "");
        assert!(!no_tasks.contains('$'), "a name with '$' survived");
        assert!(v.contains("module snapgen_core("));
        assert!(v.contains("module snapgen_core_sequencer("));
        assert!(!v.contains("module top"));
        assert!(v.contains(".clock(clock)"));
        assert!(v.contains("`default_nettype none"));
        assert!(v.contains("isolate_assignments"));
    }
}
