//! The stop unit's microprogram: the stop law ([`super::StopLaw`]) for the word-serial engine
//! of [`super::micro`], in three phases.
//!
//! * **Prep** (when a stop is requested; the move plays on): latch `J` and `−A`, and compute
//!   `D(−A)`, the velocity a release from the hold level takes off.
//! * **Init** (from the tick that takes the stop; ticks wait): the direction, the normalised
//!   next velocity `V` and acceleration `Λ`, `D(Λ)`, `E = V + D(Λ)`, whether the stop began
//!   outside its limits (`E < 0`: the end game lands it regardless of them) and whether it
//!   leaves them (that, or `|Λ| > A`: reported); it runs on into Decide.
//! * **Decide** (before every stopping tick; ticks wait): the law's comparisons, the next level
//!   and `E`, the mode, and the snap `dir·(level − Λ) − j`; or the end, when the chain is at
//!   rest.
//!
//! The series sum `D(λ) = Σ λ + i·J` over the levels below zero is computed exactly, as
//! [`super::release_drop`] defines it, without the product `J·(n − 1)`: with
//! `N = −λ + J − 1 = n·J + r` (so `n = ceil(−λ/J)`), `2λ + J·(n − 1) = λ − 1 − r`, hence
//! `D = n·(λ − 1 − r) / 2`. `n ≥ 2^48` (checked as `N >> 48 ≥ J`) or a product below `−2^127`
//! saturates `D` at `D_FLOOR`. The division is non-restoring over the low 48 bits of `N`
//! (the high ones start the remainder), the product shift-and-add from the quotient's top bit.

use std::sync::OnceLock;

use super::micro::{AMod, ASrc, BMode, Combine, Cond, Derived, Flag, FlagSrc, Instr, Op};
use super::SUM_COUNT_BITS;

/// Registers: the ones the law keeps from tick to tick, then temporaries.
pub mod reg {
    /// `J`, the jerk limit.
    pub const JL: u8 = 0;
    /// `−A`, the hold level.
    pub const LO: u8 = 1;
    /// `D(−A)`.
    pub const HD: u8 = 2;
    /// `E`, the velocity left after the fastest release (normalised).
    pub const E: u8 = 3;
    /// Scratch.
    pub const T: u8 = 4;
    /// Scratch (the jerk register during Decide).
    pub const U: u8 = 5;
    /// `V`, the next velocity (normalised).
    pub const VV: u8 = 6;
    /// `Λ`, the next acceleration (normalised).
    pub const L: u8 = 7;
    /// `V + Λ`.
    pub const SVL: u8 = 8;
    /// `μ = −(V + Λ)`, the end game's level.
    pub const MU: u8 = 9;
    /// `Λ − J`.
    pub const BG: u8 = 10;
    /// `E + Λ`.
    pub const EH: u8 = 11;
    /// `E + Λ + min(Λ − J, 0)`.
    pub const EG: u8 = 12;
    /// `V + Λ + D(−A)`.
    pub const EP: u8 = 13;
    /// The next level (before that, `μ − Λ`).
    pub const LEVEL: u8 = 14;
    /// The series sum's `N`, then its quotient shifted to the top.
    pub const N: u8 = 8;
    /// The division's partial remainder `r`.
    pub const R: u8 = 9;
    /// The dividend's low bits, shifted out as the quotient shifts in.
    pub const NQ: u8 = 10;
    /// `λ − 1 − r`.
    pub const M: u8 = 11;
    /// The product `n·M`.
    pub const P: u8 = 12;
    /// `D(Λ)` during Init.
    pub const DL: u8 = 13;
}

use reg::*;

/// Register names for listings (temporaries named by their use in Decide / in the sum).
pub const REG_NAMES: [&str; 16] = [
    "JL", "LO", "HD", "E", "T", "U", "VV", "L", "SVL|N", "MU|R", "BG|NQ", "EH|M", "EG|P", "EP|DL",
    "LEVEL", "-",
];

