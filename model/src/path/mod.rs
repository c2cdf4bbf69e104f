//! Several axes along one path (seed 002's Cartesian path following): the rules by which a
//! path length `s`, integrated by the chain, becomes each axis's position.
//!
//! Built so far: [`interp`], the interpolator's rules for lines, arcs and helices,
//! [`cordic`], the integer sine and cosine it uses, [`engine`], the fabric's interpolator
//! clock by clock, [`sequencer`], the fabric's ring of segments that finds the segment of
//! each tick's path length and starts the interpolator on it, and [`steppers`], the N-axis
//! output stage for stepper drives around both, and [`core`], the motion core whose chain
//! integrates `s` driving that stage. The group stop along the path (within each segment's
//! limits), the command interface that writes the ring and the position controllers per axis
//! are not built yet (issue 22).

pub mod cordic;
pub mod core;
pub mod engine;
pub mod interp;
pub mod sequencer;
pub mod steppers;

/// `$name(w, rest)` in a block's `impl` (`$target` its inputs, which hold the path
/// sequencer's `write` and `extend` ports by name): `rest` with the writes and extension of
/// `w`, each port copied by name from the spec's list.
macro_rules! host_inputs_of {
    (
        $name:ident, $target:ident;
        clock: $cdoc:literal;
        inputs {
            reset { $($reset:tt)* }
            write { $( $w:ident : $wk:ident [$wb:expr] $wt:ty, $wdoc:literal; )* }
            extend { $( $e:ident : $ek:ident [$eb:expr] $et:ty, $edoc:literal; )* }
            $($rest:tt)*
        }
        outputs { $($outs:tt)* }
    ) => {
        /// The inputs `rest` with the sequencer's writes and extension of `w` (as
        /// [`crate::path::sequencer::segment_writes`] makes them).
        pub fn $name(w: &crate::ports::PathSeqInputs, rest: &$target) -> $target {
            $target {
                $( $w: w.$w, )*
                $( $e: w.$e, )*
                ..*rest
            }
        }
    };
}
pub(crate) use host_inputs_of;
