// The path interpolator (its reference, register for register, is
// snapgen_model::path::engine; the rule it follows is snapgen_model::path::interp): a distance
// `offset` into the loaded path segment becomes every axis's position, one axis after the
// other, through one shared datapath:
//
//   * a serial multiplier: a (X_BITS, signed) times b (SHARE_BITS or RATE_BITS, signed), one
//     radix-4 Booth digit of b (-2..2, from the lowest) per two clocks into the right-shifting
//     accumulator {hi, lo}. The exact product, so its high bits round toward -inf;
//   * the CORDIC (snapgen_model::path::cordic), one step per two clocks, its arctangents in a
//     ROM.
//
// For routed timing the wide sums take two clocks: the accumulator's sum is added low half
// then high half (the carry registered between them), as is each product's use
// (base + product); a CORDIC step shifts on one clock and adds (65 bits) on the next. The
// widest sums left in one clock are the CORDIC's 65 bits and the angle's 64.
//
// Template: snapgen_hdl fills the values in double braces (the axes, the CORDIC's gain and
// steps) and the //@ line (the arctangent ROM) from the model's constants, and puts the
// widths it names (X_BITS, SHARE_BITS, ...) in front as localparams.

localparam [2:0] S_IDLE = 3'd0, S_MULTIPLY = 3'd1, S_FINISH = 3'd2,
                 S_CORDIC_INIT = 3'd3, S_CORDIC = 3'd4, S_ROTATE = 3'd5;
localparam [1:0] J_ANGLE = 2'd0, J_RADIUS = 2'd1, J_PLANE = 2'd2, J_AXIS = 2'd3;
localparam [3:0] AXES = 4'd{{AXES}};              // axes of this design
localparam [6:0] LAST_STEP = 7'd{{LAST_STEP}};    // the CORDIC's last step
localparam [6:0] SHARE_LAST = 7'd{{SHARE_LAST}};  // a share product's last digit
localparam [6:0] RATE_LAST = 7'd{{RATE_LAST}};    // the rate product's last digit
localparam [CORDIC_BITS-1:0] GAIN = {{CORDIC_BITS}}'d{{GAIN}};  // floor(K * 2^62)

