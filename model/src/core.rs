//! Clock-accurate model of the motion core (`snapgen_hdl::core::MotionCore`): tick divider,
//! two-bank program memory, sequencer, the controlled-stop unit and the integrator chain,
//! updated once per fabric clock with exactly the hardware's rules. Co-simulation drives this
//! model and the Verilated core with the same inputs and compares every output on every clock.
//!
//! Per clock, from the values before the edge:
//! * `tick` is a register: after each edge it is `divider ≥ tick_div` (the divider after the
//!   edge, `tick_div` before it) unless the stop unit is computing its next snap after the
//!   edge (the tick then waits: the divider keeps counting and the tick comes on the first
//!   clock the snap is ready). A new `tick_div` counts from the clock after it is written.
//! * The sequencer reads the *active* bank while busy and the *standby* bank while idle, at
//!   address `index + 1` (busy) or 0 (idle).
//! * A start (accepted only while idle, not stopping, and without a pending stop, abort or
//!   reset) swaps the banks and loads segment 0; the bank that was active becomes standby with
//!   its count cleared.
//! * On a tick while busy the sequencer counts the tick down and moves to the next segment,
//!   dropping the snap to 0 and raising `done` after the last one.
//! * The chain steps on every tick (see [`crate::chain`]) with the sequencer's snap, or while
//!   stopping with the stop unit's.
//! * `stop` (a controlled stop, [`crate::stop`]) latches the stop limits and starts the stop
//!   unit's *Prep* phase (`prep` clocks of [`phase_clocks`], the move plays on); the first tick
//!   after it takes the stop: a program playing is cut there (busy falls, `aborted` rises;
//!   `done` is left: a program that ended first did run to its end), then the unit spends
//!   `init` clocks computing where its law begins and `decide` clocks before every tick
//!   choosing that tick's snap (ticks wait for it); when the
//!   registers are at rest it lets go (`stopping` falls). Requests while a stop runs are
//!   ignored.
//! * `abort_move` zeroes v, a and j at once (the emergency stop, with the amplifier off) and
//!   cancels a stop; reset puts x at the centre of cell 0; `load` puts it at the centre of
//!   cell `load_position` with v = a = j = 0 (the executor raises it only with the axis at
//!   rest and no program playing).
//! * `tick_count` counts the ticks since the last start while a program plays or a stop runs;
//!   `ticks` counts every tick since reset (64 bits).
//! * `at_rest` (registered) is v = a = j = 0 on the last clock; `heading_pos`/`heading_neg`
//!   (registered) give the sign of the first non-zero of v, a, j: where the axis goes next (a
//!   move from rest heads somewhere from its first tick).
//! * Writes go to the standby bank.
//! * `swap` arms a **program swap** for the tick T = `swap_last + 1` (low 32 bits of the time
//!   base): the tick that brings `ticks` from `swap_last` to T is still the old program's (or
//!   the idle chain's), and on it the sequencer loads segment 0 of the standby bank, as a start
//!   does, so the tick from T to T + 1 is the new program's first: the new program starts from
//!   the registers at T, as they are (nothing is reset). An arm is taken only when
//!   `swap_last − (ticks + 1) − 1`, modulo 2^32, is below 2^31 (with `ticks` before the
//!   edge: T lies 3 to 2^31 + 2 ticks ahead; wrap-safe), not while a stop is requested or
//!   runs, and not with a swap already armed; otherwise it changes nothing. A stop request, an abort or a reset cancels
//!   an armed swap; a start is not taken while one is armed.

use crate::chain::{wrap, ChainState};
use crate::format::{Format, Widths, FRAC_BITS};
use crate::stop::{phase_clocks, PhaseClocks, StopLaw, StopLimits};

/// Segments per bank.
pub const BANK_DEPTH: usize = snapgen_spec::widths::MAX_SEGMENTS as usize;
/// A segment index or count (`INDEX_BITS` wide) wraps with this mask.
const INDEX_MASK: u8 = ((1u32 << snapgen_spec::widths::INDEX_BITS) - 1) as u8;

pub use crate::ports::{CoreCommand, CoreInputs, CoreOutputs, CoreStatus};

