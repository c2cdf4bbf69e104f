//! The path interpolator clock by clock: the rule of [`super::interp`] as the fabric computes
//! it (`hdl/verilog/interpolator.v`, block `snapgen_interpolator`), register for register.
//!
//! One shared datapath serves every axis, so an added axis costs two small memory words and a
//! few dozen clocks rather than a multiplier:
//!
//! * a **serial multiplier**: `a · b` for a signed [`X_BITS`]-bit `a` and a signed `n`-bit `b`
//!   (`n` = [`SHARE_BITS`] for a share, a growth, a sine or a cosine; [`RATE_BITS`] for an
//!   arc's rate), one radix-4 Booth digit of `b` (`−2…2`, from the lowest) per two clocks into
//!   a right-shifting accumulator `hi:lo`: the exact product, so `>>` rounds toward −∞ exactly
//!   as [`super::interp`]'s 256-bit `mul_shift`;
//! * the **CORDIC** of [`super::cordic`], one step per two clocks.
//!
//! For routed timing (docs/PATH.md) the wide sums take two clocks: the accumulator's
//! [`T_BITS`]-bit sum is added low half then high half (the carry between them registered), as
//! is each product's use (`base + product`); a CORDIC step shifts on one clock and adds (65
//! bits) on the next; the angle's 64-bit sum is the widest left in one clock.
//!
//! A computation starts on `start` (while idle) with `offset`, the distance `r` into the
//! loaded segment, and writes each axis once (`out_write`, `out_axis`, `out_value`), `done`
//! with the last write:
//!
//! * **line**: for each axis `k`, `from_k + ((r · share_k) >> 62)`:
//!   [`SHARE_BITS`]` + 2` clocks per axis after the one that takes `start`;
//! * **arc**: the angle `start ± ((r · rate) >> 120)` ([`RATE_BITS`]` + 2` clocks), the CORDIC
//!   (1 + 2·[`ITERATIONS`] + 1 clocks: set up, steps, quadrant), the radius
//!   `radius + ((r · growth) >> 62)`, the plane's axes `centre + ((ρ · cos) >> 62)` and
//!   `centre + ((ρ · sin) >> 62)`, then the other axes as on a line (each
//!   [`SHARE_BITS`]` + 2` clocks). [`clocks`] counts them.
//!
//! Every register wraps to its fabric width. For a segment whose values fit their ports
//! ([`load_inputs`] checks) and an offset within the segment (or a cell beyond it), the
//! results equal [`Segment::at`] (tested), which is the rule the host plans with.

use snapgen_spec::widths::{
    AXIS_BITS, MAX_AXES, RATE_BITS, RATE_FRAC, SHARE_BITS, SHARE_FRAC, TURN_BITS, X_BITS,
};

use super::cordic::{constants, ITERATIONS};
use super::interp::{Segment, Shape};
use crate::chain::wrap;
use crate::ports::{InterpInputs, InterpOutputs};

/// Width of the multiplier's high accumulator (`a` and its sign).
pub const HI_BITS: u32 = X_BITS + 1;
/// Width of the multiplier's low accumulator and of its `b` operand register.
pub const LO_BITS: u32 = RATE_BITS;
/// Width of the CORDIC's `x`, `y` and `z` (a share and its sign: `|x|, |y| < 2^63` and
/// `|z| ≤ 2^62` on every step, tested).
pub const CORDIC_BITS: u32 = SHARE_BITS + 1;
/// Width of the multiplier's digit counter.
pub const COUNT_BITS: u32 = 7;
/// Width of the accumulator's sum `hi + d·a` (`|hi| < |a|`, `|d| ≤ 2`).
pub const T_BITS: u32 = HI_BITS + 2;
/// Where a wide sum is split: bits below it are added on one clock, the rest (with the
/// registered carry) on the next.
pub const SPLIT: u32 = 57;

