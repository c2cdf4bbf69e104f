//! The stop unit: the fabric's controlled stop from any state, to rest exactly, within the
//! stop's jerk and acceleration limits, without reversing (the law: `snapgen_model::stop`;
//! docs/MODEL.md, "The controlled stop").
//!
//! A small word-serial engine runs the law as a microprogram (`snapgen_model::stop::program`,
//! the one source of the ROM below and of the model's timing): 144-bit values as three 48-bit
//! words, one 48-bit adder, a 16-register file in LUT-RAM, flags and predicated writes
//! (`snapgen_model::stop::micro` documents the machine). Phases:
//!
//! * **Prep** when a stop is requested (`request` while idle; the limits are latched): `J`,
//!   `−A` and the series sum `D(−A)`; the move plays on. Then **Armed**: the core takes the
//!   stop on the next tick (`engage`).
//! * **Run** from `engage`: Init (where the law begins) runs into Decide (the next tick's
//!   snap); the core holds its ticks while the unit runs (`computing`). Then **Ready**: the
//!   chain takes `snap` on the next tick, which starts Decide again; a Decide that finds the
//!   chain at rest ends the stop.
//!
//! One wide adder instead of one per operation: about a tenth of the logic of a parallel
//! unit and a short critical path, for `prep` + `init` + `decide` clocks (see
//! `snapgen_model::stop::phase_clocks`; within one tick of the default 1250 clocks).
//!
//! rust-hdl 0.46 has no signed arithmetic, memories with two asynchronous read ports or
//! functions, so this block writes its own Verilog; for rust-hdl's simulator it runs the
//! model's interpreter of the same machine (`snapgen_model::stop::micro::Engine`). The Verilog
//! is what is checked: Verilator co-simulation against `snapgen_model::CoreModel`, whose stop
//! is the law itself, every clock.

use rust_hdl::prelude::*;
use snapgen_model::stop::micro::{
    Derived, Engine, EngineInputs, Flag, Instr, Step, COND_TRUE, DERIVED, FIELDS, FLAGS, KIND_HALT,
    KIND_LOOP, KIND_OP, REGISTERS, ROM_BITS, TESTABLE_FLAGS, WORDS, WORD_BITS,
};
use snapgen_model::stop::program::{microprogram, REG_NAMES};

use crate::sim_bits::{from_u128, to_i128, to_u128};
use crate::D_BITS;

const _: () = assert!(D_BITS == 104 && WORD_BITS == 48 && WORDS == 3);
const _: () =
    assert!(TESTABLE_FLAGS + DERIVED <= COND_TRUE as usize && FLAGS <= 32 && REGISTERS == 16);

/// The stop unit.
#[derive(LogicBlock, Default)]
pub struct StopUnit {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Cancel the stop at once (the emergency stop).
    pub cancel: Signal<In, Bit>,
    /// Request a stop (taken while idle: the limits are latched and Prep starts).
    pub request: Signal<In, Bit>,
    /// The core takes the stop on this clock's tick (the chain steps with the program's snap).
    pub engage: Signal<In, Bit>,
    /// The chain steps on this clock (with `snap` while `ready`).
    pub tick: Signal<In, Bit>,
    /// Velocity register.
    pub v: Signal<In, Bits<D_BITS>>,
    /// Acceleration register.
    pub a: Signal<In, Bits<D_BITS>>,
    /// Jerk register.
    pub j: Signal<In, Bits<D_BITS>>,
    /// The stop's jerk limit (raw, unsigned; latched on the request).
    pub jerk_limit: Signal<In, Bits<D_BITS>>,
    /// The stop's acceleration limit (raw, unsigned; latched on the request).
    pub accel_limit: Signal<In, Bits<D_BITS>>,
    /// A stop is requested or runs.
    pub active: Signal<Out, Bit>,
    /// Prepared: the stop is taken on the next tick.
    pub armed: Signal<Out, Bit>,
    /// The stop runs and the unit is computing: the next tick must wait.
    pub computing: Signal<Out, Bit>,
    /// `snap` is the next tick's.
    pub ready: Signal<Out, Bit>,
    /// The next tick's snap.
    pub snap: Signal<Out, Bits<D_BITS>>,
    /// The last stop began outside its limits (landed regardless of them).
    pub over: Signal<Out, Bit>,
    /// The axis heads forward: on the last clock the first non-zero of v, a, j was positive.
    pub heading_pos: Signal<Out, Bit>,
    /// The axis heads backward: ... negative.
    pub heading_neg: Signal<Out, Bit>,
    /// The chain is at rest: v = a = j = 0 (combinational).
    pub at_rest: Signal<Out, Bit>,
    _sim: SimState,
}

