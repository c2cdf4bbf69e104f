//! The stop unit's engine: a word-serial arithmetic unit that runs the stop law as a short
//! microprogram ([`super::program`]). This module is its instruction set, its encoding (the
//! ROM word the Verilog decodes: one layout, [`Field`], for both) and a clock-accurate
//! interpreter — a second implementation of the Verilog engine, used to check the microprogram
//! against [`super::StopLaw`] far faster than co-simulation can.
//!
//! # The machine
//! * Values are 144-bit two's complement, three 48-bit words; an operation adds and writes one
//!   word a clock (low word first; [`AMod::Shr`] high word first) after a clock that reads its
//!   conditions and first operands (the fabric reads each word a clock before it adds it), so
//!   every instruction that computes takes [`OP_CLOCKS`] clocks, and one more
//!   ([`FLAG_CLOCKS`]) when it writes a flag an instruction that may follow it reads at once
//!   ([`Op::land`]): the clock the fabric applies the flag write on, so every instruction's
//!   conditions are read from the flag register itself. `LOOP` and `HALT` take one.
//! * 16 registers in a register file (LUT-RAM in the fabric: two read ports, one write port).
//! * Operand A is a register or an external value (the chain's `v`, `a`, `j` sign-extended, the
//!   latched stop limits zero-extended, 0, or `D_FLOOR`), optionally shifted: one bit left (a
//!   bit shifted in; the bit shifted out is kept), one word right (arithmetic) or two words
//!   left, or one bit right (arithmetic). Operand B is a register added, subtracted (or
//!   `~B`), or chosen by a condition.
//! * A result is written only if the instruction's predicate holds; each instruction may set,
//!   AND or OR one flag: the result's sign or not-sign, the bit shifted out, whether operand A
//!   as read is zero or does not fit in 128 bits (tested off the adder's path), or a
//!   condition. Conditions are flags, their negations, and the law's
//!   case analysis on flags ([`Derived`], the only logic that is not arithmetic).
//! * `LOOP n` repeats the instructions up to the one marked `end_loop` n times (no nesting).
//!   `HALT` ends a phase.

mod engine;
mod listing;

pub use engine::{Engine, EngineInputs, Step};

/// Bits of a word: the adder's width.
pub const WORD_BITS: u32 = 48;
/// Words of a value.
pub const WORDS: u32 = 3;
/// Bits of a value.
pub const VALUE_BITS: u32 = WORD_BITS * WORDS;
/// Clocks of a computing instruction: a read clock, then one per word.
pub const OP_CLOCKS: u32 = WORDS + 1;
/// Clocks a computing instruction whose flag write [lands](Op::land) takes beyond
/// [`OP_CLOCKS`]: the fabric applies the write on a clock of its own (nothing else happens on
/// it), so no instruction's conditions are read in one clock's path with the write's result.
pub const FLAG_CLOCKS: u32 = 1;
/// Registers in the register file.
pub const REGISTERS: usize = 16;
/// Bit mask of a word.
pub const WORD_MASK: u64 = (1 << WORD_BITS) - 1;
/// Width of the external chain values and limits (the core's registers).
pub const EXT_BITS: u32 = 104;

/// The engine's flags (one bit each).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Flag {
    /// The bit shifted out by the last one-bit left shift that kept it.
    C = 0,
    /// The series sum saturates (its quotient or product is out of range): sticky.
    V,
    /// The division's partial remainder is negative.
    Rs,
    /// The level λ of the series sum is ≥ 0 (`D = 0`); in Decide, an Over stop releases at
    /// once (`V + Λ > 0`).
    Zero,
    /// The next velocity is 0 (when the stop begins).
    Vz,
    /// The next velocity is negative (when the stop begins).
    Vs,
    /// The next acceleration is negative (when the stop begins).
    Ls,
    /// The stop's direction is negative.
    Dir,
    /// The stop began outside its limits.
    Over,
    /// Law mode Brake.
    Brake,
    /// Law mode Hold.
    Hold,
    /// The next Brake flag (a temporary while the mode is updated).
    NextBrake,
    /// The end game applies (without `Over`).
    End,
    /// λ < −A.
    Below,
    /// λ > −A.
    Above,
    /// λ − J > −A (braking a full step stays within −A).
    Bgt,
    /// λ − J < 0.
    Bgn,
    /// `E` after braking a full step is ≥ 0.
    EgOk,
    /// `E` after braking onto −A is ≥ 0.
    EpOk,
    /// `E` after holding the level is ≥ 0.
    EhOk,
    /// The chain is at rest (v = a = j = 0).
    Rest,
    /// The stop leaves its limits (reported): `Over`, or `|Λ| > A` when it begins.
    Exceeds,
}

