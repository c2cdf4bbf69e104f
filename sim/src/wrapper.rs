//! The co-simulation top level: the generated core, renamed `snapgen_core`, behind a register
//! on every input (`top`).
//!
//! Why: Verilator evaluates all combinational logic that depends on top-level inputs on every
//! `eval` (both clock edges). rust-hdl's blocks are combinational next-state logic reading
//! their inputs, so the core's whole logic ran twice per clock. With the inputs registered, it
//! depends on registers only and runs once per clock: measured 171 → 90 ns per clock. The
//! model sees the same one-clock delay (`cosim` clocks it with the previous clock's inputs), so
//! every output is still compared on every clock. This wrapper exists only in co-simulation;
//! `snapgen verilog` writes the core alone.

use snapgen_hdl::{
    ADDR_BITS, D_BITS, INDEX_BITS, J_BITS, POSITION_BITS, TICK_BITS, V_BITS, X_BITS,
};

/// The core's Verilog with its modules renamed `snapgen_core*`, plus the wrapper `top`.
pub fn cosim_top(core_verilog: &str) -> String {
    let core = core_verilog
        .replace("module top(", "module snapgen_core(")
        .replace("top$", "snapgen_core$");
    let wrapper = format!(
        "\
// Co-simulation wrapper: registers every input of the core for one clock.
module top(
    input wire clock,
    input wire reset,
    input wire [{t}:0] tick_div,
    input wire start,
    input wire stop,
    input wire write_enable,
    input wire [{ad}:0] write_address,
    input wire [{t}:0] write_ticks,
    input wire [{d}:0] write_snap,
    input wire count_enable,
    input wire [{ix}:0] count_value,
    input wire [{ix}:0] cruise_value,
    input wire soft_stop,
    output wire [{x}:0] x,
    output wire [{v}:0] v,
    output wire [{v}:0] a,
    output wire [{j}:0] j,
    output wire [{p}:0] position,
    output wire [{ix}:0] segment,
    output wire busy,
    output wire done,
    output wire aborted,
    output wire [{t}:0] tick_count,
    output wire tick,
    output wire active_bank,
    output wire [{ix}:0] standby_count
);
    reg r_reset = 1'b0;
    reg [{t}:0] r_tick_div = {tb}'d0;
    reg r_start = 1'b0;
    reg r_stop = 1'b0;
    reg r_write_enable = 1'b0;
    reg [{ad}:0] r_write_address = {adb}'d0;
    reg [{t}:0] r_write_ticks = {tb}'d0;
    reg [{d}:0] r_write_snap = {db}'d0;
    reg r_count_enable = 1'b0;
    reg [{ix}:0] r_count_value = {ixb}'d0;
    reg [{ix}:0] r_cruise_value = {ixb}'d0;
    reg r_soft_stop = 1'b0;
    always @(posedge clock) begin
        r_reset <= reset;
        r_tick_div <= tick_div;
        r_start <= start;
        r_stop <= stop;
        r_write_enable <= write_enable;
        r_write_address <= write_address;
        r_write_ticks <= write_ticks;
        r_write_snap <= write_snap;
        r_count_enable <= count_enable;
        r_count_value <= count_value;
        r_cruise_value <= cruise_value;
        r_soft_stop <= soft_stop;
    end
    snapgen_core core(
        .clock(clock), .reset(r_reset), .tick_div(r_tick_div), .start(r_start), .stop(r_stop),
        .write_enable(r_write_enable), .write_address(r_write_address),
        .write_ticks(r_write_ticks), .write_snap(r_write_snap),
        .count_enable(r_count_enable), .count_value(r_count_value),
        .cruise_value(r_cruise_value), .soft_stop(r_soft_stop),
        .x(x), .v(v), .a(a), .j(j), .position(position), .segment(segment), .busy(busy),
        .done(done), .aborted(aborted), .tick_count(tick_count), .tick(tick),
        .active_bank(active_bank), .standby_count(standby_count)
    );
endmodule
",
        t = TICK_BITS - 1,
        tb = TICK_BITS,
        ad = ADDR_BITS - 1,
        adb = ADDR_BITS,
        d = D_BITS - 1,
        db = D_BITS,
        ix = INDEX_BITS - 1,
        ixb = INDEX_BITS,
        x = X_BITS - 1,
        v = V_BITS - 1,
        j = J_BITS - 1,
        p = POSITION_BITS - 1,
    );
    core + &wrapper
}