/// The unit for rust-hdl's simulator: the model's interpreter of the same engine.
#[derive(Clone, Debug, Default)]
struct SimState {
    phase: u8,
    engine: Engine,
    jerk_limit: u128,
    accel_limit: u128,
    heading: i8,
}

const IDLE: u8 = 0;
const PREP: u8 = 1;
const ARMED: u8 = 2;
const RUN: u8 = 3;
const READY: u8 = 4;

impl Logic for StopUnit {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let s = &mut self._sim;
            let p = microprogram();
            let (v, a, j) = (
                to_i128(self.v.val()),
                to_i128(self.a.val()),
                to_i128(self.j.val()),
            );
            s.heading = if v != 0 {
                v.signum()
            } else if a != 0 {
                a.signum()
            } else {
                j.signum()
            } as i8;
            if self.reset.val() {
                s.phase = IDLE;
                s.engine.flags = 0;
            } else if self.cancel.val() {
                s.phase = IDLE;
            } else {
                match s.phase {
                    IDLE if self.request.val() => {
                        s.phase = PREP;
                        s.engine.jump(p.prep);
                        s.jerk_limit = to_u128(self.jerk_limit.val());
                        s.accel_limit = to_u128(self.accel_limit.val());
                    }
                    ARMED if self.engage.val() => {
                        s.phase = RUN;
                        s.engine.jump(p.init);
                    }
                    READY if self.tick.val() => {
                        s.phase = RUN;
                        s.engine.jump(p.decide);
                    }
                    PREP | RUN => {
                        let i = EngineInputs {
                            v: to_i128(self.v.val()),
                            a: to_i128(self.a.val()),
                            j: to_i128(self.j.val()),
                            jerk_limit: s.jerk_limit,
                            accel_limit: s.accel_limit,
                        };
                        if s.engine.clock(&p.code, &i) == Step::Halted {
                            let rest = s.engine.flags >> (Flag::Rest as u32) & 1 == 1;
                            s.phase = match s.phase {
                                PREP => ARMED,
                                _ if rest => IDLE,
                                _ => READY,
                            };
                        }
                    }
                    _ => {}
                }
            }
        }
        let s = &self._sim;
        self.heading_pos.next = s.heading > 0;
        self.heading_neg.next = s.heading < 0;
        self.at_rest.next = self.v.val() == Bits::<D_BITS>::default()
            && self.a.val() == Bits::<D_BITS>::default()
            && self.j.val() == Bits::<D_BITS>::default();
        self.active.next = s.phase != IDLE;
        self.armed.next = s.phase == ARMED;
        self.computing.next = s.phase == RUN;
        self.ready.next = s.phase == READY;
        self.snap.next = from_u128(s.engine.snap);
        self.over.next = s.engine.flags >> (Flag::Exceeds as u32) & 1 == 1;
    }

    fn connect(&mut self) {
        self.active.connect();
        self.armed.connect();
        self.computing.connect();
        self.ready.connect();
        self.snap.connect();
        self.over.connect();
        self.heading_pos.connect();
        self.heading_neg.connect();
        self.at_rest.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(stop_unit_verilog())
    }
}

