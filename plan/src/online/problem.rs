//! From a continuous profile ([`super::transition`], [`super::position`]) to the discrete
//! problem [`super::exact`] solves: pieces of whole ticks, which of their levels are free, and
//! the end conditions.

use arrayvec::ArrayVec;

use snapgen_model::chain::ChainState;

use super::exact::{to_f64, Caps, Condition, DPiece, Problem, MAX_FREE, MAX_PIECES};
use super::position::{self, PositionProfile};
use super::transition::{self, TickLimits, Transition};
use super::{Cases, OnlineError, OnlineTarget, RawLimits};

/// How a piece's real duration becomes whole ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Rounding {
    /// Up (1e-6-tick tolerance, as the other planners): the levels can only come out lower.
    Up,
    /// To the nearest whole tick: what a plan from a state on one of the planner's own
    /// trajectories usually needs to find that trajectory's own tick counts again.
    Nearest,
}

impl Rounding {
    /// Ticks of a piece of real duration `t`, at least `min`.
    fn ticks(self, t: f64, min: u64) -> u64 {
        let n = match self {
            Rounding::Up => crate::planner::ceil_ticks(t),
            Rounding::Nearest => {
                let r = crate::planner::fmath::round(t);
                if r.is_finite() && r > 0.0 {
                    r.min((u64::MAX / 4) as f64) as u64
                } else {
                    0
                }
            }
        };
        n.max(min)
    }
}

/// Which continuous profile an attempt realises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Profile {
    /// The time-optimal one ([`position::plan`]).
    Optimal,
    /// Brake to the end speed at once, its rounding taken up at the end ([`position::ease`]).
    Ease,
}

/// Where the continuous profile a program realises starts, seen from the registers.
///
/// The chain integrates with the left rectangle rule (`x += v; v += a; a += j`, seed 000 eqs
/// 72–75), so its registers at tick `k` are a continuous profile's `X(k)`, `V(k + ½)`,
/// `A(k + 1)`, and the jerk register holds the continuous jerk of `[k + 1, k + 2]` (exact for a
/// piecewise-linear acceleration, to `J/8` where the jerk changes). A program's first piece
/// sets the jerk on tick 1, so it acts from continuous time 2, and every piece then spans as
/// many units as it has ticks; the end, where the acceleration reaches zero, is one tick past
/// the program's last (the settle). Planning the continuous profile from the state at time 2
/// — `X = x + 2v + a`, `V = v + 3a/2 + 3j/8`, `A = a + j` — rather than from the registers
/// themselves makes its durations the programs' tick counts up to their fractions, instead of
/// up to a tick or two of acceleration: what lets a plan from a state on one of the planner's
/// own trajectories find that trajectory's tick counts again. Order 2: the first level acts on
/// the acceleration from tick 2, time 2½, where `V = v + 2a + j` and `X = x + 5v/2 + 2a + j/2`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Continuous {
    /// Velocity (raw per tick).
    pub v: f64,
    /// Acceleration (raw per tick²; 0 for order 2, whose levels step).
    pub a: f64,
    /// Position past the register (raw).
    pub dx: f64,
}

impl Continuous {
    /// The continuous start for a program of order `o` played from `s`.
    pub fn of(s: &ChainState, o: u8) -> Continuous {
        let (v, a, j) = (to_f64(s.v), to_f64(s.a), to_f64(s.j));
        if o == 2 {
            Continuous {
                v: v + 2.0 * a + j,
                a: 0.0,
                dx: 2.5 * v + 2.0 * a + 0.5 * j,
            }
        } else {
            Continuous {
                v: v + 1.5 * a + 0.375 * j,
                a: a + j,
                dx: 2.0 * v + a,
            }
        }
    }
}

