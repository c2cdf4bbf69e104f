//! The path core clock by clock (the fabric's `snapgen_path_core`, `hdl/verilog/path_core.v`;
//! issue 22): seed 002's architecture in one block. The motion core ([`CoreModel`]) integrates
//! the path length `s` as it integrates a single axis — its programs, stop and swaps at an
//! absolute tick are the whole group's — and the path steppers ([`PathSteppers`]) map `s` onto
//! every axis on each of its ticks.
//!
//! The one register of its own, `tick_q`, is the core's tick a clock late: on the clock after
//! the chain steps, the steppers take a tick with the chain's new position register as `s`, so
//! every tick's axes are the path at the position the chain reached on it (committed on the
//! next tick, as the steppers commit). A reset resets both (the steppers' path empties; the
//! chain goes to its home, the centre of cell 0).
//!
//! The ports are the spec's `with_path_core_ports!`: the core's and the steppers' (but the
//! steppers' `tick` and `s`, driven inside), each copied by name ([`PathCore::core_inputs`],
//! [`PathCore::steppers_inputs`]), so no list is typed here.

use super::sequencer::SequencerError;
use super::steppers::PathSteppers;
use crate::core::CoreModel;
use crate::format::Format;
use crate::ports::{
    CoreInputs, CoreOutputs, PathCoreInputs, PathCoreOutputs, PathSteppersInputs,
    PathSteppersOutputs,
};

/// The path core's blocks and its register.
#[derive(Clone, Debug)]
pub struct PathCore {
    /// The motion core (its chain integrates `s`).
    pub core: CoreModel,
    /// The path steppers.
    pub steppers: PathSteppers,
    /// The core's tick, a clock late.
    tick_q: bool,
}

/// `PathCore::core_inputs`: every motion core input, by name.
macro_rules! core_inputs_of {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $($outs:tt)* }
    ) => {
        /// The motion core's inputs of the path core's inputs `i` (each by name).
        pub fn core_inputs(i: &PathCoreInputs) -> CoreInputs {
            CoreInputs { $($( $i: i.$i, )*)* }
        }
    };
}

/// `PathCore::with_core`: every motion core input, by name, into the path core's.
macro_rules! with_core_of {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $($outs:tt)* }
    ) => {
        /// The path core's inputs `rest` with the motion core's inputs of `c` (each by name):
        /// what a command executor drives, with the path's and the drives' inputs as they are.
        pub fn with_core(c: &CoreInputs, rest: &PathCoreInputs) -> PathCoreInputs {
            PathCoreInputs { $($( $i: c.$i, )*)* ..*rest }
        }
    };
}

/// `PathCore::steppers_inputs`: every path steppers input but `tick` and `s`, by name.
macro_rules! steppers_inputs_of {
    (
        clock: $cdoc:literal;
        inputs {
            reset { $( $r:ident : $rk:ident [$rb:expr] $rt:ty, $rdoc:literal; )* }
            write { $( $w:ident : $wk:ident [$wb:expr] $wt:ty, $wdoc:literal; )* }
            extend { $( $e:ident : $ek:ident [$eb:expr] $et:ty, $edoc:literal; )* }
            tick { $($tick:tt)* }
            drives { $( $d:ident : $dk:ident [$db:expr] $dt:ty, $ddoc:literal; )* }
        }
        outputs { $($outs:tt)* }
    ) => {
        /// The path steppers' inputs of the path core's inputs `i` (each by name), with the
        /// tick `tick` at the path length `s`.
        pub fn steppers_inputs(i: &PathCoreInputs, tick: bool, s: i128) -> PathSteppersInputs {
            PathSteppersInputs {
                $( $r: i.$r, )*
                $( $w: i.$w, )*
                $( $e: i.$e, )*
                $( $d: i.$d, )*
                tick,
                s,
            }
        }
    };
}

/// `PathCore::outputs_of`: the path core's outputs from its blocks', by name.
macro_rules! outputs_of {
    (
        clock: $cdoc:literal;
        inputs { $($ins:tt)* }
        outputs {
            registers { $( $x:ident : $xk:ident [$xb:expr] $xt:ty, $xdoc:literal; )* }
            status { $( $st:ident : $stk:ident [$stb:expr] $stt:ty, $stdoc:literal; )* }
            report { $( $r:ident : $rk:ident [$rb:expr] $rt:ty, $rdoc:literal; )* }
            debug { $( $g:ident : $gk:ident [$gb:expr] $gt:ty, $gdoc:literal; )* }
            path { $( $p:ident : $pk:ident [$pb:expr] $pt:ty, $pdoc:literal; )* }
            pins { $( $n:ident : $nk:ident [$nb:expr] $nt:ty, $ndoc:literal; )* }
            drives { $( $d:ident : $dk:ident [$db:expr] $dt:ty, $ddoc:literal; )* }
        }
    ) => {
        /// The path core's outputs from the motion core's `c` and the steppers' `p`.
        pub fn outputs_of(c: &CoreOutputs, p: &PathSteppersOutputs) -> PathCoreOutputs {
            PathCoreOutputs {
                $( $x: c.$x, )*
                $( $st: c.$st, )*
                $( $r: c.$r, )*
                $( $g: c.$g, )*
                $( $p: p.$p, )*
                $( $n: p.$n, )*
                $( $d: p.$d, )*
            }
        }
    };
}

