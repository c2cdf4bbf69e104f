//! The engine's clock-accurate interpreter: a second implementation of the Verilog engine,
//! word by word and clock by clock, to check the microprogram against the law quickly.

use super::*;

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
    /// Clock of the instruction being executed: 0 reads, 1..=[`WORDS`] add word `step − 1`,
    /// `WORDS + 1` applies its flag write (an instruction whose write [lands](Op::land)).
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
            ASrc::Floor => ext_word(crate::stop::D_FLOOR, 128, true, k),
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
        if self.step == WORDS + 1 {
            // The flag's clock (the fabric applies the flag written on the last word's clock;
            // here it was written at once): the instruction ends.
            self.next_instruction(&op);
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
        if last && !op.land {
            self.next_instruction(&op);
        } else {
            self.step += 1;
        }
        Step::Running
    }

    /// The instruction after `op`, on its last clock: the loop's start or the next.
    fn next_instruction(&mut self, op: &Op) {
        self.step = 0;
        if op.end_loop && self.loop_count > 1 {
            self.loop_count -= 1;
            self.pc = self.loop_pc;
        } else {
            self.pc += 1;
        }
    }

    fn pred_holds(&self, op: &Op) -> bool {
        op.pred.eval(self.flags)
    }
}
