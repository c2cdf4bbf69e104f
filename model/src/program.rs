//! The segment program: the fabric-facing form of every plan.
//!
//! A program is a list of segments, each `(ticks, snap)`: the sequencer feeds `snap` (a raw value
//! in the format's snap LSB) to the integrator chain for `ticks` consecutive ticks, then moves on.
//! Seed 000's 16 switching times (eqs 50–53) with one snap value and a direction become 15 or 16
//! segments; jerk steps (order 3) and acceleration steps (order 2) become one-tick snap impulses,
//! so every planner, and later every re-planned or buffered move, runs on the same core.
//!
//! The binary form (what the host uploads) is, per segment, the tick count as a little-endian
//! `u32` followed by the snap as a little-endian two's-complement integer of
//! `ceil(d_bits / 8)` bytes; the whole program is preceded by its segment count as a
//! little-endian `u16`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::error::ProgramError;
use crate::format::Format;

/// One program segment: `snap` for `ticks` ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Segment {
    /// Number of ticks (≥ 1).
    pub ticks: u32,
    /// Raw snap value fed to the chain on each of those ticks.
    pub snap: i128,
}

/// A program: what the sequencer plays.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Program {
    /// The segments, in play order.
    pub segments: Vec<Segment>,
}

impl Program {
    /// An empty program (a zero-length move).
    pub fn empty() -> Self {
        Program::default()
    }

    /// Total number of ticks the program lasts.
    pub fn total_ticks(&self) -> u64 {
        self.segments.iter().map(|s| u64::from(s.ticks)).sum()
    }

    /// The program with every snap negated: the mirror image of the move.
    pub fn negated(&self) -> Self {
        Program {
            segments: self
                .segments
                .iter()
                .map(|s| Segment {
                    ticks: s.ticks,
                    snap: -s.snap,
                })
                .collect(),
        }
    }

    /// Checks the program against the format's program memory, tick counter and snap width.
    pub fn validate(&self, format: &Format) -> Result<(), ProgramError> {
        if self.segments.len() > format.max_segments {
            return Err(ProgramError::TooManySegments {
                count: self.segments.len(),
                max: format.max_segments,
            });
        }
        let snap_max = Format::register_max(format.widths.d);
        for (index, s) in self.segments.iter().enumerate() {
            if s.ticks == 0 {
                return Err(ProgramError::ZeroTicks { index });
            }
            if format.tick_bits < 32 && u64::from(s.ticks) >> format.tick_bits != 0 {
                return Err(ProgramError::TicksTooLarge {
                    index,
                    ticks: u64::from(s.ticks),
                    bits: format.tick_bits,
                });
            }
            if s.snap > snap_max || s.snap < -snap_max - 1 {
                return Err(ProgramError::SnapTooLarge {
                    index,
                    snap: s.snap,
                    bits: format.widths.d,
                });
            }
        }
        Ok(())
    }

    /// Bytes per encoded snap value for this format.
    pub fn snap_bytes(format: &Format) -> usize {
        format.widths.d.div_ceil(8) as usize
    }

    /// Encodes the program in the binary upload form (see the module documentation).
    pub fn to_bytes(&self, format: &Format) -> Result<Vec<u8>, ProgramError> {
        self.validate(format)?;
        let count =
            u16::try_from(self.segments.len()).map_err(|_| ProgramError::TooManySegments {
                count: self.segments.len(),
                max: usize::from(u16::MAX),
            })?;
        let nb = Self::snap_bytes(format);
        let mut out = Vec::with_capacity(2 + self.segments.len() * (4 + nb));
        out.extend_from_slice(&count.to_le_bytes());
        for s in &self.segments {
            out.extend_from_slice(&s.ticks.to_le_bytes());
            out.extend_from_slice(&s.snap.to_le_bytes()[..nb]);
        }
        Ok(out)
    }

    /// Decodes the binary upload form; the inverse of [`Program::to_bytes`].
    pub fn from_bytes(bytes: &[u8], format: &Format) -> Result<Self, ProgramError> {
        let nb = Self::snap_bytes(format);
        let (head, mut rest) = bytes
            .split_first_chunk::<2>()
            .ok_or(ProgramError::Malformed(
                "shorter than the 2-byte segment count",
            ))?;
        let count = usize::from(u16::from_le_bytes(*head));
        if rest.len() != count * (4 + nb) {
            return Err(ProgramError::Malformed(
                "length does not match the segment count",
            ));
        }
        let mut segments = Vec::with_capacity(count);
        for _ in 0..count {
            let (t, r) = rest.split_at(4);
            let (d, r) = r.split_at(nb);
            rest = r;
            let ticks = u32::from_le_bytes(t.try_into().expect("split_at(4)"));
            let mut wide = [0u8; 16];
            wide[..nb].copy_from_slice(d);
            // Sign-extend from the top encoded byte.
            if d[nb - 1] & 0x80 != 0 {
                wide[nb..].fill(0xff);
            }
            segments.push(Segment {
                ticks,
                snap: i128::from_le_bytes(wide),
            });
        }
        let p = Program { segments };
        p.validate(format)?;
        Ok(p)
    }
}

