//! The position controller (model: `snapgen_model::io::servo`): PID on the following error
//! with velocity and acceleration feed-forward, integrator anti-windup, output saturation and
//! the following-error limit, computed serially in 27 clocks per sample without a wide
//! multiplier.
//!
//! # Datapath (one sample)
//!
//! ```text
//! sample clock  e48 = x[111:64] − {count, 16'h8000}, e = sat32(e48); vs = v[103:48];
//!               as = a[103:40] (the I/O top brings in these slices)
//! step 0        fault, peak; the first term's operand magnitude |e| and gain KP;
//!               sum = 2^47 (the rounding's half)
//! 5 terms × 5   the products of a gain digit (most significant first) and the operand's
//!               magnitude (four 16 × 16, registered: the DSP blocks' own register) on 3
//!               clocks, each added one clock later, acc = (acc << 16) + partial (carry-save:
//!               one carry chain); the next term's operand registered on the last of these;
//!               then sum ±= acc, the next operand's magnitude and gain. Term 0's first
//!               three clocks also update D and the integrator, read from term 1's operand
//!               on: Δ = e − e_prev, I + e, F >>> k; then I = clamp(I + e) unless held,
//!               F −= F >>> k; then F += Δ
//! finish        u = sum >>> 48; duty = clamp(u, ±OUTPUT_LIMIT); saturation flags
//! ```
//!
//! Every clock has at most one carry chain (an addition or a compare) after its registers —
//! the limits' negations are latched with the sample, |x| > L is tested as x > L or x < −L,
//! and the integrator's clamp decides with I + e, from I, e and L (three operands added
//! carry-save: I + e + ~L ≥ 0, I + e + L < 0), so that no compare follows the sum — so that the
//! I/O top closes routed timing (docs/HDL.md).
//!
//! Gains are not negative, so a term's sign is its operand's; products are of magnitudes and
//! exact (112 bits), the sum is exact (116 bits): the result is the model's integer law, to the
//! bit, `LATENCY` clocks after the sample. The gains and limits are latched with the sample: a
//! CONFIGURE while one computes applies from the next.
//!
//! rust-hdl 0.46 has only a 16 × 16 multiplier and no signed shifts, so this block writes its
//! own Verilog; its `update()` is the same register-level design in Rust (the digit-serial
//! multiplier, the magnitudes, the rounding), not the model: rust-hdl's simulator runs that
//! against the model's arithmetic law (`hdl/tests/servo.rs`), and Verilator runs the Verilog
//! against the model in the I/O top's co-simulations. (The products are registered because an
//! unregistered DSP multiply followed by the two additions was 8.5 ns of logic, more than a
//! 125 MHz clock allows.)

use rust_hdl::prelude::*;
use snapgen_model::io::servo::{
    ServoConfig, A_SHIFT, E_FRAC, GAIN_BITS, LATENCY, OUT_SHIFT, V_SHIFT,
};

use crate::sim_bits::to_u128;
use crate::template::{fill, Holes};

/// The controller's template.
const TEMPLATE: &str = include_str!("../verilog/servo.v");
use crate::{A_BITS, POSITION_BITS, V_BITS, X_BITS};

/// The slices of the chain's registers the controller reads: `ref_position = x[111:64]`,
/// `velocity = v[103:48]`, `accel = a[103:40]`.
pub const REFERENCE_LOW: usize = 64;
/// `velocity = v[103:VELOCITY_LOW]`.
pub const VELOCITY_LOW: usize = V_SHIFT as usize;
/// `accel = a[103:ACCEL_LOW]`.
pub const ACCEL_LOW: usize = A_SHIFT as usize;

/// Gain register width.
pub const GAIN_REG_BITS: usize = 48;
/// Terms of the law: e, I, D, v, a.
const TERMS: u32 = 5;
/// 16-bit digits of a gain.
const DIGITS: u32 = 3;

const _: () = {
    assert!(GAIN_BITS as usize <= GAIN_REG_BITS && GAIN_REG_BITS == 16 * DIGITS as usize);
    assert!(LATENCY == 1 + TERMS * (DIGITS + 2) + 1);
    assert!(X_BITS == 112 && V_BITS == 104 && A_BITS == 104);
    assert!(E_FRAC == 16 && V_SHIFT == 48 && A_SHIFT == 40 && OUT_SHIFT == 48);
    assert!(
        X_BITS - REFERENCE_LOW == 48 && V_BITS - VELOCITY_LOW == 56 && A_BITS - ACCEL_LOW == 64
    );
};

