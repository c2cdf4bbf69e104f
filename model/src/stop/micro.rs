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
//!   every instruction that computes takes [`OP_CLOCKS`] clocks. `LOOP` and `HALT` take one.
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

/// Bits of a word: the adder's width.
pub const WORD_BITS: u32 = 48;
/// Words of a value.
pub const WORDS: u32 = 3;
/// Bits of a value.
pub const VALUE_BITS: u32 = WORD_BITS * WORDS;
/// Clocks of a computing instruction: a read clock, then one per word.
pub const OP_CLOCKS: u32 = WORDS + 1;
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
}

/// An instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Instr {
    /// Compute ([`OP_CLOCKS`] clocks).
    Op(Op),
    /// Repeat the following body `n` times (one clock).
    Loop(u32),
    /// End of a phase (one clock).
    Halt,
}

impl Instr {
    /// Clocks it takes.
    pub fn clocks(&self) -> u32 {
        match self {
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
pub const FIELDS: [Field; 17] = {
    const NAMES: [(&str, u32); 17] = [
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
    ];
    let mut out = [Field {
        name: "",
        lsb: 0,
        bits: 0,
    }; 17];
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
            }
        }
        w
    }
}

/// The engine's inputs on a clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EngineInputs {
    /// The chain's velocity, acceleration and jerk registers.
    pub v: i128,
    /// Acceleration.
    pub a: i128,
    /// Jerk.
    pub j: i128,
    /// The latched jerk limit (104 bits, unsigned).
    pub jerk_limit: u128,
    /// The latched acceleration limit (104 bits, unsigned).
    pub accel_limit: u128,
}

/// Word `k` of `x` sign-extended (or zero-extended) from `bits` to [`VALUE_BITS`].
fn ext_word(x: i128, bits: u32, signed: bool, k: u32) -> u64 {
    let (low, neg) = if signed {
        let v = crate::chain::wrap(x, bits);
        (v as u128, v < 0)
    } else {
        ((x as u128) & ((1u128 << bits) - 1), false)
    };
    if k < 2 {
        ((low >> (k * WORD_BITS)) as u64) & WORD_MASK
    } else {
        // Word 2: bits 96..144, the top 16 the sign.
        let high: u64 = if neg { 0xffff } else { 0 };
        (((low >> 96) as u64) | (high << 32)) & WORD_MASK
    }
}

/// The clock-accurate engine (the Verilog's second implementation).
#[derive(Clone, Debug)]
pub struct Engine {
    /// Register file, `[register][word]`.
    pub rf: [[u64; WORDS as usize]; REGISTERS],
    /// Flags, bit `k` flag `k`.
    pub flags: u32,
    /// Program counter.
    pub pc: usize,
    /// Clock of the instruction being executed: 0 reads, 1.. add word `step − 1`.
    pub step: u32,
    loop_count: u32,
    loop_pc: usize,
    carry: bool,
    shift_bit: bool,
    zero_acc: bool,
    fill: bool,
    /// The snap register (low 104 bits of the last `to_snap` result).
    pub snap: u128,
}

impl Default for Engine {
    fn default() -> Self {
        Engine {
            rf: [[0; WORDS as usize]; REGISTERS],
            flags: 0,
            pc: 0,
            step: 0,
            loop_count: 0,
            loop_pc: 0,
            carry: false,
            shift_bit: false,
            zero_acc: false,
            fill: false,
            snap: 0,
        }
    }
}

/// What a clock of the engine did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Still running.
    Running,
    /// Executed a `HALT`.
    Halted,
}

impl Engine {
    /// Starts running at `pc` (the word counter restarts).
    pub fn jump(&mut self, pc: usize) {
        self.pc = pc;
        self.step = 0;
    }

    fn flag(&self, f: Flag) -> bool {
        self.flags >> (f as u32) & 1 == 1
    }

    /// One value's words, as an `i128` (its low 128 bits; for tests).
    pub fn value(&self, r: usize) -> i128 {
        let w = &self.rf[r];
        (u128::from(w[0]) | u128::from(w[1]) << 48 | u128::from(w[2]) << 96) as i128
    }

