// The path sequencer (its reference, register for register, is
// snapgen_model::path::sequencer): the ring of path segments the host writes ahead of the
// motion and, on each tick, the segment the path length s lies in, the interpolator's load
// and its start.
//
//   * The ring: PATH_SLOTS segments in block RAM (span, shape, one word per axis), wrapping
//     PATH_INDEX_BITS-bit indices. A write is accepted in order (the segment after the highest
//     written, or more words of the highest while it is not in the path) into a free slot or
//     one whose segment is more than one before the current (never the current segment or the
//     one before it), and forgets the segment whose slot it takes; an extension takes in every
//     segment written. Anything else sets the sticky `refused`.
//   * A tick, when idle: `commit` if a computation ended since the last one, then (unless the
//     path is empty) the seek. Each step reads the span (two clocks: every read passes the
//     block RAM's register and one more, so its slow output drives only a register), forms
//     r = s - start and r - length (112-bit differences over two clocks each, split at SPLIT,
//     and their comparisons with a cell on a clock of their own, for routed timing) and
//     moves back a segment when r < 0 or on when r >= length, within oldest..last and never
//     both ways in one seek. Where it stops it clamps r (a cell before the path's first
//     segment, a cell beyond its last, elsewhere the segment), loads the interpolator if it
//     holds another segment (the shape with axis 0, then one axis per clock), starts it and
//     waits for `done`. A tick while this runs is `late` (sticky) and dropped.
//
// Template: snapgen_hdl fills the values in double braces (the axes, and whether seg_axis
// names one: always, in a design of 8) and puts the widths it names (X_BITS, PATH_SLOTS, ...)
// in front as localparams.

localparam [3:0] S_IDLE = 4'd0, S_READ = 4'd1, S_FETCH = 4'd2, S_OFFSET_LOW = 4'd3,
                 S_OFFSET_HIGH = 4'd4, S_PAST_LOW = 4'd5, S_PAST_HIGH = 4'd6, S_JUDGE = 4'd7,
                 S_DECIDE = 4'd8, S_LOAD_AXIS = 4'd9, S_WAIT = 4'd10;
