// The position controller (its reference is snapgen_model::io::servo): PID on the following
// error with velocity and acceleration feed-forward, computed digit-serially. Template:
// snapgen_hdl fills the values in double braces (the law's shifts and the serial schedule,
// from snapgen_model::io::servo); its configuration inputs are the contract's servo
// parameters, named as their registers.

// Fixed point (snapgen_model::io::servo): e in counts * 2^-{{E_FRAC}}, vs = v >>> {{V_SHIFT}},
// as = a >>> {{A_SHIFT}}, u = (sum + 2^{{HALF}}) >>> {{OUT_SHIFT}}; {{LATENCY}} clocks from sample to duty.
reg [SERVO_PERIOD_BITS-1:0] divider = {SERVO_PERIOD_BITS{1'b0}};   // ticks to the next sample
reg busy = 1'b0;
reg step0 = 1'b0;                    // the first clock after a sample
reg [2:0] term = 3'd0;               // 0 e, 1 I, 2 D, 3 vs, 4 as
reg [2:0] digit = 3'd0;              // 0..{{LAST_DIGIT}}: a gain digit's products; 1..{{DIGITS}}: their
                                     // addition a clock later; {{SUM_CLOCK}}: into the sum
reg fin = 1'b0;                      // the last clock: round and saturate
reg [47:0] e48_q = 48'd0;            // the sample's following error
reg [55:0] vs_q = 56'd0;             // v[103:48]
reg [63:0] as_q = 64'd0;             // a[103:40]
reg [47:0] f_q = 48'd0;              // the derivative filter's state F (the operand: F >>> k)
reg [47:0] i_q = 48'd0;              // the integrator
reg [31:0] eprev_q = 32'd0;
reg primed = 1'b0;                   // a sample since the amplifier came on
reg [31:0] e_q = 32'd0;              // the sample's e = sat32(e48)
// Term 0's first clocks update D and the integrator (read from term 1's operand on):
reg [32:0] delta_q = 33'd0;          // Δ = e − e_prev (0 on the first sample)
reg [47:0] dfilt_q = 48'd0;          // F >>> k, the filter's leak
reg [47:0] isum_q = 48'd0;           // I + e (read when it is within ±L)
reg hold_q = 1'b0;                   // the integrator holds (the output was clamped its way)
reg sat_hi = 1'b0, sat_lo = 1'b0;    // the last output was clamped
reg [63:0] mag_q = 64'd0;            // the term's operand: magnitude, sign
reg neg_q = 1'b0;
reg [47:0] gain_q = 48'd0;           // the term's gain, shifted a digit left per product clock
reg [111:0] acc_q = 112'd0;          // gain * |operand|, digit by digit
reg [31:0] p0 = 32'd0, p1 = 32'd0, p2 = 32'd0, p3 = 32'd0;   // a digit's products, registered
/* verilator lint_off UNUSEDSIGNAL */ // the fraction below bit 47 is what the rounding drops
reg [115:0] sum_q = 116'd0;          // the terms so far (two's complement)
/* verilator lint_on UNUSEDSIGNAL */
// The configuration latched at the sample (a CONFIGURE meanwhile waits for the next sample).
reg [KP_BITS-1:0] kp_q = {KP_BITS{1'b0}};
reg [KI_BITS-1:0] ki_q = {KI_BITS{1'b0}};
reg [KD_BITS-1:0] kd_q = {KD_BITS{1'b0}};
reg [KV_BITS-1:0] kv_q = {KV_BITS{1'b0}};
reg [KA_BITS-1:0] ka_q = {KA_BITS{1'b0}};
reg [INTEGRAL_LIMIT_BITS-1:0] ilim_q = {INTEGRAL_LIMIT_BITS{1'b0}};
reg [OUTPUT_LIMIT_BITS-1:0] olim_q = {OUTPUT_LIMIT_BITS{1'b0}};
reg [FOLLOWING_LIMIT_BITS-1:0] flim_q = {FOLLOWING_LIMIT_BITS{1'b0}};
reg [D_FILTER_BITS-1:0] dfk_q = {D_FILTER_BITS{1'b0}};
// ... and the limits' negations, latched with them (each compare is then one carry chain).
reg [48:0] flim_neg_q = 49'd0;       // −(FOLLOWING_LIMIT << {{E_FRAC}})
reg [47:0] ilim_neg_q = 48'd0;       // −INTEGRAL_LIMIT
reg [16:0] olim_neg_q = 17'd0;       // −OUTPUT_LIMIT
reg [15:0] duty_q = 16'd0;
reg fault_q = 1'b0, overrun_q = 1'b0;
reg [31:0] peak_q = 32'd0;

// The sample's error.
wire due = tick && (servo_period != {SERVO_PERIOD_BITS{1'b0}})
   && (divider == {SERVO_PERIOD_BITS{1'b0}});
wire [47:0] e48_now = ref_position - {count, 16'h8000};   // count n: the centre of cell n
// e = sat32(e48), taken with it.
wire e_sat_hi = !e48_now[47] && (e48_now[46:31] != 16'd0);
wire e_sat_lo = e48_now[47] && (e48_now[46:31] != 16'hffff);
wire [31:0] e_sat = e_sat_hi ? 32'h7fff_ffff : (e_sat_lo ? 32'h8000_0000 : e48_now[31:0]);

// Step 0: the following check (|e48| > L as e48 > L or e48 < −L), the peak (|e| > peak as
// peak − e < 0 or peak + e < 0) and the first term's operand |e|.
wire fault_now = e48_q[47] ? ($signed({e48_q[47], e48_q}) < $signed(flim_neg_q))
   : (e48_q > {flim_q, 16'd0});
/* verilator lint_off UNUSEDSIGNAL */ // only their signs are read
wire [32:0] peak_minus_e = {1'b0, peak_q} - {e_q[31], e_q};
wire [32:0] peak_plus_e = {1'b0, peak_q} + {e_q[31], e_q};
/* verilator lint_on UNUSEDSIGNAL */
wire above_peak = e_q[31] ? peak_plus_e[32] : peak_minus_e[32];
wire [31:0] e_abs = e_q[31] ? (~e_q + 32'd1) : e_q;                // 2^31 fits

// Term 0's digit clocks 0-2: Δ, I + e, F >>> k; then I = clamp(I + e) unless held and
// F −= F >>> k; then F += Δ: F + Δ − (F >>> k) in all.
wire [47:0] d_filt = $signed(f_q) >>> dfk_q;                       // F >>> k
wire hold = (sat_hi && !e_q[31] && (e_q != 32'd0)) || (sat_lo && e_q[31]);
// The clamp's decisions, taken with I + e (digit clock 0) from I, e and the limit L, so that no
// compare follows the sum: I + e > L as I + e + ~L >= 0 (~L = −L − 1), I + e < −L as
// I + e + L < 0; each three operands added carry-save (their bitwise sum and carries, then one
// carry chain), in 50 bits (|I| < 2^47, |e| < 2^31, 0 <= L < 2^48).
wire [49:0] iw = {{2{i_q[47]}}, i_q};
wire [49:0] ew = {{18{e_q[31]}}, e_q};
wire [49:0] lw = {{(50 - INTEGRAL_LIMIT_BITS){1'b0}}, ilim_q};
/* verilator lint_off UNUSEDSIGNAL */ // only their signs are read
wire [49:0] over_t = (iw ^ ew ^ ~lw) + {(iw[48:0] & ew[48:0]) | (iw[48:0] & ~lw[48:0])
   | (ew[48:0] & ~lw[48:0]), 1'b0};
wire [49:0] under_t = (iw ^ ew ^ lw) + {(iw[48:0] & ew[48:0]) | (iw[48:0] & lw[48:0])
   | (ew[48:0] & lw[48:0]), 1'b0};
/* verilator lint_on UNUSEDSIGNAL */
reg i_over_q = 1'b0, i_under_q = 1'b0;
wire [47:0] i_next = hold_q ? i_q : (i_over_q ? ilim_q : (i_under_q ? ilim_neg_q : isum_q));
wire first_term = (term == 3'd0);

// The next term's operand (sign-extended to 64 bits), registered on the clock before the term
// starts (op_q), and its gain. Term 0's operand is e, its magnitude e_abs (step 0).
wire [2:0] next_term = term + 3'd1;
reg [63:0] op;
reg [47:0] next_gain;
always @(*) begin
   case (next_term)
   3'd1: begin op = {{16{i_q[47]}}, i_q}; next_gain = ki_q; end
   3'd2: begin op = {{16{d_filt[47]}}, d_filt}; next_gain = kd_q; end   // F updated in term 0
   3'd3: begin op = {{8{vs_q[55]}}, vs_q}; next_gain = kv_q; end
   default: begin op = as_q; next_gain = ka_q; end
   endcase
end
reg [63:0] op_q = 64'd0;
wire [63:0] op_mag = op_q[63] ? (~op_q + 64'd1) : op_q;             // |-2^63| = 2^63 fits

// One gain digit (most significant first: the gain register's top 16 bits, which it shifts up
// a digit per product clock, so the multipliers read a register) times the magnitude: four
// 16 x 16 products, registered; added to the accumulator on the next clock.
wire [15:0] g = gain_q[47:32];
// acc = (acc << 16) + {p2, p0} + {p3, p1} << 16: three operands, added carry-save (their
// bitwise sum and carries, then one carry chain).
wire [111:0] acc_x = {acc_q[95:0], 16'd0};
wire [111:0] acc_y = {48'd0, p2, p0};
wire [111:0] acc_z = {32'd0, p3, p1, 16'd0};
wire [110:0] acc_carries = (acc_x[110:0] & acc_y[110:0]) | (acc_x[110:0] & acc_z[110:0])
   | (acc_y[110:0] & acc_z[110:0]);   // (the carry out of bit 111 leaves the 112 bits)
wire [111:0] acc_next = (acc_x ^ acc_y ^ acc_z) + {acc_carries, 1'b0};

// Finish: round to nearest (halves up): the sum starts at 2^{{HALF}}, so u = sum >>> {{OUT_SHIFT}};
// saturate.
wire [67:0] u = sum_q[115:48];
// u > OUTPUT_LIMIT and u < −OUTPUT_LIMIT, split at bit 16 so that no 68-bit carry chain
// precedes the output's multiplexer: the high 52 bits all 0 or all 1 (wide ANDs), beside a
// 16-bit compare of the low bits. (−OUTPUT_LIMIT, 17 bits: its high bits are all 1 when it is
// below 0, all 0 when it is 0.)
wire u_top_zero = u[67:16] == 52'd0;
wire u_top_ones = u[67:16] == {52{1'b1}};
wire u_hi = (!u[67] && !u_top_zero) || (u_top_zero && (u[15:0] > olim_q));
wire u_lo = olim_neg_q[16]
   ? ((u[67] && !u_top_ones) || (u_top_ones && (u[15:0] < olim_neg_q[15:0])))
   : u[67];

// The controller's state: what it carries from sample to sample (the divider, the integrator,
// the derivative filter, the last error and output) and its schedule, cleared while the
// amplifier is off.
always @(posedge clock) begin
   fault_q <= 1'b0;
   overrun_q <= 1'b0;
   if (reset || start) peak_q <= 32'd0;
   if (reset || !enable) begin
      divider <= {SERVO_PERIOD_BITS{1'b0}};
      busy <= 1'b0;
      step0 <= 1'b0;
      term <= 3'd0;
      digit <= 3'd0;
      fin <= 1'b0;
      f_q <= 48'd0;
      i_q <= 48'd0;
      eprev_q <= 32'd0;
      primed <= 1'b0;
      sat_hi <= 1'b0;
      sat_lo <= 1'b0;
      duty_q <= 16'd0;
   end else begin
      if (tick && (servo_period != {SERVO_PERIOD_BITS{1'b0}}))
         divider <= (divider == {SERVO_PERIOD_BITS{1'b0}}) ? servo_period - 1'b1 : divider - 1'b1;
      if (due && busy) overrun_q <= 1'b1;
      else if (due) begin
         busy <= 1'b1;
         step0 <= 1'b1;
      end
      if (busy) begin
         if (step0) begin
            fault_q <= fault_now;
            if (!start && above_peak) peak_q <= e_abs;
            step0 <= 1'b0;
            term <= 3'd0;
            digit <= 3'd0;
         end else if (!fin) begin
            if (first_term && (digit == 3'd0)) begin
               eprev_q <= e_q;
               primed <= 1'b1;
            end
            if (first_term && (digit == 3'd1)) begin
               i_q <= i_next;
               f_q <= f_q - dfilt_q;
            end
            if (first_term && (digit == 3'd2)) f_q <= f_q + {{15{delta_q[32]}}, delta_q};
            if (digit != 3'd{{SUM_CLOCK}}) digit <= digit + 3'd1;
            else begin
               digit <= 3'd0;
               if (term != 3'd{{LAST_TERM}}) term <= term + 3'd1;
               else fin <= 1'b1;
            end
         end else begin
            sat_hi <= u_hi;
            sat_lo <= u_lo;
            duty_q <= u_hi ? olim_q : (u_lo ? olim_neg_q[15:0] : u[15:0]);
            busy <= 1'b0;
            fin <= 1'b0;
         end
      end
   end
end

// The datapath: no reset, each register written before a sample reads it. The sample's
// operands and the configuration are taken on every clock the controller is idle (so on a
// sample's clock, due and not busy, they hold that clock's values) and read only while it
// computes: their some 350 enables are a register (busy), not the sample's decision.
always @(posedge clock) begin
   if (!busy) begin
      e48_q <= e48_now;
      e_q <= e_sat;
      vs_q <= velocity;
      as_q <= accel;
      kp_q <= kp;
      ki_q <= ki;
      kd_q <= kd;
      kv_q <= kv;
      ka_q <= ka;
      ilim_q <= integral_limit;
      olim_q <= output_limit;
      flim_q <= following_limit;
      dfk_q <= d_filter;
      flim_neg_q <= ~{1'b0, following_limit, 16'd0} + 49'd1;
      ilim_neg_q <= ~integral_limit + 48'd1;
      olim_neg_q <= ~{1'b0, output_limit} + 17'd1;
   end else if (step0) begin
      sum_q <= 116'd1 << {{HALF}};
      acc_q <= 112'd0;
      mag_q <= {32'd0, e_abs};
      neg_q <= e_q[31];
      gain_q <= kp_q;
   end else if (!fin) begin
      if (first_term && (digit == 3'd0)) begin
         delta_q <= primed ? ({e_q[31], e_q} - {eprev_q[31], eprev_q}) : 33'd0;
         isum_q <= i_q + {{16{e_q[31]}}, e_q};
         i_over_q <= !over_t[49];
         i_under_q <= under_t[49];
         hold_q <= hold;
         dfilt_q <= d_filt;
      end
      if (digit != 3'd{{SUM_CLOCK}}) begin
         if (digit != 3'd0) acc_q <= acc_next;
         if (digit == 3'd{{DIGITS}}) op_q <= op;
         if (digit < 3'd{{DIGITS}}) begin
            p0 <= g * mag_q[15:0];
            p1 <= g * mag_q[31:16];
            p2 <= g * mag_q[47:32];
            p3 <= g * mag_q[63:48];
            gain_q <= {gain_q[31:0], 16'd0};
         end
      end else begin
         sum_q <= neg_q ? sum_q - {4'd0, acc_q} : sum_q + {4'd0, acc_q};
         acc_q <= 112'd0;
         if (term != 3'd{{LAST_TERM}}) begin
            mag_q <= op_mag;
            neg_q <= op_q[63];
            gain_q <= next_gain;
         end
      end
   end
end

always @(*) begin
   duty = duty_q;
   fault = fault_q;
   overrun = overrun_q;
   peak = peak_q;
end