/// The microprogram and the entry point of each phase.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Microprogram {
    /// Instructions.
    pub code: Vec<Instr>,
    /// Where Prep starts.
    pub prep: usize,
    /// Where Init starts.
    pub init: usize,
    /// Where Decide starts (Init runs into it).
    pub decide: usize,
}

/// Clocks of each phase (the core model's timing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhaseClocks {
    /// Prep, its `HALT` included.
    pub prep: u32,
    /// Init up to Decide.
    pub init: u32,
    /// Decide, its `HALT` included.
    pub decide: u32,
}

impl Microprogram {
    /// Clocks from `start` to the first `HALT` (inclusive), loops unrolled.
    pub fn clocks_from(&self, start: usize, stop_before: Option<usize>) -> u32 {
        let mut pc = start;
        let mut clocks = 0;
        let mut loop_start = 0;
        let mut left = 0;
        loop {
            if Some(pc) == stop_before {
                return clocks;
            }
            let i = self.code[pc];
            clocks += i.clocks();
            match i {
                Instr::Halt => return clocks,
                Instr::Loop(n) => {
                    loop_start = pc + 1;
                    left = n;
                    pc += 1;
                }
                Instr::Op(op) => {
                    if op.end_loop && left > 1 {
                        left -= 1;
                        pc = loop_start;
                    } else {
                        pc += 1;
                    }
                }
            }
        }
    }

    /// Clocks of each phase.
    pub fn phase_clocks(&self) -> PhaseClocks {
        PhaseClocks {
            prep: self.clocks_from(self.prep, None),
            init: self.clocks_from(self.init, Some(self.decide)),
            decide: self.clocks_from(self.decide, None),
        }
    }
}

/// The microprogram (built once).
pub fn microprogram() -> &'static Microprogram {
    static PROGRAM: OnceLock<Microprogram> = OnceLock::new();
    PROGRAM.get_or_init(build)
}

/// The clocks of each phase of [`microprogram`].
pub fn phase_clocks() -> PhaseClocks {
    static CLOCKS: OnceLock<PhaseClocks> = OnceLock::new();
    *CLOCKS.get_or_init(|| microprogram().phase_clocks())
}

/// An instruction under construction.
#[derive(Clone, Copy)]
struct I(Op);

impl I {
    /// `dst = a` (then shifted and added to as the other methods say).
    fn new(dst: Option<u8>, a: ASrc) -> Self {
        I(Op {
            dst,
            a,
            a_mod: AMod::None,
            b: BMode::None,
            pred: Cond::True,
            flag: None,
            to_snap: false,
            end_loop: false,
            land: false,
        })
    }
    fn a_mod(mut self, m: AMod) -> Self {
        self.0.a_mod = m;
        self
    }
    fn b(mut self, b: BMode) -> Self {
        self.0.b = b;
        self
    }
    fn when(mut self, c: Cond) -> Self {
        self.0.pred = c;
        self
    }
    fn flag(mut self, f: Flag, src: FlagSrc, comb: Combine) -> Self {
        self.0.flag = Some((f, src, comb));
        self
    }
    fn set(self, f: Flag, src: FlagSrc) -> Self {
        self.flag(f, src, Combine::Set)
    }
    fn and(self, f: Flag, src: FlagSrc) -> Self {
        self.flag(f, src, Combine::And)
    }
    fn to_snap(mut self) -> Self {
        self.0.to_snap = true;
        self
    }
    fn end_loop(mut self) -> Self {
        self.0.end_loop = true;
        self
    }
    fn done(self) -> Instr {
        Instr::Op(self.0)
    }
}

fn r(x: u8) -> ASrc {
    ASrc::Reg(x)
}

