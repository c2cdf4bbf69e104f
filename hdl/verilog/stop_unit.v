// The stop unit's engine (its reference is snapgen_model::stop::micro, the law
// snapgen_model::stop): a word-serial microcoded datapath over 48-bit words that brings the
// chain to rest within its limits. Template: snapgen_hdl fills the values in double braces
// (the microprogram's entry points, widths of the ROM and the flags) and the //@ lines (the
// ROM, the instruction fields, the law's case analysis, the external operands) from the
// model's microprogram, and puts the widths it names (D_BITS) in front as localparams.
//
// The engine's datapath (operand reads, the adder, the flag logic, the next program counter)
// is computed in its clocked process, under the phase that uses it: a simulator evaluates none
// of it while the unit is idle.

// ---- The engine (snapgen_model::stop::micro): phases, registers -------------------------------
// An instruction that computes takes 4 clocks (step 0..3): step s reads operand word s (for
// s < 3) and adds word s - 1 (for s > 0); step 0 also samples the conditions, from the flag
// register. One whose flag write an instruction that may follow it reads at once (its ROM
// bit LAND) takes a fifth (`land`), on which the write is applied; any other write is applied
// on the next instruction's step 0, which does not read that flag: the flags an instruction's
// conditions read are always the register's. LOOP and HALT take one clock. The instruction
// register holds ROM[pc]; both move as the engine runs.
localparam [2:0] PH_IDLE = 3'd0, PH_PREP = 3'd1, PH_ARMED = 3'd2, PH_RUN = 3'd3, PH_READY = 3'd4;
localparam [6:0] PC_PREP = 7'd{{PC_PREP}}, PC_INIT = 7'd{{PC_INIT}}, PC_DECIDE = 7'd{{PC_DECIDE}};
localparam [31:0] FLAG_COUNT = {{FLAGS}};       // the engine's flags (snapgen_model::stop::micro)
localparam [1:0] K_OP = 2'd{{K_OP}}, K_LOOP = 2'd{{K_LOOP}}, K_HALT = 2'd{{K_HALT}};
// A shifts (0: none), B modes (0: none), flag sources (5: a condition), flag writes (0: none,
// 1: set).
localparam [2:0] M_SHL = 3'd1, M_WRIGHT = 3'd2, M_WLEFT2 = 3'd3, M_SHR = 3'd4;
localparam [2:0] B_ADD = 3'd1, B_SUB = 3'd2, B_SUBONE = 3'd3, B_ADDSUB = 3'd4, B_ADDIF = 3'd5;
localparam [2:0] S_SIGN = 3'd0, S_NSIGN = 3'd1, S_ZERO_A = 3'd2, S_SHIFT = 3'd3, S_WIDE_A = 3'd4;
localparam [1:0] C_AND = 2'd2, C_OR = 2'd3;
//@ flag_names
reg [2:0] phase = PH_IDLE;
reg ready_q = 1'b0;                      // phase == PH_READY, registered with it
reg armed_q = 1'b0;                      // phase == PH_ARMED, registered with it
reg [6:0] pc = 7'd0;
reg [6:0] pc2 = 7'd2;                    // pc + 2, kept beside it (the ROM's address below)
reg [{{IR_TOP}}:0] ir = {{IR_HALT}};              // the instruction at pc (and its first_reads)
reg [1:0] step = 2'd0;
reg step_first = 1'b0, step_last = 1'b0;  // step is 1, 3 (registered with it)
reg land = 1'b0;                         // the flag write's clock, after step 3
// The register file's read addresses on this clock ({A_SRC[3:0], ak}, {B_REG, kr} of ir and
// step), computed on the clock before from the instruction and step it leaves: no decoding
// between ir and the register file's read.
reg [5:0] ra_q = 6'd0;
reg [5:0] rb_q = 6'd0;
// ... and, with them, operand A's source one-hot (a_select): the register file's read, the
// sign fill above word 2, word ak of an external value, D_FLOOR's top word, or none (zero, or
// below word 0): A's multiplexer is an AND-OR of registered selects, with no decoding of the
// instruction or the step before it.
reg [{{A_SEL_TOP}}:0] a_sel_q = {{A_SEL_BITS}}'d0;
reg [5:0] loop_count = 6'd0;
reg [6:0] loop_pc = 7'd0;
reg [6:0] loop_pc2 = 7'd2;               // loop_pc + 2
reg [{{IR_TOP}}:0] ir_inc = {{IR_HALT}};          // the instruction at pc + 1
reg [{{IR_TOP}}:0] ir_loop = {{IR_HALT}};         // the instruction at loop_pc
reg [{{IR_TOP}}:0] ir_loop_inc = {{IR_HALT}};     // the instruction at loop_pc + 1
reg [47:0] a_q = 48'd0;                  // operand words read on the previous clock
reg [47:0] b_q = 48'd0;
// The instruction decoded on step 0 (its conditions evaluated), for the adding steps.
reg shl_in = 1'b0;                       // the bit a left shift takes into this word: the
                                         // condition on word 0, then the last word's top bit
