//! The model's port structs, made from `snapgen_spec`'s port lists: one field per port of the
//! fabric's block, with the port's name, so that the model, the fabric and the harness cannot
//! name or size a port differently.
//!
//! * [`CoreInputs`], [`CoreOutputs`]: the motion core (`snapgen_core`) for one clock;
//!   [`CoreCommand`] is its `command` section (what the executor drives) and [`CoreStatus`]
//!   its `status` section (what the executor reads).
//! * [`IoInputs`], [`IoOutputs`]: the I/O top's pins (`snapgen_io`) for one clock, the status
//!   block as a [`snapgen_spec::Status`].
//! * [`StationInputs`], [`StationOutputs`]: the station (`snapgen_io_station`,
//!   [`crate::station`]) for one clock.
//! * [`AxiInputs`], [`AxiOutputs`]: the AXI4-Lite top (`snapgen_axi`, [`crate::io::axi`]) for
//!   one clock.
//! * [`InterpInputs`], [`InterpOutputs`]: the path interpolator (`snapgen_interpolator`,
//!   [`crate::path::engine`]) for one clock.
//! * [`StepDirInputs`], [`StepDirOutputs`]: the step/dir generator (`snapgen_step_dir`,
//!   [`crate::io::step_dir`]) for one clock.
//! * [`PathSeqInputs`], [`PathSeqOutputs`]: the path sequencer (`snapgen_path_sequencer`,
//!   [`crate::path::sequencer`]) for one clock.
//! * [`PathSteppersInputs`], [`PathSteppersOutputs`]: the path steppers
//!   (`snapgen_path_steppers`, [`crate::path::steppers`]) for one clock.
//! * [`PathCoreInputs`], [`PathCoreOutputs`]: the path core (`snapgen_path_core`,
//!   [`crate::path::core`]) for one clock.

/// A block's inputs and outputs as two structs.
macro_rules! port_structs {
    (
        $inputs:ident, $outputs:ident, $what:literal;
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        #[doc = concat!("The inputs of ", $what, " for one clock.")]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct $inputs {
            $( $( #[doc = $idoc] pub $i: $it, )* )*
        }

        #[doc = concat!("The outputs of ", $what, " after a clock edge.")]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct $outputs {
            $( $( #[doc = $odoc] pub $o: $ot, )* )*
        }
    };
}

snapgen_spec::with_motion_core_ports!(
    port_structs! { CoreInputs, CoreOutputs, "the motion core"; }
);
snapgen_spec::with_io_top_ports!(port_structs! { IoInputs, IoOutputs, "the I/O top"; });
snapgen_spec::with_station_ports!(port_structs! { StationInputs, StationOutputs, "the station"; });
snapgen_spec::with_axi_top_ports!(port_structs! { AxiInputs, AxiOutputs, "the AXI4-Lite top"; });
snapgen_spec::with_interpolator_ports!(port_structs! {
    InterpInputs, InterpOutputs, "the path interpolator";
});
snapgen_spec::with_step_dir_ports!(port_structs! {
    StepDirInputs, StepDirOutputs, "the step/dir generator";
});
snapgen_spec::with_path_sequencer_ports!(port_structs! {
    PathSeqInputs, PathSeqOutputs, "the path sequencer";
});
snapgen_spec::with_path_steppers_ports!(port_structs! {
    PathSteppersInputs, PathSteppersOutputs, "the path steppers";
});
snapgen_spec::with_path_core_ports!(port_structs! {
    PathCoreInputs, PathCoreOutputs, "the path core";
});

/// The core's `command` inputs and `status` outputs as structs of their own.
macro_rules! core_sections {
    (
        clock: $cdoc:literal;
        inputs {
            reset { $($r:tt)* }
            config { $($c:tt)* }
            encoder { $($e:tt)* }
            command { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* }
        }
        outputs {
            registers { $($x:tt)* }
            status { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* }
            report { $($rp:tt)* }
            debug { $($d:tt)* }
        }
    ) => {
        /// The core's `command` inputs: what the executor drives (one-clock pulses and the
        /// values they carry).
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct CoreCommand {
            $( #[doc = $idoc] pub $i: $it, )*
        }

        /// The core's `status` outputs: what the executor and the status block read.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct CoreStatus {
            $( #[doc = $odoc] pub $o: $ot, )*
        }

        impl CoreInputs {
            /// Sets the `command` inputs.
            pub fn set_command(&mut self, c: &CoreCommand) {
                $( self.$i = c.$i; )*
            }

            /// The `command` inputs.
            pub fn command(&self) -> CoreCommand {
                CoreCommand { $( $i: self.$i, )* }
            }
        }

        impl CoreOutputs {
            /// The `status` outputs.
            pub fn status(&self) -> CoreStatus {
                CoreStatus { $( $o: self.$o, )* }
            }
        }
    };
}

snapgen_spec::with_motion_core_ports!(core_sections! {});
