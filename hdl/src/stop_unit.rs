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
    field, AMod, ASrc, Derived, Engine, EngineInputs, Flag, Instr, Step, COND_TRUE, DERIVED,
    FIELDS, FLAGS, KIND_HALT, KIND_LOOP, KIND_OP, REGISTERS, ROM_BITS, TESTABLE_FLAGS, WORDS,
    WORD_BITS,
};
use snapgen_model::stop::program::{microprogram, REG_NAMES};

use crate::protocol_v::LocalParam;
use crate::sim_bits::{from_u128, to_i128, to_u128};
use crate::template::{fill, Holes};

/// The unit's template.
const TEMPLATE: &str = include_str!("../verilog/stop_unit.v");
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
    /// `computing` after this clock's edge (for the tick divider's register).
    pub computing_next: Signal<Out, Bit>,
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
    /// The chain was at rest on the last clock: v = a = j = 0 (registered).
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
    at_rest: bool,
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
            s.at_rest = v == 0 && a == 0 && j == 0;
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
        self.at_rest.next = s.at_rest;
        self.active.next = s.phase != IDLE;
        self.armed.next = s.phase == ARMED;
        self.computing.next = s.phase == RUN;
        let p = microprogram();
        let halts = p
            .code
            .get(s.engine.pc)
            .is_none_or(|i| matches!(i, Instr::Halt));
        self.computing_next.next = !self.reset.val()
            && !self.cancel.val()
            && ((s.phase == ARMED && self.engage.val())
                || (s.phase == READY && self.tick.val())
                || (s.phase == RUN && !halts));
        self.ready.next = s.phase == READY;
        self.snap.next = from_u128(s.engine.snap);
        self.over.next = s.engine.flags >> (Flag::Exceeds as u32) & 1 == 1;
    }

    fn connect(&mut self) {
        self.active.connect();
        self.armed.connect();
        self.computing.connect();
        self.computing_next.connect();
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
    let digits = (IR_BITS as usize).div_ceil(4);
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
            "   7'd{pc}: rom = {IR_BITS}'h{:0digits$x}; // {}\n",
            first_reads(i) << ROM_BITS | i.encode(),
            i.listing(&REG_NAMES)
        ));
    }
    s.push_str(&format!(
        "   default: rom = {IR_BITS}'h{:0digits$x}; // HALT\n",
        first_reads(&Instr::Halt) << ROM_BITS | Instr::Halt.encode()
    ));
    s
}

/// Bits of an instruction word in the fabric: the ROM word and [`first_reads`] above it.
const IR_BITS: u32 = ROM_BITS + 12 + A_SEL_BITS;