/// `dst = D(lam)`: the series sum (module documentation). Uses T, N, R, NQ, M, P; sets the
/// flags Zero, V, Rs, C.
fn series_sum(code: &mut Vec<Instr>, lam: u8, dst: u8) {
    use FlagSrc::*;
    let count = SUM_COUNT_BITS;
    let c = |i: I| i.done();
    code.extend([
        // λ ≥ 0: D = 0.
        c(I::new(Some(T), r(lam)).set(Flag::Zero, NotSign)),
        // N = J − λ − 1.
        c(I::new(Some(N), r(JL)).b(BMode::SubOne(lam))),
        // n ≥ 2^48 ⇔ N >> 48 ≥ J: saturated.
        c(I::new(Some(T), r(N))
            .a_mod(AMod::WordRight)
            .b(BMode::Sub(JL))
            .set(Flag::V, NotSign)),
        // The remainder starts as N >> 48 (< J); the low 48 bits go to the top of NQ.
        c(I::new(Some(R), r(N))
            .a_mod(AMod::WordRight)
            .set(Flag::Rs, Sign)),
        c(I::new(Some(NQ), r(N)).a_mod(AMod::WordLeft2)),
        c(I::new(Some(NQ), r(NQ))
            .a_mod(AMod::Shl(Cond::False))
            .set(Flag::C, ShiftOut)),
        Instr::Loop(count),
        // Non-restoring: R = 2R + bit − J if R ≥ 0, else 2R + bit + J; q = (R ≥ 0).
        c(I::new(Some(R), r(R))
            .a_mod(AMod::Shl(Cond::Is(Flag::C)))
            .b(BMode::AddSub(JL, Cond::Is(Flag::Rs)))
            .set(Flag::Rs, Sign)),
        c(I::new(Some(NQ), r(NQ))
            .a_mod(AMod::Shl(Cond::Not(Flag::Rs)))
            .set(Flag::C, ShiftOut)
            .end_loop()),
        // The remainder r ≥ 0.
        c(I::new(Some(R), r(R))
            .b(BMode::Add(JL))
            .when(Cond::Is(Flag::Rs))),
        // M = λ − 1 − r.
        c(I::new(Some(M), r(lam)).b(BMode::SubOne(R))),
        // The quotient n (the low word of NQ) to the top word; P = 0.
        c(I::new(Some(N), r(NQ)).a_mod(AMod::WordLeft2)),
        c(I::new(Some(P), ASrc::Zero)),
        Instr::Loop(count),
        c(I::new(Some(N), r(N))
            .a_mod(AMod::Shl(Cond::False))
            .set(Flag::C, ShiftOut)),
        // P is tested before it doubles (it never decreases in magnitude, and it fits in 144
        // bits one step after it stops fitting in 128); the last P after the loop.
        c(I::new(Some(P), r(P))
            .a_mod(AMod::Shl(Cond::False))
            .b(BMode::AddIf(M, Cond::Is(Flag::C)))
            .flag(Flag::V, WideA, Combine::Or)
            .end_loop()),
        c(I::new(None, r(P)).flag(Flag::V, WideA, Combine::Or)),
        // D = n·M / 2 (n·M is even), D_FLOOR when saturated, 0 for λ ≥ 0.
        c(I::new(Some(dst), r(P)).a_mod(AMod::Shr)),
        c(I::new(Some(dst), ASrc::Floor).when(Cond::Is(Flag::V))),
        c(I::new(Some(dst), ASrc::Zero).when(Cond::Is(Flag::Zero))),
    ]);
}

/// `dst = ±src` by the stop's direction (negated when it is negative).
fn normalise(dst: u8, src: u8) -> I {
    I::new(Some(dst), ASrc::Zero).b(BMode::AddSub(src, Cond::Not(Flag::Dir)))
}