/// Where the stop unit is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum StopPhase {
    /// No stop.
    #[default]
    Idle,
    /// Requested; computing what does not depend on the state: clocks left.
    Prep(u32),
    /// Ready to take the stop on the next tick.
    Armed,
    /// Computing where the law begins: clocks left.
    Init(u32),
    /// Choosing the next tick's snap: clocks left.
    Decide(u32),
    /// The next tick's snap is ready.
    Ready(i128),
}

/// The clock-accurate core model.
#[derive(Clone, Debug)]
pub struct CoreModel {
    widths: Widths,
    home: i128,
    mem_ticks: [[u32; BANK_DEPTH]; 2],
    mem_snap: [[i128; BANK_DEPTH]; 2],
    counts: [u8; 2],
    bank: bool,
    aborted: bool,
    divider: u32,
    busy: bool,
    done: bool,
    index: u8,
    left: u32,
    snap: i128,
    tick_count: u32,
    ticks: u64,
    chain: ChainState,
    /// The tick enable for the next edge (a register).
    tick: bool,
    clocks: PhaseClocks,
    stop_phase: StopPhase,
    stop_limits: StopLimits,
    stop_law: Option<StopLaw>,
    stop_over: bool,
    heading: i8,
    /// v = a = j = 0 before the last edge (a register).
    at_rest: bool,
    swap_pending: bool,
    swap_last: u32,
}

impl CoreModel {
    /// A core in its power-up state (all registers 0, memory 0), as the Verilog's initial
    /// values; apply a reset to home the position.
    pub fn new(format: &Format) -> Self {
        CoreModel {
            widths: format.widths,
            home: format.home_raw(),
            mem_ticks: [[0; BANK_DEPTH]; 2],
            mem_snap: [[0; BANK_DEPTH]; 2],
            counts: [0; 2],
            bank: false,
            aborted: false,
            divider: 0,
            busy: false,
            done: false,
            index: 0,
            left: 0,
            snap: 0,
            tick_count: 0,
            ticks: 0,
            chain: ChainState::default(),
            tick: false,
            clocks: phase_clocks(),
            stop_phase: StopPhase::Idle,
            stop_limits: StopLimits::default(),
            stop_law: None,
            stop_over: false,
            heading: 0,
            at_rest: false,
            swap_pending: false,
            swap_last: 0,
        }
    }

    /// The chain's registers.
    pub fn chain(&self) -> ChainState {
        self.chain
    }

    /// True while a program plays.
    pub fn busy(&self) -> bool {
        self.busy
    }

    /// True while a controlled stop is requested or runs.
    #[inline]
    pub fn stopping(&self) -> bool {
        self.stop_phase != StopPhase::Idle
    }

    /// Segment count of the standby program (0: nothing to start).
    pub fn standby_count(&self) -> u8 {
        self.counts[usize::from(!self.bank)]
    }

    /// One rising clock edge with inputs `i`; returns the outputs after it.
    #[inline]
    pub fn clock(&mut self, i: &CoreInputs) -> CoreOutputs {
        self.edge(i);
        self.outputs()
    }

