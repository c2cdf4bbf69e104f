//! The path steppers clock by clock (the fabric's `snapgen_path_steppers`,
//! `hdl/verilog/path_steppers.v`; issue 22): the N-axis output stage of a path design for
//! stepper drives, made of blocks each with its own reference:
//!
//! * the path sequencer ([`super::sequencer`]) and the interpolator it drives
//!   ([`super::engine`]), wired by name;
//! * per axis, two position registers: `next` takes the interpolator's write of the axis, and
//!   `position` takes `next` on the sequencer's `commit`, so every axis changes on the same
//!   clock, to its position at the tick before;
//! * per axis, a step/dir generator ([`crate::io::step_dir`]) on the whole-LSB part of
//!   `position` (`position >> FRAC_BITS`, the low [`POSITION_BITS`] bits), with that axis's
//!   step length and the drives' common pulse timing;
//! * per axis, the `overrun` flag: the pulses were behind (a step still `due`) when the next
//!   tick's positions came, so the axis moves faster than its pulses follow. (The generator's
//!   own `overrun`, a position more than a step ahead, is not used: a tick's jump is often
//!   several steps, which the pulses then follow within the tick.) Sticky until the axis is
//!   disabled or the stage reset.
//!
//! The position registers are not reset (a reset empties the path; the axes hold where they
//! are). A host that loads a new path disables the drives (`enable` low: each anchors its step
//! grid at its position) until a tick has committed the path's start.

use snapgen_spec::widths::{FRAC_BITS, MAX_AXES, POSITION_BITS, STEP_TIMER_BITS};

use super::engine::Engine;
use super::sequencer::{PathSequencer, SequencerError};
use crate::io::step_dir::StepDir;
use crate::ports::{PathSeqInputs, PathSteppersInputs, PathSteppersOutputs, StepDirInputs};

const _: () = assert!(STEP_TIMER_BITS == 16 && POSITION_BITS == 32 && MAX_AXES == 8);

/// `PathSteppers::sequencer_inputs`: the sequencer's inputs of the stage's, each by name
/// from the spec's list (the interpolator's `done` from its outputs).
macro_rules! sequencer_inputs_of {
    (
        clock: $cdoc:literal;
        inputs {
            reset { $( $r:ident : $rk:ident [$rb:expr] $rt:ty, $rdoc:literal; )* }
            write { $( $w:ident : $wk:ident [$wb:expr] $wt:ty, $wdoc:literal; )* }
            extend { $( $e:ident : $ek:ident [$eb:expr] $et:ty, $edoc:literal; )* }
            tick { $( $t:ident : $tk:ident [$tb:expr] $tt:ty, $tdoc:literal; )* }
            interpolator { $( $d:ident : $dk:ident [$db:expr] $dt:ty, $ddoc:literal; )* }
        }
        outputs { $($outs:tt)* }
    ) => {
        /// The sequencer's inputs of the stage's inputs `i` (the interpolator's answer from
        /// its outputs after the last clock).
        fn sequencer_inputs(&self, i: &PathSteppersInputs) -> PathSeqInputs {
            let answer = self.interpolator.outputs();
            PathSeqInputs {
                $( $r: i.$r, )*
                $( $w: i.$w, )*
                $( $e: i.$e, )*
                $( $t: i.$t, )*
                $( $d: answer.$d, )*
            }
        }
    };
}

/// The stage's blocks and registers.
#[derive(Clone, Debug)]
pub struct PathSteppers {
    axes: u8,
    /// The path sequencer.
    pub sequencer: PathSequencer,
    /// The interpolator.
    pub interpolator: Engine,
    /// Each axis's `next` register (raw, the chain's format).
    pub next: Vec<i128>,
    /// Each axis's `position` register (raw).
    pub position: Vec<i128>,
    /// Each axis's step/dir generator.
    pub drives: Vec<StepDir>,
    /// Each axis's overrun flag (bit k).
    pub behind: u8,
    out: PathSteppersOutputs,
}

impl PathSteppers {
    /// The stage for `axes` axes (1 to [`MAX_AXES`]) at power-up.
    pub fn new(axes: u8) -> Result<Self, SequencerError> {
        let sequencer = PathSequencer::new(axes)?;
        let n = usize::from(axes);
        let mut s = PathSteppers {
            axes,
            sequencer,
            interpolator: Engine::new(axes),
            next: vec![0; n],
            position: vec![0; n],
            drives: vec![StepDir::new(); n],
            behind: 0,
            out: PathSteppersOutputs::default(),
        };
        s.publish();
        Ok(s)
    }

    /// The outputs after the last clock.
    pub fn outputs(&self) -> PathSteppersOutputs {
        self.out
    }

    /// Axis `k`'s position in whole output LSBs, as its step/dir generator reads it.
    pub fn whole(&self, k: usize) -> u32 {
        (self.position[k] >> FRAC_BITS) as u32
    }

    snapgen_spec::with_path_sequencer_ports!(super::host_inputs_of! {
        with_writes, PathSteppersInputs;
    });
    snapgen_spec::with_path_sequencer_ports!(sequencer_inputs_of! {});

    /// The stage's inputs that carry the sequencer's host-side inputs `w` (its writes and
    /// extensions; every other input at rest).
    pub fn host_inputs(w: &PathSeqInputs) -> PathSteppersInputs {
        Self::with_writes(w, &PathSteppersInputs::default())
    }