    fn a_word(&self, op: &Op, k: i32, i: &EngineInputs) -> u64 {
        if k < 0 {
            return 0;
        }
        if k >= WORDS as i32 {
            return if self.fill { WORD_MASK } else { 0 };
        }
        let k = k as u32;
        match op.a {
            ASrc::Reg(r) => self.rf[usize::from(r)][k as usize],
            ASrc::Zero => 0,
            ASrc::V => ext_word(i.v, EXT_BITS, true, k),
            ASrc::A => ext_word(i.a, EXT_BITS, true, k),
            ASrc::J => ext_word(i.j, EXT_BITS, true, k),
            ASrc::JerkLimit => ext_word(i.jerk_limit as i128, EXT_BITS, false, k),
            ASrc::AccelLimit => ext_word(i.accel_limit as i128, EXT_BITS, false, k),
            ASrc::Floor => ext_word(super::D_FLOOR, 128, true, k),
        }
    }

    /// One clock with program `prog` and inputs `i`.
    pub fn clock(&mut self, prog: &[Instr], i: &EngineInputs) -> Step {
        let instr = prog[self.pc];
        let op = match instr {
            Instr::Halt => return Step::Halted,
            Instr::Loop(n) => {
                self.loop_count = n;
                self.loop_pc = self.pc + 1;
                self.pc += 1;
                return Step::Running;
            }
            Instr::Op(op) => op,
        };
        if self.step == 0 {
            // The read clock (the fabric reads the conditions and the first words).
            self.step = 1;
            return Step::Running;
        }
        let word = self.step - 1;
        let last = word == WORDS - 1;
        // The word processed: high first for a right shift.
        let k = if op.a_mod == AMod::Shr {
            WORDS - 1 - word
        } else {
            word
        };
        let first = word == 0;
        let write = self.pred_holds(&op);
        let (b_word, cin) = {
            let (reg, kind, cond) = match op.b {
                BMode::None => (0, 0, true),
                BMode::Add(r) => (r, 1, true),
                BMode::Sub(r) => (r, 2, true),
                BMode::SubOne(r) => (r, 3, true),
                BMode::AddSub(r, c) => (r, 4, c.eval(self.flags)),
                BMode::AddIf(r, c) => (r, 5, c.eval(self.flags)),
            };
            let b = self.rf[usize::from(reg)][k as usize];
            match (kind, cond) {
                (0, _) => (0, false),
                (1, _) | (4, true) | (5, true) => (b, false),
                (2, _) | (4, false) => (!b & WORD_MASK, true),
                (3, _) => (!b & WORD_MASK, false),
                _ => (0, false),
            }
        };
        let mut shift_out = false;
        let a = match op.a_mod {
            AMod::None => self.a_word(&op, k as i32, i),
            AMod::WordRight => self.a_word(&op, k as i32 + 1, i),
            AMod::WordLeft2 => self.a_word(&op, k as i32 - 2, i),
            AMod::Shl(c) => {
                let w = self.a_word(&op, k as i32, i);
                let inb = if first {
                    c.eval(self.flags)
                } else {
                    self.shift_bit
                };
                shift_out = w >> (WORD_BITS - 1) & 1 == 1;
                ((w << 1) | u64::from(inb)) & WORD_MASK
            }
            AMod::Shr => {
                let w = self.a_word(&op, k as i32, i);
                let top = if first {
                    w >> (WORD_BITS - 1) & 1 == 1
                } else {
                    self.shift_bit
                };
                shift_out = w & 1 == 1;
                (w >> 1) | (u64::from(top) << (WORD_BITS - 1))
            }
        };
        let a_read = match op.a_mod {
            AMod::None | AMod::Shl(_) | AMod::Shr => self.a_word(&op, k as i32, i),
            AMod::WordRight => self.a_word(&op, k as i32 + 1, i),
            AMod::WordLeft2 => self.a_word(&op, k as i32 - 2, i),
        };
        let carry_in = if first { cin } else { self.carry };
        let sum = a + b_word + u64::from(carry_in);
        let result = sum & WORD_MASK;
        // Registers carried to the next word.
        let zero_acc = (first || self.zero_acc) && a_read == 0;
        if write {
            if let Some(d) = op.dst {
                self.rf[usize::from(d)][k as usize] = result;
            }
            if op.to_snap {
                let shift = k * WORD_BITS;
                let mask = ((1u128 << WORD_BITS) - 1) << shift;
                let bits = (u128::from(result) << shift) & ((1u128 << EXT_BITS) - 1);
                self.snap = (self.snap & !mask) | bits;
            }
        }
        if last && write {
            if let Some((f, src, comb)) = op.flag {
                let v = match src {
                    FlagSrc::Sign => result >> (WORD_BITS - 1) & 1 == 1,
                    FlagSrc::NotSign => result >> (WORD_BITS - 1) & 1 == 0,
                    FlagSrc::ZeroA => zero_acc,
                    FlagSrc::ShiftOut => shift_out,
                    FlagSrc::WideA => {
                        // Bits 127..143 of the value are bits 31..47 of word 2.
                        let top = a_read >> 31;
                        top != 0 && top != (1 << 17) - 1
                    }
                    FlagSrc::Test(c) => c.eval(self.flags),
                };
                let old = self.flag(f);
                let new = match comb {
                    Combine::Set => v,
                    Combine::And => old && v,
                    Combine::Or => old || v,
                };
                self.flags = (self.flags & !(1 << f as u32)) | (u32::from(new) << f as u32);
            }
        }
        // Registers between words (as the Verilog's: updated on every word clock).
        self.carry = sum >> WORD_BITS & 1 == 1;
        self.zero_acc = zero_acc;
        self.shift_bit = shift_out;
        // The sign of the word read by a one-word right shift, for the fill of the top word.
        if op.a_mod == AMod::WordRight {
            let w = self.a_word(&op, k as i32 + 1, i);
            self.fill = w >> (WORD_BITS - 1) & 1 == 1;
        }
        if last {
            self.step = 0;
            if op.end_loop && self.loop_count > 1 {
                self.loop_count -= 1;
                self.pc = self.loop_pc;
            } else {
                self.pc += 1;
            }
        } else {
            self.step += 1;
        }
        Step::Running
    }