const _: () = {
    assert!(LO_BITS >= SHARE_BITS && RATE_BITS <= 1 << COUNT_BITS);
    assert!(SHARE_FRAC <= SHARE_BITS && RATE_FRAC <= RATE_BITS && TURN_BITS == 64);
    assert!(HI_BITS + LO_BITS <= 256 && X_BITS < 127 && T_BITS < 127);
    assert!(SPLIT < X_BITS && T_BITS - SPLIT <= SPLIT + 1 && SHARE_BITS % 2 == 0);
    assert!(MAX_AXES == 1 << AXIS_BITS);
};

/// The state register (`state` in the fabric).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum State {
    /// Waiting for `start`.
    #[default]
    Idle = 0,
    /// A product, one digit of `b` per two clocks (`phase` 0: the low half of the sum; 1: the
    /// high half, and the shift).
    Multiply = 1,
    /// The product is used (`phase` 0: the low half of `base + product`; 1: the high half, a
    /// write, the angle or the radius, and the next product begins).
    Finish = 2,
    /// The CORDIC's start: the quadrant taken off the angle.
    CordicInit = 3,
    /// A CORDIC step (`phase` 0: the shifts; 1: the additions).
    Cordic = 4,
    /// The quadrant put back: the cosine and the sine.
    Rotate = 5,
}

/// What a product is for (`job` in the fabric).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Job {
    /// `r · rate`: the angle turned.
    #[default]
    Angle = 0,
    /// `r · growth`: the radius's change.
    Radius = 1,
    /// `ρ · cos` or `ρ · sin` (`half`): a plane axis.
    Plane = 2,
    /// `r · share_k`: axis `k`.
    Axis = 3,
}

/// The loaded segment (the fabric's shape registers and axis memories).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Loaded {
    /// An arc (else a line).
    pub arc: bool,
    /// Counter-clockwise.
    pub ccw: bool,
    /// The plane's axes.
    pub plane: [u8; 2],
    /// The centre in the plane.
    pub centre: [i128; 2],
    /// The radius at the start.
    pub radius: i128,
    /// The radius's change per raw unit (62 fraction bits).
    pub growth: i128,
    /// The angle at the start.
    pub start_angle: u64,
    /// The angular rate (120 fraction bits).
    pub rate: i128,
    /// Each axis at the start.
    pub from: [i128; MAX_AXES as usize],
    /// Each axis's share of the length.
    pub share: [i128; MAX_AXES as usize],
}

/// The interpolator's registers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Engine {
    /// Axes of the design (1 to [`MAX_AXES`], fixed at generation).
    axes: u8,
    /// The loaded segment.
    pub seg: Loaded,
    /// State.
    pub state: State,
    /// What the product being formed is for.
    pub job: Job,
    /// The plane axis of a [`Job::Plane`] product (0: first, cosine; 1: second, sine).
    pub half: bool,
    /// The axis of a [`Job::Axis`] product.
    pub k: u8,
    /// The half of a two-clock step (see [`State`]).
    pub phase: bool,
    /// Multiplier: digits of `b` left minus one.
    pub count: u8,
    /// Multiplier: the bit of `b` below the next digit (Booth's overlap).
    pub prev: bool,
    /// The low [`SPLIT`] bits of a sum added on the last clock.
    pub low: u128,
    /// The carry out of them.
    pub carry: bool,
    /// CORDIC: `y >> step`, `x >> step` (and the fabric's `atan(step)`, the same on both
    /// clocks of a step), from the last clock.
    pub shifted: (i128, i128),
    /// What the product will be added to (the radius, a plane axis's centre, an axis's start),
    /// taken on every clock of a product (a memory read and a choice that take a clock of their
    /// own).
    pub base: i128,
    /// The axis of the product after this one (bit 3: there is one), and its share, taken on
    /// every clock of a product likewise (the choice of the axis and the memory read).
    pub next: u8,
    /// See [`Engine::next`].
    pub next_share: i128,
    /// Multiplier: the signed operand.
    pub a: i128,
    /// Multiplier: the bits of `b` not yet used (lowest next).
    pub b: u128,
    /// Multiplier: the high accumulator (signed).
    pub hi: i128,
    /// Multiplier: the low accumulator (product bits shifted in from the top).
    pub lo: u128,
    /// The offset of the computation.
    pub r: i128,
    /// The arc's radius at `r`.
    pub rho: i128,
    /// The arc's angle at `r`.
    pub theta: u64,
    /// The angle's quadrant.
    pub quadrant: u8,
    /// CORDIC `x`.
    pub x: i128,
    /// CORDIC `y`.
    pub y: i128,
    /// CORDIC `z`.
    pub z: i128,
    /// CORDIC step.
    pub step: u8,
    /// The cosine at `r` (62 fraction bits).
    pub cos: i128,
    /// The sine at `r`.
    pub sin: i128,
    /// The outputs after the last clock.
    out: InterpOutputs,
}