fn build() -> Microprogram {
    use FlagSrc::*;
    let mut code = Vec::new();
    let c = |i: I| i.done();

    // Prep: J, −A, D(−A).
    let prep = code.len();
    code.extend([
        c(I::new(Some(JL), ASrc::JerkLimit)),
        c(I::new(Some(T), ASrc::AccelLimit)),
        c(I::new(Some(LO), ASrc::Zero).b(BMode::Sub(T))),
    ]);
    series_sum(&mut code, LO, HD);
    code.push(Instr::Halt);

    // Init: direction, V, Λ, D(Λ), E, Over; the mode starts as Brake.
    let init = code.len();
    code.extend([
        c(I::new(Some(T), ASrc::A)),
        c(I::new(Some(VV), ASrc::V).b(BMode::Add(T))),
        c(I::new(None, r(VV)).set(Flag::Vz, ZeroA)),
        c(I::new(None, r(VV)).set(Flag::Vs, Sign)),
        c(I::new(Some(L), ASrc::J)
            .b(BMode::Add(T))
            .set(Flag::Ls, Sign)),
        c(I::new(None, ASrc::Zero).set(Flag::Dir, Test(Cond::When(Derived::DirNow)))),
        c(normalise(VV, VV).set(Flag::Brake, Test(Cond::True))),
        c(normalise(L, L).set(Flag::Hold, Test(Cond::False))),
    ]);
    series_sum(&mut code, L, DL);
    code.extend([
        c(I::new(Some(E), r(VV))
            .b(BMode::Add(DL))
            .set(Flag::Over, Sign)),
        // Exceeds (reported): Over, or Λ < −A, or Λ > A (T = A), gathered in Below (a
        // Decide temporary) and written by Init's last instruction, where the core model
        // takes it.
        c(I::new(None, r(E)).set(Flag::Below, Sign)),
        c(I::new(None, r(L))
            .b(BMode::Sub(LO))
            .flag(Flag::Below, Sign, Combine::Or)),
        c(I::new(Some(T), ASrc::Zero).b(BMode::Sub(LO))),
        c(I::new(None, r(T))
            .b(BMode::Sub(L))
            .flag(Flag::Below, Sign, Combine::Or)),
        c(I::new(None, ASrc::Zero).set(Flag::Exceeds, Test(Cond::Is(Flag::Below)))),
    ]);

    // Decide: at rest? then the law (StopLaw::level) and the snap.
    let decide = code.len();
    code.extend([
        c(I::new(None, ASrc::V).set(Flag::Rest, ZeroA)),
        c(I::new(None, ASrc::A).and(Flag::Rest, ZeroA)),
        c(I::new(Some(U), ASrc::J).and(Flag::Rest, ZeroA)),
        c(I::new(Some(T), ASrc::A)),
        c(I::new(Some(VV), ASrc::V).b(BMode::Add(T))),
        c(normalise(VV, VV)),
        c(I::new(Some(L), ASrc::J).b(BMode::Add(T))),
        c(normalise(L, L)),
        // End game: μ = −(V + Λ) with −J ≤ μ ≤ 0 and |μ − Λ| ≤ J.
        c(I::new(Some(SVL), r(VV))
            .b(BMode::Add(L))
            .set(Flag::End, NotSign)),
        // Zero: the release of an Over stop applies (μ < 0, i.e. V + Λ > 0; ANDed with Over
        // below).
        c(I::new(Some(MU), ASrc::Zero)
            .b(BMode::Sub(SVL))
            .set(Flag::Zero, Sign)),
        c(I::new(None, r(MU))
            .b(BMode::Add(JL))
            .and(Flag::End, NotSign)),
        c(I::new(Some(LEVEL), r(MU))
            .b(BMode::Sub(L))
            .and(Flag::Zero, Test(Cond::Is(Flag::Over)))),
        c(I::new(None, r(LEVEL))
            .b(BMode::Add(JL))
            .and(Flag::End, NotSign)),
        c(I::new(None, r(JL))
            .b(BMode::Sub(LEVEL))
            .and(Flag::End, NotSign)),
        // Where Λ is against −A, and braking a full step.
        c(I::new(None, r(L)).b(BMode::Sub(LO)).set(Flag::Below, Sign)),
        c(I::new(None, r(LO)).b(BMode::Sub(L)).set(Flag::Above, Sign)),
        c(I::new(Some(BG), r(L))
            .b(BMode::Sub(JL))
            .set(Flag::Bgn, Sign)),
        c(I::new(None, r(LO)).b(BMode::Sub(BG)).set(Flag::Bgt, Sign)),
        // The candidates for E.
        c(I::new(Some(EH), r(E))
            .b(BMode::Add(L))
            .set(Flag::EhOk, NotSign)),
        c(I::new(Some(EG), r(EH))
            .b(BMode::AddIf(BG, Cond::Is(Flag::Bgn)))
            .set(Flag::EgOk, NotSign)),
        c(I::new(Some(EP), r(SVL))
            .b(BMode::Add(HD))
            .set(Flag::EpOk, NotSign)),
        // The next level and E: step up by J unless a case below applies.
        c(I::new(Some(LEVEL), r(L)).b(BMode::Add(JL))),
        c(I::new(Some(LEVEL), r(L)).when(Cond::When(Derived::LevelHold))),
        c(I::new(Some(LEVEL), r(BG)).when(Cond::When(Derived::LevelGrid))),
        c(I::new(Some(LEVEL), r(LO)).when(Cond::When(Derived::LevelLimit))),
        c(I::new(Some(LEVEL), r(MU)).when(Cond::When(Derived::LevelEnd))),
        c(I::new(Some(E), r(EH)).when(Cond::When(Derived::ExcessHold))),
        c(I::new(Some(E), r(EG)).when(Cond::When(Derived::ExcessGrid))),
        c(I::new(Some(E), r(EP)).when(Cond::When(Derived::ExcessLimit))),
        // Over with V + Λ > 0 (Zero, free in Decide): release at once to level 0, E = V + Λ.
        c(I::new(Some(LEVEL), ASrc::Zero).when(Cond::Is(Flag::Zero))),
        c(I::new(Some(E), r(SVL)).when(Cond::Is(Flag::Zero))),
        // The snap dir·(level − Λ) − j, and the mode (NB first: NextHold reads Brake).
        c(I::new(Some(T), r(LEVEL))
            .b(BMode::Sub(L))
            .set(Flag::NextBrake, Test(Cond::When(Derived::NextBrake)))),
        c(normalise(T, T).set(Flag::Hold, Test(Cond::When(Derived::NextHold)))),
        c(I::new(Some(T), r(T))
            .b(BMode::Sub(U))
            .to_snap()
            .set(Flag::Brake, Test(Cond::Is(Flag::NextBrake)))),
        // After the release the law brakes within its limits (NextBrake has it): no longer Over.
        c(I::new(None, ASrc::Zero)
            .set(Flag::Over, Test(Cond::False))
            .when(Cond::Is(Flag::Zero))),
        Instr::Halt,
    ]);
    mark_lands(&mut code);
    let p = Microprogram {
        code,
        prep,
        init,
        decide,
    };
    check(&p);
    p
}

