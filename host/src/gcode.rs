//! G-code to path elements: the words a CNC integrator writes for lines and arcs, read into
//! [`snapgen_plan::path::Element`]s on the output grid, every error with its line before
//! anything moves.
//!
//! Parsed by the `g-code` crate (exact decimals); interpreted here with its modal state:
//!
//! | words | meaning |
//! |---|---|
//! | `G0` | rapid: a line at the axes' own limits |
//! | `G1 X Y Z F` | a line at feed `F` |
//! | `G2`/`G3` `X Y Z` with `I J K` or `R` | a clockwise / counter-clockwise arc (a helix when the third axis moves); `I J K` the centre from the start (incremental), `R` its radius (negative: more than half a turn); the start's point again with `I J K`: a full turn |
//! | `G17` `G18` `G19` | the arc's plane: XY, ZX, YZ (counter-clockwise from the first axis toward the second) |
//! | `G20` `G21` | inches, millimetres (the machine's unit is the millimetre) |
//! | `G90` `G91` | absolute, incremental coordinates |
//! | `F` | feed in units per minute |
//! | `N` | line number (ignored) |
//! | `M2` `M30` | end of program (what follows is not read) |
//! | `( … )` `; …` | comments |
//!
//! Anything else — another G or M code, a word such as `S`, `T`, `A` — is refused with its
//! line, as is a feed move before any `F`, an arc whose centre or radius does not fit its end
//! point, or a program without an end. The machine starts at 0 on every axis.
//!
//! **Arcs from CAM.** A CAM post rounds an arc's end point and centre to its decimals, so the
//! end rarely lies on the circle through the start: an end up to the tolerance
//! ([`DEFAULT_ARC_TOLERANCE_MM`], `--arc-tolerance`) nearer or farther than the start has its
//! centre corrected onto the chord's perpendicular bisector (as TwinCAT's centre-point
//! correction does), and the path is the circle through both points; farther off, the block
//! is refused.

use g_code::emit::{Field, Value};
use g_code::parse::ast::Spanned;
use snapgen_plan::path::Element;

/// One motion block.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Its line in the file (from 1).
    pub line: usize,
    /// The element it moves along.
    pub element: Element,
    /// Its feed (mm/s), or None for a rapid (the axes' own limits).
    pub feed: Option<f64>,
}

/// What is wrong with a program.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GcodeError {
    /// The text does not parse as G-code.
    #[error("line {line}, column {column}: not G-code (expected {expected})")]
    Parse {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What the parser expected.
        expected: String,
    },
    /// A word this reader does not carry out.
    #[error("line {line}: {word} is not supported (supported: G0-G3, G17-G19, G20, G21, G90, G91, X Y Z I J K R F N, M2, M30)")]
    Unsupported {
        /// Line.
        line: usize,
        /// The word.
        word: String,
    },
    /// A feed move before any feed rate.
    #[error("line {line}: a feed move (G1, G2, G3) needs a feed rate: give F (units/min) on it or before it")]
    NoFeed {
        /// Line.
        line: usize,
    },
    /// A feed rate that is not a positive number.
    #[error("line {line}: F{value} is not a positive feed rate")]
    BadFeed {
        /// Line.
        line: usize,
        /// The value.
        value: f64,
    },
    /// An arc without a centre or radius, or whose radius cannot reach its end point.
    #[error("line {line}: {why}")]
    Arc {
        /// Line.
        line: usize,
        /// Why.
        why: String,
    },
    /// A point beyond what the axes' output can hold.
    #[error(
        "line {line}: {axis} at {mm} mm is beyond the axes' reach (±{limit} mm: 2^31 output LSBs)"
    )]
    Range {
        /// Line.
        line: usize,
        /// The axis.
        axis: char,
        /// Where it was sent (mm).
        mm: f64,
        /// The reach (mm).
        limit: f64,
    },
    /// A tolerance that is not a number ≥ 0.
    #[error("--arc-tolerance {value}: give a number of mm ≥ 0")]
    Tolerance {
        /// The value.
        value: f64,
    },
    /// A program that does not end with M2 or M30.
    #[error("the program has no end: finish it with M2 or M30")]
    NoEnd,
}