/// Why a segment cannot be loaded into the interpolator (a segment that loads is computed
/// exactly as [`Segment::at`] at every offset from a cell before its start to a cell past its
/// end: no register on the way wraps).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LoadError {
    /// The segment names more axes than the design has.
    #[error("the segment has {got} axes; the interpolator was generated for {axes}: generate it for more axes")]
    Axes {
        /// Axes of the segment.
        got: usize,
        /// Axes of the design.
        axes: u8,
    },
    /// A value does not fit its port.
    #[error("the segment's {what} ({value}) does not fit the interpolator's {bits}-bit port: split the element or use a coarser position format")]
    Width {
        /// Which value.
        what: &'static str,
        /// The value.
        value: i128,
        /// The port's width.
        bits: u32,
    },
    /// An arc's plane names an axis the design does not have, or the same axis twice.
    #[error("the arc's plane ({first}, {second}) is not two different axes of {axes}")]
    Plane {
        /// The plane's first axis.
        first: usize,
        /// The plane's second axis.
        second: usize,
        /// Axes of the design.
        axes: u8,
    },
}

fn fits(what: &'static str, value: i128, bits: u32, signed: bool) -> Result<i128, LoadError> {
    let ok = if signed {
        wrap(value, bits) == value
    } else {
        value >= 0 && (bits >= 127 || value >> bits == 0)
    };
    if ok {
        Ok(value)
    } else {
        Err(LoadError::Width { what, value, bits })
    }
}

/// The largest magnitude of `base + ((r · slope) >> 62)` over `r` from `−cell` to `r_end` (a
/// line in `r`: at one of the two ends), saturating.
fn reach(base: i128, slope: i128, r_end: i128) -> i128 {
    let at = |r: i128| {
        let v = ethnum::I256::from(base)
            + ((ethnum::I256::from(r) * ethnum::I256::from(slope)) >> SHARE_FRAC);
        let m = v.unsigned_abs();
        if m > ethnum::U256::from(i128::MAX as u128) {
            i128::MAX
        } else {
            m.as_i128()
        }
    };
    at(-(1i128 << crate::FRAC_BITS)).max(at(r_end))
}