/// Marks each instruction whose flag write must land on a clock of its own ([`Op::land`]):
/// one that may be followed (the next instruction, or the loop's start after a body's last)
/// by an instruction that reads the flag it writes on its first clock.
fn mark_lands(code: &mut [Instr]) {
    let mut loop_start = 0;
    for pc in 0..code.len() {
        let next = |k: usize| code.get(k).copied().unwrap_or(Instr::Halt);
        match code[pc] {
            Instr::Loop(_) => loop_start = pc + 1,
            Instr::Op(op) => {
                if let Some((f, _, _)) = op.flag {
                    let land = next(pc + 1).reads_first(f)
                        || (op.end_loop && next(loop_start).reads_first(f));
                    code[pc] = Instr::Op(Op { land, ..op });
                }
            }
            Instr::Halt => {}
        }
    }
}

/// The program's own consistency: what the engine assumes of it.
fn check(p: &Microprogram) {
    let mut in_loop = false;
    for (pc, i) in p.code.iter().enumerate() {
        match i {
            Instr::Loop(n) => {
                assert!(!in_loop, "pc {pc}: nested loop");
                assert!((1..64).contains(n), "pc {pc}: loop count");
                in_loop = true;
            }
            Instr::Op(op) => {
                if op.end_loop {
                    assert!(in_loop, "pc {pc}: end_loop outside a loop");
                    in_loop = false;
                }
                // Reading words already written: a two-word left shift in place.
                if op.a_mod == AMod::WordLeft2 {
                    assert!(
                        op.dst.is_none() || op.a != ASrc::Reg(op.dst.unwrap_or(255)),
                        "pc {pc}: WordLeft2 in place"
                    );
                }
                // Operand A's tests see its last word only for a low-word-first operation.
                if let Some((_, FlagSrc::WideA, _)) = op.flag {
                    assert!(op.a_mod != AMod::Shr, "pc {pc}: WideA with Shr");
                }
                if op.a_mod == AMod::Shr {
                    assert!(op.b == BMode::None && op.flag.is_none(), "pc {pc}: Shr");
                }
            }
            Instr::Halt => assert!(!in_loop, "pc {pc}: HALT in a loop"),
        }
    }
    assert!(p.code.len() <= 128, "the program counter has 7 bits");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::{wrap, ChainState};
    use crate::format::DEFAULT_FORMAT;
    use crate::stop::micro::{Engine, EngineInputs, Step};
    use crate::stop::{play, release_drop, StopLimits};
    use proptest::prelude::*;

    /// Runs the engine from `pc` to its HALT: the clocks it took.
    fn run(e: &mut Engine, pc: usize, i: &EngineInputs) -> u32 {
        let prog = &microprogram().code;
        e.jump(pc);
        let mut n = 1;
        while e.clock(prog, i) == Step::Running {
            n += 1;
            assert!(n < 100_000, "runaway program");
        }
        n
    }

    fn inputs(s: &ChainState, l: &StopLimits) -> EngineInputs {
        EngineInputs {
            v: s.v,
            a: s.a,
            j: s.j,
            jerk_limit: l.jerk as u128,
            accel_limit: l.accel as u128,
        }
    }

    /// A whole stop on the engine (Prep, Init + Decide, then Decide before every tick), the
    /// chain stepped with its snaps: every tick's registers, and whether it began over.
    fn engine_stop(start: ChainState, l: StopLimits, max: usize) -> (Vec<ChainState>, bool) {
        let p = microprogram();
        let c = phase_clocks();
        let w = DEFAULT_FORMAT.widths;
        let mut e = Engine::default();
        let mut s = start;
        assert_eq!(run(&mut e, p.prep, &inputs(&s, &l)), c.prep);
        assert_eq!(run(&mut e, p.init, &inputs(&s, &l)), c.init + c.decide);
        let over = e.flags >> (Flag::Exceeds as u32) & 1 == 1;
        let mut out = Vec::new();
        while e.flags >> (Flag::Rest as u32) & 1 == 0 && out.len() < max {
            s = s.step(wrap(e.snap as i128, w.d), &w);
            out.push(s);
            assert_eq!(run(&mut e, p.decide, &inputs(&s, &l)), c.decide);
        }
        (out, over)
    }

    #[test]
    fn phases_are_short_enough_for_the_default_tick() {
        let c = phase_clocks();
        // 1250 clocks per tick at 125 MHz and Ts = 10 µs: no stopping tick ever waits.
        assert!(c.init + c.decide < 1250, "{c:?}");
        assert!(c.prep < 1250, "{c:?}");
    }

    #[test]
    fn the_series_sum_by_hand() {
        for (lo, j) in [
            (10i128, 3i128),
            (9, 3),
            (1, 3),
            (0, 3),
            (7, 7),
            (1 << 100, 1),
        ] {
            let l = StopLimits { jerk: j, accel: lo };
            let mut e = Engine::default();
            run(
                &mut e,
                microprogram().prep,
                &inputs(&ChainState::default(), &l),
            );
            assert_eq!(
                e.value(usize::from(HD)),
                release_drop(-lo, j),
                "A {lo} J {j}"
            );
        }
    }

    /// Limits a CONFIGURE can set: at most `Param::StopAccel.max()` (103 bits, the engine's
    /// limit inputs), as the executor refuses larger ones.
    fn limits() -> impl Strategy<Value = StopLimits> {
        let most = snapgen_spec::Param::StopAccel.max();
        (0u32..100, 0u32..100, 1i128..1000, 1i128..1000).prop_map(move |(jb, ab, jm, am)| {
            let jerk = (jm << jb.min(90)).max(1);
            let accel = (am << ab.min(100)).min(most).max(jerk);
            StopLimits { jerk, accel }
        })
    }

    /// A long jerk-limited stop from a high speed with the widest acceleration limit a
    /// CONFIGURE can set. (proptest once drew this state with an acceleration limit of 2^108,
    /// which the executor refuses and the engine's 103-bit inputs cannot hold: the test's
    /// strategy was at fault, not the engine.)
    #[test]
    fn the_engine_stops_as_the_law_at_the_widest_limits() {
        let l = StopLimits {
            jerk: 216_576,
            accel: snapgen_spec::Param::StopAccel.max(),
        };
        let s = ChainState {
            x: 0,
            v: -758_495_629_464_170_268,
            a: 0,
            j: 0,
        };
        let (want, law) = play(s, l, 3000);
        let (got, over) = engine_stop(s, l, 3000);
        assert_eq!(over, law.over_limits());
        assert_eq!(got, want);
    }

    proptest! {
        /// D(−A) on the engine equals the exact sum, saturation included.
        #[test]
        fn the_engines_series_sum_is_exact(
            jb in 0u32..103, ab in 0u32..104, jm in 1u128..1 << 20, am in 0u128..1 << 20,
        ) {
            let jerk = ((jm << jb) & ((1 << 103) - 1)).max(1) as i128;
            let accel = ((am << ab) & ((1 << 104) - 1)) as i128;
            let l = StopLimits { jerk, accel };
            let mut e = Engine::default();
            run(&mut e, microprogram().prep, &inputs(&ChainState::default(), &l));
            prop_assert_eq!(e.value(usize::from(HD)), release_drop(-accel, jerk));
        }

        /// From states within reach of the limits: the engine's stop is the law's, tick by
        /// tick.
        #[test]
        fn the_engine_stops_as_the_law(
            l in limits(),
            v in -(1i128 << 60)..(1 << 60), a in -(1i128 << 40)..(1 << 40),
            j in -(1i128 << 20)..(1 << 20), scale in 0u32..40,
        ) {
            let s = ChainState { x: 0, v: v << scale, a: a << (scale / 2), j: j << (scale / 3) };
            let (want, law) = play(s, l, 3000);
            let (got, over) = engine_stop(s, l, 3000);
            prop_assert_eq!(over, law.over_limits());
            prop_assert_eq!(got, want);
        }

        /// Small states and limits: every branch of the law, end games, beyond-limit starts.
        #[test]
        fn the_engine_stops_as_the_law_in_the_small(
            jerk in 1i128..20, extra in 0i128..50,
            v in -3000i128..3000, a in -200i128..200, j in -40i128..40,
        ) {
            let l = StopLimits { jerk, accel: jerk + extra };
            let s = ChainState { x: 0, v, a, j };
            let (want, law) = play(s, l, 5000);
            let (got, over) = engine_stop(s, l, 5000);
            prop_assert_eq!(over, law.over_limits());
            prop_assert_eq!(got, want);
        }
    }
}
