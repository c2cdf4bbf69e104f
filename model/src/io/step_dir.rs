//! The step/dir generator clock by clock (the fabric's `snapgen_step_dir`,
//! `hdl/verilog/step_dir.v`, register for register; issue 22): a stepper drive's step and
//! direction lines made from an axis's whole-LSB position.
//!
//! The step grid: while disabled the generator anchors it at the position (`down` = the
//! position, `up` = the position + `step_lsb`, no pulse); once enabled, a step is due upward
//! when the position reaches `up` and downward when it falls below `down`, each step moving
//! both edges by `step_lsb`. So after any motion the steps issued are
//! `⌊(position − anchor) / step_lsb⌋` once the pulses have caught up: the exact integer
//! position, no rounding of its own. (Positions wrap at 32 bits; the comparisons are on
//! wrapping differences, right while the position stays within 2³¹ LSB of the edges.)
//!
//! One step: a clock to decide it (idle), `high_clocks` with the step line high (the step is
//! counted on its rising edge), `low_clocks` low. A change of direction first holds the new
//! direction for `setup_clocks` before the rising edge; the direction never changes during a
//! pulse or its low time, so it holds `high_clocks + low_clocks` after each rising edge. The
//! fastest pulse train is one step per `1 + high + low` clocks ([`max_steps_per_second`]):
//! an axis faster than that falls behind, and once the position is more than a whole step
//! ahead of the pulses `overrun` is raised (sticky until disabled or reset). A reversal costs
//! the setup time too: at most one step per `2 + high + low + setup` clocks
//! ([`safe_steps_per_second`]) never raises it. Disabling lets
//! a pulse that has begun finish, then anchors the grid again. `due` says, a clock late, that a
//! step not yet begun was due (the pulses are behind the position): a stage that moves the
//! position in jumps (the path steppers, once per tick) uses it to tell pulses that could not
//! follow from a jump of several steps that they will.

use crate::ports::{StepDirInputs, StepDirOutputs};

/// The generator's states (`state` in the fabric).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    /// Deciding the next step (or anchoring the grid while disabled).
    #[default]
    Idle = 0,
    /// The direction changed: held before the next rising edge.
    Setup = 1,
    /// The step line is high.
    High = 2,
    /// The step line is low after a pulse.
    Low = 3,
}

/// The generator's registers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StepDir {
    /// State.
    pub phase: Phase,
    /// Clocks left in the state, minus one.
    pub timer: u16,
    /// The direction line.
    pub dir: bool,
    /// The step line.
    pub step: bool,
    /// The next upward step's edge (a position).
    pub up: u32,
    /// The next downward step's edge: a step down is due below it.
    pub down: u32,
    /// Steps issued since enabled.
    pub steps: u32,
    /// The position ran more than a step ahead of the pulses.
    pub overrun: bool,
    /// On the last edge a step was due that did not begin there.
    pub due: bool,
}

/// `x` with 0 taken as 1 (a length or a time of zero clocks would be none).
fn at_least_one(x: u16) -> u16 {
    x.max(1)
}

/// The fastest pulse train the timing allows, in steps per second at `clock_hz`: one step per
/// `1 + high + low` clocks (the decision, the high and the low time).
pub fn max_steps_per_second(clock_hz: f64, high_clocks: u16, low_clocks: u16) -> f64 {
    clock_hz / (1.0 + f64::from(at_least_one(high_clocks)) + f64::from(at_least_one(low_clocks)))
}

/// The pulse rate a motion may use with no overrun even when every step reverses, in steps per
/// second at `clock_hz`: one step per `2 + high + low + setup` clocks (a reversal adds the
/// setup time and a decision). An axis whose velocity limit, in steps, stays within it never
/// raises `overrun`; between this and [`max_steps_per_second`] it may on a reversal at speed.
pub fn safe_steps_per_second(
    clock_hz: f64,
    high_clocks: u16,
    low_clocks: u16,
    setup_clocks: u16,
) -> f64 {
    clock_hz
        / (2.0
            + f64::from(at_least_one(high_clocks))
            + f64::from(at_least_one(low_clocks))
            + f64::from(at_least_one(setup_clocks)))
}

impl StepDir {
    /// At power-up: disabled, idle, both lines low.
    pub fn new() -> Self {
        Self::default()
    }

    /// The outputs after the last clock.
    pub fn outputs(&self) -> StepDirOutputs {
        StepDirOutputs {
            step: self.step,
            dir: self.dir,
            steps: self.steps,
            overrun: self.overrun,
            due: self.due,
        }
    }

