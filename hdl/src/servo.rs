//! The position controller (model: `snapgen_model::io::servo`): PID on the following error
//! with velocity and acceleration feed-forward, integrator anti-windup, output saturation and
//! the following-error limit, computed serially in 27 clocks per sample without a wide
//! multiplier.
//!
//! # Datapath (one sample)
//!
//! ```text
//! sample clock  e48 = x[111:64] − {count, 16'h8000}; vs = v[103:48]; as = a[103:40] (the I/O top
//!               brings in these slices)
//! step 0        fault, peak, e = sat32(e48), F += Δ − (F >>> k) with Δ = e − e_prev,
//!               I = clamp(I + e) unless held (the derivative operand is F >>> k);
//!               the first term's operand magnitude |e| and gain KP
//! 5 terms × 5   the products of a gain digit (most significant first) and the operand's
//!               magnitude (four 16 × 16, registered: the DSP blocks' own register) on 3
//!               clocks, each added one clock later, acc = (acc << 16) + partial; then
//!               sum ±= acc, the next operand and gain
//! finish        u = (sum + 2^47) >>> 48; duty = clamp(u, ±OUTPUT_LIMIT); saturation flags
//! ```
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
use snapgen_model::io::servo::{A_SHIFT, E_FRAC, GAIN_BITS, LATENCY, OUT_SHIFT, V_SHIFT};

use crate::sim_bits::to_u128;
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

/// The controller.
#[derive(LogicBlock, Default)]
pub struct Servo {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// The amplifier is enabled (otherwise everything but the peak clears).
    pub enable: Signal<In, Bit>,
    /// The core's tick enable.
    pub tick: Signal<In, Bit>,
    /// A program starts: the peak error clears.
    pub start: Signal<In, Bit>,
    /// The reference position: the position register's bits 111:64 (counts · 2^-16).
    pub ref_position: Signal<In, Bits<48>>,
    /// The velocity register's bits 103:48 (counts/tick · 2^-32).
    pub velocity: Signal<In, Bits<56>>,
    /// The acceleration register's bits 103:40 (counts/tick² · 2^-40).
    pub accel: Signal<In, Bits<64>>,
    /// Encoder count.
    pub count: Signal<In, Bits<POSITION_BITS>>,
    /// SERVO_PERIOD (ticks per sample; 0: off).
    pub period: Signal<In, Bits<16>>,
    /// KP.
    pub kp: Signal<In, Bits<GAIN_REG_BITS>>,
    /// KI.
    pub ki: Signal<In, Bits<GAIN_REG_BITS>>,
    /// KD.
    pub kd: Signal<In, Bits<GAIN_REG_BITS>>,
    /// KV.
    pub kv: Signal<In, Bits<GAIN_REG_BITS>>,
    /// KA.
    pub ka: Signal<In, Bits<GAIN_REG_BITS>>,
    /// INTEGRAL_LIMIT.
    pub integral_limit: Signal<In, Bits<GAIN_REG_BITS>>,
    /// OUTPUT_LIMIT.
    pub output_limit: Signal<In, Bits<16>>,
    /// FOLLOWING_LIMIT (counts).
    pub following_limit: Signal<In, Bits<32>>,
    /// D_FILTER (the derivative filter's shift).
    pub d_filter: Signal<In, Bits<4>>,
    /// Duty (two's complement, PWM clocks).
    pub duty: Signal<Out, Bits<16>>,
    /// Pulse: the following error is beyond its limit.
    pub fault: Signal<Out, Bit>,
    /// Pulse: a sample was skipped.
    pub overrun: Signal<Out, Bit>,
    /// Peak |following error| since START (counts · 2^-16).
    pub peak: Signal<Out, Bits<32>>,
    _rtl: Rtl,
}

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
    sat_hi: bool,
    sat_lo: bool,
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
    period: u16,
    gains: [u64; 5],
    integral_limit: u64,
    output_limit: u16,
    following_limit: u32,
    d_filter: u8,
}