/// What every attempt at one plan shares.
pub(super) struct Setup<'a> {
    pub start: &'a ChainState,
    pub target: OnlineTarget,
    /// Order (3 or 2).
    pub o: u8,
    pub lim: RawLimits,
    /// The end velocity (raw).
    pub v_end: i128,
    /// The start's acceleration magnitude over its first tick.
    pub a_entry: i128,
    pub caps: Caps,
    /// The continuous profile's start.
    pub cont: Continuous,
    /// Position targets: the centre of the target cell (raw), the distance to the goal the
    /// program's main part aims at (raw, real), and the direction (`±1`, chosen once with the
    /// true limits so that no attempt with lowered ones reverses where the first would not).
    pub goal: Option<(i128, f64, f64)>,
}

/// A discrete problem with its caps, the seed 002 cases it went through and the continuous
/// profile's duration.
pub(super) struct Built {
    pub problem: Problem,
    pub caps: Caps,
    pub cases: Cases,
    pub continuous: f64,
}

/// Appends the discrete pieces of a transition: jerk pieces free (order 3), the hold fixed at
/// zero jerk; order 2: its acceleration piece free.
///
/// A jerk piece keeps at least one tick so that its level stays free. Where its real duration
/// is under a tick and a hold lies beside it (a start already holding its acceleration, an end
/// that only releases one), that tick comes out of the hold: the two are rounded together, as
/// one stretch at nearly the same acceleration, and the transition does not grow by a tick it
/// would have to carry the axis through.
fn push_transition(
    pieces: &mut ArrayVec<DPiece, MAX_PIECES>,
    guess: &mut [f64; MAX_FREE],
    free: &mut usize,
    t: &Transition,
    order: u8,
    cap: usize,
    rounding: Rounding,
) {
    let ps = t.pieces();

    let mut ticks = [0u64; 3];
    for (n, p) in ticks.iter_mut().zip(ps) {
        *n = rounding.ticks(p.t, 0);
    }
    if order == 3 && ps.len() == 3 && ps[1].t > 0.0 {
        let short = |p: &super::transition::Piece| p.t < 1.0 - 1e-6;
        let (first, last) = (short(&ps[0]), short(&ps[2]));
        if first || last {
            let mut span = ps[1].t;
            let mut taken = 0;
            for (i, s) in [(0, first), (2, last)] {
                if s {
                    span += ps[i].t;
                    ticks[i] = 1;
                    taken += 1;
                }
            }
            ticks[1] = rounding.ticks(span, 0).saturating_sub(taken);
        }
    }
    for (i, p) in ps.iter().enumerate() {
        let is_hold = order == 3 && i == 1;
        if is_hold {
            if ticks[i] > 0 {
                pieces.push(DPiece {
                    ticks: ticks[i],
                    free: None,
                    cap,
                    slack: true,
                    held: if t.rise { 1 } else { -1 },
                });
            }
        } else {
            guess[*free] = p.level;
            pieces.push(DPiece {
                ticks: ticks[i].max(1),
                free: Some(*free),
                cap,
                slack: false,
                held: 0,
            });
            *free += 1;
        }
    }
}

/// The cases of a transition.
fn cases_of(t: &Transition) -> (bool, transition::Entry, transition::Shape) {
    (t.rise, t.entry, t.shape)
}