/// Builds a program from overlapping snap patterns.
///
/// Snap is piecewise constant; the builder stores only where it *changes*, so patterns may
/// overlap (their snaps add) and coinciding impulses merge into one segment.
#[derive(Clone, Debug, Default)]
pub struct SnapTimeline {
    changes: BTreeMap<u64, i128>,
    end: u64,
}

impl SnapTimeline {
    /// An empty timeline.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `snap` on ticks `[start, start + ticks)`.
    pub fn add(&mut self, start: u64, ticks: u64, snap: i128) {
        if ticks == 0 || snap == 0 {
            return;
        }
        *self.changes.entry(start).or_insert(0) += snap;
        *self.changes.entry(start + ticks).or_insert(0) -= snap;
        self.end = self.end.max(start + ticks);
    }

    /// Adds a one-tick impulse of `snap` at tick `at`.
    pub fn impulse(&mut self, at: u64, snap: i128) {
        self.add(at, 1, snap);
    }

    /// Makes the program last at least until `end` (trailing zero-snap ticks).
    pub fn extend_to(&mut self, end: u64) {
        self.end = self.end.max(end);
    }

    /// The program: maximal runs of equal snap, covering `[0, end)`. Fails only if a run is
    /// longer than a `u32` tick count.
    pub fn to_program(&self) -> Result<Program, ProgramError> {
        let mut segments: Vec<Segment> = Vec::new();
        let mut level = 0i128;
        let mut at = 0u64;
        let mut push = |from: u64, to: u64, snap: i128| -> Result<(), ProgramError> {
            let mut left = to - from;
            while left > 0 {
                if let Some(last) = segments.last_mut() {
                    if last.snap == snap && last.ticks < u32::MAX {
                        let room = u64::from(u32::MAX - last.ticks).min(left);
                        last.ticks += room as u32;
                        left -= room;
                        continue;
                    }
                }
                let n = left.min(u64::from(u32::MAX));
                segments.push(Segment {
                    ticks: n as u32,
                    snap,
                });
                left -= n;
            }
            Ok(())
        };
        for (&t, &delta) in &self.changes {
            if t > at {
                push(at, t.min(self.end), level)?;
            }
            at = at.max(t);
            level += delta;
        }
        if self.end > at {
            push(at, self.end, level)?;
        }
        Ok(Program { segments })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;

    #[test]
    fn timeline_merges_overlaps_and_impulses() {
        let mut t = SnapTimeline::new();
        t.add(0, 3, 5);
        t.impulse(2, 1);
        t.impulse(5, -2);
        t.extend_to(7);
        let p = t.to_program().unwrap();
        assert_eq!(
            p.segments,
            vec![
                Segment { ticks: 2, snap: 5 },
                Segment { ticks: 1, snap: 6 },
                Segment { ticks: 2, snap: 0 },
                Segment { ticks: 1, snap: -2 },
                Segment { ticks: 1, snap: 0 },
            ]
        );
        assert_eq!(p.total_ticks(), 7);
    }

    #[test]
    fn bytes_round_trip_with_negative_snap() {
        let p = Program {
            segments: vec![
                Segment {
                    ticks: 7,
                    snap: -(1i128 << 100),
                },
                Segment {
                    ticks: u32::MAX,
                    snap: (1i128 << 102) - 1,
                },
            ],
        };
        let b = p.to_bytes(&DEFAULT_FORMAT).unwrap();
        assert_eq!(b.len(), 2 + 2 * (4 + 13));
        assert_eq!(Program::from_bytes(&b, &DEFAULT_FORMAT).unwrap(), p);
    }

    #[test]
    fn malformed_bytes_are_rejected() {
        assert!(Program::from_bytes(&[1], &DEFAULT_FORMAT).is_err());
        assert!(Program::from_bytes(&[1, 0, 0], &DEFAULT_FORMAT).is_err());
        // A zero-tick segment is not a valid program.
        let mut b = vec![1, 0, 0, 0, 0, 0];
        b.extend_from_slice(&[0u8; 13]);
        assert!(matches!(
            Program::from_bytes(&b, &DEFAULT_FORMAT),
            Err(ProgramError::ZeroTicks { index: 0 })
        ));
    }

    #[test]
    fn oversized_snap_is_rejected() {
        let p = Program {
            segments: vec![Segment {
                ticks: 1,
                snap: 1i128 << 103,
            }],
        };
        assert!(matches!(
            p.validate(&DEFAULT_FORMAT),
            Err(ProgramError::SnapTooLarge { .. })
        ));
    }
}
