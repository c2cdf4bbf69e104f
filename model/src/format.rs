//! The fixed-point format: the single source of truth for every register width, the number of
//! fractional bits below the output position LSB, the tick period `Ts` and the physical size of
//! one output position LSB. The HDL generator reads the same type.
//!
//! # Shared-LSB chain
//! All four accumulators (jerk, acceleration, velocity, position) and the snap input share one
//! internal LSB `L = position_lsb · 2^-FRAC_BITS` *per power of the tick*: a raw snap value `d`
//! means `d · L / Ts⁴`, a raw jerk `j · L / Ts³`, acceleration `a · L / Ts²`, velocity `v · L / Ts`
//! and position `x · L`. With that scaling, seed 000 eqs 72–75 (`j_k = Ts·d_{k-1} + j_{k-1}`, …)
//! become pure integer additions, `j += d; a += j; v += a; x += v`, with no multiplier and no
//! rounding anywhere in the chain.
//!
//! # Output position
//! The fabric outputs `x >> FRAC_BITS` (arithmetic shift, i.e. rounding toward −∞): the number
//! of whole output LSBs. A position at rest sits at the *centre* of its output cell
//! (`x = cell · 2^F + 2^(F-1)`), so that a residual below half an output LSB never changes the
//! output.

use fixed::types::extra::U80;
use fixed::FixedI128;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;

/// Number of fractional bits of the position register below the output LSB.
///
/// Fixed at compile time so that the typed position, [`PositionFix`], can state its layout
/// (the fabric's, `snapgen_spec::widths::FRAC_BITS`).
pub const FRAC_BITS: u32 = snapgen_spec::widths::FRAC_BITS;

const _: () = assert!(FRAC_BITS == 80, "PositionFix's layout (U80) states it");

/// A position in output LSBs with [`FRAC_BITS`] fractional bits: the typed view of the raw
/// position register (`to_bits`/`from_bits` give the register's integer).
pub type PositionFix = FixedI128<U80>;

/// Widths in bits of the chain's registers (all signed two's complement).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Widths {
    /// Position accumulator.
    pub x: u32,
    /// Velocity accumulator.
    pub v: u32,
    /// Acceleration accumulator.
    pub a: u32,
    /// Jerk accumulator.
    pub j: u32,
    /// Snap input (the value a program segment holds).
    pub d: u32,
}

impl Widths {
    /// The fabric's widths (`snapgen_spec::widths`).
    pub const FABRIC: Widths = Widths {
        x: snapgen_spec::widths::X_BITS,
        v: snapgen_spec::widths::V_BITS,
        a: snapgen_spec::widths::A_BITS,
        j: snapgen_spec::widths::J_BITS,
        d: snapgen_spec::widths::D_BITS,
    };

    /// The widths in chain order `[x, v, a, j, d]`.
    pub fn as_array(&self) -> [u32; 5] {
        [self.x, self.v, self.a, self.j, self.d]
    }
}

/// The fixed-point format of the motion core and of its programs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Format {
    /// Tick (sampling) period `Ts` in seconds.
    pub ts: f64,
    /// Physical size of one output position LSB, in user units (m, rad, …).
    pub position_lsb: f64,
    /// Register widths.
    pub widths: Widths,
    /// Width of a segment's tick count (and of the fabric's segment tick counter).
    pub tick_bits: u32,
    /// Largest number of segments a program may hold (the fabric's program memory depth).
    pub max_segments: usize,
}

/// The default format: `Ts` = 10 µs (125 MHz / 1250), output LSB = 1e-6 unit, and the
/// fabric's widths (`snapgen_spec::widths`: 80 fractional bits, position 112 bits,
/// velocity/acceleration/jerk/snap 104 bits, 32-bit segment tick counts, 32 segments per
/// program).
pub const DEFAULT_FORMAT: Format = Format {
    ts: 1e-5,
    position_lsb: 1e-6,
    widths: Widths::FABRIC,
    tick_bits: snapgen_spec::widths::TICK_BITS,
    max_segments: snapgen_spec::widths::MAX_SEGMENTS as usize,
};

impl Default for Format {
    fn default() -> Self {
        DEFAULT_FORMAT
    }
}

/// The physical quantity a raw register value stands for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Quantity {
    /// Position (units).
    #[default]
    Position,
    /// Velocity (units/s).
    Velocity,
    /// Acceleration (units/s²).
    Acceleration,
    /// Jerk (units/s³).
    Jerk,
    /// Snap (units/s⁴).
    Snap,
}