/// The largest position magnitude (output LSBs): the fabric's 32-bit position output.
const POSITION_LIMIT: f64 = 2147483647.0;

/// The modal state.
struct Modal {
    motion: u32,
    plane: [usize; 2],
    inch: bool,
    incremental: bool,
    feed: Option<f64>,
}

/// The value of a word, as a number.
fn number(f: &Field) -> Option<f64> {
    match &f.value {
        Value::Rational(_) | Value::Integer(_) | Value::Float(_) => f.value.as_f64(),
        Value::String(_) => None,
    }
}

/// The default tolerance on an arc's radii (mm): its end may lie this much nearer to or
/// farther from its centre than its start (CAM output rounds both to its decimals); the
/// centre is then corrected ([`read_with`]). TwinCAT CNC's default for the same check is 5 µm.
pub const DEFAULT_ARC_TOLERANCE_MM: f64 = 0.005;

/// Reads `src` into motion blocks on a grid of `lsb` mm (module documentation), arcs within
/// [`DEFAULT_ARC_TOLERANCE_MM`].
pub fn read(src: &str, lsb: f64) -> Result<Vec<Block>, GcodeError> {
    read_with(src, lsb, DEFAULT_ARC_TOLERANCE_MM)
}

/// Reads `src` into motion blocks on a grid of `lsb` mm (module documentation). An arc whose
/// end is up to `arc_tolerance` mm nearer to or farther from its centre than its start (but
/// more than an LSB) has its centre moved onto the chord's perpendicular bisector, to the grid
/// point nearest to where its programmed centre projects whose radii differ by at most an LSB
/// (the path is then that circle through both points, swept the same way); beyond the
/// tolerance it is refused with its line.
pub fn read_with(src: &str, lsb: f64, arc_tolerance: f64) -> Result<Vec<Block>, GcodeError> {
    if !(arc_tolerance.is_finite() && arc_tolerance >= 0.0) {
        return Err(GcodeError::Tolerance {
            value: arc_tolerance,
        });
    }
    let file = g_code::parse::file_parser(src).map_err(|e| GcodeError::Parse {
        line: e.location.line,
        column: e.location.column,
        expected: e.expected.to_string(),
    })?;
    // Where each line begins, for a block's line number from its byte offset.
    let starts: Vec<usize> = std::iter::once(0)
        .chain(src.match_indices('\n').map(|(k, _)| k + 1))
        .collect();
    let line_of = |offset: usize| starts.partition_point(|&s| s <= offset);
    let mut m = Modal {
        motion: 0,
        plane: [0, 1],
        inch: false,
        incremental: false,
        feed: None,
    };
    let mut at = [0i64; 3];
    let mut blocks = Vec::new();
    for l in file.iter() {
        let line = line_of(l.span().0);
        let unsupported = |word: String| GcodeError::Unsupported { line, word };
        let mut words: Vec<(char, f64)> = Vec::new();
        let mut moved = false;
        let mut end = false;
        for parsed in l.iter_fields() {
            let f = Field::from(parsed);
            let letters = f.letters.to_ascii_uppercase();
            let value =
                number(&f).ok_or_else(|| unsupported(format!("{letters} with a string")))?;
            let mut chars = letters.chars();
            let (Some(letter), None) = (chars.next(), chars.next()) else {
                return Err(unsupported(letters));
            };
            let code = (value.fract() == 0.0 && value >= 0.0).then_some(value as u32);
            match (letter, code) {
                ('G', Some(c @ 0..=3)) => {
                    m.motion = c;
                    moved = true;
                }
                ('G', Some(17)) => m.plane = [0, 1],
                ('G', Some(18)) => m.plane = [2, 0],
                ('G', Some(19)) => m.plane = [1, 2],
                ('G', Some(20)) => m.inch = true,
                ('G', Some(21)) => m.inch = false,
                ('G', Some(90)) => m.incremental = false,
                ('G', Some(91)) => m.incremental = true,
                ('M', Some(2 | 30)) => end = true,
                ('G' | 'M', _) => return Err(unsupported(format!("{letter}{value}"))),
                ('X' | 'Y' | 'Z' | 'I' | 'J' | 'K' | 'R', _) => {
                    words.push((letter, value));
                    if matches!(letter, 'X' | 'Y' | 'Z') {
                        moved = true;
                    }
                }
                ('F', _) => words.push((letter, value)),
                ('N', _) => {}
                _ => return Err(unsupported(format!("{letter}{value}"))),
            }
        }
        let scale = if m.inch { 25.4 } else { 1.0 };
        let word = |c: char| words.iter().rev().find(|w| w.0 == c).map(|w| w.1 * scale);
        if let Some(f) = words.iter().rev().find(|w| w.0 == 'F').map(|w| w.1) {
            if !(f.is_finite() && f > 0.0) {
                return Err(GcodeError::BadFeed { line, value: f });
            }
            m.feed = Some(f * scale / 60.0);
        }
        let cells = |mm: f64| (mm / lsb).round() as i64;
        let has = |letters: &[char]| words.iter().any(|w| letters.contains(&w.0));
        let arc_words = has(&['I', 'J', 'K', 'R']);
        if arc_words && !(moved && m.motion >= 2) {
            return Err(GcodeError::Arc {
                line,
                why: "I J K R belong to an arc (G2, G3)".into(),
            });
        }
        // A move: coordinates, or an arc's centre alone (the start's point again: a full turn).
        if moved && (has(&['X', 'Y', 'Z']) || arc_words) {
            let mut to = at;
            for (k, c) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                if let Some(v) = word(c) {
                    let v = v / lsb;
                    let target = if m.incremental { at[k] as f64 + v } else { v };
                    if target.is_nan() || target.abs() >= POSITION_LIMIT {
                        return Err(GcodeError::Range {
                            line,
                            axis: c,
                            mm: target * lsb,
                            limit: POSITION_LIMIT * lsb,
                        });
                    }
                    to[k] = target.round() as i64;
                }
            }
            let feed = if m.motion == 0 {
                None
            } else {
                Some(m.feed.ok_or(GcodeError::NoFeed { line })?)
            };
            let element = match m.motion {
                0 | 1 => Element::Line { to: to.to_vec() },
                _ => arc(line, &m, at, to, lsb, arc_tolerance, |c| word(c).map(cells))?,
            };
            if to != at || !matches!(element, Element::Line { .. }) {
                blocks.push(Block {
                    line,
                    element,
                    feed,
                });
            }
            at = to;
        }
        if end {
            return Ok(blocks);
        }
    }
    Err(GcodeError::NoEnd)
}

