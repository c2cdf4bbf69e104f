// The path steppers (reference: snapgen_model::path::steppers): the N-axis output stage of a
// path design for stepper drives.
//
//   * The path sequencer (snapgen_path_sequencer) and the interpolator it drives
//     (snapgen_interpolator), wired by name: the sequencer's `interpolator` outputs are the
//     interpolator's inputs (the wires ip_*), its `done` the interpolator's.
//   * Per axis (the generate block `axis`): `next_x` takes the interpolator's write of the
//     axis, `position_x` takes `next_x` on the sequencer's `commit`, so every axis changes on
//     the same clock to its position at the tick before; a step/dir generator
//     (snapgen_step_dir) on the whole-LSB part of `position_x`; and `behind`, the axis's
//     overrun: a step was still due when the next tick's positions came (the generator's own
//     overrun, a position more than a step ahead, is left unused: a tick's jump is often
//     several steps, which the pulses then follow within the tick).
//   * The position registers are not reset: a reset empties the path, the axes hold.
//
// Template: snapgen_hdl writes the //@ lines from the spec's port lists (the wires between the
// blocks, their instances, the outputs) and the values in double braces.

//@ wires

//@ sequencer

//@ interpolator

wire [{{AXES}}-1:0] step_w, dir_w, behind_w;
//@ unused

genvar gk;
generate for (gk = 0; gk < {{AXES}}; gk = gk + 1) begin : axis
   localparam [AXIS_BITS-1:0] K = gk[AXIS_BITS-1:0];
   /* verilator lint_off UNUSEDSIGNAL */ // the generator reads the whole LSBs only
   reg [X_BITS-1:0] position_x = {X_BITS{1'b0}};
   /* verilator lint_on UNUSEDSIGNAL */
   reg [X_BITS-1:0] next_x = {X_BITS{1'b0}};
   reg behind = 1'b0;
   wire step_k, dir_k, due_k;
   always @(posedge clock) begin
      if (commit) position_x <= next_x;
      if (ip_out_write && ip_out_axis == K) next_x <= ip_out_value;
      if (reset || !enable[gk]) behind <= 1'b0;
      else if (commit && due_k) behind <= 1'b1;
   end
   //@ drive
   assign step_w[gk] = step_k;
   assign dir_w[gk] = dir_k;
   assign behind_w[gk] = behind;
end
endgenerate

always @(*) begin
   //@ outputs
end