/// The clocks' inputs that load `segment` into an interpolator of `axes` axes: the shape, then
/// one axis per clock (every other input at rest). Refuses a value that would not fit its port.
pub fn load_inputs(segment: &Segment, axes: u8) -> Result<Vec<InterpInputs>, LoadError> {
    let n = usize::from(axes);
    let (from, share) = match &segment.shape {
        Shape::Line { from, dir } | Shape::Arc { from, dir, .. } => (from, dir),
    };
    if from.len() > n || share.len() != from.len() {
        return Err(LoadError::Axes {
            got: from.len(),
            axes,
        });
    }
    // The offsets the segment is computed at: a cell before its start to a cell past its end;
    // every value on the way must fit its register for the fabric to follow the rule.
    let r_max = segment
        .length
        .abs()
        .saturating_add(1i128 << crate::FRAC_BITS);
    fits("length", r_max, X_BITS, true)?;
    for (k, (&x, &d)) in from.iter().zip(share).enumerate() {
        let plane_axis = matches!(&segment.shape, Shape::Arc { plane, .. } if plane.contains(&k));
        if !plane_axis {
            fits("axis's reach", reach(x, d, r_max), X_BITS, true)?;
        }
    }
    let mut shape = InterpInputs {
        load_shape: true,
        ..Default::default()
    };
    if let Shape::Arc {
        plane,
        centre,
        radius,
        growth,
        start,
        rate,
        ccw,
        ..
    } = &segment.shape
    {
        if plane[0] >= from.len() || plane[1] >= from.len() || plane[0] == plane[1] {
            return Err(LoadError::Plane {
                first: plane[0],
                second: plane[1],
                axes,
            });
        }
        shape.arc = true;
        shape.ccw = *ccw;
        shape.plane_first = plane[0] as u8;
        shape.plane_second = plane[1] as u8;
        shape.centre_first = fits("centre", centre[0], X_BITS, true)?;
        shape.centre_second = fits("centre", centre[1], X_BITS, true)?;
        shape.radius = fits("radius", *radius, X_BITS, true)?;
        shape.growth = fits("radius growth", *growth, SHARE_BITS, true)?;
        shape.start_angle = start.0;
        shape.rate = fits("angular rate", *rate, RATE_BITS - 1, false)?;
        // The radius, and the plane's axes (within the radius of the centre), over the reach.
        let rho = reach(*radius, *growth, r_max);
        fits("radius over the segment", rho, X_BITS, true)?;
        for c in centre {
            fits(
                "arc's reach",
                c.saturating_abs().saturating_add(rho),
                X_BITS,
                true,
            )?;
        }
    }
    let mut out = vec![shape];
    for k in 0..n {
        out.push(InterpInputs {
            load_axis: true,
            axis: k as u8,
            from: fits("start", from.get(k).copied().unwrap_or(0), X_BITS, true)?,
            share: fits(
                "share",
                share.get(k).copied().unwrap_or(0),
                SHARE_BITS,
                true,
            )?,
            ..Default::default()
        });
    }
    Ok(out)
}

/// Clocks from the one that takes `start` to the one that raises `done`, both included, for a
/// segment of this kind.
pub fn clocks(arc: bool, axes: u8) -> u64 {
    let product = u64::from(SHARE_BITS) + 2;
    if arc {
        let others = u64::from(axes.saturating_sub(2));
        1 + (u64::from(RATE_BITS) + 2) + 1 + 2 * ITERATIONS as u64 + 1 + product * (3 + others)
    } else {
        1 + product * u64::from(axes)
    }
}

impl Engine {
    /// An interpolator of `axes` axes (1 to [`MAX_AXES`]) at power-up: idle, nothing loaded.
    pub fn new(axes: u8) -> Self {
        assert!(
            (1..=MAX_AXES as u8).contains(&axes),
            "1 to {MAX_AXES} axes, not {axes}"
        );
        Engine {
            axes,
            ..Default::default()
        }
    }

    /// The outputs after the last clock.
    pub fn outputs(&self) -> InterpOutputs {
        self.out
    }