    /// One clock edge with inputs `i`: every block and register from the values before it.
    pub fn clock(&mut self, i: &PathSteppersInputs) {
        let seq_in = self.sequencer_inputs(i);
        let so = self.sequencer.outputs();
        let eo = self.interpolator.outputs();
        let drive_in: Vec<StepDirInputs> = (0..usize::from(self.axes))
            .map(|k| StepDirInputs {
                reset: i.reset,
                step_lsb: (i.step_lsb >> (16 * k)) as u16,
                high_clocks: i.high_clocks,
                low_clocks: i.low_clocks,
                setup_clocks: i.setup_clocks,
                enable: i.enable >> k & 1 == 1,
                position: self.whole(k),
            })
            .collect();
        // The axes' registers.
        if so.commit {
            self.position = self.next.clone();
        }
        for (k, d) in self.drives.iter().enumerate() {
            let bit = 1u8 << k;
            if i.reset || i.enable & bit == 0 {
                self.behind &= !bit;
            } else if so.commit && d.outputs().due {
                self.behind |= bit;
            }
        }
        if eo.out_write {
            if let Some(x) = self.next.get_mut(usize::from(eo.out_axis)) {
                *x = eo.out_value;
            }
        }
        self.sequencer.clock(&seq_in);
        self.interpolator
            .clock(&PathSequencer::interp_inputs(&so, i.reset));
        for (d, di) in self.drives.iter_mut().zip(&drive_in) {
            d.clock(di);
        }
        self.publish();
    }

    /// The outputs of the blocks as they stand.
    fn publish(&mut self) {
        let so = self.sequencer.outputs();
        let bits = |f: &dyn Fn(&StepDir) -> bool| {
            self.drives
                .iter()
                .enumerate()
                .fold(0u8, |acc, (k, d)| acc | (u8::from(f(d)) << k))
        };
        self.out = PathSteppersOutputs {
            path_segment: so.path_segment,
            running: so.running,
            empty: so.empty,
            late: so.late,
            refused: so.refused,
            step: bits(&|d| d.outputs().step),
            dir: bits(&|d| d.outputs().dir),
            overrun: self.behind,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::super::interp::{Path, Segment, Shape};
    use super::super::sequencer::{segment_writes, worst_clocks};
    use super::*;

    const ONE: i128 = 1 << 62;
    const CELL: i128 = 1 << FRAC_BITS;

    /// Writes `path` into the stage (every word, then one extension).
    fn load(st: &mut PathSteppers, path: &Path, axes: u8) {
        let mut start = 0;
        for (k, g) in path.segments.iter().enumerate() {
            for w in segment_writes(k as u16, start, g, axes).unwrap() {
                st.clock(&PathSteppers::host_inputs(&w));
            }
            start += g.length;
        }
        st.clock(&PathSteppersInputs {
            seg_index: path.segments.len() as u16 - 1,
            extend: true,
            ..Default::default()
        });
    }

    #[test]
    fn the_steps_on_the_lines_are_the_paths_positions() {
        // 300 LSB along X and Y at once, then a half turn of radius 100 LSB: steps of 1 LSB on
        // X, 3 on Y; s moving 2 LSB of path per tick, slower than the pulses can follow.
        let axes = 2u8;
        let lsb = |x: i128| x * CELL;
        let line = Segment {
            length: lsb(424),
            shape: Shape::Line {
                from: vec![lsb(0), lsb(0)],
                dir: vec![ONE * 300 / 424, ONE * 300 / 424],
            },
        };
        let end = line.at(line.length);
        let arc = Segment {
            length: lsb(314),
            shape: Shape::Arc {
                plane: [0, 1],
                centre: [end[0], end[1] + lsb(100)],
                radius: lsb(100),
                growth: 0,
                start: super::super::cordic::Turn(3 << 62),
                rate: (1i128 << 63) / 314 * (1 << (super::super::interp::RATE_SHIFT - 80)),
                ccw: true,
                from: end.clone(),
                dir: vec![0, 0],
            },
        };
        let path = Path {
            segments: vec![line, arc],
        };
        let mut st = PathSteppers::new(axes).unwrap();
        load(&mut st, &path, axes);
        let period = worst_clocks(axes, 1) + 200;
        let base = PathSteppersInputs {
            step_lsb: 1 | (3 << 16),
            high_clocks: 2,
            low_clocks: 2,
            setup_clocks: 2,
            ..Default::default()
        };
        let mut counted = [0i64; 2];
        let mut last = (0u8, 0u8);
        let total = path.length();
        let mut s = 0;
        let mut anchor = None;
        for tick in 0..(total / lsb(2) + 40) {
            // Two ticks to commit the start, then enabled.
            let enable = if tick >= 2 { 0b11 } else { 0 };
            if enable != 0 && anchor.is_none() {
                anchor = Some([st.whole(0), st.whole(1)]);
            }
            if tick >= 2 {
                s = (s + lsb(2)).min(total);
            }
            for c in 0..period {
                let i = PathSteppersInputs {
                    tick: c == 0,
                    s,
                    enable,
                    ..base
                };
                st.clock(&i);
                let o = st.outputs();
                for (k, n) in counted.iter_mut().enumerate() {
                    if o.step >> k & 1 == 1 && last.0 >> k & 1 == 0 {
                        *n += if o.dir >> k & 1 == 1 { 1 } else { -1 };
                    }
                }
                last = (o.step, o.dir);
            }
        }
        let o = st.outputs();
        assert_eq!((o.late, o.refused, o.overrun), (false, false, 0), "{o:?}");
        let at = path.at(total).unwrap();
        let anchor = anchor.unwrap();
        for (k, step) in [1i64, 3].into_iter().enumerate() {
            let moved = i64::from((at[k] >> FRAC_BITS) as u32 as i32) - i64::from(anchor[k] as i32);
            assert_eq!(counted[k], moved.div_euclid(step), "axis {k}");
        }
        // X: 300 along the line, out and back on the half turn; Y: 300, then 200 on it.
        assert_eq!(counted, [300, 500 / 3]);
    }
}
