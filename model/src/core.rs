//! Clock-accurate model of the motion core (`snapgen_hdl::core::MotionCore`): tick divider,
//! two-bank program memory, sequencer and integrator chain, updated once per fabric clock with
//! exactly the hardware's rules. Co-simulation drives this model and the Verilated core with
//! the same inputs and compares every output on every clock.
//!
//! Per clock, from the values before the edge:
//! * `tick = divider_count >= tick_div`; the divider restarts on reset or tick.
//! * The sequencer reads the *active* bank while busy and the *standby* bank while idle, at
//!   address `index + 1` (busy) or 0 (idle).
//! * A start (accepted only while idle and not stopped or reset) swaps the banks and loads
//!   segment 0; the bank that was active becomes standby with its count cleared.
//! * On a tick while busy the sequencer counts the tick down and moves to the next segment,
//!   dropping the snap to 0 and raising `done` after the last one.
//! * The chain steps with the snap register's value on every tick (see [`crate::chain`]);
//!   `stop` zeroes v, a, j at once; reset puts x at the centre of cell 0.
//! * Writes go to the standby bank.

use crate::chain::{wrap, ChainState};
use crate::format::{Format, Widths, FRAC_BITS};

/// Segments per bank.
pub const BANK_DEPTH: usize = 32;

/// The core's inputs for one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CoreInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// Clocks per tick minus one.
    pub tick_div: u32,
    /// Start the standby program.
    pub start: bool,
    /// Stop now (abort).
    pub stop: bool,
    /// Write one segment of the standby program.
    pub write_enable: bool,
    /// Segment address to write (0..32).
    pub write_address: u8,
    /// Tick count to write.
    pub write_ticks: u32,
    /// Snap to write (raw; the low `d` bits are stored).
    pub write_snap: i128,
    /// Set the standby program's segment count.
    pub count_enable: bool,
    /// Segment count (0..=32).
    pub count_value: u8,
    /// Cruise segment of the standby program, written with the count (63: none).
    pub cruise_value: u8,
    /// Controlled stop: end the cruise now (or as soon as it is reached) and decelerate as
    /// planned. Ignored while idle.
    pub soft_stop: bool,
}

/// The core's outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CoreOutputs {
    /// Position register.
    pub x: i128,
    /// Velocity register.
    pub v: i128,
    /// Acceleration register.
    pub a: i128,
    /// Jerk register.
    pub j: i128,
    /// Whole output LSBs: `x >> FRAC_BITS`, low 32 bits.
    pub position: u32,
    /// Segment playing.
    pub segment: u8,
    /// Playing.
    pub busy: bool,
    /// Last program finished.
    pub done: bool,
    /// Last program was stopped.
    pub aborted: bool,
    /// Ticks since the start.
    pub tick_count: u32,
    /// Tick enable (combinational, for the next edge).
    pub tick: bool,
    /// Bank playing.
    pub active_bank: bool,
    /// Segment count of the standby program.
    pub standby_count: u8,
}

/// The clock-accurate core model.
#[derive(Clone, Debug)]
pub struct CoreModel {
    widths: Widths,
    home: i128,
    mem_ticks: [[u32; BANK_DEPTH]; 2],
    mem_snap: [[i128; BANK_DEPTH]; 2],
    counts: [u8; 2],
    cruise: [u8; 2],
    skip: bool,
    bank: bool,
    aborted: bool,
    divider: u32,
    busy: bool,
    done: bool,
    index: u8,
    left: u32,
    snap: i128,
    tick_count: u32,
    chain: ChainState,
    tick_div: u32,
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
            cruise: [0; 2],
            skip: false,
            bank: false,
            aborted: false,
            divider: 0,
            busy: false,
            done: false,
            index: 0,
            left: 0,
            snap: 0,
            tick_count: 0,
            chain: ChainState::default(),
            tick_div: 0,
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
        let tick = self.divider >= i.tick_div;
        let read_bank = usize::from(self.bank ^ !self.busy);
        let count = self.counts[read_bank];
        let address = if self.busy {
            usize::from(self.index.wrapping_add(1)) % BANK_DEPTH
        } else {
            0
        };
        let entry_ticks = self.mem_ticks[read_bank][address];
        let entry_snap = self.mem_snap[read_bank][address];
        let next_index = (self.index + 1) & 0x3f;
        let started = !i.reset && !i.stop && i.start && !self.busy;
        let old_snap = self.snap;
        let old_bank = self.bank;
        // A controlled stop ends the cruise segment on its next tick.
        let cut = self.skip && self.index == self.cruise[read_bank];
        let old_busy = self.busy;