    /// One clock edge with inputs `i`.
    pub fn clock(&mut self, i: &InterpInputs) {
        let old = self.clone();
        self.out.out_write = false;
        self.out.done = false;
        if i.load_shape {
            let s = &mut self.seg;
            s.arc = i.arc;
            s.ccw = i.ccw;
            s.plane = [i.plane_first & 7, i.plane_second & 7];
            s.centre = [wrap(i.centre_first, X_BITS), wrap(i.centre_second, X_BITS)];
            s.radius = wrap(i.radius, X_BITS);
            s.growth = wrap(i.growth, SHARE_BITS);
            s.start_angle = i.start_angle;
            s.rate = wrap(i.rate, RATE_BITS);
        }
        if i.load_axis && (i.axis & 7) < self.axes {
            let k = usize::from(i.axis & 7);
            self.seg.from[k] = wrap(i.from, X_BITS);
            self.seg.share[k] = wrap(i.share, SHARE_BITS);
        }
        if i.reset {
            self.state = State::Idle;
        } else {
            self.advance(&old, i);
        }
        self.out.busy = self.state != State::Idle;
    }

    /// The state machine (registers read from `old`, as a clock edge does).
    fn advance(&mut self, old: &Engine, i: &InterpInputs) {
        match old.state {
            State::Idle => {
                if i.start {
                    let r = wrap(i.offset, X_BITS);
                    self.r = r;
                    if old.seg.arc {
                        self.multiply(r, old.seg.rate as u128, RATE_BITS, Job::Angle);
                    } else {
                        // A line moves every axis: the first is axis 0.
                        self.k = 0;
                        self.multiply(r, share_bits(old.seg.share[0]), SHARE_BITS, Job::Axis);
                    }
                }
            }
            State::Multiply => {
                let first = if old.job == Job::Axis { old.k + 1 } else { 0 };
                let plane = old.seg.plane;
                self.next = (first..self.axes)
                    .find(|&k| !(old.seg.arc && (k == plane[0] || k == plane[1])))
                    .map_or(0, |k| 8 | k);
                self.next_share = old.seg.share[usize::from(old.next & 7)];
                self.base = match old.job {
                    Job::Radius => old.seg.radius,
                    Job::Plane => old.seg.centre[usize::from(old.half)],
                    Job::Angle | Job::Axis => old.seg.from[usize::from(old.k)],
                };
                // Booth's digit d = −2·b₁ + b₀ + prev: its magnitude's multiple of a, and
                // whether it subtracts (then ~multiple + 1).
                let (b0, b1) = (old.b & 1 == 1, old.b & 2 == 2);
                let neg = b1 && !(b0 && old.prev);
                let two = (b1 && !b0 && !old.prev) || (!b1 && b0 && old.prev);
                let zero = b0 == b1 && b1 == old.prev;
                let multiple = if zero {
                    0
                } else if two {
                    old.a << 1
                } else {
                    old.a
                };
                let addend = wrap(if neg { !multiple } else { multiple }, T_BITS);
                let hi = wrap(old.hi, T_BITS);
                let mask = (1i128 << SPLIT) - 1;
                if !old.phase {
                    let sum = (hi & mask) + (addend & mask) + i128::from(neg);
                    self.low = (sum & mask) as u128;
                    self.carry = sum >> SPLIT == 1;
                    self.phase = true;
                } else {
                    let high = (hi >> SPLIT) + (addend >> SPLIT) + i128::from(old.carry);
                    let t = wrap((high << SPLIT) | old.low as i128, T_BITS);
                    self.hi = wrap(t >> 2, HI_BITS);
                    self.lo = (old.lo >> 2) | (((t & 3) as u128) << (LO_BITS - 2));
                    self.b = old.b >> 2;
                    self.prev = b1;
                    self.phase = false;
                    if old.count == 0 {
                        self.state = State::Finish;
                    } else {
                        self.count = old.count - 1;
                    }
                }
            }
            State::Finish => self.finish(old),
            State::CordicInit => {
                let q = (old.theta.wrapping_add(1 << 61) >> 62) & 3;
                self.quadrant = q as u8;
                self.z = i128::from(old.theta.wrapping_sub(q << 62) as i64);
                self.x = constants().gain;
                self.y = 0;
                self.step = 0;
                self.state = State::Cordic;
            }
            State::Cordic => {
                let n = usize::from(old.step);
                if !old.phase {
                    self.shifted = (old.y >> n, old.x >> n);
                    self.phase = true;
                } else {
                    let (dx, dy) = old.shifted;
                    let atan = constants().atan[n];
                    let (x, y, z) = if old.z >= 0 {
                        (old.x - dx, old.y + dy, old.z - atan)
                    } else {
                        (old.x + dx, old.y - dy, old.z + atan)
                    };
                    self.x = wrap(x, CORDIC_BITS);
                    self.y = wrap(y, CORDIC_BITS);
                    self.z = wrap(z, CORDIC_BITS);
                    self.step = old.step.wrapping_add(1) & 0x3f;
                    self.phase = false;
                    if n == ITERATIONS - 1 {
                        self.state = State::Rotate;
                    }
                }
            }
            State::Rotate => {
                let (c, s) = match old.quadrant {
                    0 => (old.x, old.y),
                    1 => (-old.y, old.x),
                    2 => (-old.x, -old.y),
                    _ => (old.y, -old.x),
                };
                self.cos = wrap(c, SHARE_BITS);
                self.sin = wrap(s, SHARE_BITS);
                self.multiply(old.r, share_bits(old.seg.growth), SHARE_BITS, Job::Radius);
            }
        }
    }