/// Number of flags.
pub const FLAGS: usize = 22;
/// Flags a condition can test (the first ones); the others ([`Flag::Exceeds`]) are only
/// written and read out.
pub const TESTABLE_FLAGS: usize = 21;

impl Flag {
    /// Every flag, by index.
    pub const ALL: [Flag; FLAGS] = [
        Flag::C,
        Flag::V,
        Flag::Rs,
        Flag::Zero,
        Flag::Vz,
        Flag::Vs,
        Flag::Ls,
        Flag::Dir,
        Flag::Over,
        Flag::Brake,
        Flag::Hold,
        Flag::NextBrake,
        Flag::End,
        Flag::Below,
        Flag::Above,
        Flag::Bgt,
        Flag::Bgn,
        Flag::EgOk,
        Flag::EpOk,
        Flag::EhOk,
        Flag::Rest,
        Flag::Exceeds,
    ];

    /// Its name in the Verilog (`F_...`).
    pub fn name(self) -> &'static str {
        match self {
            Flag::C => "C",
            Flag::V => "V",
            Flag::Rs => "RS",
            Flag::Zero => "ZERO",
            Flag::Vz => "VZ",
            Flag::Vs => "VS",
            Flag::Ls => "LS",
            Flag::Dir => "DIR",
            Flag::Over => "OVER",
            Flag::Brake => "BRAKE",
            Flag::Hold => "HOLD",
            Flag::NextBrake => "NB",
            Flag::End => "END",
            Flag::Below => "BELOW",
            Flag::Above => "ABOVE",
            Flag::Bgt => "BGT",
            Flag::Bgn => "BGN",
            Flag::EgOk => "EGOK",
            Flag::EpOk => "EPOK",
            Flag::EhOk => "EHOK",
            Flag::Rest => "REST",
            Flag::Exceeds => "EXCEEDS",
        }
    }
}

/// Conditions computed from the flags: the stop law's case analysis
/// ([`super::StopLaw`]'s `level`), written once here and once in the Verilog.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Derived {
    /// The direction when the stop begins: the next velocity's sign, else the next
    /// acceleration's.
    DirNow = 0,
    /// The next level is λ (hold).
    LevelHold,
    /// The next level is λ − J (brake a full step).
    LevelGrid,
    /// The next level is −A (brake onto the limit).
    LevelLimit,
    /// The next level is μ (the end game).
    LevelEnd,
    /// `E` becomes `E + λ` (hold).
    ExcessHold,
    /// `E` becomes `E + λ + min(λ − J, 0)` (brake a full step).
    ExcessGrid,
    /// `E` becomes `V + λ + D(−A)` (brake onto the limit).
    ExcessLimit,
    /// The mode after this tick is Brake.
    NextBrake,
    /// The mode after this tick is Hold.
    NextHold,
}

/// Number of derived conditions.
pub const DERIVED: usize = 10;

impl Derived {
    /// Every derived condition, by index.
    pub const ALL: [Derived; DERIVED] = [
        Derived::DirNow,
        Derived::LevelHold,
        Derived::LevelGrid,
        Derived::LevelLimit,
        Derived::LevelEnd,
        Derived::ExcessHold,
        Derived::ExcessGrid,
        Derived::ExcessLimit,
        Derived::NextBrake,
        Derived::NextHold,
    ];