    fn pred_holds(&self, op: &Op) -> bool {
        op.pred.eval(self.flags)
    }
}

impl Cond {
    /// Its name in listings.
    pub fn listing(self) -> String {
        match self {
            Cond::True => "1".into(),
            Cond::False => "0".into(),
            Cond::Is(f) => f.name().into(),
            Cond::Not(f) => format!("!{}", f.name()),
            Cond::When(d) => d.name().into(),
        }
    }
}

impl Instr {
    /// One line of assembly, registers named by `names`.
    pub fn listing(&self, names: &[&str; REGISTERS]) -> String {
        let op = match self {
            Instr::Loop(n) => return format!("LOOP {n}"),
            Instr::Halt => return "HALT".into(),
            Instr::Op(op) => op,
        };
        let reg = |r: u8| names[usize::from(r)].to_string();
        let a = match op.a {
            ASrc::Reg(r) => reg(r),
            ASrc::Zero => "0".into(),
            ASrc::V => "v".into(),
            ASrc::A => "a".into(),
            ASrc::J => "j".into(),
            ASrc::JerkLimit => "jerk_limit".into(),
            ASrc::AccelLimit => "accel_limit".into(),
            ASrc::Floor => "D_FLOOR".into(),
        };
        let a = match op.a_mod {
            AMod::None => a,
            AMod::Shl(c) => format!("({a}<<1 | {})", c.listing()),
            AMod::WordRight => format!("({a}>>48)"),
            AMod::WordLeft2 => format!("({a}<<96)"),
            AMod::Shr => format!("({a}>>>1)"),
        };
        let b = match op.b {
            BMode::None => String::new(),
            BMode::Add(r) => format!(" + {}", reg(r)),
            BMode::Sub(r) => format!(" - {}", reg(r)),
            BMode::SubOne(r) => format!(" + ~{}", reg(r)),
            BMode::AddSub(r, c) => format!(" + ({} ? {} : -{})", c.listing(), reg(r), reg(r)),
            BMode::AddIf(r, c) => format!(" + ({} ? {} : 0)", c.listing(), reg(r)),
        };
        let mut s = match op.dst {
            Some(d) => format!("{} = {a}{b}", reg(d)),
            None => format!("test {a}{b}"),
        };
        if op.pred != Cond::True {
            s = format!("if {}: {s}", op.pred.listing());
        }
        if let Some((f, src, comb)) = op.flag {
            let src = match src {
                FlagSrc::Sign => "sign".to_string(),
                FlagSrc::NotSign => "!sign".to_string(),
                FlagSrc::ZeroA => "zero(A)".to_string(),
                FlagSrc::ShiftOut => "shifted out".to_string(),
                FlagSrc::WideA => "wide(A)".to_string(),
                FlagSrc::Test(c) => c.listing(),
            };
            let op = match comb {
                Combine::Set => "=",
                Combine::And => "&=",
                Combine::Or => "|=",
            };
            s.push_str(&format!("; {} {op} {src}", f.name()));
        }
        if op.to_snap {
            s.push_str("; snap = it");
        }
        if op.end_loop {
            s.push_str("; END LOOP");
        }
        s
    }
}