    /// A product's use, and the next step.
    fn finish(&mut self, old: &Engine) {
        // The product shifted right by 62 (a share's product), low bits, and what it is added
        // to (taken while the product was formed).
        let p62 = wrap(
            (old.hi << (SHARE_BITS - SHARE_FRAC))
                | (old.lo >> (LO_BITS - SHARE_BITS + SHARE_FRAC)) as i128,
            X_BITS,
        );
        let base = old.base;
        let mask = (1i128 << SPLIT) - 1;
        if !old.phase {
            let sum = (base & mask) + (p62 & mask);
            self.low = (sum & mask) as u128;
            self.carry = sum >> SPLIT == 1;
            self.phase = true;
            return;
        }
        self.phase = false;
        let sum = wrap(
            (((base >> SPLIT) + (p62 >> SPLIT) + i128::from(old.carry)) << SPLIT) | old.low as i128,
            X_BITS,
        );
        match old.job {
            Job::Angle => {
                let turned =
                    ((old.hi << (RATE_BITS - RATE_FRAC)) as u128 | (old.lo >> RATE_FRAC)) as u64;
                self.theta = if old.seg.ccw {
                    old.seg.start_angle.wrapping_add(turned)
                } else {
                    old.seg.start_angle.wrapping_sub(turned)
                };
                self.state = State::CordicInit;
            }
            Job::Radius => {
                self.rho = sum;
                self.half = false;
                self.multiply(sum, share_bits(old.cos), SHARE_BITS, Job::Plane);
            }
            Job::Plane => {
                self.write(old.seg.plane[usize::from(old.half)], sum);
                if old.half {
                    self.next_product(old);
                } else {
                    self.half = true;
                    self.multiply(old.rho, share_bits(old.sin), SHARE_BITS, Job::Plane);
                }
            }
            Job::Axis => {
                let k = old.k;
                self.write(k, sum);
                self.next_product(old);
            }
        }
    }

    /// Presents axis `k`'s position on the next clock.
    fn write(&mut self, k: u8, value: i128) {
        self.out.out_write = true;
        self.out.out_axis = k;
        self.out.out_value = value;
    }

    /// The product `r · share_k` for the next axis that moves as on a line (all on a line; the
    /// plane's two excepted on an arc), chosen while the last product was formed, or the end
    /// of the computation.
    fn next_product(&mut self, old: &Engine) {
        if old.next & 8 != 0 {
            self.k = old.next & 7;
            self.multiply(old.r, share_bits(old.next_share), SHARE_BITS, Job::Axis);
        } else {
            self.state = State::Idle;
            self.out.done = true;
        }
    }

