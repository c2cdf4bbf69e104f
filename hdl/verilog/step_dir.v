// The step/dir generator (its reference, register for register, is
// snapgen_model::io::step_dir): a stepper drive's step and direction lines from an axis's
// whole-LSB position. The grid is anchored at the position while disabled; a step is due up
// when the position reaches `up`, down when it falls below `down`; each step moves both edges
// by step_lsb. One step: a clock to decide it, high_clocks high (counted on the rising edge),
// low_clocks low; a new direction is held setup_clocks before the next rising edge and never
// changes during a pulse or its low time. Positions wrap: every comparison is the sign of a
// wrapping difference. Times and the step length of 0 act as 1.

localparam [1:0] P_IDLE = 2'd0, P_SETUP = 2'd1, P_HIGH = 2'd2, P_LOW = 2'd3;

reg [1:0] phase = P_IDLE;
reg [STEP_TIMER_BITS-1:0] timer = {STEP_TIMER_BITS{1'b0}};   // clocks left in the phase, minus one
reg dir_q = 1'b0, step_q = 1'b0, overrun_q = 1'b0;
reg due_q = 1'b0;                                  // a step was due that did not begin
reg [POSITION_BITS-1:0] up = {POSITION_BITS{1'b0}};     // the next upward step's edge
reg [POSITION_BITS-1:0] down = {POSITION_BITS{1'b0}};   // a downward step is due below it
reg [POSITION_BITS-1:0] count = {POSITION_BITS{1'b0}};  // steps issued since enabled

// 0 acts as 1.
wire [STEP_TIMER_BITS-1:0] lsb = (step_lsb == 0) ? 1 : step_lsb;
wire [STEP_TIMER_BITS-1:0] high_last = (high_clocks == 0) ? 0 : high_clocks - 1;
wire [STEP_TIMER_BITS-1:0] low_last = (low_clocks == 0) ? 0 : low_clocks - 1;
wire [STEP_TIMER_BITS-1:0] setup_last = (setup_clocks == 0) ? 0 : setup_clocks - 1;
wire [POSITION_BITS-1:0] k = {{(POSITION_BITS-STEP_TIMER_BITS){1'b0}}, lsb};
// Wrapping differences: "at or past" is a non-negative difference (its sign bit clear).
wire [POSITION_BITS-1:0] to_up = position - up;
wire [POSITION_BITS-1:0] to_down = position - down;
// position - (up + k) and position - (down - k) as three-input sums: one carry-save level,
// then one carry chain (position + ~up + ~k + 2, position + ~down + k + 1), for routed timing.
wire [POSITION_BITS-1:0] nu_a = position, nu_b = ~up, nu_c = ~k;
wire [POSITION_BITS-1:0] nu_carry = {(nu_a[POSITION_BITS-2:0] & nu_b[POSITION_BITS-2:0])
                                   | (nu_a[POSITION_BITS-2:0] & nu_c[POSITION_BITS-2:0])
                                   | (nu_b[POSITION_BITS-2:0] & nu_c[POSITION_BITS-2:0]), 1'b0};
wire [POSITION_BITS-1:0] to_next_up = (nu_a ^ nu_b ^ nu_c) + nu_carry + 2;
wire [POSITION_BITS-1:0] nd_b = ~down;
wire [POSITION_BITS-1:0] nd_carry = {(position[POSITION_BITS-2:0] & nd_b[POSITION_BITS-2:0])
                                   | (position[POSITION_BITS-2:0] & k[POSITION_BITS-2:0])
                                   | (nd_b[POSITION_BITS-2:0] & k[POSITION_BITS-2:0]), 1'b0};
wire [POSITION_BITS-1:0] to_next_down = (position ^ nd_b ^ k) + nd_carry + 1;
wire want_up = !to_up[POSITION_BITS-1];
wire want_down = to_down[POSITION_BITS-1];

always @(posedge clock) begin
   if (reset) begin
      phase <= P_IDLE;
      timer <= {STEP_TIMER_BITS{1'b0}};
      dir_q <= 1'b0;
      step_q <= 1'b0;
      overrun_q <= 1'b0;
      due_q <= 1'b0;
      up <= position + k;
      down <= position;
      count <= {POSITION_BITS{1'b0}};
   end else begin
      // A step is due that does not begin on this edge (in P_IDLE with the direction right,
      // it does).
      due_q <= enable && (want_up || want_down) && !(phase == P_IDLE && dir_q == want_up);
      if (!enable) overrun_q <= 1'b0;
      else if (!to_next_up[POSITION_BITS-1] || to_next_down[POSITION_BITS-1]) overrun_q <= 1'b1;
      case (phase)
      P_IDLE: if (!enable) begin
         up <= position + k;
         down <= position;
         count <= {POSITION_BITS{1'b0}};
      end else if (want_up || want_down) begin
         if (dir_q != want_up) begin
            dir_q <= want_up;
            timer <= setup_last;
            phase <= P_SETUP;
         end else begin
            step_q <= 1'b1;
            timer <= high_last;
            phase <= P_HIGH;
            if (want_up) begin
               count <= count + 1;
               down <= up;
               up <= up + k;
            end else begin
               count <= count - 1;
               up <= down;
               down <= down - k;
            end
         end
      end
      P_HIGH: if (timer == 0) begin
         step_q <= 1'b0;
         timer <= low_last;
         phase <= P_LOW;
      end else begin
         timer <= timer - 1;
      end
      default: if (timer == 0) begin // P_SETUP, P_LOW
         phase <= P_IDLE;
      end else begin
         timer <= timer - 1;
      end
      endcase
   end
end

always @(*) begin
   step = step_q;
   dir = dir_q;
   steps = count;
   overrun = overrun_q;
   due = due_q;
end
