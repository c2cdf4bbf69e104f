//! The interpolator: a path length `s` (the chain's position register, raw) becomes each
//! axis's position (raw, the chain's format: [`crate::FRAC_BITS`] bits below the output LSB),
//! by integer rules a fabric can follow once per tick.
//!
//! A path is a list of [`Segment`]s, each with its length in `s` (raw) and its shape, prepared
//! by the host (`snapgen_plan::path`). Within a segment, at `r = s − start` (`0 ≤ r ≤ length`;
//! the path's first and last segments up to a cell beyond, [`Path::at`]):
//!
//! * **Line**: `xᵢ = fromᵢ + ((r · dirᵢ) >> 62)`, `dirᵢ` the axis's share of the length
//!   (`Δxᵢ / length`, 62 fraction bits).
//! * **Arc** (and helix): `θ = start + sign·((r · rate) >> RATE_SHIFT)` (wrapping [`Turn`]s),
//!   `(c, s) = cos_sin(θ)` ([`super::cordic`]), `ρ = radius + ((r · growth) >> 62)`; the
//!   plane's axes are `centre + ((ρ · c) >> 62)` and `centre + ((ρ · s) >> 62)`; every other
//!   axis moves as on a line, `fromᵢ + ((r · dirᵢ) >> 62)` (a helix's climb; 0 for a flat
//!   arc). `growth` takes the radius from the start's to the end point's when the end point,
//!   on its grid, is not quite on the circle (a spiral of a fraction of an LSB, as G-code
//!   interpreters do).
//!
//! `>>` rounds toward −∞ (an arithmetic shift), the products are exact (256 bits).

use ethnum::I256;

use super::cordic::{cos_sin, Turn, ONE_BITS};

/// Fraction bits of an arc's angular rate (turns·2⁶⁴ per raw unit of `s`).
pub const RATE_SHIFT: u32 = snapgen_spec::widths::RATE_FRAC;

/// How a segment maps its length onto the axes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Shape {
    /// A straight line.
    Line {
        /// Every axis at the segment's start (raw).
        from: Vec<i128>,
        /// Each axis's share of the length, `Δxᵢ / length` with 62 fraction bits.
        dir: Vec<i128>,
    },
    /// A circular arc in the plane of two axes, the others moving linearly (a helix).
    Arc {
        /// The plane's two axes (counter-clockwise turns from the first toward the second).
        plane: [usize; 2],
        /// The centre in the plane (raw).
        centre: [i128; 2],
        /// The radius at the start (raw).
        radius: i128,
        /// The radius's change per raw unit of `s` (62 fraction bits).
        growth: i128,
        /// The angle at the segment's start.
        start: Turn,
        /// Turns·2⁶⁴ per raw unit of `s`, with [`RATE_SHIFT`] fraction bits (≥ 0).
        rate: i128,
        /// Counter-clockwise (true) or clockwise.
        ccw: bool,
        /// Every axis at the segment's start (raw; the plane's axes are not read).
        from: Vec<i128>,
        /// The other axes' share of the length (62 fraction bits; the plane's axes are 0).
        dir: Vec<i128>,
    },
}

/// One piece of a path, in `s`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Segment {
    /// Its length in `s` (raw).
    pub length: i128,
    /// Its shape.
    pub shape: Shape,
}

/// `(a · b) >> shift`, exact, rounding toward −∞.
fn mul_shift(a: i128, b: i128, shift: u32) -> i128 {
    ((I256::from(a) * I256::from(b)) >> shift).as_i128()
}

impl Segment {
    /// Every axis at `r` into the segment (`0 ≤ r ≤ length`, or up to a cell beyond: the rule
    /// goes on).
    pub fn at(&self, r: i128) -> Vec<i128> {
        match &self.shape {
            Shape::Line { from, dir } => from
                .iter()
                .zip(dir)
                .map(|(&x, &d)| x + mul_shift(r, d, ONE_BITS))
                .collect(),
            Shape::Arc {
                plane,
                centre,
                radius,
                growth,
                start,
                rate,
                ccw,
                from,
                dir,
            } => {
                let rho = radius + mul_shift(r, *growth, ONE_BITS);
                let turned = mul_shift(r, *rate, RATE_SHIFT) as u64;
                let theta = if *ccw {
                    start.0.wrapping_add(turned)
                } else {
                    start.0.wrapping_sub(turned)
                };
                let (c, s) = cos_sin(Turn(theta));
                let mut out: Vec<i128> = from
                    .iter()
                    .zip(dir)
                    .map(|(&x, &d)| x + mul_shift(r, d, ONE_BITS))
                    .collect();
                out[plane[0]] = centre[0] + mul_shift(rho, c, ONE_BITS);
                out[plane[1]] = centre[1] + mul_shift(rho, s, ONE_BITS);
                out
            }
        }
    }
}