/// The arc of a G2/G3 block from `at` to `to` (module documentation).
fn arc(
    line: usize,
    m: &Modal,
    at: [i64; 3],
    to: [i64; 3],
    lsb: f64,
    tolerance: f64,
    word: impl Fn(char) -> Option<i64>,
) -> Result<Element, GcodeError> {
    let [p, q] = m.plane;
    let letters = ['I', 'J', 'K'];
    let ccw = m.motion == 3;
    let bad = |why: String| GcodeError::Arc { line, why };
    let off_plane = (0..3).find(|&i| i != p && i != q).map(|i| letters[i]);
    if let Some(c) = off_plane.filter(|&c| word(c).is_some()) {
        return Err(bad(format!(
            "{c} is not an offset in this arc's plane (G17: I J, G18: K I, G19: J K)"
        )));
    }
    let centre = match (word(letters[p]), word(letters[q]), word('R')) {
        (None, None, None) => {
            return Err(bad(
                "an arc needs its centre (I J K) or its radius (R)".into()
            ))
        }
        (_, _, Some(r)) if word(letters[p]).is_none() && word(letters[q]).is_none() => {
            centre_of_radius([at[p], at[q]], [to[p], to[q]], r as f64, ccw, lsb).map_err(bad)?
        }
        (i, j, None) => [
            at[p].saturating_add(i.unwrap_or(0)),
            at[q].saturating_add(j.unwrap_or(0)),
        ],
        _ => {
            return Err(bad(
                "give an arc's centre (I J K) or its radius (R), not both".into(),
            ))
        }
    };
    if centre
        .iter()
        .any(|&c| c.unsigned_abs() as f64 >= 2.0 * POSITION_LIMIT)
    {
        return Err(bad(format!(
            "the arc's centre ({} mm, {} mm) is beyond the axes' reach",
            centre[0] as f64 * lsb,
            centre[1] as f64 * lsb
        )));
    }
    let centre = corrected_centre([at[p], at[q]], [to[p], to[q]], centre, tolerance / lsb, lsb)
        .map_err(bad)?;
    Ok(Element::Arc {
        plane: m.plane,
        centre,
        ccw,
        to: to.to_vec(),
    })
}