// ---- The loaded segment -------------------------------------------------------------------
reg seg_arc = 1'b0, seg_ccw = 1'b0;
reg [2:0] seg_plane_first = 3'd0, seg_plane_second = 3'd0;
reg [X_BITS-1:0] seg_centre_first = {X_BITS{1'b0}}, seg_centre_second = {X_BITS{1'b0}};
reg [X_BITS-1:0] seg_radius = {X_BITS{1'b0}};
reg [SHARE_BITS-1:0] seg_growth = {SHARE_BITS{1'b0}};
reg [63:0] seg_start_angle = 64'd0;
reg [RATE_BITS-1:0] seg_rate = {RATE_BITS{1'b0}};
// Each axis at the segment's start and its share of the length: 8 words (an axis index's
// range); only the design's axes are ever written, the others stay 0.
reg [X_BITS-1:0] seg_from [0:7];
reg [SHARE_BITS-1:0] seg_share [0:7];
integer seg_i;
initial for (seg_i = 0; seg_i < 8; seg_i = seg_i + 1) begin
   seg_from[seg_i] = {X_BITS{1'b0}};
   seg_share[seg_i] = {SHARE_BITS{1'b0}};
end

// ---- The computation ------------------------------------------------------------------------
reg [2:0] state = S_IDLE;
reg phase = 1'b0;                              // the half of a two-clock step
reg [1:0] job = J_ANGLE;
reg half = 1'b0;                               // a plane product's axis: 0 first (cos), 1 second (sin)
reg [2:0] k = 3'd0;                            // an axis product's axis
reg [6:0] count = 7'd0;                        // digits of b left minus one
reg [X_BITS-1:0] mul_a = {X_BITS{1'b0}};       // the multiplier's signed operand
reg [LO_BITS-1:0] mul_b = {LO_BITS{1'b0}};     // the bits of b not yet used, lowest next
reg prev = 1'b0;                               // the bit of b below the next digit (Booth)
reg [HI_BITS-1:0] hi = {HI_BITS{1'b0}};        // the accumulator: high part (signed),
/* verilator lint_off UNUSEDSIGNAL */ // its lowest two bits leave as the next ones come in
reg [LO_BITS-1:0] lo = {LO_BITS{1'b0}};        // low part (product bits, in from the top)
/* verilator lint_on UNUSEDSIGNAL */
reg [SPLIT-1:0] low = {SPLIT{1'b0}};           // a split sum's low half, added on the last clock,
reg carry = 1'b0;                              // and its carry
reg [X_BITS-1:0] base_q = {X_BITS{1'b0}};      // what the product will be added to
reg [3:0] next_q = 4'd0;                       // the next product's axis (bit 3: there is one)
reg [SHARE_BITS-1:0] next_share = {SHARE_BITS{1'b0}};  // and its share
reg [X_BITS-1:0] r = {X_BITS{1'b0}};           // the offset being computed
reg [X_BITS-1:0] rho = {X_BITS{1'b0}};         // the arc's radius at r
reg [63:0] theta = 64'd0;                      // the arc's angle at r (a turn is 2^64)
reg [1:0] quadrant = 2'd0;
reg [CORDIC_BITS-1:0] cx = {CORDIC_BITS{1'b0}}, cy = {CORDIC_BITS{1'b0}}, cz = {CORDIC_BITS{1'b0}};
reg [CORDIC_BITS-1:0] cy_shift = {CORDIC_BITS{1'b0}}, cx_shift = {CORDIC_BITS{1'b0}};  // y, x >>> step
reg [CORDIC_BITS-1:0] atan_q = {CORDIC_BITS{1'b0}};                                      // atan(step)
reg [5:0] step = 6'd0;
reg [SHARE_BITS-1:0] cosine = {SHARE_BITS{1'b0}}, sine = {SHARE_BITS{1'b0}};
reg write_q = 1'b0, done_q = 1'b0;
reg [2:0] axis_q = 3'd0;
reg [X_BITS-1:0] value_q = {X_BITS{1'b0}};

// ---- The arctangents: atan(2^-i) in turns * 2^64, rounded (snapgen_model::path::cordic) ------
function automatic [CORDIC_BITS-1:0] atan(input [5:0] i);
   case (i)
//@ atan_cases
   endcase
endfunction

// The first axis at or after `from` that moves as on a line (every axis on a line; on an arc,
// all but the plane's two): its index in [2:0], and bit 3 set when there is one.
function automatic [3:0] next_axis(input [3:0] first, input is_arc, input [2:0] p0, input [2:0] p1);
   integer n;
   begin
      next_axis = 4'd0;
      for (n = {{AXES_TOP}}; n >= 0; n = n - 1)
         if (n[3:0] >= first && !(is_arc && (n[2:0] == p0 || n[2:0] == p1)))
            next_axis = {1'b1, n[2:0]};
   end
endfunction

// ---- The datapath, from the registers ------------------------------------------------------
// Booth's digit d = -2*b1 + b0 + prev: zero, a or 2a, subtracted as ~multiple + 1.
wire d_zero = (mul_b[0] == mul_b[1]) && (mul_b[1] == prev);
wire d_two = (mul_b[1] && !mul_b[0] && !prev) || (!mul_b[1] && mul_b[0] && prev);
wire d_neg = mul_b[1] && !(mul_b[0] && prev);
wire [T_BITS-1:0] a_wide = {{(T_BITS-X_BITS){mul_a[X_BITS-1]}}, mul_a};
wire [T_BITS-1:0] multiple = d_zero ? {T_BITS{1'b0}} : d_two ? {a_wide[T_BITS-2:0], 1'b0} : a_wide;
wire [T_BITS-1:0] addend = d_neg ? ~multiple : multiple;
wire [T_BITS-1:0] hi_wide = {{(T_BITS-HI_BITS){hi[HI_BITS-1]}}, hi};
wire [SPLIT:0] t_low = {1'b0, hi_wide[SPLIT-1:0]} + {1'b0, addend[SPLIT-1:0]} + {{SPLIT{1'b0}}, d_neg};
wire [T_BITS-SPLIT-1:0] t_high = hi_wide[T_BITS-1:SPLIT] + addend[T_BITS-1:SPLIT] + {{(T_BITS-SPLIT-1){1'b0}}, carry};
wire [T_BITS-1:0] t = {t_high, low};
// The product shifted right by 62 (a share's product), and what it is added to (taken into
// base_q on every clock of the product: the memory read and the choice take a clock of their
// own).
wire [X_BITS-1:0] p62 = {hi[X_BITS-1-(SHARE_BITS-SHARE_FRAC):0], lo[LO_BITS-1:LO_BITS-SHARE_BITS+SHARE_FRAC]};
wire [X_BITS-1:0] base = (job == J_RADIUS) ? seg_radius
                       : (job == J_PLANE) ? (half ? seg_centre_second : seg_centre_first)
                       : seg_from[k];
wire [SPLIT:0] s_low = {1'b0, base_q[SPLIT-1:0]} + {1'b0, p62[SPLIT-1:0]};
wire [X_BITS-SPLIT-1:0] s_high = base_q[X_BITS-1:SPLIT] + p62[X_BITS-1:SPLIT] + {{(X_BITS-SPLIT-1){1'b0}}, carry};
wire [X_BITS-1:0] sum = {s_high, low};
wire [63:0] turned = {hi[63-(RATE_BITS-RATE_FRAC):0], lo[LO_BITS-1:RATE_FRAC]};
wire [1:0] quarter = theta[63:62] + {1'b0, theta[61]};  // the nearest quarter turn: (theta + 2^61) >> 62
wire [63:0] z_start = theta - {quarter, 62'd0};

// Begins the product factor_a * factor_b (factor_b's digits: last + 1), for the job `for_job`.
task begin_multiply(input [X_BITS-1:0] factor_a, input [LO_BITS-1:0] factor_b, input [6:0] last, input [1:0] for_job);
   begin
      mul_a <= factor_a; mul_b <= factor_b; count <= last; prev <= 1'b0; phase <= 1'b0;
      hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}}; job <= for_job; state <= S_MULTIPLY;
   end
endtask

// The product r * share for the next axis that moves as on a line (chosen while the last
// product was formed), or the end of the computation.
task next_product;
   begin
      if (next_q[3]) begin
         k <= next_q[2:0];
         begin_multiply(r, {{(LO_BITS-SHARE_BITS){1'b0}}, next_share}, SHARE_LAST, J_AXIS);
      end else begin
         state <= S_IDLE;
         done_q <= 1'b1;
      end
   end
endtask

always @(posedge clock) begin : interpolate
   write_q <= 1'b0;
   done_q <= 1'b0;
   if (load_shape) begin
      seg_arc <= arc;
      seg_ccw <= ccw;
      seg_plane_first <= plane_first;
      seg_plane_second <= plane_second;
      seg_centre_first <= centre_first;
      seg_centre_second <= centre_second;
      seg_radius <= radius;
      seg_growth <= growth;
      seg_start_angle <= start_angle;
      seg_rate <= rate;
   end
   if (load_axis && ({1'b0, axis} < AXES)) begin
      seg_from[axis] <= from;
      seg_share[axis] <= share;
   end
   if (reset) begin
      state <= S_IDLE;
   end else begin
      case (state)
      S_IDLE: if (start) begin
         r <= offset;
         if (seg_arc) begin
            begin_multiply(offset, seg_rate, RATE_LAST, J_ANGLE);
         end else begin
            // A line moves every axis: the first is axis 0.
            k <= 3'd0;
            begin_multiply(offset, {{(LO_BITS-SHARE_BITS){1'b0}}, seg_share[0]}, SHARE_LAST, J_AXIS);
         end
      end
      S_MULTIPLY: if (!phase) begin
         base_q <= base;
         next_q <= next_axis((job == J_AXIS) ? {1'b0, k} + 4'd1 : 4'd0, seg_arc, seg_plane_first, seg_plane_second);
         next_share <= seg_share[next_q[2:0]];
         low <= t_low[SPLIT-1:0];
         carry <= t_low[SPLIT];
         phase <= 1'b1;
      end else begin
         base_q <= base;
         next_q <= next_axis((job == J_AXIS) ? {1'b0, k} + 4'd1 : 4'd0, seg_arc, seg_plane_first, seg_plane_second);
         next_share <= seg_share[next_q[2:0]];
         hi <= t[T_BITS-1:2];
         lo <= {t[1:0], lo[LO_BITS-1:2]};
         mul_b <= {2'b00, mul_b[LO_BITS-1:2]};
         prev <= mul_b[1];
         phase <= 1'b0;
         if (count == 7'd0) state <= S_FINISH;
         else count <= count - 7'd1;
      end
      S_FINISH: if (!phase) begin
         low <= s_low[SPLIT-1:0];
         carry <= s_low[SPLIT];
         phase <= 1'b1;
      end else begin
         phase <= 1'b0;
         case (job)
         J_ANGLE: begin
            theta <= seg_ccw ? seg_start_angle + turned : seg_start_angle - turned;
            state <= S_CORDIC_INIT;
         end
         J_RADIUS: begin
            rho <= sum;
            half <= 1'b0;
            begin_multiply(sum, {{(LO_BITS-SHARE_BITS){1'b0}}, cosine}, SHARE_LAST, J_PLANE);
         end
         J_PLANE: begin
            write_q <= 1'b1;
            axis_q <= half ? seg_plane_second : seg_plane_first;
            value_q <= sum;
            if (!half) begin
               half <= 1'b1;
               begin_multiply(rho, {{(LO_BITS-SHARE_BITS){1'b0}}, sine}, SHARE_LAST, J_PLANE);
            end else begin
               next_product;
            end
         end
         default: begin // J_AXIS
            write_q <= 1'b1;
            axis_q <= k;
            value_q <= sum;
            next_product;
         end
         endcase
      end
      S_CORDIC_INIT: begin
         quadrant <= quarter;
         cz <= {z_start[63], z_start};
         cx <= GAIN;
         cy <= {CORDIC_BITS{1'b0}};
         step <= 6'd0;
         phase <= 1'b0;
         state <= S_CORDIC;
      end
      S_CORDIC: if (!phase) begin
         cy_shift <= $signed(cy) >>> step;
         cx_shift <= $signed(cx) >>> step;
         atan_q <= atan(step);
         phase <= 1'b1;
      end else begin
         if (!cz[CORDIC_BITS-1]) begin
            cx <= cx - cy_shift; cy <= cy + cx_shift; cz <= cz - atan_q;
         end else begin
            cx <= cx + cy_shift; cy <= cy - cx_shift; cz <= cz + atan_q;
         end
         step <= step + 6'd1;
         phase <= 1'b0;
         if ({1'b0, step} == LAST_STEP) state <= S_ROTATE;
      end
      S_ROTATE: begin
         case (quadrant)
         2'd0: begin cosine <= cx[SHARE_BITS-1:0]; sine <= cy[SHARE_BITS-1:0]; end
         2'd1: begin cosine <= -cy[SHARE_BITS-1:0]; sine <= cx[SHARE_BITS-1:0]; end
         2'd2: begin cosine <= -cx[SHARE_BITS-1:0]; sine <= -cy[SHARE_BITS-1:0]; end
         default: begin cosine <= cy[SHARE_BITS-1:0]; sine <= -cx[SHARE_BITS-1:0]; end
         endcase
         begin_multiply(r, {{(LO_BITS-SHARE_BITS){1'b0}}, seg_growth}, SHARE_LAST, J_RADIUS);
      end
      default: state <= S_IDLE;
      endcase
   end
end

always @(*) begin
   busy = state != S_IDLE;
   done = done_q;
   out_write = write_q;
   out_axis = axis_q;
   out_value = value_q;
end