    /// Begins the product `a · b`, `b` of `n` bits (`n / 2` digits).
    fn multiply(&mut self, a: i128, b: u128, n: u32, job: Job) {
        self.a = a;
        self.b = b;
        self.prev = false;
        self.phase = false;
        self.hi = 0;
        self.lo = 0;
        self.count = (n / 2 - 1) as u8;
        self.job = job;
        self.state = State::Multiply;
    }
}

/// A share-width value's bits as the `b` register holds them (zero above).
fn share_bits(v: i128) -> u128 {
    u128::from(v as u64)
}

#[cfg(test)]
mod tests {
    use super::super::cordic::{Turn, ONE_BITS};
    use super::super::interp::RATE_SHIFT;
    use super::*;
    use rand::{Rng, SeedableRng};

    const ONE: i128 = 1 << ONE_BITS;

    /// Loads `g`, starts at `r` and clocks until done: the writes and the clocks taken.
    fn run(g: &Segment, axes: u8, r: i128) -> (Vec<i128>, u64) {
        let mut e = Engine::new(axes);
        for i in load_inputs(g, axes).expect("fits") {
            e.clock(&i);
        }
        let mut got = vec![None; usize::from(axes)];
        e.clock(&InterpInputs {
            start: true,
            offset: r,
            ..Default::default()
        });
        let mut clocks = 1;
        while !e.outputs().done {
            assert!(e.outputs().busy, "busy until done");
            e.clock(&InterpInputs::default());
            clocks += 1;
            let o = e.outputs();
            if o.out_write {
                let slot = &mut got[usize::from(o.out_axis)];
                assert!(slot.is_none(), "axis {} written twice", o.out_axis);
                *slot = Some(o.out_value);
            }
            assert!(clocks < 10_000, "never done");
        }
        assert!(!e.outputs().busy, "idle when done");
        (
            got.into_iter().map(|v| v.expect("every axis")).collect(),
            clocks,
        )
    }

    /// A random segment of `axes` axes on a grid of up to 2^29 output LSBs, as the host makes
    /// them (raw = LSB · 2^80), and a random offset within it or a cell beyond.
    fn random_segment(rng: &mut impl Rng, axes: u8) -> (Segment, i128) {
        let raw = |lsb: i128| lsb << crate::FRAC_BITS;
        let n = usize::from(axes);
        let length = raw(rng.gen_range(1..1 << 30)) + rng.gen_range(0..1 << 40);
        let from: Vec<i128> = (0..n)
            .map(|_| raw(rng.gen_range(-(1 << 30)..1 << 30)))
            .collect();
        let dir: Vec<i128> = (0..n).map(|_| rng.gen_range(-ONE..=ONE)).collect();
        let cell = raw(1);
        let r = rng.gen_range(-cell..=length + cell);
        let shape = if n >= 2 && rng.gen_bool(0.5) {
            let first = rng.gen_range(0..n);
            let second = (first + rng.gen_range(1..n)) % n;
            let mut dir = dir;
            dir[first] = 0;
            dir[second] = 0;
            let radius = raw(rng.gen_range(1..1 << 29));
            // Up to two turns over the length.
            let turns = rng.gen_range(0..(2i128 << 64));
            Shape::Arc {
                plane: [first, second],
                centre: [
                    raw(rng.gen_range(-(1 << 29)..1 << 29)),
                    raw(rng.gen_range(-(1 << 29)..1 << 29)),
                ],
                radius,
                growth: rng.gen_range(-(ONE >> 20)..=ONE >> 20),
                start: Turn(rng.gen()),
                rate: ((ethnum::I256::from(turns) << RATE_SHIFT) / ethnum::I256::from(length))
                    .as_i128(),
                ccw: rng.gen(),
                from,
                dir,
            }
        } else {
            Shape::Line { from, dir }
        };
        (Segment { length, shape }, r)
    }