/// The ROM: one `case` entry per instruction, each with its assembly as a comment.
fn rom_case() -> String {
    let p = microprogram();
    let digits = (ROM_BITS as usize).div_ceil(4);
    let mut s = String::new();
    for (pc, i) in p.code.iter().enumerate() {
        let label = if pc == p.prep {
            "   // ---- Prep\n"
        } else if pc == p.init {
            "   // ---- Init\n"
        } else if pc == p.decide {
            "   // ---- Decide\n"
        } else {
            ""
        };
        s.push_str(label);
        s.push_str(&format!(
            "   7'd{pc}: rom = {ROM_BITS}'h{:0digits$x}; // {}\n",
            i.encode(),
            i.listing(&REG_NAMES)
        ));
    }
    s.push_str(&format!(
        "   default: rom = {ROM_BITS}'h{:0digits$x}; // HALT\n",
        Instr::Halt.encode()
    ));
    s
}

/// The law's case analysis on the flags (the second implementation of `micro::Derived`): each
/// derived condition's name and expression, in order (an expression may use the ones before).
const DERIVED_LOGIC: [(&str, &str); 16] = [
    ("d_end", "flags[F_OVER] | flags[F_END]"),
    ("d_below", "~d_end & flags[F_BRAKE] & flags[F_BELOW]"),
    ("d_sel_ok", "flags[F_BGT] ? flags[F_EGOK] : flags[F_EPOK]"),
    ("d_brake", "~d_end & flags[F_BRAKE] & flags[F_ABOVE] & d_sel_ok"),
    ("d_release", "~d_end & ~d_below & ~d_brake"),
    (
        "d_at_limit",
        "(flags[F_BRAKE] & ~flags[F_BELOW] & ~flags[F_ABOVE]) | flags[F_HOLD]",
    ),
    ("d_dir_now", "flags[F_VZ] ? flags[F_LS] : flags[F_VS]"),
    ("d_level_hold", "d_release & flags[F_EHOK]"),
    ("d_level_grid", "d_brake & flags[F_BGT]"),
    ("d_level_limit", "d_brake & ~flags[F_BGT]"),
    ("d_level_end", "d_end"),
    ("d_excess_hold", "d_level_hold"),
    ("d_excess_grid", "d_level_grid"),
    ("d_excess_limit", "d_level_limit"),
    ("d_next_brake", "d_below | (d_brake & flags[F_BGT])"),
    (
        "d_next_hold",
        "(d_brake & ~flags[F_BGT]) | (d_release & ~(flags[F_BRAKE] & flags[F_ABOVE]) & d_at_limit & flags[F_EHOK])",
    ),
];