    /// Its name in the Verilog (`D_...`).
    pub fn name(self) -> &'static str {
        match self {
            Derived::DirNow => "DIR_NOW",
            Derived::LevelHold => "LEVEL_HOLD",
            Derived::LevelGrid => "LEVEL_GRID",
            Derived::LevelLimit => "LEVEL_LIMIT",
            Derived::LevelEnd => "LEVEL_END",
            Derived::ExcessHold => "EXCESS_HOLD",
            Derived::ExcessGrid => "EXCESS_GRID",
            Derived::ExcessLimit => "EXCESS_LIMIT",
            Derived::NextBrake => "NEXT_BRAKE",
            Derived::NextHold => "NEXT_HOLD",
        }
    }

    /// Its value for the flags `f` (bit `k` is flag `k`).
    pub fn eval(self, f: u32) -> bool {
        let g = |x: Flag| f >> (x as u32) & 1 == 1;
        // The end game, Brake below −A, Brake a step, or the release rule (StopLaw::level).
        let end = g(Flag::Over) || g(Flag::End);
        let below = !end && g(Flag::Brake) && g(Flag::Below);
        let sel_ok = if g(Flag::Bgt) {
            g(Flag::EgOk)
        } else {
            g(Flag::EpOk)
        };
        let brake = !end && g(Flag::Brake) && g(Flag::Above) && sel_ok;
        let release = !end && !below && !brake;
        let at_limit = (g(Flag::Brake) && !g(Flag::Below) && !g(Flag::Above)) || g(Flag::Hold);
        match self {
            Derived::DirNow => {
                if g(Flag::Vz) {
                    g(Flag::Ls)
                } else {
                    g(Flag::Vs)
                }
            }
            Derived::LevelHold | Derived::ExcessHold => release && g(Flag::EhOk),
            Derived::LevelGrid | Derived::ExcessGrid => brake && g(Flag::Bgt),
            Derived::LevelLimit | Derived::ExcessLimit => brake && !g(Flag::Bgt),
            Derived::LevelEnd => end,
            // An Over stop that releases at once (Zero in Decide) brakes within its limits
            // from there.
            Derived::NextBrake => {
                below || (brake && g(Flag::Bgt)) || (g(Flag::Over) && g(Flag::Zero))
            }
            Derived::NextHold => {
                (brake && !g(Flag::Bgt))
                    || (release && !(g(Flag::Brake) && g(Flag::Above)) && at_limit && g(Flag::EhOk))
            }
        }
    }
}

/// A condition: always, a flag, a derived condition, or the negation of one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cond {
    /// Always true.
    True,
    /// Always false.
    False,
    /// A flag.
    Is(Flag),
    /// A flag is clear.
    Not(Flag),
    /// A derived condition.
    When(Derived),
}

/// Index of the always-true condition in the encoding.
pub const COND_TRUE: u32 = 31;

impl Cond {
    /// Encoding: `{negate, index}`: index < 21 a flag, 21..31 a derived condition, 31 true.
    pub fn encode(self) -> u32 {
        match self {
            Cond::True => COND_TRUE,
            Cond::False => 32 | COND_TRUE,
            Cond::Is(f) | Cond::Not(f) if f as usize >= TESTABLE_FLAGS => {
                panic!("flag {} is not testable", f.name())
            }
            Cond::Is(f) => f as u32,
            Cond::Not(f) => 32 | f as u32,
            Cond::When(d) => TESTABLE_FLAGS as u32 + d as u32,
        }
    }

    /// Its value for the flags `f`.
    pub fn eval(self, f: u32) -> bool {
        eval_code(self.encode(), f)
    }

    /// Whether its value may depend on flag `f` (a derived condition's: on any flag).
    pub fn reads(self, f: Flag) -> bool {
        match self {
            Cond::True | Cond::False => false,
            Cond::Is(g) | Cond::Not(g) => g == f,
            Cond::When(_) => true,
        }
    }
}

/// Evaluates an encoded condition (as the Verilog does).
pub fn eval_code(code: u32, f: u32) -> bool {
    let index = code & 31;
    let v = if index == COND_TRUE {
        true
    } else if (index as usize) < TESTABLE_FLAGS {
        f >> index & 1 == 1
    } else {
        Derived::ALL[index as usize - TESTABLE_FLAGS].eval(f)
    };
    v ^ (code >> 5 & 1 == 1)
}

/// Operand A's source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ASrc {
    /// A register.
    Reg(u8),
    /// 0.
    Zero,
    /// The chain's velocity (sign-extended).
    V,
    /// The chain's acceleration (sign-extended).
    A,
    /// The chain's jerk (sign-extended).
    J,
    /// The latched jerk limit (zero-extended).
    JerkLimit,
    /// The latched acceleration limit (zero-extended).
    AccelLimit,
    /// `D_FLOOR` = −2^126.
    Floor,
}

impl ASrc {
    /// Encoding: 0..16 registers, then the external values.
    pub fn encode(self) -> u32 {
        match self {
            ASrc::Reg(r) => u32::from(r),
            ASrc::Zero => 16,
            ASrc::V => 17,
            ASrc::A => 18,
            ASrc::J => 19,
            ASrc::JerkLimit => 20,
            ASrc::AccelLimit => 21,
            ASrc::Floor => 22,
        }
    }
}

/// How operand A is shifted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AMod {
    /// As is.
    None,
    /// `2A + bit`: one bit left, the condition's value shifted in, the top bit shifted out.
    Shl(Cond),
    /// `A >> 48` (arithmetic: one word right).
    WordRight,
    /// `A << 96` (two words left).
    WordLeft2,
    /// `A >> 1` (arithmetic; computed high word first; B must be none).
    Shr,
}

