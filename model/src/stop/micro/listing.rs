//! The microprogram as assembly: a listing to read and debug it by.

use super::*;

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
