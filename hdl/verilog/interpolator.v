// The path interpolator (its reference, register for register, is
// snapgen_model::path::engine; the rule it follows is snapgen_model::path::interp): a distance
// `offset` into the loaded path segment becomes every axis's position, one axis after the
// other, through one shared datapath:
//
//   * a serial multiplier: a (X_BITS, signed) times b (SHARE_BITS or RATE_BITS, signed), one
//     bit of b per clock from the lowest into the right-shifting accumulator {hi, lo}; the
//     last bit (b's sign) subtracts a. The exact product, so its high bits round toward -inf;
//   * the CORDIC (snapgen_model::path::cordic), one step per clock, its arctangents in a ROM.
//
// Template: snapgen_hdl fills the values in double braces (the axes, the CORDIC's gain and
// steps) and the //@ line (the arctangent ROM) from the model's constants, and puts the
// widths it names (X_BITS, SHARE_BITS, ...) in front as localparams.

localparam [2:0] S_IDLE = 3'd0, S_MULTIPLY = 3'd1, S_FINISH = 3'd2,
                 S_CORDIC_INIT = 3'd3, S_CORDIC = 3'd4, S_ROTATE = 3'd5;
localparam [1:0] J_ANGLE = 2'd0, J_RADIUS = 2'd1, J_PLANE = 2'd2, J_AXIS = 2'd3;
localparam [3:0] AXES = 4'd{{AXES}};              // axes of this design
localparam [6:0] LAST_STEP = 7'd{{LAST_STEP}};    // the CORDIC's last step
localparam [6:0] SHARE_LAST = 7'd{{SHARE_LAST}};  // a share product's last bit
localparam [6:0] RATE_LAST = 7'd{{RATE_LAST}};    // the rate product's last bit
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
reg [1:0] job = J_ANGLE;
reg half = 1'b0;                               // a plane product's axis: 0 first (cos), 1 second (sin)
reg [2:0] k = 3'd0;                            // an axis product's axis
reg [6:0] count = 7'd0;                        // bits of b left minus one
reg [X_BITS-1:0] mul_a = {X_BITS{1'b0}};       // the multiplier's signed operand
reg [LO_BITS-1:0] mul_b = {LO_BITS{1'b0}};     // the bits of b not yet used, lowest next
reg [HI_BITS-1:0] hi = {HI_BITS{1'b0}};        // the accumulator: high part (signed),
/* verilator lint_off UNUSEDSIGNAL */ // its lowest bit leaves as the next one comes in
reg [LO_BITS-1:0] lo = {LO_BITS{1'b0}};        // low part (product bits, in from the top)
/* verilator lint_on UNUSEDSIGNAL */
reg [X_BITS-1:0] r = {X_BITS{1'b0}};           // the offset being computed
reg [X_BITS-1:0] rho = {X_BITS{1'b0}};         // the arc's radius at r
reg [63:0] theta = 64'd0;                      // the arc's angle at r (a turn is 2^64)
reg [1:0] quadrant = 2'd0;
reg [CORDIC_BITS-1:0] cx = {CORDIC_BITS{1'b0}}, cy = {CORDIC_BITS{1'b0}}, cz = {CORDIC_BITS{1'b0}};
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

// The multiplier's step and the product's high bits, from the registers.
wire [HI_BITS:0] addend = !mul_b[0] ? {(HI_BITS+1){1'b0}}
                        : (count == 7'd0) ? -{{2{mul_a[X_BITS-1]}}, mul_a}
                        : {{2{mul_a[X_BITS-1]}}, mul_a};
wire [HI_BITS:0] t = {hi[HI_BITS-1], hi} + addend;
wire [X_BITS-1:0] p62 = {hi[X_BITS-1-(SHARE_BITS-SHARE_FRAC):0], lo[LO_BITS-1:LO_BITS-SHARE_BITS+SHARE_FRAC]};
// A product's use: its base (the radius, a plane axis's centre, an axis's start) plus p62, in
// one adder.
wire [X_BITS-1:0] base = (job == J_RADIUS) ? seg_radius
                       : (job == J_PLANE) ? (half ? seg_centre_second : seg_centre_first)
                       : seg_from[k];
wire [X_BITS-1:0] sum = base + p62;
wire [63:0] turned = {hi[63-(RATE_BITS-RATE_FRAC):0], lo[LO_BITS-1:RATE_FRAC]};
wire [1:0] quarter = theta[63:62] + {1'b0, theta[61]};  // the nearest quarter turn: (theta + 2^61) >> 62
wire [63:0] z_start = theta - {quarter, 62'd0};
wire [CORDIC_BITS-1:0] cx_shift = $signed(cx) >>> step;
wire [CORDIC_BITS-1:0] cy_shift = $signed(cy) >>> step;

always @(posedge clock) begin : interpolate
   reg [3:0] nx;
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
            mul_a <= offset; mul_b <= seg_rate; count <= RATE_LAST;
            hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}}; job <= J_ANGLE; state <= S_MULTIPLY;
         end else begin
            nx = next_axis(4'd0, seg_arc, seg_plane_first, seg_plane_second);
            k <= nx[2:0];
            mul_a <= offset; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, seg_share[nx[2:0]]};
            count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
            job <= J_AXIS; state <= S_MULTIPLY;
         end
      end
      S_MULTIPLY: begin
         hi <= t[HI_BITS:1];
         lo <= {t[0], lo[LO_BITS-1:1]};
         mul_b <= {1'b0, mul_b[LO_BITS-1:1]};
         if (count == 7'd0) state <= S_FINISH;
         else count <= count - 7'd1;
      end
      S_FINISH: case (job)
         J_ANGLE: begin
            theta <= seg_ccw ? seg_start_angle + turned : seg_start_angle - turned;
            state <= S_CORDIC_INIT;
         end
         J_RADIUS: begin
            rho <= sum;
            half <= 1'b0;
            mul_a <= sum; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, cosine};
            count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
            job <= J_PLANE; state <= S_MULTIPLY;
         end
         J_PLANE: begin
            write_q <= 1'b1;
            axis_q <= half ? seg_plane_second : seg_plane_first;
            value_q <= sum;
            if (!half) begin
               half <= 1'b1;
               mul_a <= rho; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, sine};
               count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
               state <= S_MULTIPLY;
            end else begin
               nx = next_axis(4'd0, seg_arc, seg_plane_first, seg_plane_second);
               if (nx[3]) begin
                  k <= nx[2:0];
                  mul_a <= r; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, seg_share[nx[2:0]]};
                  count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
                  job <= J_AXIS; state <= S_MULTIPLY;
               end else begin
                  state <= S_IDLE;
                  done_q <= 1'b1;
               end
            end
         end
         default: begin // J_AXIS
            write_q <= 1'b1;
            axis_q <= k;
            value_q <= sum;
            nx = next_axis({1'b0, k} + 4'd1, seg_arc, seg_plane_first, seg_plane_second);
            if (nx[3]) begin
               k <= nx[2:0];
               mul_a <= r; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, seg_share[nx[2:0]]};
               count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
               state <= S_MULTIPLY;
            end else begin
               state <= S_IDLE;
               done_q <= 1'b1;
            end
         end
      endcase
      S_CORDIC_INIT: begin
         quadrant <= quarter;
         cz <= {z_start[63], z_start};
         cx <= GAIN;
         cy <= {CORDIC_BITS{1'b0}};
         step <= 6'd0;
         state <= S_CORDIC;
      end
      S_CORDIC: begin
         if (!cz[CORDIC_BITS-1]) begin
            cx <= cx - cy_shift; cy <= cy + cx_shift; cz <= cz - atan(step);
         end else begin
            cx <= cx + cy_shift; cy <= cy - cx_shift; cz <= cz + atan(step);
         end
         step <= step + 6'd1;
         if ({1'b0, step} == LAST_STEP) state <= S_ROTATE;
      end
      S_ROTATE: begin
         case (quadrant)
         2'd0: begin cosine <= cx[SHARE_BITS-1:0]; sine <= cy[SHARE_BITS-1:0]; end
         2'd1: begin cosine <= -cy[SHARE_BITS-1:0]; sine <= cx[SHARE_BITS-1:0]; end
         2'd2: begin cosine <= -cx[SHARE_BITS-1:0]; sine <= -cy[SHARE_BITS-1:0]; end
         default: begin cosine <= cy[SHARE_BITS-1:0]; sine <= -cx[SHARE_BITS-1:0]; end
         endcase
         mul_a <= r; mul_b <= {{(LO_BITS-SHARE_BITS){1'b0}}, seg_growth};
         count <= SHARE_LAST; hi <= {HI_BITS{1'b0}}; lo <= {LO_BITS{1'b0}};
         job <= J_RADIUS; state <= S_MULTIPLY;
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