/// A path: its segments end to end from `s = 0`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Path {
    /// The segments.
    pub segments: Vec<Segment>,
}

impl Path {
    /// The whole length in `s` (raw).
    pub fn length(&self) -> i128 {
        self.segments.iter().map(|g| g.length).sum()
    }

    /// Every axis at path length `s`: the segment `s` lies in (a segment's end belongs to it
    /// only at the path's end: elsewhere the next one starts there). Before 0 the first
    /// segment's rule, and beyond the length the last one's, go on for up to one output cell
    /// (a chain at rest on a position stands within a cell's width of it, on either side: the
    /// axes move smoothly with `s` rather than starting or stopping while it moves), then
    /// stay. None for a path without segments.
    pub fn at(&self, s: i128) -> Option<Vec<i128>> {
        let mut start = 0i128;
        let last = self.segments.len().checked_sub(1)?;
        for (k, g) in self.segments.iter().enumerate() {
            if s < start + g.length || k == last {
                let cell = 1i128 << crate::FRAC_BITS;
                let before = if k == 0 { -cell } else { 0 };
                let beyond = if k == last { cell } else { 0 };
                return Some(g.at((s - start).clamp(before, g.length + beyond)));
            }
            start += g.length;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: i128 = 1 << ONE_BITS;

    #[test]
    fn a_line_moves_each_axis_by_its_share() {
        let g = Segment {
            length: 1000,
            shape: Shape::Line {
                from: vec![10, -5],
                dir: vec![ONE * 3 / 4, -ONE / 2],
            },
        };
        assert_eq!(g.at(0), vec![10, -5]);
        assert_eq!(g.at(500), vec![385, -255]);
        assert_eq!(g.at(1000), vec![760, -505]);
        // Rounding toward −∞: 1 · 0.75 → 0; 1 · −0.5 → −1.
        assert_eq!(g.at(1), vec![10, -6]);
    }

    #[test]
    fn an_arc_turns_by_its_rate() {
        // A quarter turn (2^62 in Turn units) over s = 2^100, radius 2^100, climbing 2^100:
        // rate = 2^62 / 2^100 · 2^RATE_SHIFT.
        let arc = |ccw| Segment {
            length: 1 << 100,
            shape: Shape::Arc {
                plane: [0, 1],
                centre: [0, 0],
                radius: 1 << 100,
                growth: 0,
                start: Turn(0),
                rate: 1 << (62 + RATE_SHIFT - 100),
                ccw,
                from: vec![0, 0, 7],
                dir: vec![0, 0, ONE],
            },
        };
        // Within CORDIC's error (32 units of 2^-62) times the radius.
        let near =
            |p: Vec<i128>, q: [i128; 3]| p.iter().zip(q).all(|(a, b)| (a - b).abs() <= 1 << 45);
        let g = arc(true);
        assert!(near(g.at(0), [1 << 100, 0, 7]));
        assert!(near(g.at(1 << 100), [0, 1 << 100, 7 + (1 << 100)]));
        assert!(near(
            arc(false).at(1 << 100),
            [0, -(1 << 100), 7 + (1 << 100)]
        ));
        // Half way: 45°, both plane axes at √½ of the radius.
        let half = g.at(1 << 99);
        let r = ((1u128 << 100) as f64 * std::f64::consts::FRAC_1_SQRT_2) as i128;
        assert!(
            (half[0] - r).abs() < 1 << 50 && (half[1] - r).abs() < 1 << 50,
            "{half:?}"
        );
    }

    #[test]
    fn a_path_hands_on_at_each_segment_end() {
        let line = |from: i128, len: i128| Segment {
            length: len,
            shape: Shape::Line {
                from: vec![from],
                dir: vec![ONE],
            },
        };
        let p = Path {
            segments: vec![line(0, 10), line(100, 5)],
        };
        assert_eq!(p.length(), 15);
        assert_eq!(p.at(9), Some(vec![9]));
        assert_eq!(p.at(10), Some(vec![100]), "the next segment's start");
        assert_eq!(p.at(15), Some(vec![105]));
        let cell = 1i128 << crate::FRAC_BITS;
        assert_eq!(
            p.at(15 + cell + 99),
            Some(vec![105 + cell]),
            "beyond the end: on for a cell"
        );
        assert_eq!(
            p.at(-3),
            Some(vec![-3]),
            "before the start: back for a cell"
        );
        assert_eq!(p.at(-cell - 9), Some(vec![-cell]));
        assert_eq!(Path { segments: vec![] }.at(0), None);
    }
}