/// The unit's Verilog.
///
/// The engine's datapath (operand reads, the adder, the flag logic, the next program counter)
/// is computed in its clocked process, under the phase that uses it, with the process's local
/// variables: the same registers and the same values on every clock as one `assign` per
/// signal would give, but a simulator evaluates none of it while the unit is idle (Verilator
/// evaluates every continuous assignment on every clock: as `assign`s, the idle unit cost a
/// quarter of the core's co-simulation time).
fn stop_unit_verilog() -> String {
    let p = microprogram();
    assert!(p.code.len() <= 128, "the program counter has 7 bits");
    let mut fields = String::new();
    for f in FIELDS {
        fields.push_str(&format!(
            "wire [{}:0] i_{} = ir[{}:{}];\n",
            f.bits - 1,
            f.name.to_lowercase(),
            f.lsb + f.bits - 1,
            f.lsb
        ));
    }
    // The flags' indices: all listed; localparams (below) for those the logic names.
    let list: Vec<String> = Flag::ALL
        .iter()
        .map(|f| format!("{} {}", *f as u8, f.name()))
        .collect();
    let flags = format!("// Flags (bit: name): {}.\n", list.join(", "));
    // The derived conditions as a function of the flags, in Derived::ALL order
    // (TESTABLE_FLAGS + k).
    let decls: Vec<String> = DERIVED_LOGIC.iter().map(|(n, _)| n.to_string()).collect();
    let mut derived_code = String::new();
    for (n, e) in &DERIVED_LOGIC {
        derived_code.push_str(&format!("               {n} = {e};\n"));
    }
    let derived: Vec<String> = Derived::ALL
        .iter()
        .rev()
        .map(|d| format!("d_{}", d.name().to_lowercase()))
        .collect();
    for d in &derived {
        assert!(decls.contains(d), "no expression for {d}");
    }
    let pad = COND_TRUE as usize - TESTABLE_FLAGS - DERIVED;
    derived_code.push_str(&format!(
        "               conds = {{1'b1, {}{}, flags[{}:0]}};\n",
        if pad > 0 {
            format!("{pad}'d0, ")
        } else {
            String::new()
        },
        derived.join(", "),
        TESTABLE_FLAGS - 1
    ));
    let derived_decl = format!("   reg {};\n", decls.join(", "));
    let derived_zero = format!("   {{{}}} = {}'d0;\n", decls.join(", "), decls.len());
    let mut ext_cases = String::new();
    for (code, name, signed) in [
        (17, "v", true),
        (18, "a", true),
        (19, "j", true),
        (20, "jlim", false),
        (21, "alim", false),
    ] {
        let top = if signed {
            format!("{{{{40{{{name}[103]}}}}, {name}[103:96]}}")
        } else {
            format!("{{40'd0, {name}[103:96]}}")
        };
        ext_cases.push_str(&format!(
            "      5'd{code}: a_ext = (ak == 2'd0) ? {name}[47:0] : (ak == 2'd1) ? {name}[95:48] : {top};\n"
        ));
    }
    let ir_halt = format!("{ROM_BITS}'h{:x}", Instr::Halt.encode());
    let body = format!(
        r#"
// ---- The engine (snapgen_model::stop::micro): phases, registers -------------------------------
// An instruction that computes takes 4 clocks (step 0..3): step s reads operand word s (for
// s < 3) and adds word s - 1 (for s > 0); step 0 also samples the conditions. LOOP and HALT
// take one clock. The instruction register holds ROM[pc]; both move as the engine runs.
localparam [2:0] PH_IDLE = 3'd0, PH_PREP = 3'd1, PH_ARMED = 3'd2, PH_RUN = 3'd3, PH_READY = 3'd4;
localparam [6:0] PC_PREP = 7'd{prep}, PC_INIT = 7'd{init}, PC_DECIDE = 7'd{decide};
localparam [1:0] K_OP = 2'd{k_op}, K_LOOP = 2'd{k_loop}, K_HALT = 2'd{k_halt};
// A shifts (0: none), B modes (0: none), flag sources (5: a condition), flag writes (0: none,
// 1: set).
localparam [2:0] M_SHL = 3'd1, M_WRIGHT = 3'd2, M_WLEFT2 = 3'd3, M_SHR = 3'd4;
localparam [2:0] B_ADD = 3'd1, B_SUB = 3'd2, B_SUBONE = 3'd3, B_ADDSUB = 3'd4, B_ADDIF = 3'd5;
localparam [2:0] S_SIGN = 3'd0, S_NSIGN = 3'd1, S_ZERO_A = 3'd2, S_SHIFT = 3'd3, S_WIDE_A = 3'd4;
localparam [1:0] C_AND = 2'd2, C_OR = 2'd3;
{flags}FLAG_PARAMS
reg [2:0] phase = PH_IDLE;
reg [6:0] pc = 7'd0;
reg [{rb}:0] ir = {ir_halt};             // the instruction at pc
reg [1:0] step = 2'd0;
reg [5:0] loop_count = 6'd0;
reg [6:0] loop_pc = 7'd0;
reg [47:0] a_q = 48'd0;                  // operand words read on the previous clock
reg [47:0] b_q = 48'd0;
// The instruction decoded on step 0 (its conditions evaluated), for the adding steps.
reg c_shift_in = 1'b0;                   // the bit shifted into a left shift
reg c_pred = 1'b0;                       // write the result and the flag
reg c_flag = 1'b0;                       // a flag set from a condition
reg do_shl = 1'b0, do_shr = 1'b0;        // A shifted one bit left, right
reg b_en = 1'b0, b_inv = 1'b0;           // B added, inverted
reg cin0 = 1'b0;                         // carry into word 0
reg [{nf}:0] flag_we = {flags_bits}'d0;  // the flag written (one-hot)
reg flag_and = 1'b0, flag_or = 1'b0;     // combined by AND, OR (else set)
reg [5:0] src = 6'd0;                    // flag source: sign, !sign, zero, shift, wide, cond
reg carry = 1'b0;                        // between words: the adder's carry,
reg shift_bit = 1'b0;                    // the bit a shift moves across,
reg zero_acc = 1'b0;                     // the result is zero so far,
reg fill = 1'b0;                         // the sign of a one-word right shift's source
reg [{nf}:0] flags = {flags_bits}'d0;
reg [103:0] jlim = 104'd0;               // the limits, latched on the request
reg [103:0] alim = 104'd0;
reg [103:0] snap_reg = 104'd0;
reg [47:0] rf [0:63];                    // 16 registers x 4 word slots (3 used), LUT-RAM
integer rf_i;
initial for (rf_i = 0; rf_i < 64; rf_i = rf_i + 1) rf[rf_i] = 48'd0;

// ---- The microprogram (snapgen_model::stop::program) -----------------------------------------
function automatic [{rb}:0] rom(input [6:0] addr);
   case (addr)
{rom}   endcase
endfunction
{fields}
// ---- Conditions: flags, the law's case analysis on them (micro::Derived), true -------------
// (The engine's process writes every selection out: a function's arguments and locals cost a
// simulator stores on every clock, executed or not.)

wire running = (phase == PH_PREP) || (phase == PH_RUN);

// ---- The engine: one clocked process; its datapath is evaluated only while it runs ---------
always @(posedge clock) begin : engine
   // Read: operand words for word `step` (high word first for a right shift).
   reg shr;
   reg [1:0] kr, ak, ke;
   reg [2:0] ak_wide;
   reg a_below, a_above;
   reg [47:0] a_ext, a_raw;
   // Add: word step - 1, from the words read.
   reg first, last, shift_out, a_zero, a_wide, f_src, write;
   reg [47:0] a_op, b_op, result;
   reg [48:0] sum;
   reg [{nf}:0] f_new;
   reg [31:0] conds;
   reg [6:0] pc_next;
   reg fetch;                            // load pc and ir (with ROM[pc_next])
   // The law's case analysis on the flags (micro::Derived), for the step-0 conditions.
{derived_decl}   // The step-0 conditions: b's, and the shift-in, predicate and flag conditions.
   reg c_b, c_shift, c_p, c_f;
   // Every local has a value on every clock (none is a register); the datapath's are computed
   // only while the engine runs.
   {{shr, kr, ak, ke, ak_wide, a_below, a_above, a_ext, a_raw}} = {locals_a}'d0;
   {{first, last, shift_out, a_zero, a_wide, f_src, write, a_op, b_op, result, sum}} = {locals_b}'d0;
   f_new = {flags_bits}'d0;
   conds = 32'd0;
   pc_next = pc;
   fetch = 1'b0;
{derived_zero}   {{c_b, c_shift, c_p, c_f}} = 4'd0;
   if (running) begin
      shr = i_a_mod == M_SHR;
      kr = shr ? 2'd2 - step : step;
      // The word of A read: kr, kr + 1 (one word right) or kr - 2 (two words left).
      ak_wide = (i_a_mod == M_WRIGHT) ? {{1'b0, kr}} + 3'd1 : {{1'b0, kr}};
      a_below = (i_a_mod == M_WLEFT2) && (kr < 2'd2);
      a_above = ak_wide == 3'd3;
      ak = (i_a_mod == M_WLEFT2) ? kr - 2'd2 : ak_wide[1:0];
      // External values, word ak of their 144-bit extension: the chain's registers
      // sign-extended, the limits zero-extended.
      case (i_a_src)
{ext_cases}      5'd22: a_ext = (ak == 2'd2) ? 48'hffff_c000_0000 : 48'd0;   // D_FLOOR = -2^126
      default: a_ext = 48'd0;                                    // 16: zero
      endcase
      a_raw = a_below ? 48'd0 : a_above ? {{48{{fill}}}}
         : (i_a_src[4] ? a_ext : rf[{{i_a_src[3:0], ak}}]);
      first = step == 2'd1;
      last = step == 2'd3;
      ke = shr ? 2'd3 - step : step - 2'd1;
      a_op = do_shl ? {{a_q[46:0], first ? c_shift_in : shift_bit}}
         : do_shr ? {{first ? a_q[47] : shift_bit, a_q[47:1]}} : a_q;
      shift_out = do_shl ? a_q[47] : (do_shr & a_q[0]);
      b_op = b_en ? (b_q ^ {{48{{b_inv}}}}) : 48'd0;
      sum = {{1'b0, a_op}} + {{1'b0, b_op}} + {{48'd0, first ? cin0 : carry}};
      result = sum[47:0];
      // Operand A as read is zero; does not fit in 128 bits (its bits 127..143, bits 31..47
      // of word 2, not all equal). Both off the adder's path.
      a_zero = (first | zero_acc) & (a_q == 48'd0);
      a_wide = (a_q[47:31] != 17'd0) && (a_q[47:31] != 17'h1ffff);
      f_src = (src[0] & result[47]) | (src[1] & ~result[47]) | (src[2] & a_zero)
         | (src[3] & shift_out) | (src[4] & a_wide) | (src[5] & c_flag);
      f_new = flag_and ? (flags & {{{flags_bits}{{f_src}}}})
         : flag_or ? (flags | {{{flags_bits}{{f_src}}}}) : {{{flags_bits}{{f_src}}}};
      write = (i_kind == K_OP) && (step != 2'd0) && c_pred;
      // The next instruction.
      if (i_kind == K_LOOP) pc_next = pc + 7'd1;
      else if ((i_kind == K_OP) && last)
         pc_next = (i_end_loop && (loop_count != 6'd1)) ? loop_pc : pc + 7'd1;
      fetch = 1'b1;
      if (write && i_write) rf[{{i_dst, ke}}] <= result;
   end
   if (reset) begin
      phase <= PH_IDLE;
      flags <= {flags_bits}'d0;
   end else if (cancel) begin
      phase <= PH_IDLE;
   end else begin
      case (phase)
      PH_IDLE: if (request) begin
         phase <= PH_PREP;
         step <= 2'd0;
         jlim <= jerk_limit;
         alim <= accel_limit;
         pc_next = PC_PREP;
         fetch = 1'b1;
      end
      PH_ARMED: if (engage) begin
         phase <= PH_RUN;
         step <= 2'd0;
         pc_next = PC_INIT;
         fetch = 1'b1;
      end
      PH_READY: if (tick) begin
         phase <= PH_RUN;
         step <= 2'd0;
         pc_next = PC_DECIDE;
         fetch = 1'b1;
      end
      default: if (running) begin
         case (i_kind)
         K_LOOP: begin
            loop_count <= i_count;
            loop_pc <= pc + 7'd1;
         end
         K_OP: begin
            a_q <= a_raw;
            b_q <= rf[{{i_b_reg, kr}}];
            if ((i_a_mod == M_WRIGHT) && !last) fill <= a_raw[47];
            if (step == 2'd0) begin
{derived_code}               c_b = conds[i_b_cond[4:0]] ^ i_b_cond[5];
               c_shift = conds[i_shift_in[4:0]] ^ i_shift_in[5];
               c_p = conds[i_pred[4:0]] ^ i_pred[5];
               c_f = conds[i_flag_cond[4:0]] ^ i_flag_cond[5];
               c_shift_in <= c_shift;
               c_pred <= c_p;
               c_flag <= c_f;
               do_shl <= i_a_mod == M_SHL;
               do_shr <= shr;
               b_en <= (i_b_mode == B_ADD) || (i_b_mode == B_SUB) || (i_b_mode == B_SUBONE)
                  || (i_b_mode == B_ADDSUB) || ((i_b_mode == B_ADDIF) && c_b);
               b_inv <= (i_b_mode == B_SUB) || (i_b_mode == B_SUBONE)
                  || ((i_b_mode == B_ADDSUB) && !c_b);
               cin0 <= (i_b_mode == B_SUB) || ((i_b_mode == B_ADDSUB) && !c_b);
               flag_we <= (i_combine != 2'd0) ? ({flags_bits}'d1 << i_flag) : {flags_bits}'d0;
               flag_and <= i_combine == C_AND;
               flag_or <= i_combine == C_OR;
               src <= {{i_flag_src == 3'd5, i_flag_src == S_WIDE_A, i_flag_src == S_SHIFT,
                  i_flag_src == S_ZERO_A, i_flag_src == S_NSIGN, i_flag_src == S_SIGN}};
            end else begin
               carry <= sum[48];
               zero_acc <= a_zero;
               shift_bit <= shift_out;
            end
            if (write && i_to_snap) begin
               case (ke)
               2'd0: snap_reg[47:0] <= result;
               2'd1: snap_reg[95:48] <= result;
               default: snap_reg[103:96] <= result[7:0];
               endcase
            end
            if (write && last) flags <= (flags & ~flag_we) | (flag_we & f_new);
            if (last && i_end_loop && (loop_count != 6'd1)) loop_count <= loop_count - 6'd1;
            step <= last ? 2'd0 : step + 2'd1;
         end
         K_HALT: begin
            // Prep done, or a decision made (or the chain found at rest).
            if (phase == PH_PREP) phase <= PH_ARMED;
            else if (flags[F_REST]) phase <= PH_IDLE;
            else phase <= PH_READY;
         end
         default: ;
         endcase
      end
      endcase
   end
   // One ROM read, for whichever instruction comes next.
   if (fetch) begin
      pc <= pc_next;
      ir <= rom(pc_next);
   end
end

// ---- Heading (for the limit switches), registered: the sign of v, else a, else j ---------------
wire v_zero = v == 104'd0;
wire a_zero = a == 104'd0;
wire j_zero = j == 104'd0;
reg heading_pos_q = 1'b0;
reg heading_neg_q = 1'b0;
always @(posedge clock) begin
   heading_pos_q <= !v_zero ? ~v[103] : (!a_zero ? ~a[103] : (~j[103] && !j_zero));
   heading_neg_q <= !v_zero ? v[103] : (!a_zero ? a[103] : j[103]);
end

always @(*) begin
   active = phase != PH_IDLE;
   armed = phase == PH_ARMED;
   computing = phase == PH_RUN;
   ready = phase == PH_READY;
   snap = snap_reg;
   over = flags[F_EXCEEDS];
   heading_pos = heading_pos_q;
   heading_neg = heading_neg_q;
   at_rest = v_zero && a_zero && j_zero;
end
"#,
        prep = p.prep,
        init = p.init,
        decide = p.decide,
        k_op = KIND_OP,
        k_loop = KIND_LOOP,
        k_halt = KIND_HALT,
        nf = FLAGS - 1,
        flags_bits = FLAGS,
        rb = ROM_BITS - 1,
        ir_halt = ir_halt,
        rom = rom_case(),
        fields = fields,
        flags = flags,
        derived_decl = derived_decl,
        derived_zero = derived_zero,
        derived_code = derived_code,
        ext_cases = ext_cases,
        locals_a = 1 + 2 + 2 + 2 + 3 + 1 + 1 + 48 + 48,
        locals_b = 7 + 48 * 3 + 49,
    );
    let mut params = String::new();
    for f in Flag::ALL {
        if body.contains(&format!("[F_{}]", f.name())) {
            params.push_str(&format!("localparam F_{} = {};\n", f.name(), f as u8));
        }
    }
    body.replace("FLAG_PARAMS\n", &params)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stop_unit_is_synthesizable() {
        let stat = crate::synth_check::synth_block("stop_unit", StopUnit::default());
        eprintln!("{stat}");
    }
}