    /// One rising clock edge with inputs `i` (read the outputs with [`CoreModel::outputs`]).
    #[inline]
    pub fn edge(&mut self, i: &CoreInputs) {
        let w = self.widths;
        // Combinational values before the edge.
        let tick = self.tick;
        // The armed swap is due on this tick: the state after it is the new program's start.
        let due = self.swap_pending
            && tick
            && self.ticks as u32 == self.swap_last
            && !i.reset
            && !i.abort_move
            && !i.stop;
        let fetch_first = !self.busy || due;
        let read_bank = usize::from(self.bank ^ fetch_first);
        let count = self.counts[read_bank];
        let address = if !fetch_first {
            usize::from(self.index.wrapping_add(1)) % BANK_DEPTH
        } else {
            0
        };
        let entry_ticks = self.mem_ticks[read_bank][address];
        let entry_snap = self.mem_snap[read_bank][address];
        let next_index = (self.index + 1) & INDEX_MASK;
        let stopping = self.stop_phase != StopPhase::Idle;
        // The stop has been taken: its ticks count.
        let engaged = matches!(
            self.stop_phase,
            StopPhase::Init(_) | StopPhase::Decide(_) | StopPhase::Ready(_)
        );
        let old_busy = self.busy;
        let started =
            !i.reset && !i.abort_move && i.start && !self.busy && !stopping && !self.swap_pending;
        let chain_snap = match self.stop_phase {
            StopPhase::Ready(d) => d,
            _ => self.snap,
        };
        let old_bank = self.bank;
        let engage = tick && self.stop_phase == StopPhase::Armed && !i.reset && !i.abort_move;

        // Sequencer.
        if i.reset {
            self.busy = false;
            self.done = false;
            self.index = 0;
            self.left = 0;
            self.snap = 0;
            self.tick_count = 0;
            self.ticks = 0;
        } else if i.abort_move {
            self.busy = false;
            self.snap = 0;
        } else if started {
            self.index = 0;
            self.tick_count = 0;
            if count == 0 {
                self.done = true;
                self.snap = 0;
            } else {
                self.busy = true;
                self.done = false;
                self.left = entry_ticks;
                self.snap = entry_snap;
            }
        } else if tick {
            if self.busy || engaged {
                self.tick_count = self.tick_count.wrapping_add(1);
            }
            if due {
                // The swap: segment 0 of the standby program from the next tick on.
                self.index = 0;
                self.tick_count = 0;
                if count == 0 {
                    self.busy = false;
                    self.done = true;
                    self.snap = 0;
                } else {
                    self.busy = true;
                    self.done = false;
                    self.left = entry_ticks;
                    self.snap = entry_snap;
                }
            } else if engage {
                // The stop takes the program's place from the next tick. DONE is left as it
                // is: false while a program plays (the program is cut), and a program that
                // ended before the stop was taken did run to its end.
                self.busy = false;
                self.snap = 0;
            } else if self.busy {
                if self.left == 1 {
                    self.index = next_index;
                    if next_index == count {
                        self.busy = false;
                        self.done = true;
                        self.snap = 0;
                    } else {
                        self.left = entry_ticks;
                        self.snap = entry_snap;
                    }
                } else {
                    self.left = self.left.wrapping_sub(1);
                }
            }
        }

        // The swap timer: armed only for a tick at least three ahead of the time base before
        // this edge; cancelled by a stop request, an abort or a reset; spent when due.
        let lead = i
            .swap_last
            .wrapping_sub((self.ticks as u32).wrapping_add(1))
            .wrapping_sub(1);
        if i.reset || i.abort_move || i.stop || due {
            self.swap_pending = false;
        } else if i.swap && !self.swap_pending && !stopping && lead < 1 << 31 {
            self.swap_pending = true;
            self.swap_last = i.swap_last;
        }

        // The time base: every tick since reset.
        if !i.reset && tick {
            self.ticks = self.ticks.wrapping_add(1);
        }

        // The heading and at-rest registers: the sign of the first non-zero of v, a, j.
        let c = self.chain;
        self.at_rest = c.v == 0 && c.a == 0 && c.j == 0;
        self.heading = if c.v != 0 {
            c.v.signum()
        } else if c.a != 0 {
            c.a.signum()
        } else {
            c.j.signum()
        } as i8;

        // Chain (eqs 72–75 on a tick, from the snap before the edge).
        if i.reset {
            self.chain = ChainState::at_rest(self.home);
        } else if i.abort_move {
            self.chain = ChainState::at_rest(self.chain.x);
        } else if i.load {
            let cell = i128::from(i.load_position as i32) << FRAC_BITS;
            self.chain = ChainState::at_rest(cell + (1 << (FRAC_BITS - 1)));
        } else if tick {
            self.chain = self.chain.step(chain_snap, &w);
        }

        // The stop unit.
        if i.reset || i.abort_move {
            self.stop_phase = StopPhase::Idle;
            self.stop_law = None;
            if i.reset {
                self.stop_over = false;
            }
        } else {
            let c = self.clocks;
            self.stop_phase = match self.stop_phase {
                StopPhase::Idle if i.stop => {
                    // The fabric's limit inputs are 104-bit unsigned.
                    let mask = (1i128 << w.d) - 1;
                    self.stop_limits = StopLimits {
                        jerk: i.stop_jerk & mask,
                        accel: i.stop_accel & mask,
                    };
                    StopPhase::Prep(c.prep)
                }
                StopPhase::Idle => StopPhase::Idle,
                StopPhase::Prep(n) if n > 1 => StopPhase::Prep(n - 1),
                StopPhase::Prep(_) => StopPhase::Armed,
                StopPhase::Armed if engage => StopPhase::Init(c.init),
                StopPhase::Armed => StopPhase::Armed,
                StopPhase::Init(n) if n > 1 => StopPhase::Init(n - 1),
                StopPhase::Init(_) => {
                    let s = self.chain;
                    let law = StopLaw::begin(s.v, s.a, s.j, self.stop_limits);
                    self.stop_over = law.over_limits();
                    self.stop_law = Some(law);
                    StopPhase::Decide(c.decide)
                }
                StopPhase::Decide(n) if n > 1 => StopPhase::Decide(n - 1),
                StopPhase::Decide(_) => {
                    let s = self.chain;
                    let law = self.stop_law.as_mut().expect("a law while deciding");
                    match law.next_jerk(s.v, s.a, s.j) {
                        Some(next) => StopPhase::Ready(wrap(next.wrapping_sub(s.j), w.d)),
                        None => {
                            self.stop_law = None;
                            StopPhase::Idle
                        }
                    }
                }
                StopPhase::Ready(_) if tick => StopPhase::Decide(c.decide),
                ready @ StopPhase::Ready(_) => ready,
            };
        }

        // Tick divider: counts on while a tick waits for the stop unit.
        self.divider = if i.reset || tick {
            0
        } else {
            self.divider.wrapping_add(1)
        };

        // Banks, counts and the cut-short flag.
        if i.reset {
            self.bank = false;
            self.counts = [0; 2];
            self.aborted = false;
        } else if started || due {
            self.bank = !old_bank;
            self.aborted = false;
            self.counts[usize::from(old_bank)] = 0;
        } else if i.count_enable {
            self.counts[usize::from(!old_bank)] = i.count_value & INDEX_MASK;
        }
        if !i.reset && (i.abort_move || engage) && old_busy {
            self.aborted = true;
        }

        // Memory write (standby bank before the edge).
        if i.write_enable && !i.reset {
            let b = usize::from(!old_bank);
            let a = usize::from(i.write_address) % BANK_DEPTH;
            self.mem_ticks[b][a] = i.write_ticks;
            self.mem_snap[b][a] = wrap(i.write_snap, w.d);
        }

        // The tick register: the divider is due and no stop computes after this edge.
        let computing = matches!(self.stop_phase, StopPhase::Init(_) | StopPhase::Decide(_));
        self.tick = self.divider >= i.tick_div && !computing;
    }

