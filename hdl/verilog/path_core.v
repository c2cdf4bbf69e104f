// The path core (reference: snapgen_model::path::core): seed 002's architecture in one block.
// The motion core integrates the path length s as it integrates a single axis (its programs,
// stop and swaps at an absolute tick are the whole group's); the path steppers map s onto
// every axis on each of its ticks.
//
//   * snapgen_core (its own file): each of its ports is the path core's port of the same
//     name; its outputs reach them through the wires c_*.
//   * snapgen_path_steppers (its own file, with its blocks'): each of its ports but `tick`
//     and `s` is the path core's of the same name (its outputs through the wires p_*); its
//     reset is the core's.
//   * `tick_q`: the core's tick a clock late. On the clock after the chain steps, the steppers
//     take a tick with the chain's new position register as `s`, so the axes committed on a
//     tick are the path at the position the chain reached on the tick before.
//
// Template: snapgen_hdl writes the //@ lines from the spec's port lists.

//@ wires

//@ core

//@ steppers

reg tick_q = 1'b0;
always @(posedge clock) tick_q <= c_tick & ~reset;

always @(*) begin
   //@ outputs
end