    /// One clock edge with inputs `i`.
    pub fn clock(&mut self, i: &StepDirInputs) {
        let old = self.clone();
        let k = u32::from(at_least_one(i.step_lsb));
        if i.reset {
            *self = StepDir {
                up: i.position.wrapping_add(k),
                down: i.position,
                ..StepDir::default()
            };
            return;
        }
        // Wrapping differences: "at or past" is a non-negative difference.
        let ahead = |a: u32, b: u32| (a.wrapping_sub(b) as i32) >= 0;
        let want_up = ahead(i.position, old.up);
        let want_down = !ahead(i.position, old.down);
        // A step is due that does not begin on this edge (in Idle with the direction right,
        // it does).
        let begins = old.phase == Phase::Idle && old.dir == want_up;
        self.due = i.enable && (want_up || want_down) && !begins;
        if !i.enable {
            self.overrun = false;
        } else if ahead(i.position, old.up.wrapping_add(k))
            || !ahead(i.position, old.down.wrapping_sub(k))
        {
            self.overrun = true;
        }
        match old.phase {
            Phase::Idle => {
                if !i.enable {
                    self.up = i.position.wrapping_add(k);
                    self.down = i.position;
                    self.steps = 0;
                } else if want_up || want_down {
                    if old.dir != want_up {
                        self.dir = want_up;
                        self.timer = at_least_one(i.setup_clocks) - 1;
                        self.phase = Phase::Setup;
                    } else {
                        self.step = true;
                        self.timer = at_least_one(i.high_clocks) - 1;
                        self.phase = Phase::High;
                        if want_up {
                            self.steps = old.steps.wrapping_add(1);
                            self.down = old.up;
                            self.up = old.up.wrapping_add(k);
                        } else {
                            self.steps = old.steps.wrapping_sub(1);
                            self.up = old.down;
                            self.down = old.down.wrapping_sub(k);
                        }
                    }
                }
            }
            Phase::Setup | Phase::Low => {
                if old.timer == 0 {
                    self.phase = Phase::Idle;
                } else {
                    self.timer = old.timer - 1;
                }
            }
            Phase::High => {
                if old.timer == 0 {
                    self.step = false;
                    self.timer = at_least_one(i.low_clocks) - 1;
                    self.phase = Phase::Low;
                } else {
                    self.timer = old.timer - 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs(position: i64, enable: bool) -> StepDirInputs {
        StepDirInputs {
            step_lsb: 3,
            high_clocks: 2,
            low_clocks: 3,
            setup_clocks: 4,
            enable,
            position: position as u32,
            ..Default::default()
        }
    }

    /// Runs `positions` (one per clock), returning the step line and the direction line per
    /// clock, and the generator.
    fn run(positions: &[(i64, bool)]) -> (Vec<(bool, bool)>, StepDir) {
        let mut g = StepDir::new();
        let lines = positions
            .iter()
            .map(|&(p, e)| {
                g.clock(&inputs(p, e));
                (g.step, g.dir)
            })
            .collect();
        (lines, g)
    }

    #[test]
    fn steps_follow_the_position_on_its_grid_with_the_timing_kept() {
        // Anchored at 10; up to 20 (⌊10/3⌋ = 3 steps), back to 4 (⌊−6/3⌋ = −2 steps), one LSB
        // per 5 clocks (a step per 15: slower than the train's 6).
        let mut p: Vec<(i64, bool)> = vec![(10, false); 3];
        p.extend((0..50).map(|k| (10 + k / 5, true)));
        p.extend((0..80).map(|k| (20 - k / 5, true)));
        p.extend((0..50).map(|_| (4, true)));
        let (lines, g) = run(&p);
        assert_eq!(g.steps as i32, -2);
        assert!(!g.overrun);
        // A jump of three steps at once is more than a step ahead: flagged.
        let mut jump = p.clone();
        jump.extend((0..50).map(|_| (13, true)));
        assert!(run(&jump).1.overrun);
        // Pulses: each high exactly 2 clocks, low at least 3; the direction set 4 clocks before
        // a rising edge after a change, never changing while high or low after one.
        let mut rises = Vec::new();
        for k in 1..lines.len() {
            if lines[k].0 && !lines[k - 1].0 {
                rises.push(k);
            }
        }
        assert_eq!(rises.len(), 3 + 5, "3 up, 5 down");
        for &r in &rises {
            assert!(
                lines[r].0 && lines[r + 1].0 && !lines[r + 2].0,
                "high 2 clocks"
            );
            assert!((r + 2..r + 5).all(|k| !lines[k].0), "low 3 clocks");
            let dir = lines[r].1;
            assert!((r - 4..r + 5).all(|k| lines[k].1 == dir), "setup and hold");
        }
        // The fastest train, one step per 1 + 2 + 3 clocks, behind a jump.
        let (lines, _) = run(&[vec![(0, false)], vec![(30, true); 60]].concat());
        let rises: Vec<usize> = (1..lines.len())
            .filter(|&k| lines[k].0 && !lines[k - 1].0)
            .collect();
        assert!(rises.windows(2).all(|w| w[1] - w[0] == 6), "{rises:?}");
        assert_eq!(max_steps_per_second(6.0e6, 2, 3), 1.0e6);
    }

    #[test]
    fn too_fast_is_flagged_and_disabling_clears_it() {
        // 1 LSB per clock with 3 LSB per step is 1/3 step per clock; the train allows 1/6.
        let p: Vec<(i64, bool)> = (0..300).map(|k| (k, true)).collect();
        let (_, g) = run(&p);
        assert!(g.overrun);
        let mut p = p;
        p.push((300, false));
        let (_, g) = run(&p);
        assert!(!g.overrun, "disabling clears the flag");
        p.extend((0..10).map(|_| (300, false)));
        let (_, g) = run(&p);
        assert!(!g.overrun && g.steps == 0);
    }
}