localparam [AXIS_BITS-1:0] AXES_TOP = {{AXIS_BITS}}'d{{AXES_TOP}};   // the design's last axis
localparam SHAPE_BITS = 2 + 2 * AXIS_BITS + 3 * X_BITS + SHARE_BITS + TURN_BITS + RATE_BITS;
localparam AXIS_WORD_BITS = X_BITS + SHARE_BITS;
localparam HIGH_BITS = X_BITS - SPLIT;            // the high half of a split difference
localparam CELL_BITS = X_BITS - FRAC_BITS;        // whole cells of a position
localparam [PATH_INDEX_BITS-1:0] RING = PATH_SLOTS[PATH_INDEX_BITS-1:0];
localparam [PATH_INDEX_BITS-1:0] ONE_INDEX = 1;
localparam [AXIS_BITS-1:0] ONE_AXIS = 1;
localparam [CELL_BITS-1:0] ONE_CELL = 1;
localparam [X_BITS-1:0] CELL = {{(CELL_BITS-1){1'b0}}, 1'b1, {FRAC_BITS{1'b0}}};
localparam [X_BITS-1:0] MINUS_CELL = {{CELL_BITS{1'b1}}, {FRAC_BITS{1'b0}}};

// ---- The ring -----------------------------------------------------------------------------
(* ram_style = "block" *) reg [2*X_BITS-1:0] span_mem [0:PATH_SLOTS-1];       // {start, length}
(* ram_style = "block" *) reg [SHAPE_BITS-1:0] shape_mem [0:PATH_SLOTS-1];
// {from, share} at {slot, axis}: MAX_AXES words per slot whatever the design's axes.
(* ram_style = "block" *) reg [AXIS_WORD_BITS-1:0] axis_mem [0:PATH_SLOTS*MAX_AXES-1];
integer mem_i;
initial begin
   for (mem_i = 0; mem_i < PATH_SLOTS; mem_i = mem_i + 1) begin
      span_mem[mem_i] = {2*X_BITS{1'b0}};
      shape_mem[mem_i] = {SHAPE_BITS{1'b0}};
   end
   for (mem_i = 0; mem_i < PATH_SLOTS*MAX_AXES; mem_i = mem_i + 1)
      axis_mem[mem_i] = {AXIS_WORD_BITS{1'b0}};
end

reg [PATH_INDEX_BITS-1:0] k = {PATH_INDEX_BITS{1'b0}};        // the current segment
reg [PATH_INDEX_BITS-1:0] oldest = {PATH_INDEX_BITS{1'b0}};   // the oldest still in the ring
reg [PATH_INDEX_BITS-1:0] last = {PATH_INDEX_BITS{1'b1}};     // the path's last (oldest - 1: empty)
reg [PATH_INDEX_BITS-1:0] highest = {PATH_INDEX_BITS{1'b1}};      // the highest written since reset
reg [PATH_INDEX_BITS-1:0] next_highest = {PATH_INDEX_BITS{1'b0}}; // highest + 1
reg whole = 1'b1;                                              // none forgotten since reset
reg [PATH_INDEX_BITS-1:0] loaded = {PATH_INDEX_BITS{1'b0}};   // the segment the interpolator holds
reg loaded_valid = 1'b0;

// Reads of the current segment through two registers: the block RAM's own (_m, the value
// before a write on the same clock) and one more (_q), so that the RAM's slow output drives
// nothing but a register.
reg [2*X_BITS-1:0] span_m = {2*X_BITS{1'b0}}, span_q = {2*X_BITS{1'b0}};
reg [SHAPE_BITS-1:0] shape_m = {SHAPE_BITS{1'b0}}, shape_q = {SHAPE_BITS{1'b0}};
reg [AXIS_WORD_BITS-1:0] axis_m = {AXIS_WORD_BITS{1'b0}}, axis_q = {AXIS_WORD_BITS{1'b0}};
reg [AXIS_BITS-1:0] a_read = {AXIS_BITS{1'b0}};                // the axis read next
reg [AXIS_BITS-1:0] a_m = {AXIS_BITS{1'b0}};                   // the axis of axis_m
reg [AXIS_BITS-1:0] a_q = {AXIS_BITS{1'b0}};                   // the axis of axis_q
wire [PATH_SLOT_BITS-1:0] slot = k[PATH_SLOT_BITS-1:0];
wire [PATH_SLOT_BITS-1:0] write_slot = seg_index[PATH_SLOT_BITS-1:0];
wire [X_BITS-1:0] span_start = span_q[2*X_BITS-1:X_BITS];
wire [X_BITS-1:0] span_length = span_q[X_BITS-1:0];

// ---- The host's side: writes and extensions -----------------------------------------------
// A write: in order (to the segment after the highest written, or to the highest while it is
// not yet in the path), and into a free slot or one whose segment is more than one before the
// current (neither the current segment nor the one before it, where a seek may step back on
// this very clock, is overwritten). An extension takes in every segment written: its index is
// the highest written (on a clock after that segment's last write). Differences wrap.
// In order, the window oldest..=highest is at most a ring: a new segment takes a free slot
// unless the ring is full, and then forgets the oldest, which must be more than one before the
// current; the highest's slot is its own already. So the inputs meet only equalities; the
// rest is the registers' own.
wire any_write = write_span || write_shape || write_axis;
wire axis_exists = {{AXIS_EXISTS}};                // seg_axis is an axis of the design
wire pending = highest != last;                    // written, not yet in the path
wire is_next = seg_index == next_highest;
wire is_highest = seg_index == highest && pending;
wire [PATH_INDEX_BITS-1:0] span_held = highest - oldest;
wire [PATH_INDEX_BITS-1:0] ahead_of_current = next_highest - k;
wire full = span_held == RING - ONE_INDEX;
wire room = !full || (ahead_of_current < RING - ONE_INDEX);
wire write_ok = (is_highest || (is_next && room)) && (!write_axis || axis_exists);
wire write_taken = !reset && any_write && write_ok;
wire extend_ok = seg_index == highest && pending;
wire is_empty = (last + ONE_INDEX) == oldest;

// A write taken is registered (w_*) and made on the next clock: the block RAM's write enables
// and data come from registers (routed timing). The slot is safe a clock later: a write never
// takes the slot of the current segment or the one before it, and a seek steps back at most
// one segment per 8 clocks.
reg w_span = 1'b0, w_shape = 1'b0, w_axis = 1'b0;
reg [PATH_SLOT_BITS-1:0] w_slot = {PATH_SLOT_BITS{1'b0}};
reg [AXIS_BITS-1:0] w_axis_k = {AXIS_BITS{1'b0}};
reg [2*X_BITS-1:0] w_span_d = {2*X_BITS{1'b0}};
reg [SHAPE_BITS-1:0] w_shape_d = {SHAPE_BITS{1'b0}};
reg [AXIS_WORD_BITS-1:0] w_axis_d = {AXIS_WORD_BITS{1'b0}};

always @(posedge clock) begin
   span_m <= span_mem[slot];
   shape_m <= shape_mem[slot];
   axis_m <= axis_mem[{slot, a_read}];
   a_m <= a_read;
   span_q <= span_m;
   shape_q <= shape_m;
   axis_q <= axis_m;
   a_q <= a_m;
   if (w_span) span_mem[w_slot] <= w_span_d;
   if (w_shape) shape_mem[w_slot] <= w_shape_d;
   if (w_axis) axis_mem[{w_slot, w_axis_k}] <= w_axis_d;
   w_span <= write_taken && write_span;
   w_shape <= write_taken && write_shape;
   w_axis <= write_taken && write_axis;
   w_slot <= write_slot;
   w_axis_k <= seg_axis;
   w_span_d <= {seg_start, seg_length};
   w_shape_d <= {seg_arc, seg_ccw, seg_plane_first, seg_plane_second, seg_centre_first,
                 seg_centre_second, seg_radius, seg_growth, seg_start_angle, seg_rate};
   w_axis_d <= {seg_from, seg_share};
end

// ---- The seek -----------------------------------------------------------------------------
reg [3:0] state = S_IDLE;
reg [1:0] moved = 2'b00;                          // the seek moved on (bit 0), back (bit 1)
reg fresh = 1'b0;                                 // a computation ended since the last commit
reg [X_BITS-1:0] s_q = {X_BITS{1'b0}};            // the path length latched at the tick
reg [X_BITS-1:0] r = {X_BITS{1'b0}};              // s - start
reg [X_BITS-1:0] past = {X_BITS{1'b0}};           // r - length
reg [SPLIT-1:0] low = {SPLIT{1'b0}};              // a difference's low half
reg borrow = 1'b0;                                // and its borrow
reg under_cell = 1'b0;                            // r < -CELL
reg over_cell = 1'b0;                             // r - length > CELL
reg load_shape_q = 1'b0, load_axis_q = 1'b0, start_q = 1'b0, commit_q = 1'b0;
reg late_q = 1'b0, refused_q = 1'b0;
reg [X_BITS-1:0] offset_q = {X_BITS{1'b0}};

wire [HIGH_BITS-1:0] borrow_in = {{(HIGH_BITS-1){1'b0}}, borrow};
wire below = r[X_BITS-1];                          // r < 0
wire beyond = !past[X_BITS-1];                     // r >= length
wire at_oldest = k == oldest;
wire at_last = k == last;
wire first = at_oldest && whole;                   // the path's first segment
wire [CELL_BITS-1:0] r_cells = r[X_BITS-1:FRAC_BITS];
wire [CELL_BITS-1:0] past_cells = past[X_BITS-1:FRAC_BITS];
// Below a cell before the path's first segment, or below the start of any other.
wire under = first ? under_cell : below;
// More than a cell beyond the last segment's end, or beyond another's (a seek stopped at a
// gap between spans).
wire over = at_last ? over_cell : beyond;
wire [X_BITS-1:0] length_and_cell = {span_length[X_BITS-1:FRAC_BITS] + ONE_CELL,
                                     span_length[FRAC_BITS-1:0]};

always @(posedge clock) begin
   load_shape_q <= 1'b0;
   load_axis_q <= 1'b0;
   start_q <= 1'b0;
   commit_q <= 1'b0;
   if (reset) begin
      state <= S_IDLE;
      k <= {PATH_INDEX_BITS{1'b0}};
      oldest <= {PATH_INDEX_BITS{1'b0}};
      last <= {PATH_INDEX_BITS{1'b1}};
      highest <= {PATH_INDEX_BITS{1'b1}};
      next_highest <= {PATH_INDEX_BITS{1'b0}};
      whole <= 1'b1;
      loaded_valid <= 1'b0;
      fresh <= 1'b0;
      late_q <= 1'b0;
      refused_q <= 1'b0;
   end else begin
      // The host's side.
      if (write_taken && is_next) begin
         highest <= seg_index;
         next_highest <= seg_index + ONE_INDEX;
      end
      if (write_taken && is_next && full) begin
         oldest <= oldest + ONE_INDEX;                 // the slot's segment is forgotten
         whole <= 1'b0;
      end
      if ((any_write && !write_ok) || (extend && !extend_ok)) refused_q <= 1'b1;
      if (extend && extend_ok) last <= seg_index;
      if (tick && state != S_IDLE) late_q <= 1'b1;
      case (state)
      S_IDLE: if (tick) begin
         if (fresh) begin
            commit_q <= 1'b1;
            fresh <= 1'b0;
         end
         if (!is_empty) begin
            s_q <= s;
            moved <= 2'b00;
            a_read <= {AXIS_BITS{1'b0}};
            state <= S_READ;
         end
      end
      S_READ: state <= S_FETCH;
      S_FETCH: state <= S_OFFSET_LOW;
      S_OFFSET_LOW: begin
         {borrow, low} <= {1'b0, s_q[SPLIT-1:0]} - {1'b0, span_start[SPLIT-1:0]};
         state <= S_OFFSET_HIGH;
      end
      S_OFFSET_HIGH: begin
         r <= {s_q[X_BITS-1:SPLIT] - span_start[X_BITS-1:SPLIT] - borrow_in, low};
         state <= S_PAST_LOW;
      end
      S_PAST_LOW: begin
         {borrow, low} <= {1'b0, r[SPLIT-1:0]} - {1'b0, span_length[SPLIT-1:0]};
         state <= S_PAST_HIGH;
      end
      S_PAST_HIGH: begin
         past <= {r[X_BITS-1:SPLIT] - span_length[X_BITS-1:SPLIT] - borrow_in, low};
         state <= S_JUDGE;
      end
      S_JUDGE: begin
         under_cell <= $signed(r_cells) < -$signed(ONE_CELL);
         over_cell <= ($signed(past_cells) >= $signed(ONE_CELL)) && (past != CELL);
         state <= S_DECIDE;
      end
      // A seek never turns back (spans end to end never need it; a gap between two would
      // make it go to and fro): it stops where it would.
      S_DECIDE: if (below && !at_oldest && !moved[0]) begin
         k <= k - ONE_INDEX;
         moved[1] <= 1'b1;
         state <= S_READ;
      end else if (beyond && !at_last && !moved[1]) begin
         k <= k + ONE_INDEX;
         moved[0] <= 1'b1;
         state <= S_READ;
      end else begin
         if (under) offset_q <= first ? MINUS_CELL : {X_BITS{1'b0}};
         else if (over && at_last) offset_q <= length_and_cell;
         else if (over) offset_q <= span_length;
         else offset_q <= r;
         if (loaded_valid && loaded == k) begin
            start_q <= 1'b1;
            state <= S_WAIT;
         end else begin
            // The shape and axis 0 (read since the seek began), then the others as the reads
            // bring them (axis 0 twice: the read's latency).
            load_shape_q <= 1'b1;
            load_axis_q <= 1'b1;
            a_read <= ONE_AXIS;
            loaded_valid <= 1'b1;
            loaded <= k;
            state <= S_LOAD_AXIS;
         end
      end
      S_LOAD_AXIS: begin
         a_read <= a_read + ONE_AXIS;
         if (a_q == AXES_TOP) begin
            start_q <= 1'b1;
            state <= S_WAIT;
         end else begin
            load_axis_q <= 1'b1;
         end
      end
      S_WAIT: if (done) begin
         fresh <= 1'b1;
         state <= S_IDLE;
      end
      default: state <= S_IDLE;
      endcase
   end
end

always @(*) begin
   load_shape = load_shape_q;
   {arc, ccw, plane_first, plane_second, centre_first, centre_second, radius, growth,
    start_angle, rate} = shape_q;
   load_axis = load_axis_q;
   axis = a_q;
   {from, share} = axis_q;
   start = start_q;
   offset = offset_q;
   commit = commit_q;
   path_segment = k;
   running = state != S_IDLE;
   empty = is_empty;
   late = late_q;
   refused = refused_q;
end