/// The centre (in the arc's plane, LSB) of an arc of radius `r` LSB from `at` to `to`:
/// on the chord's left for a counter-clockwise arc of at most half a turn, on its right
/// clockwise; `r < 0` asks for the longer arc (G-code's R, PLCopen's radius mode). Refused
/// (why, `lsb` mm an LSB) for a full turn or a radius shorter than half the chord.
pub fn centre_of_radius(
    at: [i64; 2],
    to: [i64; 2],
    r: f64,
    ccw: bool,
    lsb: f64,
) -> Result<[i64; 2], String> {
    let (sx, sy, ex, ey) = (at[0] as f64, at[1] as f64, to[0] as f64, to[1] as f64);
    let chord = (ex - sx).hypot(ey - sy);
    if chord == 0.0 {
        return Err("a full turn cannot be given by its radius: give its centre".into());
    }
    let h2 = r * r - chord * chord / 4.0;
    if h2 < -1.0 {
        return Err(format!(
            "radius {} mm is shorter than half the chord to the end point ({} mm)",
            r.abs() * lsb,
            chord / 2.0 * lsb
        ));
    }
    let h = h2.max(0.0).sqrt();
    let (ux, uy) = ((ex - sx) / chord, (ey - sy) / chord);
    let left = ccw == (r > 0.0);
    let side = if left { 1.0 } else { -1.0 };
    Ok([
        ((sx + ex) / 2.0 - side * h * uy).round() as i64,
        ((sy + ey) / 2.0 + side * h * ux).round() as i64,
    ])
}