impl Rtl {
    /// Operand `t` (e, I, D, vs, as) as its 64-bit magnitude and sign.
    fn operand(&self, t: u32, e: i128, integral: u64, d: u64) -> (u64, bool) {
        let value: i128 = match t {
            0 => e,
            1 => sext(u128::from(integral), 48),
            2 => sext(u128::from(d), 48) >> self.d_filter,
            3 => sext(u128::from(self.vs), 56),
            _ => sext(u128::from(self.as_), 64),
        };
        (value.unsigned_abs() as u64, value < 0)
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
        let due = p.tick && p.period != 0 && self.divider == 0;
        if p.tick && p.period != 0 {
            n.divider = if self.divider == 0 {
                p.period - 1
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
            n.vs = p.velocity;
            n.as_ = p.accel;
            n.gains = p.gains;
            n.integral_limit = p.integral_limit;
            n.output_limit = p.output_limit;
            n.following_limit = p.following_limit;
            n.d_filter = p.d_filter;
            n.busy = true;
            n.step0 = true;
        }
        if self.busy {
            if self.step0 {
                let e48 = sext(u128::from(self.e48), 48);
                n.fault = e48.unsigned_abs() > u128::from(self.following_limit) << E_FRAC;
                let e = e48.clamp(-(1 << 31), (1 << 31) - 1);
                if !p.start {
                    n.peak = self.peak.max(e.unsigned_abs() as u32);
                }
                let e_prev = sext(u128::from(self.e_prev), 32);
                let delta = if self.primed { e - e_prev } else { 0 };
                let f = sext(u128::from(self.f), 48);
                n.f = low(f + delta - (f >> self.d_filter), 48) as u64;
                let hold = (self.sat_hi && e > 0) || (self.sat_lo && e < 0);
                let mut integral = sext(u128::from(self.integral), 48);
                if !hold {
                    let lim = i128::from(self.integral_limit);
                    integral = (integral + e).clamp(-lim, lim);
                }
                n.integral = low(integral, 48) as u64;
                n.e_prev = low(e, 32) as u32;
                n.primed = true;
                n.sum = 0;
                n.acc = 0;
                let (mag, neg) = self.operand(0, e, n.integral, n.f);
                n.mag = mag;
                n.neg = neg;
                n.gain = self.gains[0];
                n.step0 = false;
                n.term = 0;
                n.digit = 0;
            } else if !self.fin {
                let (k, t) = (u32::from(self.digit), u32::from(self.term));
                if k <= DIGITS {
                    // The last digit's registered products into the accumulator (from clock 1).
                    if k >= 1 {
                        let p = &self.prods;
                        let lo = u128::from(p[0]) | (u128::from(p[2]) << 32);
                        let hi = (u128::from(p[1]) << 16) | (u128::from(p[3]) << 48);
                        n.acc = ((self.acc << 16) + lo + hi) & ((1 << 112) - 1);
                    }
                    // This digit's products (gain digit, most significant first).
                    if k < DIGITS {
                        let g = (self.gain >> (16 * (DIGITS - 1 - k))) & 0xffff;
                        let m = |j: u32| (self.mag >> (16 * j)) & 0xffff;
                        n.prods = [g * m(0), g * m(1), g * m(2), g * m(3)];
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
                        let (mag, neg) = self.operand(t + 1, 0, self.integral, self.f);
                        n.mag = mag;
                        n.neg = neg;
                        n.gain = self.gains[t as usize + 1];
                        n.term = self.term + 1;
                    } else {
                        n.fin = true;
                    }
                }
            } else {
                // Finish: round, saturate.
                let sum = sext(self.sum, 116);
                let u = (sum + (1 << (OUT_SHIFT - 1))) >> OUT_SHIFT;
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
            let g = |s: &Signal<In, Bits<GAIN_REG_BITS>>| s.val().to_u64();
            let p = Ports {
                reset: self.reset.val(),
                enable: self.enable.val(),
                tick: self.tick.val(),
                start: self.start.val(),
                ref_position: self.ref_position.val().to_u64(),
                velocity: self.velocity.val().to_u64(),
                accel: to_u128(self.accel.val()) as u64,
                count: self.count.val().to_u64() as u32,
                period: self.period.val().to_u64() as u16,
                gains: [
                    g(&self.kp),
                    g(&self.ki),
                    g(&self.kd),
                    g(&self.kv),
                    g(&self.ka),
                ],
                integral_limit: g(&self.integral_limit),
                output_limit: self.output_limit.val().to_u64() as u16,
                following_limit: self.following_limit.val().to_u64() as u32,
                d_filter: self.d_filter.val().to_u64() as u8,
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
    format!(
        r#"
// Fixed point (snapgen_model::io::servo): e in counts * 2^-{e_frac}, vs = v >>> {v_shift},
// as = a >>> {a_shift}, u = (sum + 2^{half}) >>> {out_shift}; {latency} clocks from sample to duty.
reg [15:0] divider = 16'd0;          // ticks to the next sample
reg busy = 1'b0;
reg step0 = 1'b0;                    // the first clock after a sample
reg [2:0] term = 3'd0;               // 0 e, 1 I, 2 D, 3 vs, 4 as
reg [2:0] digit = 3'd0;              // 0..{last_digit}: a gain digit's products; 1..{digits}: their
                                     // addition a clock later; {sum_clock}: into the sum
reg fin = 1'b0;                      // the last clock: round and saturate
reg [47:0] e48_q = 48'd0;            // the sample's following error
reg [55:0] vs_q = 56'd0;             // v[103:48]
reg [63:0] as_q = 64'd0;             // a[103:40]
reg [47:0] f_q = 48'd0;              // the derivative filter's state F (the operand: F >>> k)
reg [47:0] i_q = 48'd0;              // the integrator
reg [31:0] eprev_q = 32'd0;
reg primed = 1'b0;                   // a sample since the amplifier came on
reg sat_hi = 1'b0, sat_lo = 1'b0;    // the last output was clamped
reg [63:0] mag_q = 64'd0;            // the term's operand: magnitude, sign
reg neg_q = 1'b0;
reg [47:0] gain_q = 48'd0;           // the term's gain
reg [111:0] acc_q = 112'd0;          // gain * |operand|, digit by digit
reg [31:0] p0 = 32'd0, p1 = 32'd0, p2 = 32'd0, p3 = 32'd0;   // a digit's products, registered
/* verilator lint_off UNUSEDSIGNAL */ // the fraction below bit 47 is what the rounding drops
reg [115:0] sum_q = 116'd0;          // the terms so far (two's complement)
/* verilator lint_on UNUSEDSIGNAL */
// The configuration latched at the sample (a CONFIGURE meanwhile waits for the next sample).
reg [47:0] kp_q = 48'd0, ki_q = 48'd0, kd_q = 48'd0, kv_q = 48'd0, ka_q = 48'd0;
reg [47:0] ilim_q = 48'd0;
reg [15:0] olim_q = 16'd0;
reg [31:0] flim_q = 32'd0;
reg [3:0] dfk_q = 4'd0;
reg [15:0] duty_q = 16'd0;
reg fault_q = 1'b0, overrun_q = 1'b0;
reg [31:0] peak_q = 32'd0;

// The sample's error.
wire due = tick && (period != 16'd0) && (divider == 16'd0);
wire [47:0] e48_now = ref_position - {{count, 16'h8000}};   // count n: the centre of cell n

// Step 0: saturation, following check, D and the integrator.
wire e_sat_hi = !e48_q[47] && (e48_q[46:31] != 16'd0);
wire e_sat_lo = e48_q[47] && (e48_q[46:31] != 16'hffff);
wire [31:0] e_sat = e_sat_hi ? 32'h7fff_ffff : (e_sat_lo ? 32'h8000_0000 : e48_q[31:0]);
wire [47:0] e48_abs = e48_q[47] ? (~e48_q + 48'd1) : e48_q;       // |-2^47| = 2^47 fits
wire fault_now = e48_abs > {{flim_q, 16'd0}};
wire [31:0] e_abs = e_sat[31] ? (~e_sat + 32'd1) : e_sat;          // 2^31 fits
wire [32:0] delta = primed ? ({{e_sat[31], e_sat}} - {{eprev_q[31], eprev_q}}) : 33'd0;
wire [47:0] d_filt = $signed(f_q) >>> dfk_q;                       // F >>> k
wire [47:0] f_next = f_q + {{{{15{{delta[32]}}}}, delta}} - d_filt; // F + Δ − (F >>> k)
wire hold = (sat_hi && !e_sat[31] && (e_sat != 32'd0)) || (sat_lo && e_sat[31]);
wire [48:0] i_sum = {{i_q[47], i_q}} + {{{{17{{e_sat[31]}}}}, e_sat}};
wire [48:0] i_lim = {{1'b0, ilim_q}};
wire [48:0] i_neg_lim = ~i_lim + 49'd1;
wire i_over = !i_sum[48] && (i_sum > i_lim);
wire i_under = i_sum[48] && ($signed(i_sum) < $signed(i_neg_lim));
wire [47:0] i_next = hold ? i_q : (i_over ? i_lim[47:0] : (i_under ? i_neg_lim[47:0] : i_sum[47:0]));

// The next term's operand (sign-extended to 64 bits) and gain: term 0 on step 0, else term + 1.
wire [2:0] next_term = step0 ? 3'd0 : term + 3'd1;
reg [63:0] op;
reg [47:0] next_gain;
always @(*) begin
   case (next_term)
   3'd0: begin op = {{{{32{{e_sat[31]}}}}, e_sat}}; next_gain = kp_q; end
   3'd1: begin op = {{{{16{{i_q[47]}}}}, i_q}}; next_gain = ki_q; end
   3'd2: begin op = {{{{16{{d_filt[47]}}}}, d_filt}}; next_gain = kd_q; end   // F updated on step 0
   3'd3: begin op = {{{{8{{vs_q[55]}}}}, vs_q}}; next_gain = kv_q; end
   default: begin op = as_q; next_gain = ka_q; end
   endcase
end
wire [63:0] op_mag = op[63] ? (~op + 64'd1) : op;                   // |-2^63| = 2^63 fits

// One gain digit (most significant first) times the magnitude: four 16 x 16 products,
// registered; added to the accumulator on the next clock.
wire [15:0] g = (digit == 3'd0) ? gain_q[47:32] : ((digit == 3'd1) ? gain_q[31:16] : gain_q[15:0]);
wire [79:0] partial = {{16'd0, p2, p0}} + {{p3, p1, 16'd0}};
wire [111:0] acc_next = {{acc_q[95:0], 16'd0}} + {{32'd0, partial}};

// Finish: round to nearest (halves up): (sum + 2^47) >>> 48 = sum[115:48] + sum[47]; saturate.
wire [67:0] u = sum_q[115:48] + {{67'd0, sum_q[47]}};
wire [67:0] lim = {{52'd0, olim_q}};
wire [67:0] neg_lim = ~lim + 68'd1;
wire u_hi = $signed(u) > $signed(lim);
wire u_lo = $signed(u) < $signed(neg_lim);

always @(posedge clock) begin
   fault_q <= 1'b0;
   overrun_q <= 1'b0;
   if (reset || start) peak_q <= 32'd0;
   if (reset || !enable) begin
      divider <= 16'd0;
      busy <= 1'b0;
      step0 <= 1'b0;
      term <= 3'd0;
      digit <= 3'd0;
      fin <= 1'b0;
      p0 <= 32'd0;
      p1 <= 32'd0;
      p2 <= 32'd0;
      p3 <= 32'd0;
      e48_q <= 48'd0;
      vs_q <= 56'd0;
      as_q <= 64'd0;
      f_q <= 48'd0;
      i_q <= 48'd0;
      eprev_q <= 32'd0;
      primed <= 1'b0;
      sat_hi <= 1'b0;
      sat_lo <= 1'b0;
      mag_q <= 64'd0;
      neg_q <= 1'b0;
      gain_q <= 48'd0;
      acc_q <= 112'd0;
      sum_q <= 116'd0;
      duty_q <= 16'd0;
   end else begin
      if (tick && (period != 16'd0)) divider <= (divider == 16'd0) ? period - 16'd1 : divider - 16'd1;
      if (due && busy) overrun_q <= 1'b1;
      else if (due) begin
         e48_q <= e48_now;
         vs_q <= velocity;
         as_q <= accel;
         kp_q <= kp;
         ki_q <= ki;
         kd_q <= kd;
         kv_q <= kv;
         ka_q <= ka;
         ilim_q <= integral_limit;
         olim_q <= output_limit;
         flim_q <= following_limit;
         dfk_q <= d_filter;
         busy <= 1'b1;
         step0 <= 1'b1;
      end
      if (busy) begin
         if (step0) begin
            fault_q <= fault_now;
            if (!start && (e_abs > peak_q)) peak_q <= e_abs;
            f_q <= f_next;
            i_q <= i_next;
            eprev_q <= e_sat;
            primed <= 1'b1;
            sum_q <= 116'd0;
            acc_q <= 112'd0;
            mag_q <= op_mag;
            neg_q <= op[63];
            gain_q <= next_gain;
            step0 <= 1'b0;
            term <= 3'd0;
            digit <= 3'd0;
         end else if (!fin) begin
            if (digit != 3'd{sum_clock}) begin
               if (digit != 3'd0) acc_q <= acc_next;
               if (digit < 3'd{digits}) begin
                  p0 <= g * mag_q[15:0];
                  p1 <= g * mag_q[31:16];
                  p2 <= g * mag_q[47:32];
                  p3 <= g * mag_q[63:48];
               end
               digit <= digit + 3'd1;
            end else begin
               sum_q <= neg_q ? sum_q - {{4'd0, acc_q}} : sum_q + {{4'd0, acc_q}};
               acc_q <= 112'd0;
               digit <= 3'd0;
               if (term != 3'd{last_term}) begin
                  mag_q <= op_mag;
                  neg_q <= op[63];
                  gain_q <= next_gain;
                  term <= term + 3'd1;
               end else fin <= 1'b1;
            end
         end else begin
            sat_hi <= u_hi;
            sat_lo <= u_lo;
            duty_q <= u_hi ? olim_q : (u_lo ? neg_lim[15:0] : u[15:0]);
            busy <= 1'b0;
            fin <= 1'b0;
         end
      end
   end
end

always @(*) begin
   duty = duty_q;
   fault = fault_q;
   overrun = overrun_q;
   peak = peak_q;
end
"#,
        e_frac = E_FRAC,
        v_shift = V_SHIFT,
        a_shift = A_SHIFT,
        half = OUT_SHIFT - 1,
        out_shift = OUT_SHIFT,
        latency = LATENCY,
        last_digit = DIGITS - 1,
        digits = DIGITS,
        sum_clock = DIGITS + 1,
        last_term = TERMS - 1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn servo_is_synthesizable() {
        crate::synth_check::synth_block("servo", Servo::default());
    }
}
