// The command executor and axis state machine (docs/PROTOCOL.md; its reference, clock for
// clock, is snapgen_model::io::executor::Executor). Template: snapgen_hdl fills the lines
// marked //@ from the contract (the command table, one register per parameter) and puts the
// localparams the body names in front of it (codes, reasons, states, widths, the design's
// constants), so no code or width is typed here as a number.
//
// On each frame with a good CRC it checks the command (code, length, arguments, then the axis
// state), applies its effect and queues its reply; a bad CRC or a dropped frame queues a NAK
// with sequence 0. Every output is registered: a next-state block in the model's order, then
// one register block.

// ---- The frame's fields (byte k of an n-byte payload is payload[8(n-1-k) +: 8]) ----------------
//@ payload_fields

// ---- The command table: known, payload length, has an effect (a retry is not executed) --------
reg known;
reg [7:0] want_len;
reg has_effect;
always @(*) begin
   known = 1'b0;
   want_len = 8'd0;
   has_effect = 1'b0;
   case (cmd)
   //@ command_table
   default: ;
   endcase
end

//@ param_functions

reg cfg_over;                                    // the CONFIGURE value is above its maximum
always @(*) begin
   cfg_over = 1'b0;
   case (cfg_param)
   //@ param_over
   default: ;
   endcase
end

