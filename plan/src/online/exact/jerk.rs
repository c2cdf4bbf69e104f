//! The jerk pieces of a problem in play order (order 2's acceleration levels become jerk
//! impulses and holds).

use super::*;

/// The jerk of a jerk piece: `c + p[plus] − p[minus]` (order 3: a free level or zero; order 2:
/// the impulse from the previous acceleration level to this one).
#[derive(Clone, Copy, Debug)]
pub(super) struct JerkLevel {
    pub(super) c: i128,
    pub(super) plus: Option<usize>,
    pub(super) minus: Option<usize>,
}

impl JerkLevel {
    pub(super) fn affine(&self) -> Affine {
        let mut a = Affine::constant(to_f64(self.c));
        if let Some(i) = self.plus {
            a.0[1 + i] += 1.0;
        }
        if let Some(i) = self.minus {
            a.0[1 + i] -= 1.0;
        }
        a
    }

    pub(super) fn exact(&self, lv: &[i128; MAX_FREE]) -> Option<i128> {
        let mut l = self.c;
        if let Some(i) = self.plus {
            l = l.checked_add(lv[i])?;
        }
        if let Some(i) = self.minus {
            l = l.checked_sub(lv[i])?;
        }
        Some(l)
    }
}

/// A jerk piece: ticks, jerk, the cap index, and whether it ends its problem piece.
#[derive(Clone, Copy, Debug)]
pub(super) struct JerkPiece {
    pub(super) ticks: u64,
    pub(super) level: JerkLevel,
    pub(super) cap: usize,
    pub(super) ends_piece: bool,
}

/// The jerk pieces of a problem, generated in play order: order 3 as given; order 2 turns each
/// acceleration level `A` into a jerk impulse `A − A_prev` on its first tick and zero jerk for
/// the rest.
#[derive(Clone)]
pub(super) struct JerkPieces<'p> {
    pub(super) p: &'p Problem,
    /// The next problem piece.
    pub(super) i: usize,
    /// Order 2: the impulse of piece `i` was given, its hold comes next.
    pub(super) hold_next: bool,
    /// Order 2: the acceleration level before piece `i`.
    pub(super) prev: JerkLevel,
}

pub(super) const ZERO_JERK: JerkLevel = JerkLevel {
    c: 0,
    plus: None,
    minus: None,
};

pub(super) fn jerk_pieces<'p>(p: &'p Problem, start: &ChainState) -> JerkPieces<'p> {
    JerkPieces {
        p,
        i: 0,
        hold_next: false,
        // The acceleration of the first tick is already decided: a + j.
        prev: JerkLevel {
            c: start.a.saturating_add(start.j),
            plus: None,
            minus: None,
        },
    }
}

impl Iterator for JerkPieces<'_> {
    type Item = JerkPiece;

    #[inline]
    fn next(&mut self) -> Option<JerkPiece> {
        let d = self.p.pieces.get(self.i)?;
        if self.p.order != 2 {
            self.i += 1;
            return Some(JerkPiece {
                ticks: d.ticks,
                level: JerkLevel {
                    c: 0,
                    plus: d.free,
                    minus: None,
                },
                cap: d.cap,
                ends_piece: true,
            });
        }
        if self.hold_next {
            self.hold_next = false;
            self.i += 1;
            return Some(JerkPiece {
                ticks: d.ticks - 1,
                level: ZERO_JERK,
                cap: d.cap,
                ends_piece: true,
            });
        }
        let impulse = JerkLevel {
            c: -self.prev.c,
            plus: d.free,
            minus: self.prev.plus,
        };
        self.prev = JerkLevel {
            c: 0,
            plus: d.free,
            minus: None,
        };
        if d.ticks > 1 {
            self.hold_next = true;
        } else {
            self.i += 1;
        }
        Some(JerkPiece {
            ticks: 1,
            level: impulse,
            cap: d.cap,
            ends_piece: d.ticks == 1,
        })
    }
}