/// The external values operand A reads, in the order of A's one-hot select (three bits each,
/// from [`A_SEL_EXT`], one a word): `ASrc`'s code, the core's register, signed (the chain's
/// registers are sign-extended to the three words, the limits zero-extended).
fn externals() -> [(u32, &'static str, bool); 5] {
    [
        (ASrc::V.encode(), "v", true),
        (ASrc::A.encode(), "a", true),
        (ASrc::J.encode(), "j", true),
        (ASrc::JerkLimit.encode(), "jlim", false),
        (ASrc::AccelLimit.encode(), "alim", false),
    ]
}

/// Operand A's one-hot select: the register file's read.
const A_SEL_RF: u32 = 0;
/// ... the sign fill (above word 2).
const A_SEL_FILL: u32 = 1;
/// ... word k of external value e ([`externals`]): bit `A_SEL_EXT + 3e + k`.
const A_SEL_EXT: u32 = 2;
/// ... `D_FLOOR`'s word 2 (its words 0 and 1 are zero).
const A_SEL_FLOOR: u32 = A_SEL_EXT + 15;
/// Bits of the select (none set: zero).
const A_SEL_BITS: u32 = A_SEL_FLOOR + 1;

/// Operand A's one-hot select for source code `src`, word `ak`, below word 0 or above word 2
/// (the template's `a_select`, which its generated cases compute on every other step).
fn a_select(src: u32, ak: u32, below: bool, above: bool) -> u128 {
    let bit = if below {
        None
    } else if above {
        Some(A_SEL_FILL)
    } else if src < 16 {
        Some(A_SEL_RF)
    } else if src == ASrc::Floor.encode() {
        (ak == 2).then_some(A_SEL_FLOOR)
    } else {
        externals()
            .iter()
            .position(|e| e.0 == src)
            .map(|e| A_SEL_EXT + 3 * e as u32 + ak)
    };
    bit.map_or(0, |b| 1 << b)
}

/// The register file's read addresses on an instruction's first clock (step 0), kept in the
/// ROM above its word so that no decoding lies between the next instruction and the register
/// file: `{A_SRC[3:0], ak}` in bits 11..6 and `{B_REG, kr}` in bits 5..0, with the words read
/// at step 0 by the template's `read_word` and `a_word` (kr = 2 for a right shift, else 0;
/// ak = kr + 1 one word right, kr − 2 two words left, else kr), and operand A's one-hot
/// select at step 0 ([`a_select`], bits 12 and up: below word 0 is a two-word left shift's
/// kr < 2, above word 2 kr + 1 = 3 one word right). 0 for LOOP and HALT.
fn first_reads(i: &Instr) -> u128 {
    let Instr::Op(op) = i else {
        return 0;
    };
    let w = i.encode();
    let bits = |name: &str| {
        let f = field(name);
        (w >> f.lsb) & ((1 << f.bits) - 1)
    };
    let kr: u128 = if op.a_mod == AMod::Shr { 2 } else { 0 };
    let ak = match op.a_mod {
        AMod::WordRight => kr + 1,
        AMod::WordLeft2 => (kr + 2) & 3,
        _ => kr,
    };
    let below = op.a_mod == AMod::WordLeft2 && kr < 2;
    let above = op.a_mod == AMod::WordRight && kr + 1 == 3;
    let sel = a_select(bits("A_SRC") as u32, ak as u32, below, above);
    sel << 12 | ((bits("A_SRC") & 0xf) << 2 | ak) << 6 | bits("B_REG") << 2 | kr
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
    (
        "d_next_brake",
        "d_below | (d_brake & flags[F_BGT]) | (flags[F_OVER] & flags[F_ZERO])",
    ),
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
    // Read from the flag register itself: an instruction that writes a flag applies the write
    // on a clock of its own (`micro::FLAG_CLOCKS`), before the next instruction reads them.
    for (n, e) in &DERIVED_LOGIC {
        let e = e.replace("flags[", "flags_q[");
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
        "               conds = {{1'b1, {}{}, flags_q[{}:0]}};\n",
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
    // External values: word `ak` of their extension to WORDS words, the chain's registers
    // sign-extended, the limits zero-extended.
    let ext = WORDS * WORD_BITS - D_BITS as u32;
    let top = format!("[D_BITS-1:{}]", 2 * WORD_BITS);
    // Operand A: each source's word ANDed with its select bit, ORed.
    let mut ext_terms = String::new();
    // The select's cases (the template's a_select) for the steps after the first.
    let mut ext_selects = String::new();
    for (e, (code, name, signed)) in externals().into_iter().enumerate() {
        let high = if signed {
            format!("{{{{{ext}{{{name}[D_BITS-1]}}}}, {name}{top}}}")
        } else {
            format!("{{{ext}'d0, {name}{top}}}")
        };
        let b = A_SEL_EXT + 3 * e as u32;
        ext_terms.push_str(&format!(
            "         | ({{48{{a_sel_q[{}]}}}} & {name}[47:0]) | ({{48{{a_sel_q[{}]}}}} & {name}[95:48])\n         | ({{48{{a_sel_q[{}]}}}} & {high})\n",
            b,
            b + 1,
            b + 2
        ));
        ext_selects.push_str(&format!(
            "      5'd{code}: a_select[{}:{}] = w;   // {name}\n",
            b + 2,
            b
        ));
    }
    ext_selects.push_str(&format!(
        "      5'd{}: a_select[{A_SEL_FLOOR}] = w[2];   // D_FLOOR\n",
        ASrc::Floor.encode()
    ));
    let holes = Holes::new()
        .value("PC_PREP", p.prep)
        .value("PC_INIT", p.init)
        .value("PC_DECIDE", p.decide)
        .value("K_OP", KIND_OP)
        .value("K_LOOP", KIND_LOOP)
        .value("K_HALT", KIND_HALT)
        .value("FLAGS", FLAGS)
        .value(
            "IR_HALT",
            format!(
                "{IR_BITS}'h{:x}",
                first_reads(&Instr::Halt) << ROM_BITS | Instr::Halt.encode()
            ),
        )
        .value("IR_TOP", IR_BITS - 1)
        .value("RA0_HI", ROM_BITS + 11)
        .value("RA0_LO", ROM_BITS + 6)
        .value("SEL0_LO", ROM_BITS + 12)
        .value("SEL0_HI", ROM_BITS + 12 + A_SEL_BITS - 1)
        .value("A_SEL_TOP", A_SEL_BITS - 1)
        .value("A_SEL_BITS", A_SEL_BITS)
        .value("A_SEL_RF", A_SEL_RF)
        .value("A_SEL_FILL", A_SEL_FILL)
        .value("A_SEL_FLOOR", A_SEL_FLOOR)
        .value("RB0_HI", ROM_BITS + 5)
        .value("RB0_LO", ROM_BITS)
        .value("LOCALS_A", 1 + 2 + 48)
        .value("LOCALS_B", 7 + 48 * 3 + 49)
        .block("flag_names", flags)
        .block("rom_cases", rom_case())
        .block("instruction_fields", fields)
        .block("derived_declarations", derived_decl)
        .block("derived_zeros", derived_zero)
        .block("derived_conditions", derived_code)
        .block("external_terms", ext_terms)
        .block("external_selects", ext_selects);
    let body = fill("stop_unit.v", TEMPLATE, &holes).expect("the stop unit's template is filled");
    let mut params: Vec<LocalParam> = Flag::ALL
        .iter()
        .map(|&f| LocalParam::new(format!("F_{}", f.name()), 5, f as u64))
        .collect();
    params.extend(crate::protocol_v::localparams());
    crate::protocol_v::with_localparams(&params, &body)
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
