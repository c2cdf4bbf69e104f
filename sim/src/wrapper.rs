//! The co-simulation top level: the generated core (`snapgen_core`) behind a register on every
//! input (`top`), written from the port tables ([`crate::fabric::CORE_INPUTS`],
//! [`crate::fabric::CORE_OUTPUTS`]).
//!
//! Why: Verilator evaluates all combinational logic that depends on top-level inputs on every
//! `eval` (both clock edges). rust-hdl's blocks are combinational next-state logic reading
//! their inputs, so the core's whole logic ran twice per clock. With the inputs registered, it
//! depends on registers only and runs once per clock: measured 171 → 90 ns per clock. The
//! model sees the same one-clock delay (`cosim` clocks it with the previous clock's inputs), so
//! every output is still compared on every clock. This wrapper exists only in co-simulation;
//! `snapgen verilog` writes the core alone.

use crate::fabric::{CORE_INPUTS, CORE_OUTPUTS};

fn range(bits: u32) -> String {
    if bits == 1 {
        String::new()
    } else {
        format!("[{}:0] ", bits - 1)
    }
}

/// The core's Verilog (modules `snapgen_core*`) plus the wrapper `top`.
pub fn cosim_top(core_verilog: &str) -> String {
    assert!(
        core_verilog.contains("module snapgen_core("),
        "the core's Verilog must define snapgen_core"
    );
    let mut ports = vec!["    input wire clock".to_string()];
    ports.extend(
        CORE_INPUTS
            .iter()
            .map(|p| format!("    input wire {}{}", range(p.bits), p.name)),
    );
    ports.extend(
        CORE_OUTPUTS
            .iter()
            .map(|p| format!("    output wire {}{}", range(p.bits), p.name)),
    );
    let mut regs = String::new();
    let mut assigns = String::new();
    for p in &CORE_INPUTS {
        regs.push_str(&format!(
            "    reg {}r_{} = {}'d0;\n",
            range(p.bits),
            p.name,
            p.bits
        ));
        assigns.push_str(&format!("        r_{0} <= {0};\n", p.name));
    }
    let mut conns: Vec<String> = vec![".clock(clock)".into()];
    conns.extend(CORE_INPUTS.iter().map(|p| format!(".{0}(r_{0})", p.name)));
    conns.extend(CORE_OUTPUTS.iter().map(|p| format!(".{0}({0})", p.name)));
    format!(
        "{core_verilog}\
// Co-simulation wrapper: registers every input of the core for one clock.
module top(
{ports}
);
{regs}    always @(posedge clock) begin
{assigns}    end
    snapgen_core core(
        {conns}
    );
endmodule
",
        ports = ports.join(",\n"),
        conns = conns.join(",\n        "),
    )
}