impl AMod {
    /// Encoding of the kind (the shift-in condition is a field of its own).
    pub fn encode(self) -> u32 {
        match self {
            AMod::None => 0,
            AMod::Shl(_) => 1,
            AMod::WordRight => 2,
            AMod::WordLeft2 => 3,
            AMod::Shr => 4,
        }
    }
}

/// What is added to operand A.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BMode {
    /// Nothing.
    None,
    /// `+ B`.
    Add(u8),
    /// `− B`.
    Sub(u8),
    /// `+ ~B` (`− B − 1`).
    SubOne(u8),
    /// `+ B` if the condition holds, else `− B`.
    AddSub(u8, Cond),
    /// `+ B` if the condition holds, else nothing.
    AddIf(u8, Cond),
}

impl BMode {
    /// Encoding: (kind, register, condition).
    pub fn encode(self) -> (u32, u32, u32) {
        match self {
            BMode::None => (0, 0, Cond::True.encode()),
            BMode::Add(r) => (1, r.into(), Cond::True.encode()),
            BMode::Sub(r) => (2, r.into(), Cond::True.encode()),
            BMode::SubOne(r) => (3, r.into(), Cond::True.encode()),
            BMode::AddSub(r, c) => (4, r.into(), c.encode()),
            BMode::AddIf(r, c) => (5, r.into(), c.encode()),
        }
    }
}

/// What a flag is set from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FlagSrc {
    /// The result is negative.
    Sign,
    /// The result is ≥ 0.
    NotSign,
    /// Operand A as read (before its shift) is 0.
    ZeroA,
    /// The bit shifted out of A (with [`AMod::Shl`]).
    ShiftOut,
    /// Operand A as read (before its shift) does not fit in 128 bits (two's complement).
    WideA,
    /// A condition, evaluated before this instruction.
    Test(Cond),
}

impl FlagSrc {
    /// Encoding: (kind, condition).
    pub fn encode(self) -> (u32, u32) {
        match self {
            FlagSrc::Sign => (0, Cond::True.encode()),
            FlagSrc::NotSign => (1, Cond::True.encode()),
            FlagSrc::ZeroA => (2, Cond::True.encode()),
            FlagSrc::ShiftOut => (3, Cond::True.encode()),
            FlagSrc::WideA => (4, Cond::True.encode()),
            FlagSrc::Test(c) => (5, c.encode()),
        }
    }
}

/// How a flag write combines with the flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Combine {
    /// `flag = src`.
    Set,
    /// `flag &= src`.
    And,
    /// `flag |= src`.
    Or,
}

/// A computing instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Op {
    /// Register written (`None`: the result only sets a flag).
    pub dst: Option<u8>,
    /// Operand A.
    pub a: ASrc,
    /// Its shift.
    pub a_mod: AMod,
    /// Operand B.
    pub b: BMode,
    /// Write the result (and the flag) only if this holds.
    pub pred: Cond,
    /// A flag to write.
    pub flag: Option<(Flag, FlagSrc, Combine)>,
    /// The result's low 104 bits are also the next tick's snap.
    pub to_snap: bool,
    /// The last instruction of a loop's body.
    pub end_loop: bool,
    /// Its flag write is applied on a clock of its own ([`FLAG_CLOCKS`]) before the next
    /// instruction starts: an instruction that may follow it reads that flag at its first clock
    /// (set by the assembler, [`super::program`]). Otherwise the write lands on the next
    /// instruction's first clock, which does not read it.
    pub land: bool,
}

/// An instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Instr {
    /// Compute ([`OP_CLOCKS`] clocks, [`FLAG_CLOCKS`] more when its flag write lands).
    Op(Op),
    /// Repeat the following body `n` times (one clock).
    Loop(u32),
    /// End of a phase (one clock).
    Halt,
}

impl Instr {
    /// Whether it reads flag `f` on its first clock: an instruction's conditions (its
    /// predicate, B's condition, the bit a left shift takes in, a flag's test), `HALT` the flag
    /// `REST`.
    pub fn reads_first(&self, f: Flag) -> bool {
        match self {
            Instr::Op(op) => {
                let b = match op.b {
                    BMode::AddSub(_, c) | BMode::AddIf(_, c) => c,
                    _ => Cond::True,
                };
                let shift_in = match op.a_mod {
                    AMod::Shl(c) => c,
                    _ => Cond::True,
                };
                let test = match op.flag {
                    Some((_, FlagSrc::Test(c), _)) => c,
                    _ => Cond::True,
                };
                [op.pred, b, shift_in, test].iter().any(|c| c.reads(f))
            }
            Instr::Halt => f == Flag::Rest,
            Instr::Loop(_) => false,
        }
    }