impl Quantity {
    /// Power of `Ts` in this quantity's scale.
    fn ts_power(self) -> i32 {
        match self {
            Quantity::Position => 0,
            Quantity::Velocity => 1,
            Quantity::Acceleration => 2,
            Quantity::Jerk => 3,
            Quantity::Snap => 4,
        }
    }

    /// Name used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Position => "position",
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
            Quantity::Snap => "snap",
        }
    }

    /// Physical unit suffix used in messages and reports.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Position => "unit",
            Quantity::Velocity => "unit/s",
            Quantity::Acceleration => "unit/s^2",
            Quantity::Jerk => "unit/s^3",
            Quantity::Snap => "unit/s^4",
        }
    }
}

/// Range and resolution of one register in physical units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegisterRange {
    /// What the register holds.
    pub quantity: Quantity,
    /// Its width.
    pub bits: u32,
    /// Physical value of one raw LSB.
    pub lsb: f64,
    /// Largest physical magnitude it holds.
    pub max: f64,
}

impl Format {
    /// The default format with another tick period.
    pub fn with_ts(ts: f64) -> Self {
        Format {
            ts,
            ..DEFAULT_FORMAT
        }
    }

    /// Checks that the format is usable; every planner calls this first.
    pub fn validate(&self) -> Result<(), FormatError> {
        if !(self.ts.is_finite() && self.ts > 0.0) {
            return Err(FormatError::Ts(self.ts));
        }
        if !(self.position_lsb.is_finite() && self.position_lsb > 0.0) {
            return Err(FormatError::PositionLsb(self.position_lsb));
        }
        for (name, w) in ["x", "v", "a", "j", "d"].iter().zip(self.widths.as_array()) {
            if !(8..=127).contains(&w) {
                return Err(FormatError::Width {
                    register: name,
                    bits: w,
                });
            }
        }
        if self.widths.x <= FRAC_BITS + 1 {
            return Err(FormatError::PositionWidth {
                bits: self.widths.x,
                frac: FRAC_BITS,
            });
        }
        if !(1..=32).contains(&self.tick_bits) {
            return Err(FormatError::TickBits(self.tick_bits));
        }
        if self.max_segments == 0 {
            return Err(FormatError::MaxSegments);
        }
        // Every scale Ts^n / L must be a finite, positive f64 (n = 1..4).
        let inv_l = 1.0 / self.internal_lsb();
        let mut ts_n = 1.0;
        for q in [
            Quantity::Velocity,
            Quantity::Acceleration,
            Quantity::Jerk,
            Quantity::Snap,
        ] {
            ts_n *= self.ts;
            let s = ts_n * inv_l;
            if !(s.is_finite() && s > 0.0) {
                return Err(FormatError::Scale(q.name()));
            }
        }
        Ok(())
    }

    /// True when a board that says `id` about itself has this format's widths, fractional
    /// bits, tick bits, program depth and snap bytes (its `Ts` is the host's to take).
    pub fn matches_identity(&self, id: &snapgen_spec::Identity) -> bool {
        let w = self.widths.as_array();
        let got = [id.x_bits, id.v_bits, id.a_bits, id.j_bits, id.d_bits];
        got.iter().zip(w).all(|(&a, b)| u32::from(a) == b)
            && u32::from(id.frac_bits) == FRAC_BITS
            && u32::from(id.tick_bits) == self.tick_bits
            && usize::from(id.max_segments) == self.max_segments
            && usize::from(id.snap_bytes) == self.widths.d.div_ceil(8) as usize
    }

    /// The internal LSB `L` of the position register, in user units.
    #[inline]
    pub fn internal_lsb(&self) -> f64 {
        // 2^-FRAC_BITS, exact.
        self.position_lsb * f64::from_bits(((1023 - FRAC_BITS) as u64) << 52)
    }

    /// Raw LSBs per physical unit of `q`: `raw = physical · scale`, `scale = Ts^n / L`
    /// (`Ts^n` by plain multiplication, the same on every platform).
    #[inline]
    pub fn scale(&self, q: Quantity) -> f64 {
        let t = self.ts;
        let ts_n = match q.ts_power() {
            0 => 1.0,
            1 => t,
            2 => t * t,
            3 => t * t * t,
            _ => t * t * t * t,
        };
        ts_n / self.internal_lsb()
    }

    /// Physical value of a raw register value (nearest f64; exact for |raw| < 2^53).
    pub fn to_physical(&self, q: Quantity, raw: i128) -> f64 {
        raw as f64 / self.scale(q)
    }