impl PathCore {
    snapgen_spec::with_path_sequencer_ports!(
        super::host_inputs_of! { host_inputs, PathCoreInputs; }
    );
    snapgen_spec::with_motion_core_ports!(core_inputs_of! {});
    snapgen_spec::with_motion_core_ports!(with_core_of! {});
    snapgen_spec::with_path_steppers_ports!(steppers_inputs_of! {});
    snapgen_spec::with_path_core_ports!(outputs_of! {});

    /// The path core for `axes` axes (1 to 8) at power-up, its chain in `format` (apply a
    /// reset to home the chain).
    pub fn new(format: &Format, axes: u8) -> Result<Self, SequencerError> {
        Ok(PathCore {
            core: CoreModel::new(format),
            steppers: PathSteppers::new(axes)?,
            tick_q: false,
        })
    }

    /// One clock edge with inputs `i`: every block and register from the values before it.
    pub fn clock(&mut self, i: &PathCoreInputs) {
        let before = self.core.outputs();
        let si = Self::steppers_inputs(i, self.tick_q, before.x);
        self.tick_q = before.tick && !i.reset;
        self.core.edge(&Self::core_inputs(i));
        self.steppers.clock(&si);
    }

    /// The outputs as they stand (after the last edge).
    pub fn outputs(&self) -> PathCoreOutputs {
        Self::outputs_of(&self.core.outputs(), &self.steppers.outputs())
    }
}

#[cfg(test)]
mod tests {
    use super::super::interp::{Path, Segment, Shape};
    use super::super::sequencer::{segment_writes, worst_clocks};
    use super::*;
    use crate::format::DEFAULT_FORMAT;
    use crate::FRAC_BITS;

    const ONE: i128 = 1 << 62;
    const CELL: i128 = 1 << FRAC_BITS;

    #[test]
    fn the_axes_follow_the_chains_position_a_tick_late() {
        // A line of 300 LSB along X and 400 along Y (500 of path), written into the ring;
        // a program of constant snap moves s; on every tick after the first the committed
        // axes are the path at the chain's position one tick before.
        let path = Path {
            segments: vec![Segment {
                length: 500 * CELL,
                shape: Shape::Line {
                    from: vec![0, 0],
                    dir: vec![ONE * 3 / 5, ONE * 4 / 5],
                },
            }],
        };
        let mut pc = PathCore::new(&DEFAULT_FORMAT, 2).unwrap();
        let tick_div = worst_clocks(2, 1) as u32 + 10;
        let idle = PathCoreInputs {
            tick_div,
            ..Default::default()
        };
        pc.clock(&PathCoreInputs {
            reset: true,
            ..idle
        });
        for w in segment_writes(0, 0, &path.segments[0], 2).unwrap() {
            pc.clock(&PathCore::host_inputs(&w, &idle));
        }
        pc.clock(&PathCoreInputs {
            extend: true,
            ..idle
        });
        // One segment: a constant snap for 200 ticks.
        pc.clock(&PathCoreInputs {
            write_enable: true,
            write_address: 0,
            write_ticks: 200,
            write_snap: 1 << 60,
            ..idle
        });
        pc.clock(&PathCoreInputs {
            count_enable: true,
            count_value: 1,
            ..idle
        });
        pc.clock(&PathCoreInputs {
            start: true,
            ..idle
        });
        let mut xs = Vec::new();
        let mut commits = 0;
        for _ in 0..200 * (u64::from(tick_div) + 1) {
            let ticked = pc.outputs().tick;
            let commit = pc.steppers.sequencer.outputs().commit;
            pc.clock(&idle);
            if ticked {
                xs.push(pc.outputs().x);
            }
            if commit {
                commits += 1;
                // The commit after the steppers' tick k takes the positions at tick k−1's s.
                let s = xs[xs.len() - 2];
                assert_eq!(pc.steppers.position, path.at(s).unwrap(), "s {s}");
            }
        }
        assert!(commits > 150, "{commits}");
        let end = *xs.last().unwrap();
        assert!(end > 20 * CELL && end < 500 * CELL, "s moved to {end}");
        let o = pc.outputs();
        assert!(!o.late && !o.refused, "{o:?}");
    }
}