    /// The outputs as they stand (after the last edge).
    #[inline]
    pub fn outputs(&self) -> CoreOutputs {
        CoreOutputs {
            x: self.chain.x,
            v: self.chain.v,
            a: self.chain.a,
            j: self.chain.j,
            position: (self.chain.x >> FRAC_BITS) as u32,
            segment: self.index,
            busy: self.busy,
            done: self.done,
            aborted: self.aborted,
            stopping: self.stopping(),
            stop_over: self.stop_over,
            tick_count: self.tick_count,
            ticks: self.ticks,
            tick: self.tick,
            at_rest: self.at_rest,
            heading_pos: self.heading > 0,
            heading_neg: self.heading < 0,
            active_bank: self.bank,
            standby_count: self.counts[usize::from(!self.bank)],
            swap_pending: self.swap_pending,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;
    use crate::program::{Program, Segment};

    fn load(m: &mut CoreModel, p: &Program) {
        for (k, s) in p.segments.iter().enumerate() {
            m.clock(&CoreInputs {
                write_enable: true,
                write_address: k as u8,
                write_ticks: s.ticks,
                write_snap: s.snap,
                ..Default::default()
            });
        }
        m.clock(&CoreInputs {
            count_enable: true,
            count_value: p.segments.len() as u8,
            ..Default::default()
        });
    }

    fn reset() -> CoreModel {
        let mut m = CoreModel::new(&DEFAULT_FORMAT);
        m.clock(&CoreInputs {
            reset: true,
            ..Default::default()
        });
        m
    }

    #[test]
    fn core_plays_a_program_like_the_chain() {
        let f = DEFAULT_FORMAT;
        let p = Program {
            segments: vec![
                Segment { ticks: 3, snap: 5 },
                Segment { ticks: 1, snap: -7 },
                Segment { ticks: 4, snap: 2 },
            ],
        };
        let mut m = reset();
        load(&mut m, &p);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        let mut n = 0;
        while m.busy() {
            m.clock(&CoreInputs::default());
            n += 1;
        }
        assert_eq!(n, 8);
        let want = ChainState::at_rest(f.home_raw()).run_program(&p, &f.widths);
        assert_eq!(m.chain(), want);
        let o = m.outputs();
        assert!(o.done && !o.busy);
        assert_eq!(o.tick_count, 8);
        // Every clock has ticked since the reset (tick_div 0): the loads, the start and the 8.
        assert_eq!(o.ticks, p.segments.len() as u64 + 1 + 1 + 8);
        assert_eq!(o.segment, 3);
        // A second start without a new upload plays nothing: the standby bank was emptied.
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        assert!(!m.busy() && m.outputs().done);
    }

    /// A program swapped in by SWAP_AT that plays to its end while a STOP is being prepared
    /// (the STOP came 7 ticks after the swap tick; the preparation lasts longer than the
    /// program) ends DONE, not cut: the stop, taken from rest, cuts nothing. Before the fix
    /// the stop's taking cleared DONE, and the host saw neither DONE nor CUT.
    #[test]
    fn a_swapped_program_that_ends_while_a_stop_is_prepared_is_done() {
        let c = phase_clocks();
        let mut m = reset();
        let long = Program {
            segments: vec![Segment {
                ticks: 5_000,
                snap: 0,
            }],
        };
        load(&mut m, &long);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        let short = Program {
            segments: vec![Segment { ticks: 20, snap: 0 }],
        };
        assert!(u64::from(short.segments[0].ticks) + 7 < u64::from(c.prep));
        load(&mut m, &short);
        let at = m.outputs().ticks + 10;
        m.clock(&CoreInputs {
            swap: true,
            swap_last: (at - 1) as u32,
            ..Default::default()
        });
        while m.outputs().ticks < at + 7 {
            m.clock(&CoreInputs::default());
        }
        assert!(
            m.busy() && m.outputs().tick_count < 10,
            "the short program plays"
        );
        m.clock(&CoreInputs {
            stop: true,
            stop_jerk: 5,
            stop_accel: 1000,
            ..Default::default()
        });
        let mut clocks = 0;
        while m.busy() || m.stopping() {
            m.clock(&CoreInputs::default());
            clocks += 1;
            assert!(clocks < 100_000);
        }
        let o = m.outputs();
        assert!(o.done, "the program ran to its end: DONE");
        assert!(!o.aborted, "nothing was cut");
    }

    /// A controlled stop in the middle of a move: prepared while the move plays on, taken on
    /// the first tick after that, then `init` clocks to begin the law and `decide` clocks
    /// before every tick; the chain follows the stop law tick by tick (played here from the
    /// registers at the tick the stop was taken) and ends at rest.
    #[test]
    fn a_controlled_stop_follows_the_law_to_rest() {
        let c = phase_clocks();
        // An order-3 start: a jerk step to `d`, held for 20 000 ticks (the stop comes in it).
        let d = 1i128 << 40;
        let program = Program {
            segments: vec![
                Segment { ticks: 1, snap: d },
                Segment {
                    ticks: 20_000,
                    snap: 0,
                },
                Segment { ticks: 1, snap: -d },
            ],
        };
        let limits = StopLimits {
            jerk: 2 * d,
            accel: 1 << 90,
        };
        let mut m = reset();
        load(&mut m, &program);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        // 12 000 ticks into the jerk phase, then the stop request.
        for _ in 0..12_000 {
            m.clock(&CoreInputs::default());
        }
        let o = m.clock(&CoreInputs {
            stop: true,
            stop_jerk: limits.jerk,
            stop_accel: limits.accel,
            ..Default::default()
        });
        assert!(
            o.stopping && o.busy,
            "the move plays on while the stop prepares"
        );
        // The move plays on for `prep` clocks (a tick each: tick_div is 0), then the next
        // tick is its last and takes the stop.
        for _ in 0..c.prep {
            let o = m.clock(&CoreInputs::default());
            assert!(o.busy && o.stopping);
        }
        let at_take = {
            let before = m.chain();
            let o = m.clock(&CoreInputs::default());
            assert!(o.stopping && !o.busy && o.aborted);
            assert_ne!(m.chain(), before);
            m.chain()
        };
        // No tick for init + decide clocks, then one every decide + 1.
        let mut clocks = 0u32;
        while !m.outputs().tick {
            m.clock(&CoreInputs::default());
            clocks += 1;
        }
        assert_eq!(clocks, c.init + c.decide);
        let (want, law) = crate::stop::play(at_take, limits, 1 << 30);
        assert!(!law.over_limits());
        let mut got = Vec::new();
        let mut gaps = std::collections::BTreeSet::new();
        let mut since = 0u32;
        while m.stopping() {
            let tick = m.outputs().tick;
            m.clock(&CoreInputs::default());
            since += 1;
            if tick {
                got.push(m.chain());
                gaps.insert(since);
                since = 0;
            }
        }
        assert_eq!(got, want);
        assert!(m.chain().is_at_rest());
        assert_eq!(gaps.into_iter().skip(1).collect::<Vec<_>>(), [c.decide + 1]);
        // The 12 000 ticks, the request's, the prep's, the one that took the stop, the stop's.
        assert_eq!(
            u64::from(m.outputs().tick_count),
            12_002 + u64::from(c.prep) + want.len() as u64
        );
    }

    #[test]
    fn tick_divider_spaces_the_ticks() {
        let p = Program {
            segments: vec![Segment { ticks: 2, snap: 1 }],
        };
        let mut m = CoreModel::new(&DEFAULT_FORMAT);
        m.clock(&CoreInputs {
            reset: true,
            tick_div: 2,
            ..Default::default()
        });
        load(&mut m, &p);
        let idle = CoreInputs {
            tick_div: 2,
            ..Default::default()
        };
        m.clock(&CoreInputs {
            start: true,
            ..idle
        });
        let mut clocks = 0;
        while m.busy() {
            m.clock(&idle);
            clocks += 1;
        }
        assert!((4..=6).contains(&clocks), "{clocks}");
        assert_eq!(m.outputs().tick_count, 2);
    }

    /// The emergency stop: v = a = j = 0 at once, and a stop in progress is cancelled.
    #[test]
    fn an_abort_holds_the_position_at_once() {
        let p = Program {
            segments: vec![Segment { ticks: 50, snap: 3 }],
        };
        let mut m = reset();
        load(&mut m, &p);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        for _ in 0..20 {
            m.clock(&CoreInputs::default());
        }
        m.clock(&CoreInputs {
            stop: true,
            stop_jerk: 1,
            stop_accel: 10,
            ..Default::default()
        });
        let x = m.chain().x;
        let o = m.clock(&CoreInputs {
            abort_move: true,
            ..Default::default()
        });
        assert!(!o.busy && !o.stopping && o.aborted);
        assert_eq!(m.chain(), ChainState::at_rest(x));
    }

    /// A swap armed for tick T mid-move: the old program plays up to T, the new one from the
    /// registers at T (nothing reset), and the chain equals the old program's first T − t0
    /// ticks followed by the whole new program, stepped independently.
    #[test]
    fn a_swap_continues_from_the_registers_at_its_tick() {
        let f = DEFAULT_FORMAT;
        let old = Program {
            segments: vec![
                Segment { ticks: 40, snap: 9 },
                Segment {
                    ticks: 40,
                    snap: -9,
                },
            ],
        };
        let new = Program {
            segments: vec![
                Segment { ticks: 3, snap: -4 },
                Segment { ticks: 5, snap: 2 },
            ],
        };
        let mut m = reset();
        load(&mut m, &old);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        let t0 = m.outputs().ticks;
        load(&mut m, &new);
        let at = m.outputs().ticks + 10;
        let o = m.clock(&CoreInputs {
            swap: true,
            swap_last: (at - 1) as u32,
            ..Default::default()
        });
        assert!(o.swap_pending && o.busy);
        // Play until the time base reaches T: the state there is the old program's.
        while m.outputs().ticks < at {
            m.clock(&CoreInputs::default());
        }
        let o = m.outputs();
        assert!(!o.swap_pending && o.busy && o.segment == 0 && o.tick_count == 0);
        let head = Program {
            segments: vec![Segment {
                ticks: (at - t0) as u32,
                snap: 9,
            }],
        };
        let at_t = ChainState::at_rest(f.home_raw()).run_program(&head, &f.widths);
        assert_eq!(m.chain(), at_t);
        let mut n = 0;
        while m.busy() {
            m.clock(&CoreInputs::default());
            n += 1;
        }
        assert_eq!(n, 8);
        assert_eq!(m.chain(), at_t.run_program(&new, &f.widths));
        assert_eq!(
            m.outputs().standby_count,
            0,
            "the swap consumed the program"
        );
    }

    /// An arm for a tick the time base has reached, or less than three ticks ahead of it
    /// (before the arming edge), or 2^31 + 3 or more ahead, is not taken: nothing changes, the
    /// old program plays on and the standby program stays.
    #[test]
    fn a_late_swap_changes_nothing() {
        let old = Program {
            segments: vec![Segment { ticks: 30, snap: 5 }],
        };
        let new = Program {
            segments: vec![Segment { ticks: 3, snap: -4 }],
        };
        // d = T − ticks (before the arming edge): accepted only in 3..2^31 + 3.
        for d in [-5i64, -1, 0, 1, 2, (1 << 31) + 3, (1 << 32) - 1] {
            let mut a = reset();
            load(&mut a, &old);
            a.clock(&CoreInputs {
                start: true,
                ..Default::default()
            });
            load(&mut a, &new);
            let mut b = a.clone();
            let at = a.outputs().ticks.wrapping_add(d as u64);
            a.clock(&CoreInputs {
                swap: true,
                swap_last: at.wrapping_sub(1) as u32,
                ..Default::default()
            });
            b.clock(&CoreInputs::default());
            assert_eq!(a.outputs(), b.outputs(), "T − ticks = {d}");
            while a.busy() {
                a.clock(&CoreInputs::default());
                b.clock(&CoreInputs::default());
                assert_eq!(a.outputs(), b.outputs());
            }
            assert_eq!(a.outputs().standby_count, 1);
        }
        // The window's ends are taken.
        for d in [3u64, (1 << 31) + 2] {
            let mut a = reset();
            load(&mut a, &new);
            let at = a.outputs().ticks + d;
            let o = a.clock(&CoreInputs {
                swap: true,
                swap_last: (at - 1) as u32,
                ..Default::default()
            });
            assert!(o.swap_pending, "T − ticks = {d}");
        }
    }

    /// A stop request cancels an armed swap: the stop runs, the swap never happens.
    #[test]
    fn a_stop_cancels_an_armed_swap() {
        let old = Program {
            segments: vec![
                Segment { ticks: 30, snap: 5 },
                Segment {
                    ticks: 30,
                    snap: -5,
                },
            ],
        };
        let new = Program {
            segments: vec![Segment { ticks: 3, snap: -4 }],
        };
        let mut m = reset();
        load(&mut m, &old);
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        load(&mut m, &new);
        let at = m.outputs().ticks + 2000;
        m.clock(&CoreInputs {
            swap: true,
            swap_last: (at - 1) as u32,
            ..Default::default()
        });
        let o = m.clock(&CoreInputs {
            stop: true,
            stop_jerk: 100,
            stop_accel: 1000,
            ..Default::default()
        });
        assert!(!o.swap_pending && o.stopping);
        while m.outputs().ticks < at + 10 {
            m.clock(&CoreInputs::default());
        }
        assert_eq!(
            m.outputs().standby_count,
            1,
            "the swap never took the program"
        );
    }
}