    #[test]
    fn the_clocked_rule_is_the_rule() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(22);
        for case in 0..400 {
            let axes = rng.gen_range(1..=MAX_AXES as u8);
            let (g, r) = random_segment(&mut rng, axes);
            let (got, took) = run(&g, axes, r);
            assert_eq!(got, g.at(r), "case {case}: {g:?} at {r}");
            let arc = matches!(g.shape, Shape::Arc { .. });
            assert_eq!(took, clocks(arc, axes), "case {case}");
        }
    }

    #[test]
    fn a_line_of_one_axis_takes_67_clocks_and_an_arc_of_four_587() {
        assert_eq!(clocks(false, 1), 67);
        assert_eq!(clocks(true, 4), 587);
        assert_eq!(clocks(true, 8), 851);
    }

    #[test]
    fn the_cordic_registers_stay_within_their_width() {
        // Every step's x, y within ±2^63 and z within ±2^62 (the 65-bit registers never wrap).
        let c = constants();
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for _ in 0..5000 {
            let theta: u64 = rng.gen();
            let q = (theta.wrapping_add(1 << 61) >> 62) & 3;
            let (mut x, mut y, mut z) = (
                c.gain,
                0i128,
                i128::from(theta.wrapping_sub(q << 62) as i64),
            );
            for (n, &a) in c.atan.iter().enumerate() {
                let (dx, dy) = (y >> n, x >> n);
                (x, y, z) = if z >= 0 {
                    (x - dx, y + dy, z - a)
                } else {
                    (x + dx, y - dy, z + a)
                };
                assert!(x.abs() < 1 << 63 && y.abs() < 1 << 63 && z.abs() <= 1 << 62);
            }
        }
    }

    #[test]
    fn a_start_while_busy_is_ignored_and_loads_are_taken_at_once() {
        let g = Segment {
            length: 1 << 90,
            shape: Shape::Line {
                from: vec![5, 7],
                dir: vec![ONE, -ONE / 2],
            },
        };
        let mut e = Engine::new(2);
        for i in load_inputs(&g, 2).unwrap() {
            e.clock(&i);
        }
        let start = |offset| InterpInputs {
            start: true,
            offset,
            ..Default::default()
        };
        e.clock(&start(1000));
        e.clock(&start(5000));
        assert_eq!(e.r, 1000, "the second start is ignored");
        let mut writes = Vec::new();
        while !e.outputs().done {
            e.clock(&InterpInputs::default());
            if e.outputs().out_write {
                writes.push(e.outputs().out_value);
            }
        }
        assert_eq!(writes, vec![1005, 7 - 500]);
        // Reset goes idle at once.
        e.clock(&start(1000));
        e.clock(&InterpInputs {
            reset: true,
            ..Default::default()
        });
        assert!(!e.outputs().busy);
    }

    #[test]
    fn values_that_do_not_fit_are_refused() {
        let g = Segment {
            length: 1,
            shape: Shape::Line {
                from: vec![1 << 120],
                dir: vec![ONE],
            },
        };
        assert!(matches!(load_inputs(&g, 1), Err(LoadError::Width { .. })));
        assert!(matches!(
            load_inputs(&g, 0),
            Err(LoadError::Axes { got: 1, axes: 0 })
        ));
        // Two axes near ±2^31 LSB apart: a length of about 2^112 raw does not fit the offset.
        let far = Segment {
            length: 1 << 112,
            shape: Shape::Line {
                from: vec![0],
                dir: vec![ONE],
            },
        };
        assert!(matches!(
            load_inputs(&far, 1),
            Err(LoadError::Width { what: "length", .. })
        ));
        // A start near the top that the line carries past it.
        let over = Segment {
            length: 1 << 100,
            shape: Shape::Line {
                from: vec![(1 << 111) - (1 << 98)],
                dir: vec![ONE],
            },
        };
        assert!(matches!(
            load_inputs(&over, 1),
            Err(LoadError::Width {
                what: "axis's reach",
                ..
            })
        ));
    }
}