/// Each point's distance from `c` (LSB), as the path's preparation measures it.
fn radii(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> (f64, f64) {
    let r = |v: [i64; 2]| ((v[0] - c[0]) as f64).hypot((v[1] - c[1]) as f64);
    (r(a), r(b))
}

/// The centre of an arc from `a` to `b` (in its plane, LSB) programmed at `c`: `c` when the
/// two radii differ by at most an LSB; when they differ by at most `tolerance` LSB, the grid
/// point nearest to `c`'s projection on the chord's perpendicular bisector, on `c`'s side of
/// the chord, whose radii differ by at most an LSB, provided it lies within `tolerance` of `c`
/// (a short chord would move the centre far: refused). Otherwise why not (`lsb` mm an LSB,
/// for the message).
pub fn corrected_centre(
    a: [i64; 2],
    b: [i64; 2],
    c: [i64; 2],
    tolerance: f64,
    lsb: f64,
) -> Result<[i64; 2], String> {
    let (rs, re) = radii(a, b, c);
    if (rs - re).abs() <= 1.0 {
        return Ok(c);
    }
    let mm = |x: f64| x * lsb;
    let radii_text = format!(
        "the arc's end is {} mm from its centre, its start {} mm",
        mm(re),
        mm(rs)
    );
    if (rs - re).abs() > tolerance.max(1.0) {
        return Err(format!(
            "{radii_text}: they differ by more than the tolerance of {} mm (--arc-tolerance)",
            mm(tolerance)
        ));
    }
    // The chord's midpoint and direction; c projected along the chord onto its bisector.
    let (mx, my) = ((a[0] + b[0]) as f64 / 2.0, (a[1] + b[1]) as f64 / 2.0);
    let (dx, dy) = ((b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
    let chord = dx.hypot(dy);
    let (ux, uy) = (dx / chord, dy / chord);
    let along = (c[0] as f64 - mx) * ux + (c[1] as f64 - my) * uy;
    let (px, py) = (c[0] as f64 - along * ux, c[1] as f64 - along * uy);
    // The side of the chord a centre lies on (the sign of the cross product).
    let side = |g: [i64; 2]| {
        (i128::from(b[0] - a[0]) * i128::from(g[1] - a[1])
            - i128::from(b[1] - a[1]) * i128::from(g[0] - a[0]))
        .signum()
    };
    let mut best: Option<([i64; 2], f64)> = None;
    for ox in -2..=2 {
        for oy in -2..=2 {
            let g = [px.round() as i64 + ox, py.round() as i64 + oy];
            let (s, e) = radii(a, b, g);
            let d = (g[0] as f64 - px).hypot(g[1] as f64 - py);
            if (s - e).abs() <= 1.0 && side(g) == side(c) && best.is_none_or(|(_, bd)| d < bd) {
                best = Some((g, d));
            }
        }
    }
    let Some((g, _)) = best else {
        return Err(format!(
            "{radii_text}, and no centre on the grid near the chord's bisector fits both"
        ));
    };
    let moved = ((g[0] - c[0]) as f64).hypot((g[1] - c[1]) as f64);
    if moved > tolerance.max(1.0) + 1.0 {
        return Err(format!(
            "{radii_text}: fitting both moves the centre {} mm, more than the tolerance of {} mm (--arc-tolerance; a short chord moves it far)",
            mm(moved),
            mm(tolerance)
        ));
    }
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    const NM: f64 = 1e-6;

    #[test]
    fn lines_arcs_and_modes() {
        let src = "G21 G90 G17 (a slot)\nG0 X10 Y0\nG1 X30 F600 ; mm/min\nG3 X30 Y40 I0 J20\nG2 X10 Y40 Z-1 R10\nG91 G1 Y-40\nM30\nG1 X99\n";
        let b = read(src, NM).unwrap();
        assert_eq!(b.len(), 5);
        let mm = |x: i64| x * 1_000_000;
        assert_eq!(
            b[0].element,
            Element::Line {
                to: vec![mm(10), 0, 0]
            }
        );
        assert_eq!((b[0].line, b[0].feed), (2, None));
        assert_eq!(b[1].feed, Some(10.0));
        assert_eq!(
            b[2].element,
            Element::Arc {
                plane: [0, 1],
                centre: [mm(30), mm(20)],
                ccw: true,
                to: vec![mm(30), mm(40), 0],
            }
        );
        // R10 from (30, 40) to (10, 40), clockwise: the centre (20, 40) (a half turn).
        let Element::Arc {
            centre, ccw, to, ..
        } = &b[3].element
        else {
            panic!()
        };
        assert_eq!(
            (*centre, *ccw, to.clone()),
            ([mm(20), mm(40)], false, vec![mm(10), mm(40), -mm(1)])
        );
        assert_eq!(
            b[4].element,
            Element::Line {
                to: vec![mm(10), 0, -mm(1)]
            }
        );
        assert_eq!(b[4].line, 6);
    }

    #[test]
    fn inches_planes_and_full_turns() {
        let src = "G20 G18 F10\nG1 X1\nG2 X1 Z0 I1 K0\nM2\n";
        let b = read(src, NM).unwrap();
        let inch = 25_400_000;
        assert_eq!(b[0].feed, Some(10.0 * 25.4 / 60.0));
        assert_eq!(
            b[1].element,
            Element::Arc {
                plane: [2, 0],
                centre: [0, 2 * inch],
                ccw: false,
                to: vec![inch, 0, 0],
            }
        );
    }

    #[test]
    fn a_centre_alone_is_a_full_turn() {
        let b = read("F60\nG1 X5\nG2 I5 J0\nM2\n", NM).unwrap();
        assert_eq!(
            b[1].element,
            Element::Arc {
                plane: [0, 1],
                centre: [10_000_000, 0],
                ccw: false,
                to: vec![5_000_000, 0, 0],
            }
        );
        assert_eq!(b[1].line, 3);
    }

    #[test]
    fn bad_programs_name_their_line() {
        let cases = [
            ("G1 X1 F100\nM3 S1000\nM2\n", "line 2: M3 is not supported"),
            ("G1 X1\nM2\n", "line 1: a feed move"),
            ("G1 X1 F100\nG2 X2\nM2\n", "line 2: an arc needs its centre"),
            (
                "F100\nG2 X10 R2\nM2\n",
                "line 2: radius 2 mm is shorter than half the chord to the end point (5 mm)",
            ),
            ("F100\nG2 X0 Y0 R2\nM2\n", "line 2: a full turn cannot"),
            ("G1 X1 F100\n", "no end"),
            ("G1 X1 F-5\nM2\n", "F-5 is not a positive"),
            ("G1 A3 F100\nM2\n", "line 1: A3 is not supported"),
            ("G41 X1 F100\nM2\n", "line 1: G41 is not supported"),
            ("G1 X1 I2 F100\nM2\n", "line 1: I J K R belong to an arc"),
            (
                "G17 F100\nG2 X1 I1 K1\nM2\n",
                "line 2: K is not an offset in this arc's plane",
            ),
            (
                "G1 X3000 F100\nM2\n",
                "line 1: X at 3000 mm is beyond the axes' reach",
            ),
        ];
        for (src, want) in cases {
            let e = read(src, NM).unwrap_err().to_string();
            assert!(e.contains(want), "{src:?}: {e}");
        }
    }

    /// A CAM arc rounded to its 3 decimals: its end 1 µm (1000 LSB) farther from the
    /// programmed centre than its start. Within the tolerance its centre is moved onto the
    /// chord's bisector, on the same side: both radii then agree within an LSB, and the
    /// centre moved no more than the rounding needs. Beyond it (or with a tolerance of 0)
    /// the block is refused with its line and both radii.
    #[test]
    fn a_cam_arc_within_the_tolerance_has_its_centre_corrected() {
        let src = "G21 F600\nG1 X10\nG3 X0 Y10.001 I-10 J0\nM2\n";
        let b = read(src, NM).unwrap();
        let Element::Arc { centre, to, .. } = &b[1].element else {
            panic!("an arc")
        };
        let (rs, re) = radii([10_000_000, 0], [to[0], to[1]], *centre);
        assert!((rs - re).abs() <= 1.0, "{rs} {re}");
        // On the bisector of (10, 0)–(0, 10.001) near (0, 0): x ≈ y − 0.001 mm or so.
        let shift = (centre[0] as f64).hypot(centre[1] as f64) * NM;
        assert!(shift < 0.001, "moved {shift} mm: {centre:?}");
        assert!(centre[0] != 0 || centre[1] != 0, "moved");
        for (tol, src) in [
            (0.005, "G21 F600\nG1 X10\nG3 X0 Y10.01 I-10 J0\nM2\n"),
            (0.0, src),
            // Nearly a full turn, its end 1 µm out: fitting both would move the centre to the
            // chord's midpoint, 10 mm away (a half turn of 0.5 µm instead of a circle).
            (0.005, "G21 F600\nG1 X10\nG3 X10.001 Y0 I-10 J0\nM2\n"),
        ] {
            let e = read_with(src, NM, tol).unwrap_err().to_string();
            assert!(
                e.contains("line 3: the arc's end is") && e.contains("more than the tolerance of"),
                "{e}"
            );
        }
        assert!(read_with(src, NM, -1.0).is_err());
    }
}