/// The discrete problem for planning limits `tick` (the true ones in `setup.lim`), every piece
/// but the settle lengthened by `extra` ticks; `None` when no continuous profile in the plan's
/// direction exists with these planning limits.
pub(super) fn build(
    setup: &Setup,
    tick: &TickLimits,
    extra: u64,
    rounding: Rounding,
    profile: Profile,
) -> Result<Option<Built>, OnlineError> {
    let (o, lim) = (setup.o, &setup.lim);
    let (v0, a0) = (setup.cont.v, setup.cont.a);
    let raw_of = |a: f64| {
        if a == tick.acc {
            lim.acc
        } else {
            lim.dec
        }
    };
    let mut guess = [0.0; MAX_FREE];
    let mut free = 0;
    let mut pieces = ArrayVec::new();
    let mut conditions = ArrayVec::new();
    let mut cruise = None;
    let push =
        |pieces: &mut ArrayVec<DPiece, MAX_PIECES>,
         guess: &mut [f64; MAX_FREE],
         free: &mut usize,
         t: &Transition,
         cap: usize| { push_transition(pieces, guess, free, t, o, cap, rounding) };
    let (cases, continuous, x_centre, rise, caps) = match (setup.target, setup.goal) {
        (OnlineTarget::Velocity(_), _) | (_, None) => {
            let t = transition::velocity(o, v0, a0, setup.v_end as f64, tick);
            push(&mut pieces, &mut guess, &mut free, &t, 0);
            let caps = Caps {
                a: [raw_of(t.accel_limit).max(setup.a_entry), 0, setup.caps.a[2]],
                ..setup.caps
            };
            let cases = Cases {
                first: cases_of(&t),
                second: None,
                branch: None,
            };
            (cases, t.duration(), 0, t.rise, caps)
        }
        (OnlineTarget::Position { .. }, Some((centre, dist, dir))) => {
            let plan = match profile {
                Profile::Optimal => position::plan,
                Profile::Ease => position::ease,
            };
            let Some(prof) = plan(o, v0, a0, dist, setup.v_end as f64, dir, tick) else {
                return Ok(None);
            };
            match prof {
                PositionProfile::Through {
                    branch,
                    first,
                    cruise: c,
                    second,
                    ..
                } => {
                    push(&mut pieces, &mut guess, &mut free, &first, 0);
                    cruise = Some(pieces.len());
                    pieces.push(DPiece {
                        ticks: rounding.ticks(c, 1),
                        free: None,
                        cap: 2,
                        slack: true,
                        held: 0,
                    });
                    if o == 3 {
                        conditions.push(Condition::A(pieces.len() - 1));
                    }
                    push(&mut pieces, &mut guess, &mut free, &second, 1);
                    let caps = Caps {
                        a: [
                            raw_of(first.accel_limit).max(setup.a_entry),
                            raw_of(second.accel_limit),
                            setup.caps.a[2],
                        ],
                        ..setup.caps
                    };
                    let cases = Cases {
                        first: cases_of(&first),
                        second: Some(cases_of(&second)),
                        branch: Some(branch),
                    };
                    (cases, prof.duration(), centre, second.rise, caps)
                }
                PositionProfile::Partial { release, fall } => {
                    // The release: a free jerk piece before the fall.
                    guess[free] = release.level;
                    pieces.push(DPiece {
                        ticks: rounding.ticks(release.t, 1),
                        free: Some(free),
                        cap: 0,
                        slack: false,
                        held: 0,
                    });
                    free += 1;
                    push(&mut pieces, &mut guess, &mut free, &fall, 0);
                    let a_fall = raw_of(fall.accel_limit).max(setup.a_entry);
                    let caps = Caps {
                        a: [a_fall, a_fall, setup.caps.a[2]],
                        ..setup.caps
                    };
                    let cases = Cases {
                        first: cases_of(&fall),
                        second: None,
                        branch: Some(prof.branch()),
                    };
                    (cases, prof.duration(), centre, fall.rise, caps)
                }
            }
        }
    };
    // The settle piece: the highest derivative back to zero (order 2 needs two ticks: the
    // acceleration step and the jerk back to zero).
    pieces.push(DPiece {
        ticks: if o == 2 { 2 } else { 1 },
        free: None,
        cap: 2,
        slack: false,
        held: 0,
    });
    if o == 3 {
        conditions.push(Condition::A(pieces.len() - 1));
    }
    conditions.push(Condition::V);
    if setup.goal.is_some() {
        conditions.push(Condition::X);
    }
    debug_assert_eq!(conditions.len(), free);
    let settle = pieces.len() - 1;
    for d in &mut pieces[..settle] {
        d.ticks += extra;
    }
    // The tick counter and the closed form's binomials bound a piece (2^40 ticks is 127 days
    // at 10 µs): longer is refused, never wrapped.
    if pieces.iter().any(|d| d.ticks >= 1 << 40) {
        return Err(OnlineError::Overflow);
    }
    // The side the end velocity is approached from: the last transition's, except at rest
    // after a position move, which is approached from its direction whatever the last
    // transition (a pulse from rest to rest, `Branch::Ease`, rises and falls back).
    let approach = match setup.goal {
        Some((_, _, dir)) if setup.v_end == 0 => -(dir as i128),
        _ => {
            if rise {
                1
            } else {
                -1
            }
        }
    };
    let problem = Problem {
        order: o,
        pieces,
        free,
        conditions,
        v_end: setup.v_end,
        approach,
        x_centre,
        guess,
        cruise,
    };
    Ok(Some(Built {
        problem,
        caps,
        cases,
        continuous,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_model::format::Widths;

    /// The chain's registers are the continuous profile's X(k), V(k + ½), A(k + 1): a program
    /// of jerk pieces played tick by tick lands where the continuous profile from
    /// [`Continuous::of`] integrated exactly over the pieces' tick counts says, to the
    /// rectangle rule's `J/8`-sized terms at the pieces' joints.
    #[test]
    fn the_continuous_start_is_where_the_chain_plays_from() {
        let w = Widths {
            x: 127,
            v: 127,
            a: 127,
            j: 127,
            d: 127,
        };
        let starts = [
            ChainState::at_rest(0),
            ChainState {
                x: 0,
                v: 1_000_000_000,
                a: 0,
                j: 0,
            },
            ChainState {
                x: 0,
                v: 5_000_000_000,
                a: -3_000_000,
                j: 0,
            },
            ChainState {
                x: 0,
                v: -2_000_000_000,
                a: 4_000_000,
                j: -7_000,
            },
        ];
        // (jerk level, ticks) and a settle tick of zero jerk.
        let program = [
            (9_000i128, 300u64),
            (0, 120),
            (-9_000, 300),
            (-4_000, 77),
            (0, 1),
        ];
        for s in starts {
            // Discrete: each piece sets its jerk on its first tick.
            let mut d = s;
            for &(level, n) in &program {
                d = d.step(level - d.j, &w);
                for _ in 1..n {
                    d = d.step(0, &w);
                }
            }
            // Continuous: from time 2, exact per piece; the settle's zero jerk ends it.
            let c = Continuous::of(&s, 3);
            let (mut x, mut v, mut a) = (to_f64(s.x) + c.dx, c.v, c.a);
            let free = &program[..program.len() - 1];
            for &(level, n) in free {
                let (t, l) = (n as f64, level as f64);
                x += v * t + a * t * t / 2.0 + l * t * t * t / 6.0;
                v += a * t + l * t * t / 2.0;
                a += l * t;
            }
            // The program's last tick N: a_N = A(N + 1), the continuous end.
            assert_eq!(to_f64(d.a), a, "{s:?}: acceleration");
            // v_N = V(N + ½) = V(N + 1) − A/2 + L/8 (the last piece's jerk L over the half
            // tick), and x_N = X(N + 1) − V(N + ½).
            let last = free[free.len() - 1].0 as f64;
            let v_half = v - a / 2.0 + last / 8.0;
            let joints = free.len() as f64;
            let tol_v = joints * 9_000.0 / 4.0 + 7_000.0;
            assert!(
                (to_f64(d.v) - v_half).abs() <= tol_v,
                "{s:?}: v {} vs {v_half}",
                d.v
            );
            let ticks: u64 = program.iter().map(|p| p.1).sum();
            let tol_x = tol_v * ticks as f64;
            assert!(
                (to_f64(d.x) - (x - v_half)).abs() <= tol_x,
                "{s:?}: x {} vs {}",
                d.x,
                x - v_half
            );
        }
    }
}