// ---- Registers --------------------------------------------------------------------------------
reg [STATE_BITS-1:0] state_q = S_DISABLED, n_state;
reg [15:0] enc_seen_q = 16'd0, n_enc_seen;       // encoder errors at the last RESET command
reg servo_overrun_q = 1'b0, n_servo_overrun;     // the controller skipped a sample
reg load_q = 1'b0, n_load;                       // the reference takes the encoder's position
reg first_pos_q = 1'b0, n_first_pos;             // the standby program's segment 0 heads +
reg first_neg_q = 1'b0, n_first_neg;             // ... or −
reg [STATE_BITS-1:0] error_q = E_NONE, n_error;
reg amplifier_q = 1'b0, n_amplifier;
reg uart_error_q = 1'b0, n_uart_error;
reg overflow_q = 1'b0, n_overflow;
reg [15:0] bad_crc_q = 16'd0, n_bad_crc;
reg [15:0] bad_frames_q = 16'd0, n_bad_frames;
//@ param_registers
reg write_enable_q = 1'b0, n_write_enable;
reg [ADDR_BITS-1:0] write_address_q = {ADDR_BITS{1'b0}}, n_write_address;
reg [TICK_BITS-1:0] write_ticks_q = {TICK_BITS{1'b0}}, n_write_ticks;
reg [D_BITS-1:0] write_snap_q = {D_BITS{1'b0}}, n_write_snap;
reg count_enable_q = 1'b0, n_count_enable;
reg [INDEX_BITS-1:0] count_value_q = {INDEX_BITS{1'b0}}, n_count_value;
reg empty_standby_q = 1'b0, n_empty_standby;   // empty the standby bank on the next clock
reg start_q = 1'b0, n_start;
reg swap_q = 1'b0, n_swap;
reg [SWAP_BITS-1:0] swap_last_q = {SWAP_BITS{1'b0}}, n_swap_last;
reg stop_q = 1'b0, n_stop;
reg abort_q = 1'b0, n_abort;
reg reply_q = 1'b0, n_reply;
reg [KIND_BITS-1:0] reply_kind_q = {KIND_BITS{1'b0}}, n_reply_kind;
reg [7:0] reply_cmd_q = 8'd0, n_reply_cmd;
reg [7:0] reply_seq_q = 8'd0, n_reply_seq;
reg [7:0] reply_aux_q = 8'd0, n_reply_aux;
reg telemetry_q = 1'b0, n_telemetry;
// The last command with an effect: code, sequence, CRC and its reply.
reg last_valid_q = 1'b0, n_last_valid;
reg [7:0] last_cmd_q = 8'd0, n_last_cmd;
reg [7:0] last_seq_q = 8'd0, n_last_seq;
reg [15:0] last_crc_q = 16'd0, n_last_crc;
reg [KIND_BITS-1:0] last_kind_q = {KIND_BITS{1'b0}}, n_last_kind;
reg [7:0] last_aux_q = 8'd0, n_last_aux;
// The watchdog: clocks of the current millisecond, milliseconds since the last good frame.
reg [31:0] prescale_q = 32'd0, n_prescale;
reg [WATCHDOG_MS_BITS-1:0] watchdog_count_q = {WATCHDOG_MS_BITS{1'b0}}, n_watchdog_count;
// Telemetry: ticks to the next frame; whether the chain was driven on the last clock.
reg [TELEMETRY_PERIOD_BITS-1:0] telemetry_left_q = {TELEMETRY_PERIOD_BITS{1'b0}}, n_telemetry_left;
reg was_driven_q = 1'b0, n_was_driven;

// ---- The inputs, registered where they arrive ---------------------------------------------------
// Every decision reads the inputs of the clock before (the model's `registered`), so no path
// runs from another block (the core's status, the reply queue, the switches) through a
// decision in one clock; the frame's code, sequence and CRC are among them. Two reads stay
// live: the frame's length and payload (complete and unchanged for hundreds of clocks around
// the frame's strobe; what the decision needs of them is decoded a clock ahead, pre_* below)
// and the time base (SWAP_AT's lead, below, is registered on every clock). 0 after a reset.
reg in_frame = 1'b0, in_bad_crc = 1'b0, in_dropped = 1'b0;
reg [7:0] in_cmd = 8'd0, in_seq = 8'd0;
reg [15:0] in_crc = 16'd0;
reg in_line_error = 1'b0, in_servo_overrun_in = 1'b0, in_queue_full = 1'b0;
reg in_busy = 1'b0, in_stopping = 1'b0, in_at_rest = 1'b0, in_swap_pending = 1'b0;
reg in_standby_empty = 1'b1;                     // the standby program's count is 0
reg in_heading_pos = 1'b0, in_heading_neg = 1'b0, in_tick = 1'b0;
reg in_limit_pos = 1'b0, in_limit_neg = 1'b0, in_estop = 1'b0, in_following_fault = 1'b0;
reg [15:0] in_encoder_errors = 16'd0;
always @(posedge clock) begin
   if (reset) begin
      in_frame <= 1'b0;
      in_cmd <= 8'd0;
      in_seq <= 8'd0;
      in_crc <= 16'd0;
      in_bad_crc <= 1'b0;
      in_dropped <= 1'b0;
      in_line_error <= 1'b0;
      in_servo_overrun_in <= 1'b0;
      in_queue_full <= 1'b0;
      in_busy <= 1'b0;
      in_stopping <= 1'b0;
      in_at_rest <= 1'b0;
      in_swap_pending <= 1'b0;
      in_standby_empty <= 1'b1;
      in_heading_pos <= 1'b0;
      in_heading_neg <= 1'b0;
      in_tick <= 1'b0;
      in_limit_pos <= 1'b0;
      in_limit_neg <= 1'b0;
      in_estop <= 1'b0;
      in_following_fault <= 1'b0;
      in_encoder_errors <= 16'd0;
   end else begin
      in_frame <= frame;
      in_cmd <= cmd;
      in_seq <= seq;
      in_crc <= crc;
      in_bad_crc <= bad_crc;
      in_dropped <= dropped;
      in_line_error <= line_error;
      in_servo_overrun_in <= servo_overrun_in;
      in_queue_full <= queue_full;
      in_busy <= busy;
      in_stopping <= stopping;
      in_at_rest <= at_rest;
      in_swap_pending <= swap_pending;
      in_standby_empty <= standby_count == {INDEX_BITS{1'b0}};
      in_heading_pos <= heading_pos;
      in_heading_neg <= heading_neg;
      in_tick <= tick;
      in_limit_pos <= limit_pos;
      in_limit_neg <= limit_neg;
      in_estop <= estop;
      in_following_fault <= following_fault;
      in_encoder_errors <= encoder_errors;
   end
end
// The start, stop and swap pulses sent two clocks ago (the status read now, registered twice,
// does not show them yet).
reg start_q2 = 1'b0, stop_q2 = 1'b0, swap_q2 = 1'b0;
always @(posedge clock) begin
   start_q2 <= !reset && start_q;
   stop_q2 <= !reset && stop_q;
   swap_q2 <= !reset && swap_q;
end

// ---- Arguments and axis state: why the command is refused (0: accepted) ----------------------
// The chain is at rest: the core's at_rest is a register, one clock old, so on the clock after
// the chain was driven (its last tick may have moved it) it does not count.
wire rested = in_at_rest && !was_driven_q;
// The axis moves: a program plays, a stop runs, or v, a or j is not 0.
wire moving = in_busy || in_stopping || !rested;
// With the controller on, POWER 1 wants a following-error limit.
wire servo_ready = (servo_period_q == {SERVO_PERIOD_BITS{1'b0}})
   || (following_limit_q != {FOLLOWING_LIMIT_BITS{1'b0}});
// The stop limits a CONFIGURE would leave valid (0 < jerk <= accel): each parameter's case
// compares the new value with the other register (two comparators side by side, off the
// parameter's multiplexer), in two clocks: each D_BITS-bit compare split in halves whose
// results are registered (less, equal above; less or equal below), then combined into
// pre_cfg_pair_bad below, two clocks after the payload and the registers (stable for longer:
// see the decode a clock ahead).
localparam HALF = D_BITS / 2;
reg jerk_hi_lt = 1'b0, jerk_hi_eq = 1'b0, jerk_lo_le = 1'b0, jerk_nonzero = 1'b0;
reg accel_hi_lt = 1'b0, accel_hi_eq = 1'b0, accel_lo_le = 1'b0, accel_nonzero = 1'b0;
reg cfg_is_jerk = 1'b0, cfg_is_accel = 1'b0;
always @(posedge clock) begin
   // CONFIGURE STOP_JERK: 0 < value <= STOP_ACCEL.
   jerk_hi_lt <= cfg_value[D_BITS-1:HALF] < stop_accel_q[D_BITS-1:HALF];
   jerk_hi_eq <= cfg_value[D_BITS-1:HALF] == stop_accel_q[D_BITS-1:HALF];
   jerk_lo_le <= cfg_value[HALF-1:0] <= stop_accel_q[HALF-1:0];
   jerk_nonzero <= cfg_value != {D_BITS{1'b0}};
   // CONFIGURE STOP_ACCEL: 0 < STOP_JERK <= value.
   accel_hi_lt <= stop_jerk_q[D_BITS-1:HALF] < cfg_value[D_BITS-1:HALF];
   accel_hi_eq <= stop_jerk_q[D_BITS-1:HALF] == cfg_value[D_BITS-1:HALF];
   accel_lo_le <= stop_jerk_q[HALF-1:0] <= cfg_value[HALF-1:0];
   accel_nonzero <= stop_jerk_q != {D_BITS{1'b0}};
   cfg_is_jerk <= cfg_param == P_STOP_JERK;
   cfg_is_accel <= cfg_param == P_STOP_ACCEL;
end
// The stop limits as they stand (POWER 1 wants them valid), compared the same way: in halves,
// then combined into pre_limits_valid below (the registers are stable for a frame's bytes).
reg limits_hi_lt = 1'b0, limits_hi_eq = 1'b0, limits_lo_le = 1'b0;
always @(posedge clock) begin
   limits_hi_lt <= stop_jerk_q[D_BITS-1:HALF] < stop_accel_q[D_BITS-1:HALF];
   limits_hi_eq <= stop_jerk_q[D_BITS-1:HALF] == stop_accel_q[D_BITS-1:HALF];
   limits_lo_le <= stop_jerk_q[HALF-1:0] <= stop_accel_q[HALF-1:0];
end
// (accel_nonzero is STOP_JERK's test: 0 < STOP_JERK.)
wire stop_limits_valid = accel_nonzero && (limits_hi_lt || (limits_hi_eq && limits_lo_le));
wire jerk_pair_valid = jerk_nonzero && (jerk_hi_lt || (jerk_hi_eq && jerk_lo_le));
wire accel_pair_valid = accel_nonzero && (accel_hi_lt || (accel_hi_eq && accel_lo_le));

// ---- The frame's decode, a clock ahead -------------------------------------------------------
// The command, its length and its payload are complete two bytes before the frame is checked,
// and the registers they are checked against (the parameters) change only on the clock after a
// frame is executed (a frame's bytes, at least 40 bit times or ten clocks, before the next one
// is) or by a reset
// (which the frame receiver shares): what depends on them alone is registered on every clock
// (the stop limits' compares in two stages, above) and is exact on the frame's clock (the state is read on that clock itself; the core's outputs a clock earlier,
// through in_*, and the received CRC on the frame receiver's own clock, through pre_retry).
reg pre_known = 1'b0;                            // the command is in the table
reg pre_len_ok = 1'b0;                           // ... and has its payload length
reg pre_has_effect = 1'b0;
reg pre_bad_argument = 1'b0;                     // its arguments are refused in any state
reg pre_cfg_at_rest = 1'b0;                      // CONFIGURE: settable only at rest
reg pre_cfg_disabled = 1'b0;                     // ... only while Disabled
reg pre_cfg_pair_bad = 1'b0;                     // ... the stop limits it would leave invalid
reg pre_power_on = 1'b0;                         // POWER 1
reg pre_seg_first = 1'b0;                        // LOAD_SEGMENT of segment 0
reg pre_seg_pos = 1'b0, pre_seg_neg = 1'b0;      // ... whose snap heads + or −
reg pre_limits_valid = 1'b0;                     // the stop limits: 0 < jerk <= accel
reg pre_servo_ready = 1'b0;
reg [PARAM_COUNT-1:0] pre_cfg_sel = {PARAM_COUNT{1'b0}};   // CONFIGURE's parameter, one-hot
always @(posedge clock) begin
   pre_known <= known;
   pre_len_ok <= known && (len == want_len);
   pre_has_effect <= has_effect;
   case (cmd)
   CMD_LOAD_SEGMENT: pre_bad_argument <= (seg_index >= MAX_SEGMENTS) || (seg_ticks == {TICK_BITS{1'b0}});
   CMD_COMMIT: pre_bad_argument <= arg0 > MAX_SEGMENTS;
   CMD_CONFIGURE: pre_bad_argument <= !param_known(cfg_param) || cfg_value[D_BITS-1] || cfg_over;
   CMD_READ_CONFIG: pre_bad_argument <= !param_known(arg0);
   CMD_POWER: pre_bad_argument <= arg0 > 8'd1;
   default: pre_bad_argument <= 1'b0;
   endcase
   pre_cfg_at_rest <= param_at_rest(cfg_param);
   pre_cfg_disabled <= param_disabled(cfg_param);
   pre_cfg_pair_bad <= (cfg_is_jerk && !jerk_pair_valid) || (cfg_is_accel && !accel_pair_valid);
   pre_power_on <= arg0 == 8'd1;
   pre_seg_first <= seg_index[ADDR_BITS-1:0] == {ADDR_BITS{1'b0}};
   pre_seg_pos <= !seg_snap[D_BITS-1] && (seg_snap != {D_BITS{1'b0}});
   pre_seg_neg <= seg_snap[D_BITS-1];
   pre_limits_valid <= stop_limits_valid;
   pre_servo_ready <= servo_ready;
   //@ param_select
end

// SWAP_AT: how far its tick lies beyond the time base (the lead: signed, wrap-safe), as it was
// on the clock before the frame is executed (the payload is complete two bytes before the
// frame is); the core arms one clock after the execution, so the time base may have ticked
// twice by then; the core wants three ticks of lead. In two clocks, with no carry chain after
// the subtraction: the tick less the time base registered (swap_diff), then the lead is
// swap_diff less the tick that came with it (in_tick: the time base counts it on the same
// edge), and its lateness and reach are registered from swap_diff's bits for either case.
// Late: the lead is negative, or its bits above LEAD_BITS are 0 and its low bits below
// SWAP_MIN_LEAD. Far (the core compares SWAP_BITS bits): the lead is 2^(SWAP_BITS-1) or more.
reg [TIME_BITS-1:0] swap_diff = {TIME_BITS{1'b0}};
always @(posedge clock) swap_diff <= swap_tick - ticks;
wire diff_neg = swap_diff[TIME_BITS-1];
wire diff_low_zero = swap_diff[TIME_BITS-2:0] == {(TIME_BITS-1){1'b0}};   // with diff_neg: the minimum
wire diff_mid_zero = swap_diff[TIME_BITS-2:LEAD_BITS] == {(TIME_BITS-1-LEAD_BITS){1'b0}};
wire diff_far = swap_diff[TIME_BITS-2:SWAP_BITS-1] != {(TIME_BITS-SWAP_BITS){1'b0}};
// The lead is swap_diff: late below SWAP_MIN_LEAD, far from 2^(SWAP_BITS-1).
wire late_same = diff_neg || (diff_mid_zero && (swap_diff[LEAD_BITS-1:0] < SWAP_MIN_LEAD[LEAD_BITS-1:0]));
wire far_same = !diff_neg && diff_far;
// The lead is swap_diff − 1 (wrapping: the minimum becomes the maximum): late up to
// SWAP_MIN_LEAD, far above 2^(SWAP_BITS-1).
wire late_ticked = (diff_neg && !diff_low_zero)
   || (!diff_neg && diff_mid_zero && (swap_diff[LEAD_BITS-1:0] <= SWAP_MIN_LEAD[LEAD_BITS-1:0]));
wire far_ticked = (diff_neg && diff_low_zero) || (!diff_neg
   && ((swap_diff[TIME_BITS-2:SWAP_BITS] != {(TIME_BITS-1-SWAP_BITS){1'b0}})
      || (swap_diff[SWAP_BITS-1] && (swap_diff[SWAP_BITS-2:0] != {(SWAP_BITS-1){1'b0}}))));
reg swap_late_q = 1'b1;
reg swap_far_q = 1'b0;
always @(posedge clock) begin
   swap_late_q <= reset || (in_tick ? late_ticked : late_same);
   swap_far_q <= !reset && (in_tick ? far_ticked : far_same);
end
wire [SWAP_BITS-1:0] swap_before = swap_tick[SWAP_BITS-1:0] - 1'b1;   // the core's swap_last: T − 1
wire toward_limit = (first_pos_q && in_limit_pos) || (first_neg_q && in_limit_neg);
// ErrorStop with the amplifier off and the axis at rest: nothing can move, as while Disabled,
// so the parameters settable only while Disabled may be set (INPUT_POLARITY set back).
wire inert = (state_q == S_ERROR_STOP) && !amplifier_q && !moving;
// Why command c would be refused in axis state st on this clock (0: it is not). Evaluated for
// the frame's own command (`reason`, the reply's) and for each command whose effect it gates
// (`taken`, below: that command's conditions alone, without the multiplexer over all commands,
// a shorter path to the registers it writes). (The state is an argument: Yosys evaluates a
// function whose arguments are all constants at elaboration, and this one reads live signals.)
function automatic [7:0] refusal(input [7:0] c, input [STATE_BITS-1:0] st);
begin
   refusal = 8'd0;
   case (c)
      CMD_LOAD_SEGMENT:
         if (pre_bad_argument) refusal = R_BAD_ARGUMENT;
         else if (in_swap_pending) refusal = R_SWAP_PENDING;
      CMD_COMMIT:
         if (pre_bad_argument) refusal = R_BAD_ARGUMENT;
         else if (in_swap_pending) refusal = R_SWAP_PENDING;
      CMD_START:
         if (st == S_DISABLED) refusal = R_NOT_ENABLED;
         else if (st == S_ERROR_STOP) refusal = R_AXIS_ERROR;
         else if (st == S_STOPPING) refusal = R_STOPPING;
         else if (in_busy) refusal = R_BUSY;
         else if (in_stopping) refusal = R_STOPPING;
         else if (in_swap_pending) refusal = R_SWAP_PENDING;
         else if (in_standby_empty) refusal = R_NO_PROGRAM;
         else if (!rested) refusal = R_BUSY;
         else if (toward_limit) refusal = R_LIMIT;
      CMD_SWAP_AT:
         if (swap_far_q) refusal = R_BAD_ARGUMENT;
         else if (st == S_DISABLED) refusal = R_NOT_ENABLED;
         else if (st == S_ERROR_STOP) refusal = R_AXIS_ERROR;
         else if (st == S_STOPPING) refusal = R_STOPPING;
         else if (in_stopping) refusal = R_STOPPING;
         else if (in_swap_pending) refusal = R_SWAP_PENDING;
         else if (in_standby_empty) refusal = R_NO_PROGRAM;
         else if (swap_late_q) refusal = R_LATE;
         else if (rested && !in_busy && toward_limit) refusal = R_LIMIT;
      CMD_STOP:
         if (st == S_DISABLED) refusal = R_NOT_ENABLED;
      CMD_HALT:
         if (st == S_DISABLED) refusal = R_NOT_ENABLED;
         else if (st == S_ERROR_STOP) refusal = R_AXIS_ERROR;
         else if (st == S_STOPPING) refusal = R_STOPPING;
      CMD_CONFIGURE:
         if (pre_bad_argument) refusal = R_BAD_ARGUMENT;
         else if (pre_cfg_at_rest && moving) refusal = R_BUSY;
         else if (pre_cfg_disabled && (st != S_DISABLED) && !inert) refusal = R_NOT_DISABLED;
         else if ((st != S_DISABLED) && pre_cfg_pair_bad) refusal = R_BAD_ARGUMENT;
      CMD_READ_CONFIG:
         if (pre_bad_argument) refusal = R_BAD_ARGUMENT;
      CMD_POWER:
         if (pre_bad_argument) refusal = R_BAD_ARGUMENT;
         else if (pre_power_on) begin
            if (st == S_ERROR_STOP) refusal = R_AXIS_ERROR;
            else if ((st == S_DISABLED) && (!pre_limits_valid || !pre_servo_ready))
               refusal = R_NOT_CONFIGURED;
         end else if (moving) refusal = R_BUSY;
      CMD_RESET:
         if ((st == S_ERROR_STOP) && (moving || in_estop)) refusal = R_AXIS_ERROR;
   default: ;
   endcase
end
endfunction
wire [7:0] reason = refusal(in_cmd, state_q);

// A retry: the frame's code, sequence and CRC are the last command's. Compared on every clock
// from the frame's fields as they stand (the CRC's on the frame's own clock) and registered:
// the last command changes only when a frame is executed.
reg pre_retry = 1'b0;
always @(posedge clock)
   pre_retry <= last_valid_q && (cmd == last_cmd_q) && (seq == last_seq_q) && (crc == last_crc_q);
wire retry = pre_has_effect && pre_retry;
// The frame is executed: good, answered, of its length, not a retry ...
wire executes = in_frame && !in_bad_crc && !in_dropped && !in_queue_full && pre_len_ok && !retry;
// ... and is command c, not refused in axis state st: c's effect applies.
function automatic taken(input [7:0] c, input [STATE_BITS-1:0] st);
   taken = executes && (in_cmd == c) && (refusal(c, st) == 8'd0);
endfunction
// The prescaler completes a millisecond on this clock (prescale_q + 1 >= CLOCKS_PER_MS),
// registered: taken on the clock before from what the prescaler does then (it restarts at 0
// on reset, a frame or a completed millisecond, else counts up by one).
reg prescale_due_q = (CLOCKS_PER_MS <= 32'd1);
always @(posedge clock)
   prescale_due_q <= (reset || in_frame || prescale_due_q) ? (CLOCKS_PER_MS <= 32'd1)
                                                            : (prescale_q + 32'd2 >= CLOCKS_PER_MS);
// The watchdog expired (registered: the count compared on the clock before decides).
reg expired = 1'b0;
always @(posedge clock)
   expired <= !reset && (watchdog_ms_q != {WATCHDOG_MS_BITS{1'b0}}) && (watchdog_count_q >= watchdog_ms_q);
// A start, stop or swap sent on either of the last two clocks (the status read now, registered
// in the core and again here, does not show it yet), or the chain driven on the last clock (the
// core's at_rest is a register: it tells where the last tick left the chain a clock later).
wire settling = start_q || stop_q || swap_q || start_q2 || stop_q2 || swap_q2 || was_driven_q;
wire driven = in_busy || in_stopping;

// CONFIGURE takes effect on the clock after the frame is executed: its decision is registered
// with the parameter (one-hot) and the value, and the parameter's register is written from
// these on the next clock. The decision's path then ends at one flip-flop, not at the enables
// of every parameter register's bits (some 700 of them, spread over the device).
reg cfg_write_q = 1'b0;
reg [PARAM_COUNT-1:0] cfg_sel_q = {PARAM_COUNT{1'b0}};
reg cfg_telemetry_q = 1'b0;
reg [D_BITS-1:0] cfg_value_q = {D_BITS{1'b0}};
always @(posedge clock) begin
   cfg_write_q <= !reset && taken(CMD_CONFIGURE, state_q);
   cfg_sel_q <= pre_cfg_sel;
   cfg_telemetry_q <= cfg_param == P_TELEMETRY_PERIOD;
   cfg_value_q <= cfg_value;
end

// ---- Next state, in the model's order ------------------------------------------------------
always @(*) begin
   // Pulses last one clock; everything else holds.
   n_write_enable = 1'b0;
   n_count_enable = 1'b0;
   n_start = 1'b0;
   n_swap = 1'b0;
   n_swap_last = swap_last_q;
   n_stop = 1'b0;
   n_abort = 1'b0;
   n_reply = 1'b0;
   n_telemetry = 1'b0;
   n_state = state_q;
   n_enc_seen = enc_seen_q;
   n_servo_overrun = servo_overrun_q;
   n_load = 1'b0;
   n_first_pos = first_pos_q;
   n_first_neg = first_neg_q;
   n_error = error_q;
   n_amplifier = amplifier_q;
   n_uart_error = uart_error_q;
   n_overflow = overflow_q;
   n_bad_crc = bad_crc_q;
   n_bad_frames = bad_frames_q;
   //@ param_holds
   n_write_address = write_address_q;
   n_write_ticks = write_ticks_q;
   n_write_snap = write_snap_q;
   n_count_value = count_value_q;
   // The standby bank emptied for a swap a stop or an abort cancelled on the last clock (a
   // COMMIT taken on this clock, below, writes the count after it).
   if (empty_standby_q) begin
      n_count_enable = 1'b1;
      n_count_value = {INDEX_BITS{1'b0}};
   end
   n_reply_kind = reply_kind_q;
   n_reply_cmd = reply_cmd_q;
   n_reply_seq = reply_seq_q;
   n_reply_aux = reply_aux_q;
   n_last_valid = last_valid_q;
   n_last_cmd = last_cmd_q;
   n_last_seq = last_seq_q;
   n_last_crc = last_crc_q;
   n_last_kind = last_kind_q;
   n_last_aux = last_aux_q;
   n_telemetry_left = telemetry_left_q;

   // Telemetry while the chain is driven, and once when it stops being driven, from the period
   // and countdown before this clock (a CONFIGURE of the period, below, restarts the countdown).
   if (telemetry_period_q != {TELEMETRY_PERIOD_BITS{1'b0}}) begin
      if (in_tick && driven) begin
         if (telemetry_left_q <= {{(TELEMETRY_PERIOD_BITS-1){1'b0}}, 1'b1}) begin
            n_telemetry = 1'b1;
            n_telemetry_left = telemetry_period_q;
         end else n_telemetry_left = telemetry_left_q - 1'b1;
      end
      if (was_driven_q && !driven) begin
         n_telemetry = 1'b1;
         n_telemetry_left = telemetry_period_q;
      end
   end
   n_was_driven = driven;

   // The watchdog: milliseconds since the last good frame (saturating).
   n_prescale = prescale_q + 32'd1;
   n_watchdog_count = watchdog_count_q;
   if (in_frame) begin
      n_prescale = 32'd0;
      n_watchdog_count = {WATCHDOG_MS_BITS{1'b0}};
   end else if (prescale_due_q) begin
      n_prescale = 32'd0;
      if (watchdog_count_q != {WATCHDOG_MS_BITS{1'b1}}) n_watchdog_count = watchdog_count_q + 1'b1;
   end

   // Frames.
   if (in_line_error) n_uart_error = 1'b1;
   if (in_servo_overrun_in) n_servo_overrun = 1'b1;
   if (in_bad_crc) begin
      n_bad_crc = bad_crc_q + 16'd1;
      if (in_queue_full) n_overflow = 1'b1;
      else begin
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_cmd = 8'd0;
         n_reply_seq = 8'd0;
         n_reply_aux = R_BAD_CRC;
      end
   end else if (in_dropped) begin
      n_bad_frames = bad_frames_q + 16'd1;
      if (in_queue_full) n_overflow = 1'b1;
      else begin
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_cmd = 8'd0;
         n_reply_seq = 8'd0;
         n_reply_aux = R_FRAMING;
      end
   end else if (in_frame) begin
      n_reply_cmd = in_cmd;
      n_reply_seq = in_seq;
      if (in_queue_full) n_overflow = 1'b1;
      else if (!pre_len_ok) begin
         n_bad_frames = bad_frames_q + 16'd1;
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_aux = pre_known ? R_BAD_LENGTH : R_UNKNOWN_COMMAND;
      end else if (retry) begin
         // A retry: the same answer, no effect.
         n_reply = 1'b1;
         n_reply_kind = last_kind_q;
         n_reply_aux = last_aux_q;
      end else begin
         // PING: a new host session; no command before it is retried.
         if (in_cmd == CMD_PING) n_last_valid = 1'b0;
         n_reply = 1'b1;
         n_reply_kind = K_ACK;
         n_reply_aux = 8'd0;
         if (reason != 8'd0) begin
            n_reply_kind = K_NAK;
            n_reply_aux = reason;
         end else case (in_cmd)
         CMD_PING: n_reply_kind = K_IDENTITY;
         CMD_READ_STATUS: n_reply_kind = K_STATUS;
         CMD_READ_STATE: n_reply_kind = K_STATE;
         CMD_READ_CONFIG: begin
            n_reply_kind = K_CONFIG;
            n_reply_aux = arg0;
         end
         default: ;
         endcase
         if (pre_has_effect) begin
            n_last_valid = 1'b1;
            n_last_cmd = in_cmd;
            n_last_seq = in_seq;
            n_last_crc = in_crc;
            n_last_kind = n_reply_kind;
            n_last_aux = n_reply_aux;
         end
      end
   end

   // The commands' effects, each when it is taken (after the frame's reply, before it in the
   // model: they write other registers).
   if (taken(CMD_LOAD_SEGMENT, state_q)) begin
      n_write_enable = 1'b1;
      n_write_address = seg_index[ADDR_BITS-1:0];
      n_write_ticks = seg_ticks;
      n_write_snap = seg_snap;
      if (pre_seg_first) begin
         n_first_pos = pre_seg_pos;
         n_first_neg = pre_seg_neg;
      end
   end
   if (taken(CMD_COMMIT, state_q)) begin
      n_count_enable = 1'b1;
      n_count_value = arg0[INDEX_BITS-1:0];
   end
   if (taken(CMD_START, state_q)) begin
      n_start = 1'b1;
      n_state = S_DISCRETE_MOTION;
      // The banks swap: the new standby program is empty.
      n_first_pos = 1'b0;
      n_first_neg = 1'b0;
   end
   if (taken(CMD_SWAP_AT, state_q)) begin
      n_swap = 1'b1;
      n_swap_last = swap_before;
      n_state = S_DISCRETE_MOTION;
      // The banks swap at the tick; no upload is taken before that.
      n_first_pos = 1'b0;
      n_first_neg = 1'b0;
   end
   if (taken(CMD_STOP, state_q) && (state_q != S_ERROR_STOP)) begin
      n_stop = 1'b1;
      n_state = S_STOPPING;
   end
   if (taken(CMD_HALT, state_q) && ((state_q == S_DISCRETE_MOTION) || (state_q == S_CONTINUOUS_MOTION)))
      n_stop = 1'b1;
   // CONFIGURE taken on the last clock (cfg_write_q, above) writes its parameter now.
   if (cfg_write_q) begin
      //@ param_set
      if (cfg_telemetry_q)
         n_telemetry_left = cfg_value_q[TELEMETRY_PERIOD_BITS-1:0];
   end
   if (taken(CMD_POWER, state_q)) begin
      if (pre_power_on) begin
         if (state_q == S_DISABLED) begin
            n_amplifier = 1'b1;
            n_state = S_STANDSTILL;
            n_load = 1'b1;                 // MC_Power: the axis holds where it is
         end
      end else begin
         n_amplifier = 1'b0;
         if (state_q == S_STANDSTILL) n_state = S_DISABLED;
      end
   end
   if (taken(CMD_RESET, state_q)) begin
      // The sticky flags clear in any state.
      n_uart_error = 1'b0;
      n_overflow = 1'b0;
      n_servo_overrun = 1'b0;
      n_enc_seen = in_encoder_errors;
      if (state_q == S_ERROR_STOP) begin
         n_error = E_NONE;
         n_state = amplifier_q ? S_STANDSTILL : S_DISABLED;
      end
   end

   // The axis by itself: the end of a move or a stop (at rest: Standstill; a program that ended
   // moving: a controlled stop into ErrorStop), then the errors (the emergency stop last: it
   // overrides everything). Not on a clock a frame is executed (a clock later: the end of a
   // move does not wait on the command's decision).
   if (((state_q == S_DISCRETE_MOTION) || (state_q == S_CONTINUOUS_MOTION) || (state_q == S_STOPPING))
         && !executes && !in_busy && !in_stopping && !settling
         && !(in_at_rest && in_swap_pending)) begin   // a swap armed at rest: a start to come
      if (in_at_rest) n_state = S_STANDSTILL;
      else begin
         n_stop = 1'b1;
         n_state = S_ERROR_STOP;
         n_error = E_PROGRAM_END;
      end
   end
   if (expired && ((state_q == S_DISCRETE_MOTION) || (state_q == S_CONTINUOUS_MOTION))) begin
      n_stop = 1'b1;
      n_state = S_ERROR_STOP;
      n_error = E_WATCHDOG;
   end
   if ((state_q != S_ERROR_STOP) && (state_q != S_DISABLED)) begin
      if (in_limit_pos && in_heading_pos) begin
         n_stop = 1'b1;
         n_state = S_ERROR_STOP;
         n_error = E_LIMIT_POSITIVE;
      end else if (in_limit_neg && in_heading_neg) begin
         n_stop = 1'b1;
         n_state = S_ERROR_STOP;
         n_error = E_LIMIT_NEGATIVE;
      end
   end
   if (in_following_fault && amplifier_q) begin
      n_abort = 1'b1;
      n_stop = 1'b0;
      n_start = 1'b0;
      n_swap = 1'b0;
      n_amplifier = 1'b0;
      n_state = S_ERROR_STOP;
      n_error = E_FOLLOWING_ERROR;
   end
   if (in_estop && !((state_q == S_ERROR_STOP) && (error_q == E_EMERGENCY_STOP))) begin
      n_abort = 1'b1;
      n_stop = 1'b0;
      n_start = 1'b0;
      n_swap = 1'b0;
      n_amplifier = 1'b0;
      n_state = S_ERROR_STOP;
      n_error = E_EMERGENCY_STOP;
   end
   // A stop or an abort cancels an armed swap, and its program, planned for the swap's tick,
   // never plays from another state: the standby bank is emptied on the next clock (a swap
   // sent on either of the last two clocks counts: the status does not show it yet).
   n_empty_standby = (n_stop || n_abort) && (in_swap_pending || swap_q || swap_q2);

end

always @(posedge clock) begin
   if (reset) begin
      state_q <= S_DISABLED;
      enc_seen_q <= 16'd0;
      servo_overrun_q <= 1'b0;
      load_q <= 1'b0;
      first_pos_q <= 1'b0;
      first_neg_q <= 1'b0;
      error_q <= E_NONE;
      amplifier_q <= 1'b0;
      uart_error_q <= 1'b0;
      overflow_q <= 1'b0;
      bad_crc_q <= 16'd0;
      bad_frames_q <= 16'd0;
      //@ param_resets
      write_enable_q <= 1'b0;
      write_address_q <= {ADDR_BITS{1'b0}};
      write_ticks_q <= {TICK_BITS{1'b0}};
      write_snap_q <= {D_BITS{1'b0}};
      count_enable_q <= 1'b0;
      count_value_q <= {INDEX_BITS{1'b0}};
      empty_standby_q <= 1'b0;
      start_q <= 1'b0;
      swap_q <= 1'b0;
      swap_last_q <= {SWAP_BITS{1'b0}};
      stop_q <= 1'b0;
      abort_q <= 1'b0;
      reply_q <= 1'b0;
      reply_kind_q <= {KIND_BITS{1'b0}};
      reply_cmd_q <= 8'd0;
      reply_seq_q <= 8'd0;
      reply_aux_q <= 8'd0;
      telemetry_q <= 1'b0;
      last_valid_q <= 1'b0;
      last_cmd_q <= 8'd0;
      last_seq_q <= 8'd0;
      last_crc_q <= 16'd0;
      last_kind_q <= {KIND_BITS{1'b0}};
      last_aux_q <= 8'd0;
      prescale_q <= 32'd0;
      watchdog_count_q <= {WATCHDOG_MS_BITS{1'b0}};
      telemetry_left_q <= {TELEMETRY_PERIOD_BITS{1'b0}};
      was_driven_q <= 1'b0;
   end else begin
      state_q <= n_state;
      enc_seen_q <= n_enc_seen;
      servo_overrun_q <= n_servo_overrun;
      load_q <= n_load;
      first_pos_q <= n_first_pos;
      first_neg_q <= n_first_neg;
      error_q <= n_error;
      amplifier_q <= n_amplifier;
      uart_error_q <= n_uart_error;
      overflow_q <= n_overflow;
      bad_crc_q <= n_bad_crc;
      bad_frames_q <= n_bad_frames;
      //@ param_clocked
      write_enable_q <= n_write_enable;
      write_address_q <= n_write_address;
      write_ticks_q <= n_write_ticks;
      write_snap_q <= n_write_snap;
      count_enable_q <= n_count_enable;
      count_value_q <= n_count_value;
      empty_standby_q <= n_empty_standby;
      start_q <= n_start;
      swap_q <= n_swap;
      swap_last_q <= n_swap_last;
      stop_q <= n_stop;
      abort_q <= n_abort;
      reply_q <= n_reply;
      reply_kind_q <= n_reply_kind;
      reply_cmd_q <= n_reply_cmd;
      reply_seq_q <= n_reply_seq;
      reply_aux_q <= n_reply_aux;
      telemetry_q <= n_telemetry;
      last_valid_q <= n_last_valid;
      last_cmd_q <= n_last_cmd;
      last_seq_q <= n_last_seq;
      last_crc_q <= n_last_crc;
      last_kind_q <= n_last_kind;
      last_aux_q <= n_last_aux;
      prescale_q <= n_prescale;
      watchdog_count_q <= n_watchdog_count;
      telemetry_left_q <= n_telemetry_left;
      was_driven_q <= n_was_driven;
   end
end

// READ_CONFIG's value, for the reply transmitter: read_param is the parameter its CONFIG reply
// names after this edge; it is decoded one-hot here (read_sel_q, as the transmitter's own
// register is taken) and the value of the parameter it selects registered on the next clock,
// an AND-OR with no 8-bit compare in front of the 104-bit multiplexer (0 for an unknown one).
reg [PARAM_COUNT-1:0] read_sel_q = {PARAM_COUNT{1'b0}};
reg [D_BITS-1:0] read_value_q = {D_BITS{1'b0}};
always @(posedge clock) begin
   read_sel_q <= {PARAM_COUNT{1'b0}};
   case (read_param)
   //@ param_read_select
   default: ;
   endcase
   read_value_q <= {D_BITS{1'b0}}
   //@ param_read
   ;
end

always @(*) begin
   write_enable = write_enable_q;
   write_address = write_address_q;
   write_ticks = write_ticks_q;
   write_snap = write_snap_q;
   count_enable = count_enable_q;
   count_value = count_value_q;
   start = start_q;
   swap = swap_q;
   swap_last = swap_last_q;
   stop = stop_q;
   abort_move = abort_q;
   load = load_q;
   servo_overrun = servo_overrun_q;
   //@ param_outputs
   state = {{(8 - STATE_BITS){1'b0}}, state_q};   // the status block's byte
   error = {{(8 - STATE_BITS){1'b0}}, error_q};
   amplifier = amplifier_q;
   uart_error = uart_error_q;
   reply_overflow = overflow_q;
   encoder_errors_seen = enc_seen_q;
   read_value = read_value_q;
   bad_crc_count = bad_crc_q;
   bad_frames_count = bad_frames_q;
   reply = reply_q;
   reply_kind = reply_kind_q;
   reply_cmd = reply_cmd_q;
   reply_seq = reply_seq_q;
   reply_aux = reply_aux_q;
   telemetry = telemetry_q;
end