    /// Largest magnitude a signed register of `bits` bits can hold.
    pub fn register_max(bits: u32) -> i128 {
        (1i128 << (bits - 1)) - 1
    }

    /// The width of the register that holds `q`.
    pub fn width(&self, q: Quantity) -> u32 {
        match q {
            Quantity::Position => self.widths.x,
            Quantity::Velocity => self.widths.v,
            Quantity::Acceleration => self.widths.a,
            Quantity::Jerk => self.widths.j,
            Quantity::Snap => self.widths.d,
        }
    }

    /// Largest physical magnitude the register for `q` can hold.
    pub fn physical_max(&self, q: Quantity) -> f64 {
        Self::register_max(self.width(q)) as f64 / self.scale(q)
    }

    /// The raw value of half an output LSB: where a position at rest sits inside its cell.
    pub fn half_lsb_raw(&self) -> i128 {
        1i128 << (FRAC_BITS - 1)
    }

    /// The position register's reset value: the centre of output cell 0.
    pub fn home_raw(&self) -> i128 {
        self.half_lsb_raw()
    }

    /// The output position (whole LSBs) of a raw position register: `x >> FRAC_BITS`,
    /// i.e. rounded toward −∞, exactly as the fabric's output port.
    pub fn output_lsb(&self, x_raw: i128) -> i128 {
        PositionFix::from_bits(x_raw).floor().to_bits() >> FRAC_BITS
    }

    /// Physical position of a raw position register, measured from the centre of cell 0
    /// (so a register at rest in cell `n` reads exactly `n · position_lsb`).
    pub fn position_physical(&self, x_raw: i128) -> f64 {
        let rel = PositionFix::from_bits(x_raw.wrapping_sub(self.home_raw()));
        rel.to_num::<f64>() * self.position_lsb
    }

    /// Range and resolution of every register, for documentation and `snapgen format`.
    pub fn ranges(&self) -> Vec<RegisterRange> {
        [
            Quantity::Position,
            Quantity::Velocity,
            Quantity::Acceleration,
            Quantity::Jerk,
            Quantity::Snap,
        ]
        .into_iter()
        .map(|q| RegisterRange {
            quantity: q,
            bits: self.width(q),
            lsb: 1.0 / self.scale(q),
            max: self.physical_max(q),
        })
        .collect()
    }

    /// Largest distance a move can have (both ways), from the centre of cell 0.
    pub fn max_distance(&self) -> f64 {
        (((1i128 << (self.widths.x - FRAC_BITS - 1)) - 2) as f64) * self.position_lsb
    }

    /// Longest duration, in seconds, that a program's total tick count can express.
    pub fn max_duration_s(&self) -> f64 {
        ((1u64 << self.tick_bits) - 1) as f64 * self.ts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn internal_lsb_is_two_to_the_minus_frac_bits() {
        assert_eq!(Format::with_ts(1e-5).internal_lsb(), 1e-6 * (-80f64).exp2());
    }

    #[test]
    fn default_format_is_valid() {
        DEFAULT_FORMAT.validate().unwrap();
    }

    #[test]
    fn output_rounds_toward_minus_infinity() {
        let f = DEFAULT_FORMAT;
        let one = 1i128 << FRAC_BITS;
        assert_eq!(f.output_lsb(3 * one), 3);
        assert_eq!(f.output_lsb(3 * one + one - 1), 3);
        assert_eq!(f.output_lsb(-1), -1);
        assert_eq!(f.output_lsb(-one), -1);
        assert_eq!(f.output_lsb(-one - 1), -2);
    }

    #[test]
    fn home_reads_zero_and_cells_read_whole_lsbs() {
        let f = DEFAULT_FORMAT;
        assert_eq!(f.position_physical(f.home_raw()), 0.0);
        let cell = 12_345i128;
        let x = (cell << FRAC_BITS) + f.half_lsb_raw();
        assert_eq!(f.output_lsb(x), cell);
        assert!((f.position_physical(x) - 12_345e-6).abs() < 1e-15);
    }

    #[test]
    fn bad_formats_are_rejected() {
        assert!(Format::with_ts(0.0).validate().is_err());
        assert!(Format::with_ts(f64::NAN).validate().is_err());
        let mut f = DEFAULT_FORMAT;
        f.widths.x = 80;
        assert!(matches!(
            f.validate(),
            Err(FormatError::PositionWidth { .. })
        ));
    }
}