    /// Clocks it takes.
    pub fn clocks(&self) -> u32 {
        match self {
            Instr::Op(op) if op.land => OP_CLOCKS + FLAG_CLOCKS,
            Instr::Op(_) => OP_CLOCKS,
            Instr::Loop(_) | Instr::Halt => 1,
        }
    }
}

/// A field of the ROM word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Its name in the Verilog (`I_NAME` is the slice).
    pub name: &'static str,
    /// Lowest bit.
    pub lsb: u32,
    /// Width.
    pub bits: u32,
}

/// The ROM word's layout, low bits first (one source for the encoder and the Verilog).
pub const FIELDS: [Field; 18] = {
    const NAMES: [(&str, u32); 18] = [
        ("KIND", 2),
        ("DST", 4),
        ("WRITE", 1),
        ("A_SRC", 5),
        ("A_MOD", 3),
        ("SHIFT_IN", 6),
        ("B_REG", 4),
        ("B_MODE", 3),
        ("B_COND", 6),
        ("PRED", 6),
        ("FLAG", 5),
        ("FLAG_SRC", 3),
        ("FLAG_COND", 6),
        ("COMBINE", 2),
        ("TO_SNAP", 1),
        ("END_LOOP", 1),
        ("COUNT", 6),
        ("LAND", 1),
    ];
    let mut out = [Field {
        name: "",
        lsb: 0,
        bits: 0,
    }; 18];
    let mut lsb = 0;
    let mut k = 0;
    while k < NAMES.len() {
        out[k] = Field {
            name: NAMES[k].0,
            lsb,
            bits: NAMES[k].1,
        };
        lsb += NAMES[k].1;
        k += 1;
    }
    out
};

/// Width of the ROM word.
pub const ROM_BITS: u32 = {
    let last = FIELDS[FIELDS.len() - 1];
    last.lsb + last.bits
};

/// Instruction kinds.
pub const KIND_OP: u32 = 0;
/// `LOOP`.
pub const KIND_LOOP: u32 = 1;
/// `HALT`.
pub const KIND_HALT: u32 = 2;

/// The field named `name`.
pub fn field(name: &str) -> Field {
    *FIELDS
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no ROM field {name}"))
}

fn put(word: &mut u128, name: &str, value: u32) {
    let f = field(name);
    assert!(
        u64::from(value) < 1u64 << f.bits,
        "field {name}: {value} does not fit"
    );
    *word |= u128::from(value) << f.lsb;
}

impl Instr {
    /// The ROM word.
    pub fn encode(&self) -> u128 {
        let mut w = 0u128;
        match self {
            Instr::Loop(n) => {
                put(&mut w, "KIND", KIND_LOOP);
                put(&mut w, "COUNT", *n);
            }
            Instr::Halt => put(&mut w, "KIND", KIND_HALT),
            Instr::Op(op) => {
                put(&mut w, "KIND", KIND_OP);
                put(&mut w, "DST", u32::from(op.dst.unwrap_or(0)));
                put(&mut w, "WRITE", u32::from(op.dst.is_some()));
                put(&mut w, "A_SRC", op.a.encode());
                put(&mut w, "A_MOD", op.a_mod.encode());
                let shift_in = match op.a_mod {
                    AMod::Shl(c) => c,
                    _ => Cond::False,
                };
                put(&mut w, "SHIFT_IN", shift_in.encode());
                let (kind, reg, cond) = op.b.encode();
                put(&mut w, "B_REG", reg);
                put(&mut w, "B_MODE", kind);
                put(&mut w, "B_COND", cond);
                put(&mut w, "PRED", op.pred.encode());
                let (flag, (src, cond), comb) = match op.flag {
                    Some((f, s, c)) => (
                        f as u32,
                        s.encode(),
                        match c {
                            Combine::Set => 1,
                            Combine::And => 2,
                            Combine::Or => 3,
                        },
                    ),
                    None => (0, (0, Cond::True.encode()), 0),
                };
                put(&mut w, "FLAG", flag);
                put(&mut w, "FLAG_SRC", src);
                put(&mut w, "FLAG_COND", cond);
                put(&mut w, "COMBINE", comb);
                put(&mut w, "TO_SNAP", u32::from(op.to_snap));
                put(&mut w, "END_LOOP", u32::from(op.end_loop));
                put(&mut w, "LAND", u32::from(op.land));
            }
        }
        w
    }
}
