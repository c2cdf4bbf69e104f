//! Step and direction lines read as the drives read them: each axis's steps counted on its
//! step line's rising edges, signed by its direction line, run by run (the lockstep of every
//! stage with step/dir outputs).

use snapgen_model::FRAC_BITS;

use crate::layout::{slot_named, Port, Slot};

/// `x`'s whole output LSBs as a step/dir generator reads them (32 bits, signed).
pub fn whole(x: i128) -> i64 {
    i64::from((x >> FRAC_BITS) as u32 as i32)
}

/// Where a run keeps each axis's steps counted on the lines.
pub trait Counted {
    /// Each axis's count.
    fn counted(&mut self) -> &mut [i64];
}

/// A stage's flags at a run's last clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EndFlags {
    /// Each axis's `overrun` (bit k).
    pub overrun: u8,
    /// The sequencer's `late`.
    pub late: bool,
    /// The sequencer's `refused`.
    pub refused: bool,
}

/// The lines' view of a lockstep: where the step and direction vectors and the flags are in a
/// clock's output words, and the step lines' levels on the last clock.
pub struct DriveLines {
    step: Slot,
    dir: Slot,
    overrun: Slot,
    late: Slot,
    refused: Slot,
    last: u8,
    /// Steps counted on every axis.
    pub steps: u64,
}

impl DriveLines {
    /// The view of a stage whose outputs are `ports` at `slots`, among them the vectors
    /// `step`, `dir` and `overrun` (axis k: bit k) and the flags `late` and `refused`.
    pub fn of(ports: &[Port], slots: &[Slot]) -> Self {
        let slot = |name: &str| slot_named(ports, slots, name);
        DriveLines {
            step: slot("step"),
            dir: slot("dir"),
            overrun: slot("overrun"),
            late: slot("late"),
            refused: slot("refused"),
            last: 0,
            steps: 0,
        }
    }

    /// Counts a batch's clocks (`got`; clocks numbered from `first + 1`, as the runs' ends
    /// are, after the clock they ended on) into the runs that ended in it
    /// (`ended`, each with the clock it ended on, in order), then into `current`; `judge`
    /// takes each ended run with the flags of its last clock.
    pub fn count<'g, R: Counted>(
        &mut self,
        got: impl Iterator<Item = &'g [u32]>,
        first: u64,
        ended: &mut Vec<(u64, R)>,
        mut current: Option<&mut R>,
        mut judge: impl FnMut(R, EndFlags),
    ) {
        let mut runs = ended.drain(..).peekable();
        for (c, g) in got.enumerate() {
            let clock = first + c as u64 + 1;
            let counts = match runs.peek_mut() {
                Some((_, run)) => run.counted(),
                None => match current.as_deref_mut() {
                    Some(run) => run.counted(),
                    None => {
                        self.last = self.step.get(g) as u8;
                        continue;
                    }
                },
            };
            self.clock(g, counts);
            if runs.peek().is_some_and(|(end, _)| *end == clock) {
                let (_, run) = runs.next().expect("peeked");
                judge(run, self.flags(g));
            }
        }
    }

    /// One clock's words `g`: each axis's step that rises on it counted into `counts`.
    pub fn clock(&mut self, g: &[u32], counts: &mut [i64]) {
        let (step, dir) = (self.step.get(g) as u8, self.dir.get(g) as u8);
        let rising = step & !self.last;
        self.last = step;
        for (k, count) in counts.iter_mut().enumerate() {
            if rising >> k & 1 == 1 {
                *count += if dir >> k & 1 == 1 { 1 } else { -1 };
                self.steps += 1;
            }
        }
    }

    /// The flags in one clock's words `g`.
    pub fn flags(&self, g: &[u32]) -> EndFlags {
        EndFlags {
            overrun: self.overrun.get(g) as u8,
            late: self.late.get(g) == 1,
            refused: self.refused.get(g) == 1,
        }
    }
}

/// Whether each axis's count on its lines is `⌊(end − start) / step⌋` of its whole positions
/// (`step_lsb`: axis k's step length in bits 16k..16k+15); the first that is not, said.
pub fn count_error(counted: &[i64], start: &[i64], end: &[i64], step_lsb: u128) -> Option<String> {
    counted
        .iter()
        .zip(start.iter().zip(end))
        .enumerate()
        .find_map(|(k, (&counted, (&from, &to)))| {
            let step = i64::from((step_lsb >> (16 * k)) as u16).max(1);
            (counted != (to - from).div_euclid(step)).then(|| {
                format!(
                    "axis {k}: {counted} steps on the lines, the rule says {} LSB / {step}",
                    to - from
                )
            })
        })
}

/// What a run's end says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Within the rate, and the counts are the rule's.
    Checked,
    /// Some tick moved an axis further than its pulses follow: the counts are not judged.
    Fast,
    /// Wrong: what.
    Wrong(String),
}

/// The verdict on a run that ended with `flags`: `late` or `refused` is wrong; a run `fast`
/// is not judged further; within the rate an overrun is wrong, and so is a count that is not
/// the rule's (`counts`, [`count_error`]).
pub fn verdict(flags: EndFlags, fast: bool, counts: impl FnOnce() -> Option<String>) -> Verdict {
    let EndFlags {
        overrun,
        late,
        refused,
    } = flags;
    if late || refused {
        return Verdict::Wrong(format!("late {late}, refused {refused}"));
    }
    if fast {
        return Verdict::Fast;
    }
    if overrun != 0 {
        return Verdict::Wrong(format!("overrun {overrun:#010b} within the rate"));
    }
    counts().map_or(Verdict::Checked, Verdict::Wrong)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_off_by_one_step_or_a_flag_is_wrong() {
        // Axis 0 steps 1 LSB: 10 steps for 10 LSB; axis 1 steps 3 LSB: −4 for −10 LSB.
        let (start, end) = ([0, 5], [10, -5]);
        let step_lsb = 1 | (3 << 16);
        assert_eq!(count_error(&[10, -4], &start, &end, step_lsb), None);
        let e = count_error(&[10, -3], &start, &end, step_lsb).expect("wrong");
        assert!(e.starts_with("axis 1: -3 steps"), "{e}");
        assert!(count_error(&[11, -4], &start, &end, step_lsb).is_some());
        let calm = EndFlags {
            overrun: 0,
            late: false,
            refused: false,
        };
        assert_eq!(verdict(calm, false, || None), Verdict::Checked);
        assert_eq!(verdict(calm, true, || Some("x".into())), Verdict::Fast);
        assert_eq!(
            verdict(calm, false, || Some("x".into())),
            Verdict::Wrong("x".into())
        );
        let behind = EndFlags { overrun: 2, ..calm };
        assert!(matches!(verdict(behind, false, || None), Verdict::Wrong(_)));
        assert_eq!(verdict(behind, true, || None), Verdict::Fast);
        let late = EndFlags { late: true, ..calm };
        assert!(matches!(verdict(late, true, || None), Verdict::Wrong(_)));
    }
}