        // Sequencer.
        if i.reset {
            self.busy = false;
            self.done = false;
            self.index = 0;
            self.left = 0;
            self.snap = 0;
            self.tick_count = 0;
        } else if i.stop {
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
        } else if tick && self.busy {
            self.tick_count = self.tick_count.wrapping_add(1);
            if self.left == 1 || cut {
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

        // Chain (eqs 72–75 on a tick, from the snap register before the edge).
        if i.reset {
            self.chain = ChainState::at_rest(self.home);
        } else if i.stop {
            self.chain = ChainState::at_rest(self.chain.x);
        } else if tick {
            self.chain = self.chain.step(old_snap, &w);
        }

        // Tick divider.
        self.divider = if i.reset || tick {
            0
        } else {
            self.divider.wrapping_add(1)
        };

        // Banks and counts.
        if i.reset {
            self.bank = false;
            self.counts = [0; 2];
            self.cruise = [0; 2];
            self.aborted = false;
        } else if started {
            self.bank = !old_bank;
            self.aborted = false;
            self.counts[usize::from(old_bank)] = 0;
        } else if i.count_enable {
            self.counts[usize::from(!old_bank)] = i.count_value & 0x3f;
            self.cruise[usize::from(!old_bank)] = i.cruise_value & 0x3f;
        }
        // Controlled stop: armed while playing, cleared by a start or a reset.
        if i.reset || started {
            self.skip = false;
        } else if i.soft_stop && old_busy && !i.stop {
            self.skip = true;
        }
        if i.stop && !i.reset {
            self.aborted = true;
        }

        // Memory write (standby bank before the edge).
        if i.write_enable && !i.reset {
            let b = usize::from(!old_bank);
            let a = usize::from(i.write_address) % BANK_DEPTH;
            self.mem_ticks[b][a] = i.write_ticks;
            self.mem_snap[b][a] = wrap(i.write_snap, w.d);
        }

        self.tick_div = i.tick_div;
    }

    /// Changes the `tick_div` input between edges (the combinational `tick` output follows it
    /// at once, as the hardware's does).
    pub fn set_tick_div(&mut self, tick_div: u32) {
        self.tick_div = tick_div;
    }

    /// The outputs as they stand (after the last edge, with the last `tick_div`).
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
            tick_count: self.tick_count,
            tick: self.divider >= self.tick_div,
            active_bank: self.bank,
            standby_count: self.counts[usize::from(!self.bank)],
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
        let mut m = CoreModel::new(&f);
        m.clock(&CoreInputs {
            reset: true,
            ..Default::default()
        });
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
        assert_eq!(o.segment, 3);
        // A second start without a new upload plays nothing: the standby bank was emptied.
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        assert!(!m.busy() && m.outputs().done);
    }

    #[test]
    fn a_controlled_stop_cuts_the_cruise_and_lands_at_rest() {
        use crate::planner::{plan, Method, MoveRequest};
        let f = DEFAULT_FORMAT;
        let p = plan(
            &MoveRequest {
                distance: 0.5,
                method: Method::Order4 {
                    vmax: 1.0,
                    amax: 5.0,
                    jmax: 50.0,
                    dmax: 1000.0,
                },
            },
            &f,
        )
        .unwrap();
        let cruise = p.cruise_segment.expect("this move cruises");
        assert_eq!(p.program.segments[cruise].ticks, 15_000);
        let mut m = CoreModel::new(&f);
        m.clock(&CoreInputs {
            reset: true,
            ..Default::default()
        });
        for (k, s) in p.program.segments.iter().enumerate() {
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
            count_value: p.program.segments.len() as u8,
            cruise_value: cruise as u8,
            ..Default::default()
        });
        m.clock(&CoreInputs {
            start: true,
            ..Default::default()
        });
        // 35 000 ticks of acceleration, then 5 000 of cruise, then the stop.
        for _ in 0..40_000 {
            m.clock(&CoreInputs::default());
        }
        m.clock(&CoreInputs {
            soft_stop: true,
            ..Default::default()
        });
        while m.busy() {
            m.clock(&CoreInputs::default());
        }
        let played = u64::from(m.outputs().tick_count);
        let mut short = p.program.clone();
        short.segments[cruise].ticks -= (p.ticks_total() - played) as u32;
        let want = ChainState::at_rest(f.home_raw()).run_program(&short, &f.widths);
        assert!(played < p.ticks_total());
        assert_eq!(m.chain(), want);
        assert_eq!(p.end_after(played), want);
        assert!(m.chain().is_at_rest());
    }

    #[test]
    fn tick_divider_spaces_the_ticks() {
        let f = DEFAULT_FORMAT;
        let p = Program {
            segments: vec![Segment { ticks: 2, snap: 1 }],
        };
        let mut m = CoreModel::new(&f);
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
}