/// The controller's ports: its own, then the `servo` group of the parameters (from the
/// contract's list: one input per parameter, named as its register).
macro_rules! servo_block {
    (
        own {
            inputs { $( $(#[$im:meta])* $i:ident : $it:ty, )* }
            outputs { $( $(#[$om:meta])* $o:ident : $ot:ty, )* }
        }
        core { $($c:tt)* }
        io { $($io:tt)* }
        host { $($h:tt)* }
        servo { $( $var:ident = $code:literal, $name:literal, $reg:ident : $ty:ty, $bits:expr,
            $sign:ident, $reset:ident $(($rv:expr))?, $settable:ident, $meaning:literal; )* }
    ) => {
        /// The controller.
        #[derive(LogicBlock, Default)]
        pub struct Servo {
            /// Fabric clock.
            pub clock: Signal<In, Clock>,
            $( $(#[$im])* pub $i: Signal<In, $it>, )*
            $( #[doc = $name] pub $reg: Signal<In, Bits<{ ($bits) as usize }>>, )*
            $( $(#[$om])* pub $o: Signal<Out, $ot>, )*
            _rtl: Rtl,
        }

        impl Servo {
            /// The configuration on the ports.
            fn config(&self) -> ServoConfig {
                ServoConfig { $( $reg: self.$reg.val().to_u64() as $ty, )* }
            }
        }
    };
}

snapgen_spec::with_params!(servo_block! {
    own {
        inputs {
            /// Synchronous reset.
            reset: Bit,
            /// The amplifier is enabled (otherwise everything but the peak clears).
            enable: Bit,
            /// The core's tick enable.
            tick: Bit,
            /// A program starts: the peak error clears.
            start: Bit,
            /// The reference position: the position register's bits 111:64 (counts · 2^-16).
            ref_position: Bits<48>,
            /// The velocity register's bits 103:48 (counts/tick · 2^-32).
            velocity: Bits<56>,
            /// The acceleration register's bits 103:40 (counts/tick² · 2^-40).
            accel: Bits<64>,
            /// Encoder count.
            count: Bits<POSITION_BITS>,
        }
        outputs {
            /// Duty (two's complement, PWM clocks).
            duty: Bits<16>,
            /// Pulse: the following error is beyond its limit.
            fault: Bit,
            /// Pulse: a sample was skipped.
            overrun: Bit,
            /// Peak |following error| since START (counts · 2^-16).
            peak: Bits<32>,
        }
    }
});

/// The register-level design, in Rust (what the Verilog below is): every register, and the
/// same statements per clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Rtl {
    divider: u16,
    busy: bool,
    /// The first clock after a sample.
    step0: bool,
    /// The term (0 e, 1 I, 2 D, 3 vs, 4 as) and its clock (0..=2 a gain digit's products,
    /// 1..=3 the last products' addition, 4 the sum).
    term: u8,
    digit: u8,
    /// The registered products of the last digit.
    prods: [u64; 4],
    /// The last clock: round and saturate.
    fin: bool,
    e48: u64,
    vs: u64,
    as_: u64,
    /// The derivative filter's state `F` (48-bit); the operand is `F >> k`.
    f: u64,
    integral: u64,
    e_prev: u32,
    primed: bool,
    /// The sample's `e = sat32(e48)`, taken with it.
    e: u32,
    /// `Δ = e − e_prev` (33-bit).
    delta: u64,
    /// `F >> k`, the filter's leak.
    d_filt: u64,
    /// `I + e` (49-bit).
    i_sum: u64,
    /// The integrator holds.
    hold: bool,
    sat_hi: bool,
    sat_lo: bool,
    /// The next term's operand (64-bit two's complement), registered the clock before it starts.
    op: u64,
    mag: u64,
    neg: bool,
    gain: u64,
    acc: u128,
    sum: u128,
    /// The configuration latched at the sample (a CONFIGURE meanwhile waits for the next).
    gains: [u64; 5],
    integral_limit: u64,
    output_limit: u16,
    following_limit: u32,
    d_filter: u8,
    duty: u16,
    fault: bool,
    overrun: bool,
    peak: u32,
}

/// Sign-extends the low `bits` of `v` to i128.
fn sext(v: u128, bits: u32) -> i128 {
    ((v << (128 - bits)) as i128) >> (128 - bits)
}

/// The low `bits` of `v`.
fn low(v: i128, bits: u32) -> u128 {
    (v as u128) & (u128::MAX >> (128 - bits))
}

/// The configuration and operands of one clock, as the Verilog sees its ports.
struct Ports {
    reset: bool,
    enable: bool,
    tick: bool,
    start: bool,
    ref_position: u64,
    velocity: u64,
    accel: u64,
    count: u32,
    config: ServoConfig,
}

impl Rtl {
    /// Operand `t` (I, D, vs, as, and as again after the last term, as the Verilog's
    /// multiplexer; e is term 0's, taken on step 0).
    fn operand(&self, t: u32) -> i128 {
        match t {
            1 => sext(u128::from(self.integral), 48),
            2 => sext(u128::from(self.f), 48) >> self.d_filter,
            3 => sext(u128::from(self.vs), 56),
            _ => sext(u128::from(self.as_), 64),
        }
    }

    fn clock(&mut self, p: &Ports) {
        let mut n = *self;
        n.fault = false;
        n.overrun = false;
        if p.reset || p.start {
            n.peak = 0;
        }
        if p.reset || !p.enable {
            n = Rtl {
                peak: n.peak,
                ..Rtl::default()
            };
            *self = n;
            return;
        }
        let c = &p.config;
        let due = p.tick && c.servo_period != 0 && self.divider == 0;
        if p.tick && c.servo_period != 0 {
            n.divider = if self.divider == 0 {
                c.servo_period - 1
            } else {
                self.divider - 1
            };
        }
        if due && self.busy {
            n.overrun = true;
        } else if due {
            // The sample: the error and the feed-forward operands.
            let centre = (u64::from(p.count) << E_FRAC) | (1 << (E_FRAC - 1));
            n.e48 = p.ref_position.wrapping_sub(centre) & ((1 << 48) - 1);
            n.e = low(
                sext(u128::from(n.e48), 48).clamp(-(1 << 31), (1 << 31) - 1),
                32,
            ) as u32;
            n.vs = p.velocity;
            n.as_ = p.accel;
            n.gains = [c.kp, c.ki, c.kd, c.kv, c.ka].map(|g| g as u64);
            n.integral_limit = c.integral_limit as u64;
            n.output_limit = c.output_limit;
            n.following_limit = c.following_limit;
            n.d_filter = c.d_filter;
            n.busy = true;
            n.step0 = true;
        }
        if self.busy {
            if self.step0 {
                // The following check, the peak, e and term 0's operand; D and the
                // integrator on term 0's first clocks, below.
                let e48 = sext(u128::from(self.e48), 48);
                n.fault = e48.unsigned_abs() > u128::from(self.following_limit) << E_FRAC;
                let e = sext(u128::from(self.e), 32);
                if !p.start {
                    n.peak = self.peak.max(e.unsigned_abs() as u32);
                }
                // Rounding to nearest: the sum starts at a half.
                n.sum = 1 << (OUT_SHIFT - 1);
                n.acc = 0;
                n.mag = e.unsigned_abs() as u64;
                n.neg = e < 0;
                n.gain = self.gains[0];
                n.step0 = false;
                n.term = 0;
                n.digit = 0;
            } else if !self.fin {
                let (k, t) = (u32::from(self.digit), u32::from(self.term));
                let e = sext(u128::from(self.e), 32);
                let f = sext(u128::from(self.f), 48);
                match (t, k) {
                    // Δ, I + e, F >> k and whether the integrator holds.
                    (0, 0) => {
                        let e_prev = sext(u128::from(self.e_prev), 32);
                        n.delta = low(if self.primed { e - e_prev } else { 0 }, 33) as u64;
                        n.e_prev = self.e;
                        n.primed = true;
                        n.i_sum = low(sext(u128::from(self.integral), 48) + e, 49) as u64;
                        n.hold = (self.sat_hi && e > 0) || (self.sat_lo && e < 0);
                        n.d_filt = low(f >> self.d_filter, 48) as u64;
                    }
                    // I = clamp(I + e) unless held; F −= F >> k.
                    (0, 1) => {
                        if !self.hold {
                            let lim = i128::from(self.integral_limit);
                            let i_sum = sext(u128::from(self.i_sum), 49);
                            n.integral = low(i_sum.clamp(-lim, lim), 48) as u64;
                        }
                        n.f = low(f - sext(u128::from(self.d_filt), 48), 48) as u64;
                    }
                    // F += Δ.
                    (0, 2) => n.f = low(f + sext(u128::from(self.delta), 33), 48) as u64,
                    _ => {}
                }
                if k <= DIGITS {
                    // The last digit's registered products into the accumulator (from clock 1).
                    if k >= 1 {
                        let p = &self.prods;
                        let lo = u128::from(p[0]) | (u128::from(p[2]) << 32);
                        let hi = (u128::from(p[1]) << 16) | (u128::from(p[3]) << 48);
                        n.acc = ((self.acc << 16) + lo + hi) & ((1 << 112) - 1);
                    }
                    // This digit's products (gain digit, most significant first: the gain
                    // register's top digit, shifted up a digit per product clock).
                    if k < DIGITS {
                        let g = (self.gain >> (16 * (DIGITS - 1))) & 0xffff;
                        let m = |j: u32| (self.mag >> (16 * j)) & 0xffff;
                        n.prods = [g * m(0), g * m(1), g * m(2), g * m(3)];
                        n.gain = (self.gain << 16) & ((1 << (16 * DIGITS)) - 1);
                    }
                    // The next term's operand, a clock before it starts.
                    if k == DIGITS {
                        n.op = low(self.operand(t + 1), 64) as u64;
                    }
                    n.digit = self.digit + 1;
                } else {
                    // The term into the sum; the next term's operand and gain.
                    let mask = (1u128 << 116) - 1;
                    n.sum = if self.neg {
                        self.sum.wrapping_sub(self.acc)
                    } else {
                        self.sum.wrapping_add(self.acc)
                    } & mask;
                    n.acc = 0;
                    n.digit = 0;
                    if t + 1 < TERMS {
                        let op = sext(u128::from(self.op), 64);
                        n.mag = op.unsigned_abs() as u64;
                        n.neg = op < 0;
                        n.gain = self.gains[t as usize + 1];
                        n.term = self.term + 1;
                    } else {
                        n.fin = true;
                    }
                }
            } else {
                // Finish: round, saturate.
                let u = sext(self.sum, 116) >> OUT_SHIFT;
                let lim = i128::from(self.output_limit);
                n.sat_hi = u > lim;
                n.sat_lo = u < -lim;
                n.duty = low(u.clamp(-lim, lim), 16) as u16;
                n.busy = false;
                n.fin = false;
            }
        }
        *self = n;
    }
}

impl Logic for Servo {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let p = Ports {
                reset: self.reset.val(),
                enable: self.enable.val(),
                tick: self.tick.val(),
                start: self.start.val(),
                ref_position: self.ref_position.val().to_u64(),
                velocity: self.velocity.val().to_u64(),
                accel: to_u128(self.accel.val()) as u64,
                count: self.count.val().to_u64() as u32,
                config: self.config(),
            };
            self._rtl.clock(&p);
        }
        let r = &self._rtl;
        self.duty.next = u64::from(r.duty).into();
        self.fault.next = r.fault;
        self.overrun.next = r.overrun;
        self.peak.next = u64::from(r.peak).into();
    }

    fn connect(&mut self) {
        self.duty.connect();
        self.fault.connect();
        self.overrun.connect();
        self.peak.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(servo_verilog())
    }
}

/// The controller's Verilog body.
pub fn servo_verilog() -> String {
    let holes = Holes::new()
        .value("E_FRAC", E_FRAC)
        .value("V_SHIFT", V_SHIFT)
        .value("A_SHIFT", A_SHIFT)
        .value("HALF", OUT_SHIFT - 1)
        .value("OUT_SHIFT", OUT_SHIFT)
        .value("LATENCY", LATENCY)
        .value("LAST_DIGIT", DIGITS - 1)
        .value("DIGITS", DIGITS)
        .value("SUM_CLOCK", DIGITS + 1)
        .value("LAST_TERM", TERMS - 1);
    let body = fill("servo.v", TEMPLATE, &holes).expect("the controller's template is filled");
    crate::protocol_v::with_localparams(&crate::protocol_v::localparams(), &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn servo_is_synthesizable() {
        crate::synth_check::synth_block("servo", Servo::default());
    }
}