reg c_pred = 1'b0;                       // write the result and the flag
reg c_flag = 1'b0;                       // a flag set from a condition
reg do_shl = 1'b0, do_shr = 1'b0;        // A shifted one bit left, right
reg b_en = 1'b0, b_inv = 1'b0;           // B added, inverted
reg cin0 = 1'b0;                         // carry into word 0
reg [FLAG_COUNT-1:0] flag_we = {FLAG_COUNT{1'b0}};  // the flag written (one-hot)
reg flag_and = 1'b0, flag_or = 1'b0;     // combined by AND, OR (else set)
reg [5:0] src = 6'd0;                    // flag source: sign, !sign, zero, shift, wide, cond
reg carry = 1'b0;                        // between words: the adder's carry,
reg shift_bit = 1'b0;                    // the bit a shift moves across,
reg zero_acc = 1'b0;                     // the result is zero so far,
reg fill = 1'b0;                         // the sign of a one-word right shift's source
// The flags. An instruction's flag write is applied a clock after its last step (`flag_pend`:
// neither the adder's result nor A's zero and width tests are in one clock's path with the
// flags' combination): on that step the flags are computed for each source the write can have
// without reading the operands — the result's sign being 0 (`flags_if0`) or 1 (`flags_if1`),
// and 1 (`flags_if_rest`) — and the sign (`flag_sign_q`, the adder's last bit) and the rest
// (`flag_rest_q`: A's zero test, the shift-out, A's width or the condition) are kept. `flags`,
// what the unit's output reads, is the register with the pending write applied: the same value
// on every clock as if it had been written at once. The engine's own readers (the conditions,
// HALT) read `flags_q`: no write of a flag they read is pending when they read (LAND above).
reg [FLAG_COUNT-1:0] flags_q = {FLAG_COUNT{1'b0}};
reg flag_pend = 1'b0;
reg flag_sign_q = 1'b0;
reg flag_rest_q = 1'b0;
reg [FLAG_COUNT-1:0] flags_if0 = {FLAG_COUNT{1'b0}};
reg [FLAG_COUNT-1:0] flags_if1 = {FLAG_COUNT{1'b0}};
reg [FLAG_COUNT-1:0] flags_if_rest = {FLAG_COUNT{1'b0}};
wire [FLAG_COUNT-1:0] flags = !flag_pend ? flags_q
   : (flag_rest_q ? flags_if_rest : (flag_sign_q ? flags_if1 : flags_if0));

// The flags after writing flag source `f` into the flag(s) `we`, combined with the old by
// AND, OR or not at all.
function automatic [FLAG_COUNT-1:0] flag_write(input [FLAG_COUNT-1:0] old,
      input [FLAG_COUNT-1:0] we, input and_, input or_, input f);
   flag_write = (old & ~we) | (we & (and_ ? (old & {FLAG_COUNT{f}})
      : or_ ? (old | {FLAG_COUNT{f}}) : {FLAG_COUNT{f}}));
endfunction
reg [D_BITS-1:0] jlim = {D_BITS{1'b0}};     // the limits, latched on the request
reg [D_BITS-1:0] alim = {D_BITS{1'b0}};
reg [D_BITS-1:0] snap_reg = {D_BITS{1'b0}};
(* ram_style = "distributed" *)  // LUT-RAM: a block RAM's read (5.6 ns on an ECP5) is in the adder's path
reg [47:0] rf [0:63];                    // 16 registers x 4 word slots (3 used)
integer rf_i;
initial for (rf_i = 0; rf_i < 64; rf_i = rf_i + 1) rf[rf_i] = 48'd0;

// ---- The microprogram (snapgen_model::stop::program) -----------------------------------------
// In logic, not block RAM: a block RAM's clock-to-out (5.6 ns on an ECP5) would start the
// engine's operand read.
function automatic [{{IR_TOP}}:0] rom(input [6:0] addr);
   (* rom_style = "logic" *) case (addr)
//@ rom_cases
   endcase
endfunction
//@ instruction_fields
// The next instruction is ROM[pc + 1] (`ir_inc`), ROM[loop_pc] (`ir_loop`), ir itself or an
// entry point's word: each a register or a constant, chosen by the next-pc decision. The one
// ROM lookup, ROM[pc + 2] from pc2 (pc + 2 in a register of its own), becomes `ir_inc` when pc
// moves on (and `ir_loop_inc`, with the loop's start): the ROM is behind no decision and before
// no other logic.
wire [6:0] pc_inc = pc + 7'd1;

// The word of a 3-word value an instruction's step reads: kr for B (high word first for a right
// shift of A) and ak for A (kr, kr + 1 one word right, kr - 2 two words left).
function automatic [1:0] read_word(input [2:0] a_mod, input [1:0] s);
   read_word = (a_mod == M_SHR) ? 2'd2 - s : s;
endfunction
function automatic [1:0] a_word(input [2:0] a_mod, input [1:0] s);
   reg [1:0] k;
   begin
      k = read_word(a_mod, s);
      a_word = (a_mod == M_WLEFT2) ? k - 2'd2 : (a_mod == M_WRIGHT) ? k + 2'd1 : k;
   end
endfunction
wire [{{IR_TOP}}:0] ir_inc2 = rom(pc2);   // ROM[pc + 2]: no adder before the ROM
// Operand A's one-hot select for A's source `code` and word `ak` (the ROM word carries step 0's).
function automatic [{{A_SEL_TOP}}:0] a_select(input [4:0] code, input [1:0] ak, input below,
      input above);
   reg [2:0] w;                          // ak, one-hot
   begin
      w = (ak == 2'd0) ? 3'b001 : (ak == 2'd1) ? 3'b010 : (ak == 2'd2) ? 3'b100 : 3'b000;
      a_select = {{A_SEL_BITS}}'d0;
      if (below) ;
      else if (above) a_select[{{A_SEL_FILL}}] = 1'b1;
      else if (!code[4]) a_select[{{A_SEL_RF}}] = 1'b1;
      else case (code)
//@ external_selects
      default: ;                         // 16: zero
      endcase
   end
endfunction
// ---- Conditions: flags, the law's case analysis on them (micro::Derived), true -------------
// (The engine's process writes every selection out: a function's arguments and locals cost a
// simulator stores on every clock, executed or not.)

wire running = (phase == PH_PREP) || (phase == PH_RUN);

// ---- The engine: one clocked process; its datapath is evaluated only while it runs ---------
always @(posedge clock) begin : engine
   // Read: operand words for word `step` (high word first for a right shift).
   reg shr;
   reg [1:0] ke;
   reg [47:0] a_raw;
   // Add: word step - 1, from the words read.
   reg first, last, shift_out, a_zero, a_wide, f_rest, write;
   reg ends;                             // the instruction's last clock: the next is fetched
   reg [47:0] a_op, b_op, result;
   reg [48:0] sum;
   reg [31:0] conds;
   reg [6:0] pc_next;
   reg [6:0] pc2_next;                   // pc_next + 2
   reg [{{IR_TOP}}:0] ir_next;              // ROM[pc_next]
   reg [{{IR_TOP}}:0] ir_inc_next;          // ROM[pc_next + 1]
   reg next_new;                         // ir_next is an instruction's first clock
   reg fetch;                            // load pc and ir
   reg [1:0] step_next;
   reg [1:0] kr_next;                    // the word read on the next clock's step
   // The law's case analysis on the flags (micro::Derived), for the step-0 conditions.
//@ derived_declarations
   // The step-0 conditions: b's, and the shift-in, predicate and flag conditions.
   reg c_b, c_shift, c_p, c_f;
   // Every local has a value on every clock (none is a register); the datapath's are computed
   // only while the engine runs.
   {shr, ke, a_raw} = {{LOCALS_A}}'d0;
   {first, last, shift_out, a_zero, a_wide, f_rest, write, a_op, b_op, result, sum} = {{LOCALS_B}}'d0;
   ends = 1'b0;
   conds = 32'd0;
   pc_next = pc;
   pc2_next = pc2;
   ir_next = ir;
   ir_inc_next = ir_inc;
   next_new = 1'b0;
   fetch = 1'b0;
   step_next = step;
//@ derived_zeros
   {c_b, c_shift, c_p, c_f} = 4'd0;
   if (running) begin
      shr = i_a_mod == M_SHR;
      // A's word (its select registered with the read addresses): kr, kr + 1 (one word
      // right) or kr - 2 (two words left); below word 0 zero, above word 2 the sign fill;
      // external values, word ak of their 144-bit extension: the chain's registers
      // sign-extended, the limits zero-extended.
      a_raw = ({48{a_sel_q[{{A_SEL_RF}}]}} & rf[ra_q]) | {48{a_sel_q[{{A_SEL_FILL}}] & fill}}
//@ external_terms
         | ({48{a_sel_q[{{A_SEL_FLOOR}}]}} & 48'hffff_c000_0000);   // D_FLOOR = -2^126
      first = step_first;
      last = step_last;
      ke = shr ? 2'd3 - step : step - 2'd1;
      a_op = do_shl ? {a_q[46:0], shl_in}
         : do_shr ? {first ? a_q[47] : shift_bit, a_q[47:1]} : a_q;
      shift_out = do_shl ? a_q[47] : (do_shr & a_q[0]);
      b_op = b_en ? (b_q ^ {48{b_inv}}) : 48'd0;
      sum = {1'b0, a_op} + {1'b0, b_op} + {48'd0, first ? cin0 : carry};
      result = sum[47:0];
      // Operand A as read is zero; does not fit in 128 bits (its bits 127..143, bits 31..47
      // of word 2, not all equal). Both off the adder's path.
      a_zero = (first | zero_acc) & (a_q == 48'd0);
      a_wide = (a_q[47:31] != 17'd0) && (a_q[47:31] != 17'h1ffff);
      f_rest = (src[2] & a_zero) | (src[3] & shift_out) | (src[4] & a_wide) | (src[5] & c_flag);
      write = (i_kind == K_OP) && (step != 2'd0) && c_pred;
      ends = (last && !i_land) || land;
      // The next instruction.
      if (i_kind == K_LOOP) begin
         pc_next = pc_inc;
         pc2_next = pc2 + 7'd1;
         ir_next = ir_inc;
         ir_inc_next = ir_inc2;
         next_new = 1'b1;
      end else if ((i_kind == K_OP) && ends) begin
         if (i_end_loop && (loop_count != 6'd1)) begin
            pc_next = loop_pc;
            pc2_next = loop_pc2;
            ir_next = ir_loop;
            ir_inc_next = ir_loop_inc;
            next_new = 1'b1;
         end else begin
            pc_next = pc_inc;
            pc2_next = pc2 + 7'd1;
            ir_next = ir_inc;
            ir_inc_next = ir_inc2;
            next_new = 1'b1;
         end
      end
      fetch = 1'b1;
      if (write && i_write) rf[{i_dst, ke}] <= result;
   end
   flags_q <= flags;
   flag_pend <= 1'b0;
   if (reset) begin
      phase <= PH_IDLE;
      flags_q <= {FLAG_COUNT{1'b0}};
   end else if (cancel) begin
      phase <= PH_IDLE;
   end else begin
      case (phase)
      PH_IDLE: if (request) begin
         phase <= PH_PREP;
         jlim <= jerk_limit;
         alim <= accel_limit;
      end
      PH_ARMED: if (engage) phase <= PH_RUN;
      PH_READY: if (tick) phase <= PH_RUN;
      default: if (running) begin
         case (i_kind)
         K_LOOP: begin
            loop_count <= i_count;
            loop_pc <= pc_inc;
            loop_pc2 <= pc2 + 7'd1;
            ir_loop <= ir_inc;
            ir_loop_inc <= ir_inc2;
         end
         K_OP: if (!land) begin
            a_q <= a_raw;
            b_q <= rf[rb_q];
            if ((i_a_mod == M_WRIGHT) && !last) fill <= a_raw[47];
            if (step == 2'd0) begin
//@ derived_conditions
               c_b = conds[i_b_cond[4:0]] ^ i_b_cond[5];
               c_shift = conds[i_shift_in[4:0]] ^ i_shift_in[5];
               c_p = conds[i_pred[4:0]] ^ i_pred[5];
               c_f = conds[i_flag_cond[4:0]] ^ i_flag_cond[5];
               shl_in <= c_shift;
               c_pred <= c_p;
               c_flag <= c_f;
               do_shl <= i_a_mod == M_SHL;
               do_shr <= shr;
               b_en <= (i_b_mode == B_ADD) || (i_b_mode == B_SUB) || (i_b_mode == B_SUBONE)
                  || (i_b_mode == B_ADDSUB) || ((i_b_mode == B_ADDIF) && c_b);
               b_inv <= (i_b_mode == B_SUB) || (i_b_mode == B_SUBONE)
                  || ((i_b_mode == B_ADDSUB) && !c_b);
               cin0 <= (i_b_mode == B_SUB) || ((i_b_mode == B_ADDSUB) && !c_b);
               flag_we <= (i_combine != 2'd0) ? ({{FLAGS}}'d1 << i_flag) : {FLAG_COUNT{1'b0}};
               flag_and <= i_combine == C_AND;
               flag_or <= i_combine == C_OR;
               src <= {i_flag_src == 3'd5, i_flag_src == S_WIDE_A, i_flag_src == S_SHIFT,
                  i_flag_src == S_ZERO_A, i_flag_src == S_NSIGN, i_flag_src == S_SIGN};
            end else begin
               carry <= sum[48];
               zero_acc <= a_zero;
               shift_bit <= shift_out;
               shl_in <= shift_out;
            end
            if (write && i_to_snap) begin
               case (ke)
               2'd0: snap_reg[47:0] <= result;
               2'd1: snap_reg[95:48] <= result;
               default: snap_reg[D_BITS-1:96] <= result[D_BITS-97:0];
               endcase
            end
            if (write && last) begin
               flag_pend <= 1'b1;
               // The source: the result's sign (src[0]), its inverse (src[1]) or the rest
               // (f_rest: src is one-hot, so the sign's candidates are the flags written with
               // 0 when the source is the rest).
               flag_sign_q <= result[47];
               flag_rest_q <= f_rest;
               flags_if0 <= flag_write(flags, flag_we, flag_and, flag_or, src[1]);
               flags_if1 <= flag_write(flags, flag_we, flag_and, flag_or, src[0]);
               flags_if_rest <= flag_write(flags, flag_we, flag_and, flag_or, 1'b1);
            end
            if (last && !i_land && i_end_loop && (loop_count != 6'd1))
               loop_count <= loop_count - 6'd1;
            step_next = last ? 2'd0 : step + 2'd1;
         end else begin
            // The flag write's clock: it lands (flags_q <= flags, above); the instruction ends.
            if (i_end_loop && (loop_count != 6'd1)) loop_count <= loop_count - 6'd1;
         end
         K_HALT: begin
            // Prep done, or a decision made (or the chain found at rest).
            if (phase == PH_PREP) phase <= PH_ARMED;
            else if (flags_q[F_REST]) phase <= PH_IDLE;
            else phase <= PH_READY;
         end
         default: ;
         endcase
      end
      endcase
   end
   // An entry point's first instruction, fetched on the clock the phase leaves IDLE, ARMED or
   // READY. Not gated by reset or cancel (their paths then end at the phase): what is fetched
   // while the phase stays IDLE is not run, and the next entry fetches again.
   case (phase)
   PH_IDLE: if (request) begin
      step_next = 2'd0;
      pc_next = PC_PREP;
      pc2_next = PC_PREP + 7'd2;
      ir_next = rom(PC_PREP);
      ir_inc_next = rom(PC_PREP + 7'd1);
      next_new = 1'b1;
      fetch = 1'b1;
   end
   PH_ARMED: if (engage) begin
      step_next = 2'd0;
      pc_next = PC_INIT;
      pc2_next = PC_INIT + 7'd2;
      ir_next = rom(PC_INIT);
      ir_inc_next = rom(PC_INIT + 7'd1);
      next_new = 1'b1;
      fetch = 1'b1;
   end
   PH_READY: if (tick) begin
      step_next = 2'd0;
      pc_next = PC_DECIDE;
      pc2_next = PC_DECIDE + 7'd2;
      ir_next = rom(PC_DECIDE);
      ir_inc_next = rom(PC_DECIDE + 7'd1);
      next_new = 1'b1;
      fetch = 1'b1;
   end
   default: ;
   endcase
   // The phase after this edge is READY (the chain's snap multiplexer reads it from a register).
   // ... and ARMED (the sequencer's snap multiplexer reads it, through `engage`).
   armed_q <= !reset && !cancel && (((phase == PH_ARMED) && !engage)
      || ((phase == PH_PREP) && (i_kind == K_HALT)));
   ready_q <= !reset && !cancel && (((phase == PH_READY) && !tick)
      || ((phase == PH_RUN) && (i_kind == K_HALT) && !flags_q[F_REST]));
   // The instruction that comes next, and its address.
   if (fetch) begin
      pc <= pc_next;
      pc2 <= pc2_next;
      ir <= ir_next;
      ir_inc <= ir_inc_next;
   end
   step <= step_next;
   land <= !reset && !cancel && running && (i_kind == K_OP) && last && i_land;
   step_first <= step_next == 2'd1;
   step_last <= step_next == 2'd3;
   // The read addresses of the next clock: a new instruction's first (step 0) from its ROM
   // word, else this instruction's at the step after this edge.
   ra_q <= next_new ? ir_next[{{RA0_HI}}:{{RA0_LO}}] : {i_a_src[3:0], a_word(i_a_mod, step_next)};
   rb_q <= next_new ? ir_next[{{RB0_HI}}:{{RB0_LO}}] : {i_b_reg, read_word(i_a_mod, step_next)};
   // A's select on the next clock: a new instruction's from its ROM word (step 0), else this
   // one's at the step after this edge.
   kr_next = read_word(i_a_mod, step_next);
   a_sel_q <= next_new ? ir_next[{{SEL0_HI}}:{{SEL0_LO}}] : a_select(i_a_src, a_word(i_a_mod, step_next),
      (i_a_mod == M_WLEFT2) && (kr_next < 2'd2),
      ((i_a_mod == M_WRIGHT) ? {1'b0, kr_next} + 3'd1 : {1'b0, kr_next}) == 3'd3);
end

// ---- Heading (for the limit switches) and at rest, registered: the sign of v, else a, else j --
wire v_zero = v == {D_BITS{1'b0}};
wire a_zero = a == {D_BITS{1'b0}};
wire j_zero = j == {D_BITS{1'b0}};
reg heading_pos_q = 1'b0;
reg heading_neg_q = 1'b0;
// At rest (v = a = j = 0), registered: a 3 x 104-bit zero test is too long to feed the
// executor's decisions in the same clock.
reg at_rest_q = 1'b0;
always @(posedge clock) begin
   at_rest_q <= v_zero && a_zero && j_zero;
   heading_pos_q <= !v_zero ? ~v[D_BITS-1] : (!a_zero ? ~a[D_BITS-1] : (~j[D_BITS-1] && !j_zero));
   heading_neg_q <= !v_zero ? v[D_BITS-1] : (!a_zero ? a[D_BITS-1] : j[D_BITS-1]);
end

always @(*) begin
   active = phase != PH_IDLE;
   armed = armed_q;
   computing = phase == PH_RUN;
   // The phase after this edge is RUN (the tick divider's register is told it).
   computing_next = !reset && !cancel && (((phase == PH_ARMED) && engage)
      || ((phase == PH_READY) && tick) || ((phase == PH_RUN) && (i_kind != K_HALT)));
   ready = ready_q;
   snap = snap_reg;
   over = flags[F_EXCEEDS];
   heading_pos = heading_pos_q;
   heading_neg = heading_neg_q;
   at_rest = at_rest_q;
end
