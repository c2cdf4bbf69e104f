//! The ports of the generated blocks and the board's pins, each list written once.
//!
//! [`with_motion_core_ports!`] and [`with_io_top_ports!`] call a macro of the caller's with the
//! block's ports, grouped in sections by direction and by what drives them:
//!
//! ```text
//! clock: "doc";
//! inputs  { section { name: bit[1] bool, "doc"; name: bits[WIDTH] RustType, "doc"; … } … }
//! outputs { section { … } … }
//! ```
//!
//! `bit` ports are one wire (the fabric's `Bit`, the model's `bool`); `bits[W]` ports are `W`
//! wires holding two's complement or an unsigned count (the Rust type says which). The fabric
//! declares its blocks' ports from these lists (`snapgen_hdl`), the model its port structs
//! (`snapgen_model`), the co-simulation its word layouts and harness header (`snapgen_sim`);
//! [`MOTION_CORE`] and [`IO_TOP`] are the same lists as tables, for the generators. Sections
//! let a block take part of another's list: the executor drives the core's `command` inputs
//! and reads its `status` outputs; the status block reads the `report` outputs.
//!
//! The I/O top's `axis` sections are per axis: a design with several axes repeats them, and
//! [`board_pins`] numbers them.

/// A port's direction, seen from the block.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dir {
    /// Into the block.
    In,
    /// Out of the block.
    Out,
}

impl Dir {
    /// As Verilog writes it.
    pub fn verilog(self) -> &'static str {
        match self {
            Dir::In => "input",
            Dir::Out => "output",
        }
    }
}

/// One port of a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Port {
    /// Name (the same in the fabric, the model and the harness).
    pub name: &'static str,
    /// Direction.
    pub dir: Dir,
    /// Width in bits.
    pub bits: u32,
    /// The section of the list it belongs to.
    pub section: &'static str,
    /// What it carries.
    pub doc: &'static str,
}

/// A block's port list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    /// The clock input's name.
    pub clock: &'static str,
    /// Every other port, inputs first, in declaration order.
    pub ports: &'static [Port],
}

impl Block {
    /// Its inputs (without the clock), in order.
    pub fn inputs(&self) -> impl Iterator<Item = &'static Port> {
        self.ports.iter().filter(|p| p.dir == Dir::In)
    }

    /// Its outputs, in order.
    pub fn outputs(&self) -> impl Iterator<Item = &'static Port> {
        self.ports.iter().filter(|p| p.dir == Dir::Out)
    }

    /// The port called `name`.
    pub fn port(&self, name: &str) -> Option<&'static Port> {
        self.ports.iter().find(|p| p.name == name)
    }

    /// The ports of `section`.
    pub fn section(&self, section: &'static str) -> impl Iterator<Item = &'static Port> {
        self.ports.iter().filter(move |p| p.section == section)
    }
}

/// Calls `$callback! { $($extra)* <the motion core's ports> }` (see the module documentation).
#[macro_export]
macro_rules! with_motion_core_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $($callback)::+ ! { $($extra)*
            clock: "Fabric clock.";
            inputs {
                reset {
                    reset: bit[1] bool, "Synchronous reset, active high.";
                }
                config {
                    tick_div: bits[$crate::widths::TICK_BITS] u32, "Clocks per tick minus one (0: a tick every clock).";
                    stop_jerk: bits[$crate::widths::D_BITS] i128, "The controlled stop's jerk limit, raw (> 0; latched when a stop is taken).";
                    stop_accel: bits[$crate::widths::D_BITS] i128, "The controlled stop's acceleration limit, raw (≥ `stop_jerk`; latched likewise).";
                }
                encoder {
                    load_position: bits[$crate::widths::POSITION_BITS] u32, "The cell for `load` (the encoder count).";
                }
                command {
                    start: bit[1] bool, "Start the standby program (one-clock pulse; ignored while busy or stopping).";
                    abort_move: bit[1] bool, "Emergency stop: sequencer idle, v = a = j = 0 now, position holds, stop cancelled.";
                    stop: bit[1] bool, "Controlled stop: taken on the next tick, ends at rest within the stop limits.";
                    load: bit[1] bool, "The reference takes the encoder's position: x at the centre of cell `load_position`, v = a = j = 0 (raised only at rest, with no program playing).";
                    write_enable: bit[1] bool, "Write one segment of the standby program.";
                    write_address: bits[$crate::widths::ADDR_BITS] u8, "Segment address to write.";
                    write_ticks: bits[$crate::widths::TICK_BITS] u32, "Segment tick count to write (≥ 1).";
                    write_snap: bits[$crate::widths::D_BITS] i128, "Segment snap to write (two's complement).";
                    count_enable: bit[1] bool, "Set the standby program's segment count.";
                    count_value: bits[$crate::widths::INDEX_BITS] u8, "Segment count to set.";
                    swap: bit[1] bool, "Arm a program swap (one-clock pulse).";
                    swap_last: bits[$crate::widths::SWAP_BITS] u32, "The low bits of the time base on the old program's last tick: the registers at `swap_last + 1` are the new program's start.";
                }
            }
            outputs {
                registers {
                    x: bits[$crate::widths::X_BITS] i128, "Position register, raw.";
                    v: bits[$crate::widths::V_BITS] i128, "Velocity register, raw.";
                    a: bits[$crate::widths::A_BITS] i128, "Acceleration register, raw.";
                    j: bits[$crate::widths::J_BITS] i128, "Jerk register, raw.";
                    position: bits[$crate::widths::POSITION_BITS] u32, "Position in whole output LSBs (`x >> FRAC_BITS`, low bits).";
                }
                status {
                    busy: bit[1] bool, "A program is playing.";
                    stopping: bit[1] bool, "A controlled stop is requested or running.";
                    ticks: bits[$crate::widths::TIME_BITS] u64, "Ticks since reset: the board's time base.";
                    heading_pos: bit[1] bool, "The axis heads forward (registered): on the last clock the first non-zero of v, a, j was positive.";
                    heading_neg: bit[1] bool, "The axis heads backward (registered).";
                    at_rest: bit[1] bool, "The chain was at rest on the last clock: v = a = j = 0 (registered: a 312-bit zero test does not feed the executor's decisions in the same clock).";
                    tick: bit[1] bool, "The tick enable (one clock wide, a register).";
                    standby_count: bits[$crate::widths::INDEX_BITS] u8, "Segment count of the standby program (0: nothing to start).";
                    swap_pending: bit[1] bool, "A program swap is armed.";
                }
                report {
                    done: bit[1] bool, "The last program ran to its end.";
                    aborted: bit[1] bool, "The last program was cut short (by a stop or an abort).";
                    stop_over: bit[1] bool, "The last stop began outside its limits (and landed regardless of them).";
                    tick_count: bits[$crate::widths::TICK_BITS] u32, "Ticks since the start, while a program plays or a stop runs.";
                }
                debug {
                    segment: bits[$crate::widths::INDEX_BITS] u8, "Segment playing.";
                    active_bank: bit[1] bool, "Bank that plays (the other one is written).";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the I/O top's ports> }` (see the module documentation):
/// the station behind a UART (`snapgen_io`). The `axis` sections are one axis's pins.
#[macro_export]
macro_rules! with_io_top_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $crate::with_front_ports! { $($callback)::+ ! { $($extra)* }
            front_inputs {
                link {
                    uart_rx: bit[1] bool, "UART receive line (idles high).";
                }
            }
            front_outputs {
                link {
                    uart_tx: bit[1] bool, "UART transmit line.";
                }
            }
            station_outputs {}
        }
    };
}

/// Calls `$callback! { $($extra)* <the station's ports> }` (see the module documentation):
/// everything of the I/O top but its transport (`snapgen_io_station`, in `snapgen_io.v`). A
/// front (the UART of `snapgen_io`, the AXI4-Lite slave of `snapgen_axi`) hands it the
/// command stream's bytes and takes its replies' bytes; it gives the front the chain's
/// registers for a snapshot.
#[macro_export]
macro_rules! with_station_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $crate::with_front_ports! { $($callback)::+ ! { $($extra)* }
            front_inputs {
                link {
                    link_valid: bit[1] bool, "A byte of the command stream on this clock (at most one every other clock).";
                    link_data: bits[8] u8, "The byte.";
                    link_error: bit[1] bool, "The transport saw a framing error on this clock (UART_ERROR; the frame receiver drops the frame).";
                    reply_take: bit[1] bool, "The front takes `reply_data` on this clock (ignored while `reply_ready` is low).";
                }
            }
            front_outputs {
                link {
                    reply_ready: bit[1] bool, "A byte of the reply stream waits.";
                    reply_data: bits[8] u8, "The byte that waits.";
                }
            }
            station_outputs {
                state {
                    ticks: bits[$crate::widths::TIME_BITS] u64, "Ticks since reset: the board's time base.";
                    x: bits[$crate::widths::X_BITS] i128, "Position register, raw.";
                    v: bits[$crate::widths::V_BITS] i128, "Velocity register, raw.";
                    a: bits[$crate::widths::A_BITS] i128, "Acceleration register, raw.";
                    j: bits[$crate::widths::J_BITS] i128, "Jerk register, raw.";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the AXI4-Lite top's ports> }` (see the module
/// documentation): the station behind an AXI4-Lite slave (`snapgen_axi`), its register map
/// [`crate::axi::REGISTERS`]. The AXI ports keep the AXI names (`s_axi_*`) so that Vivado's
/// IP packager infers the interface; the clock and the (active-high) reset are the design's.
#[macro_export]
macro_rules! with_axi_top_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $crate::with_front_ports! { $($callback)::+ ! { $($extra)* }
            front_inputs {
                axi {
                    s_axi_awvalid: bit[1] bool, "Write address valid.";
                    s_axi_awaddr: bits[$crate::axi::ADDR_BITS] u8, "Write address (bytes; the low two bits are ignored).";
                    s_axi_wvalid: bit[1] bool, "Write data valid.";
                    s_axi_wdata: bits[32] u32, "Write data.";
                    s_axi_wstrb: bits[4] u8, "Write strobes: byte lane k is written when bit k is set.";
                    s_axi_bready: bit[1] bool, "Write response ready.";
                    s_axi_arvalid: bit[1] bool, "Read address valid.";
                    s_axi_araddr: bits[$crate::axi::ADDR_BITS] u8, "Read address (bytes; the low two bits are ignored).";
                    s_axi_rready: bit[1] bool, "Read data ready.";
                }
            }
            front_outputs {
                axi {
                    s_axi_awready: bit[1] bool, "Write address ready.";
                    s_axi_wready: bit[1] bool, "Write data ready.";
                    s_axi_bvalid: bit[1] bool, "Write response valid.";
                    s_axi_bresp: bits[2] u8, "Write response: 0 OKAY, 2 SLVERR (no such register, or read-only).";
                    s_axi_arready: bit[1] bool, "Read address ready.";
                    s_axi_rvalid: bit[1] bool, "Read data valid.";
                    s_axi_rdata: bits[32] u32, "Read data.";
                    s_axi_rresp: bits[2] u8, "Read response: 0 OKAY, 2 SLVERR (no such register, or write-only).";
                    irq: bit[1] bool, "Interrupt, active high, level: an enabled cause of IRQ_STATUS is set (registered).";
                }
            }
            station_outputs {}
        }
    };
}

/// The I/O tops' common list: the station's pins and debug outputs around a front's own
/// ports (see [`with_io_top_ports!`], [`with_station_ports!`], [`with_axi_top_ports!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! with_front_ports {
    (
        $($callback:ident)::+ ! { $($extra:tt)* }
        front_inputs { $($fi:tt)* }
        front_outputs { $($fo:tt)* }
        station_outputs { $($so:tt)* }
    ) => {
        $($callback)::+ ! { $($extra)*
            clock: "Fabric clock.";
            inputs {
                reset {
                    reset: bit[1] bool, "Synchronous reset, active high.";
                }
                $($fi)*
                machine {
                    estop: bit[1] bool, "Emergency stop (polarity set by INPUT_POLARITY).";
                }
                axis {
                    enc_a: bit[1] bool, "Encoder channel A.";
                    enc_b: bit[1] bool, "Encoder channel B.";
                    enc_i: bit[1] bool, "Encoder index.";
                    limit_pos: bit[1] bool, "Positive limit switch (polarity set by INPUT_POLARITY).";
                    limit_neg: bit[1] bool, "Negative limit switch.";
                }
            }
            outputs {
                $($fo)*
                machine {
                    led_idle: bit[1] bool, "LED 0: idle.";
                    led_busy: bit[1] bool, "LED 1: busy (a program plays or a stop runs).";
                    led_fault: bit[1] bool, "LED 2: fault (ErrorStop, a framing error on the link or an encoder error seen).";
                    led_heartbeat: bit[1] bool, "LED 3: heartbeat.";
                }
                axis {
                    pwm: bit[1] bool, "PWM output.";
                    dir: bit[1] bool, "Direction output.";
                    amplifier: bit[1] bool, "Amplifier enable (low: the amplifier must not drive the motor).";
                }
                $($so)*
                debug {
                    status: bits[$crate::fields::STATUS_BITS as u32] $crate::fields::Status, "The status block as the device would report it now (docs/PROTOCOL.md), byte 0 in bits 7:0: for co-simulation and debugging.";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the path interpolator's ports> }` (see the module
/// documentation): the block that maps a distance into a path segment onto every axis
/// (`snapgen_model::path::engine`, issue 22). Values are raw, in the chain's position format.
#[macro_export]
macro_rules! with_interpolator_ports {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)*
            clock: "Fabric clock.";
            inputs {
                reset {
                    reset: bit[1] bool, "Synchronous reset, active high: the interpolator goes idle (the loaded segment stays).";
                }
                shape {
                    load_shape: bit[1] bool, "Load the segment's shape from the ports below (any clock; a computation running reads the shape as it is on each clock).";
                    arc: bit[1] bool, "The segment is an arc (or a helix); otherwise a line.";
                    ccw: bit[1] bool, "The arc turns counter-clockwise from `plane_first` toward `plane_second`.";
                    plane_first: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's first axis.";
                    plane_second: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's second axis.";
                    centre_first: bits[$crate::widths::X_BITS] i128, "The arc's centre on the first plane axis, raw.";
                    centre_second: bits[$crate::widths::X_BITS] i128, "The arc's centre on the second plane axis, raw.";
                    radius: bits[$crate::widths::X_BITS] i128, "The arc's radius at its start, raw.";
                    growth: bits[$crate::widths::SHARE_BITS] i128, "The radius's change per raw unit of the path length (62 fraction bits, signed).";
                    start_angle: bits[$crate::widths::TURN_BITS] u64, "The arc's angle at its start (a turn is 2^64).";
                    rate: bits[$crate::widths::RATE_BITS] i128, "The arc's turns·2^64 per raw unit of the path length, 120 fraction bits (≥ 0).";
                }
                axis {
                    load_axis: bit[1] bool, "Load axis `axis`'s start and share from the ports below (any clock).";
                    axis: bits[$crate::widths::AXIS_BITS] u8, "The axis to load.";
                    from: bits[$crate::widths::X_BITS] i128, "The axis at the segment's start, raw.";
                    share: bits[$crate::widths::SHARE_BITS] i128, "The axis's share of the length, `Δx / length` (62 fraction bits, signed; 0 on an arc's plane axes).";
                }
                command {
                    start: bit[1] bool, "Compute every axis at `offset` (one-clock pulse; ignored while busy).";
                    offset: bits[$crate::widths::X_BITS] i128, "The distance into the segment, raw (the path length minus the segment's start).";
                }
            }
            outputs {
                status {
                    busy: bit[1] bool, "A computation runs.";
                    done: bit[1] bool, "The computation ended on the last clock (one clock wide, with the last axis's write).";
                }
                result {
                    out_write: bit[1] bool, "`out_value` is axis `out_axis`'s position (one clock wide, once per axis and computation).";
                    out_axis: bits[$crate::widths::AXIS_BITS] u8, "The axis written.";
                    out_value: bits[$crate::widths::X_BITS] i128, "Its position, raw (the chain's position format).";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the path sequencer's ports> }` (see the module
/// documentation): the ring of path segments and, on each tick, the choice of the segment the
/// path length lies in and the interpolator's load and start
/// (`snapgen_model::path::sequencer`, issue 22). Its `interpolator` outputs are the
/// interpolator's inputs of the same names; its `done` input is the interpolator's `done`.
#[macro_export]
macro_rules! with_path_sequencer_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $($callback)::+ ! { $($extra)*
            clock: "Fabric clock.";
            inputs {
                reset {
                    reset: bit[1] bool, "Synchronous reset, active high: the path is empty (segment 0 is the next written), idle, the flags cleared.";
                }
                write {
                    seg_index: bits[$crate::widths::PATH_INDEX_BITS] u16, "The segment the writes below are for (wrapping index; accepted in order, the segment after the highest written or the highest while it is not in the path, into a free slot or one whose segment is more than one before the current; else `refused`).";
                    write_span: bit[1] bool, "Write the segment's span (`seg_start`, `seg_length`).";
                    seg_start: bits[$crate::widths::X_BITS] i128, "The path length at the segment's start, raw (the chain's position format).";
                    seg_length: bits[$crate::widths::X_BITS] i128, "The segment's length, raw (≥ 0).";
                    write_shape: bit[1] bool, "Write the segment's shape (the `seg_` fields below, as the interpolator's shape ports).";
                    seg_arc: bit[1] bool, "The segment is an arc (or a helix); otherwise a line.";
                    seg_ccw: bit[1] bool, "The arc turns counter-clockwise.";
                    seg_plane_first: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's first axis.";
                    seg_plane_second: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's second axis.";
                    seg_centre_first: bits[$crate::widths::X_BITS] i128, "The arc's centre on the first plane axis, raw.";
                    seg_centre_second: bits[$crate::widths::X_BITS] i128, "The arc's centre on the second plane axis, raw.";
                    seg_radius: bits[$crate::widths::X_BITS] i128, "The arc's radius at its start, raw.";
                    seg_growth: bits[$crate::widths::SHARE_BITS] i128, "The radius's change per raw unit of the path length (62 fraction bits).";
                    seg_start_angle: bits[$crate::widths::TURN_BITS] u64, "The arc's angle at its start (a turn is 2^64).";
                    seg_rate: bits[$crate::widths::RATE_BITS] i128, "The arc's turns·2^64 per raw unit of the path length, 120 fraction bits.";
                    write_axis: bit[1] bool, "Write the segment's axis `seg_axis` (`seg_from`, `seg_share`); an axis the design does not have is `refused`.";
                    seg_axis: bits[$crate::widths::AXIS_BITS] u8, "The axis written.";
                    seg_from: bits[$crate::widths::X_BITS] i128, "The axis at the segment's start, raw.";
                    seg_share: bits[$crate::widths::SHARE_BITS] i128, "The axis's share of the length (62 fraction bits).";
                }
                extend {
                    extend: bit[1] bool, "The path now ends with segment `seg_index`: every segment written is taken in, so it must be the highest written, on a clock after its last write (else `refused`). Every word of those segments must have been written.";
                }
                tick {
                    tick: bit[1] bool, "A tick: commit the last computation's axes and compute those at `s` (one-clock pulse).";
                    s: bits[$crate::widths::X_BITS] i128, "The path length at this tick, raw (the chain's position register), read with `tick`.";
                }
                interpolator {
                    done: bit[1] bool, "The interpolator's `done`.";
                }
            }
            outputs {
                interpolator {
                    load_shape: bit[1] bool, "Load the shape below into the interpolator.";
                    arc: bit[1] bool, "The segment is an arc.";
                    ccw: bit[1] bool, "The arc turns counter-clockwise.";
                    plane_first: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's first axis.";
                    plane_second: bits[$crate::widths::AXIS_BITS] u8, "The arc plane's second axis.";
                    centre_first: bits[$crate::widths::X_BITS] i128, "The arc's centre on the first plane axis.";
                    centre_second: bits[$crate::widths::X_BITS] i128, "The arc's centre on the second plane axis.";
                    radius: bits[$crate::widths::X_BITS] i128, "The arc's radius at its start.";
                    growth: bits[$crate::widths::SHARE_BITS] i128, "The radius's change per raw unit of the path length.";
                    start_angle: bits[$crate::widths::TURN_BITS] u64, "The arc's angle at its start.";
                    rate: bits[$crate::widths::RATE_BITS] i128, "The arc's angular rate.";
                    load_axis: bit[1] bool, "Load axis `axis` below into the interpolator.";
                    axis: bits[$crate::widths::AXIS_BITS] u8, "The axis loaded.";
                    from: bits[$crate::widths::X_BITS] i128, "The axis at the segment's start.";
                    share: bits[$crate::widths::SHARE_BITS] i128, "The axis's share of the length.";
                    start: bit[1] bool, "Start the interpolator at `offset` (one-clock pulse).";
                    offset: bits[$crate::widths::X_BITS] i128, "The distance into the segment (clamped: see the model).";
                }
                axes {
                    commit: bit[1] bool, "The axes the interpolator wrote since the last commit are the positions at the tick before: take them (one clock, on a tick).";
                }
                status {
                    path_segment: bits[$crate::widths::PATH_INDEX_BITS] u16, "The segment the sequencer is on.";
                    running: bit[1] bool, "A seek, load or computation runs.";
                    empty: bit[1] bool, "No segment yet (since reset).";
                    late: bit[1] bool, "A tick came while a computation ran (it was dropped and the axes held; sticky until reset).";
                    refused: bit[1] bool, "A write or extension was refused (sticky until reset).";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the path steppers' ports> }` (see the module
/// documentation): the N-axis output stage of a path design for stepper drives: the path
/// sequencer, the interpolator, each axis's position registers and a step/dir generator per
/// axis (`snapgen_model::path::steppers`, issue 22). Its inputs are the sequencer's (but the
/// interpolator's answer, which stays inside) and the drives' settings; its outputs the
/// sequencer's status and the lines. Per-axis ports are vectors: axis `k` is bit `k` (or
/// bits `16k..16k+15`).
#[macro_export]
macro_rules! with_path_steppers_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $crate::with_path_sequencer_ports! {
            $crate::path_steppers_from_sequencer! { $($callback)::+ ! { $($extra)* } }
        }
    };
}

/// The path steppers' list from the path sequencer's (see [`with_path_steppers_ports!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! path_steppers_from_sequencer {
    (
        $($callback:ident)::+ ! { $($extra:tt)* }
        clock: $cdoc:literal;
        inputs {
            reset { $($reset:tt)* }
            write { $($write:tt)* }
            extend { $($extend:tt)* }
            tick { $($tick:tt)* }
            interpolator { $($answer:tt)* }
        }
        outputs {
            interpolator { $($drive:tt)* }
            axes { $($axes:tt)* }
            status { $($status:tt)* }
        }
    ) => {
        $($callback)::+ ! { $($extra)*
            clock: $cdoc;
            inputs {
                reset { $($reset)* }
                write { $($write)* }
                extend { $($extend)* }
                tick { $($tick)* }
                drives {
                    step_lsb: bits[$crate::widths::STEP_TIMER_BITS * $crate::widths::MAX_AXES] u128, "Each axis's output LSBs per step (axis k: bits 16k to 16k+15; 0 acts as 1).";
                    high_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks a step line stays high (every axis; 0 acts as 1).";
                    low_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks a step line stays low after a pulse (0 acts as 1).";
                    setup_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks a direction line is stable before a rising edge after it changes (0 acts as 1).";
                    enable: bits[$crate::widths::MAX_AXES] u8, "Axis k's pulses follow its position (bit k); while low its step grid is anchored there.";
                }
            }
            outputs {
                status { $($status)* }
                pins {
                    step: bits[$crate::widths::MAX_AXES] u8, "Step lines (axis k: bit k; an axis the design lacks: 0).";
                    dir: bits[$crate::widths::MAX_AXES] u8, "Direction lines (high: toward a larger position).";
                }
                drives {
                    overrun: bits[$crate::widths::MAX_AXES] u8, "Axis k's pulses were behind when a tick's positions came (bit k: a step of the tick before was still due at the commit; sticky until disabled or reset): the axis moves faster than its pulses can follow.";
                }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the path core's ports> }` (see the module documentation):
/// the N-axis motion core of a path design for stepper drives (`snapgen_model::path::core`,
/// issue 22): the motion core, whose chain integrates the path length `s`, driving the path
/// steppers on each of its ticks. Its ports are the motion core's and the path steppers' (but
/// the steppers' `tick` and `s`, which the core drives, and their reset, which is the core's);
/// the steppers' status is the section `path`.
#[macro_export]
macro_rules! with_path_core_ports {
    ($($callback:ident)::+ ! { $($extra:tt)* }) => {
        $crate::with_motion_core_ports! {
            $crate::path_core_from_core! { $($callback)::+ ! { $($extra)* } }
        }
    };
}

/// The path core's list, first step: the motion core's list carried into the path steppers'
/// (see [`with_path_core_ports!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! path_core_from_core {
    (
        $($callback:ident)::+ ! { $($extra:tt)* }
        clock: $cdoc:literal;
        inputs { $($core_in:tt)* }
        outputs { $($core_out:tt)* }
    ) => {
        $crate::with_path_steppers_ports! {
            $crate::path_core_from_both! {
                $($callback)::+ ! { $($extra)* }
                core_inputs { $($core_in)* }
                core_outputs { $($core_out)* }
            }
        }
    };
}

/// The path core's list, second step: the motion core's and the path steppers' lists joined
/// (see [`with_path_core_ports!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! path_core_from_both {
    (
        $($callback:ident)::+ ! { $($extra:tt)* }
        core_inputs { $($core_in:tt)* }
        core_outputs { $($core_out:tt)* }
        clock: $cdoc:literal;
        inputs {
            reset { $($reset:tt)* }
            write { $($write:tt)* }
            extend { $($extend:tt)* }
            tick { $($tick:tt)* }
            drives { $($drives:tt)* }
        }
        outputs {
            status { $($status:tt)* }
            pins { $($pins:tt)* }
            drives { $($overrun:tt)* }
        }
    ) => {
        $($callback)::+ ! { $($extra)*
            clock: $cdoc;
            inputs {
                $($core_in)*
                write { $($write)* }
                extend { $($extend)* }
                drives { $($drives)* }
            }
            outputs {
                $($core_out)*
                path { $($status)* }
                pins { $($pins)* }
                drives { $($overrun)* }
            }
        }
    };
}

/// Calls `$callback! { $($extra)* <the step/dir generator's ports> }` (see the module
/// documentation): one axis's stepper-drive output, made from its whole-LSB position
/// (`snapgen_model::io::step_dir`, issue 22).
#[macro_export]
macro_rules! with_step_dir_ports {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)*
            clock: "Fabric clock.";
            inputs {
                reset {
                    reset: bit[1] bool, "Synchronous reset, active high: disabled, no pulse, the overrun flag cleared.";
                }
                config {
                    step_lsb: bits[$crate::widths::STEP_TIMER_BITS] u16, "Output LSBs per step (0 acts as 1).";
                    high_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks the step line stays high (0 acts as 1).";
                    low_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks the step line stays low after a pulse (0 acts as 1).";
                    setup_clocks: bits[$crate::widths::STEP_TIMER_BITS] u16, "Clocks the direction line is stable before a step's rising edge after it changes (0 acts as 1).";
                }
                axis {
                    enable: bit[1] bool, "Pulses follow the position; while low the step grid is anchored at the position (no pulse).";
                    position: bits[$crate::widths::POSITION_BITS] u32, "The axis's position in whole output LSBs (the core's `position`; wraps).";
                }
            }
            outputs {
                pins {
                    step: bit[1] bool, "Step line: one pulse per step, rising edge = the step.";
                    dir: bit[1] bool, "Direction line: high for steps toward a larger position.";
                }
                status {
                    steps: bits[$crate::widths::POSITION_BITS] u32, "Steps issued since enabled, signed (wraps).";
                    overrun: bit[1] bool, "The position ran more than one step ahead of the pulses (sticky until disabled or reset): the axis moves faster than the pulse rate allows.";
                    due: bit[1] bool, "On the last edge a step was due that did not begin there (enabled, the position a step or more from the grid): the pulses are behind the position.";
                }
            }
        }
    };
}

/// Builds a [`Block`] table from a port list.
macro_rules! block_table {
    (
        $table:ident, $what:literal;
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        #[doc = concat!("The ports of ", $what, ".")]
        pub const $table: Block = Block {
            clock: "clock",
            ports: &[
                $( $( Port { name: stringify!($i), dir: Dir::In, bits: $ib, section: stringify!($isec), doc: $idoc }, )* )*
                $( $( Port { name: stringify!($o), dir: Dir::Out, bits: $ob, section: stringify!($osec), doc: $odoc }, )* )*
            ],
        };
    };
}

with_motion_core_ports!(block_table! { MOTION_CORE, "the motion core (`snapgen_core`)"; });
with_io_top_ports!(block_table! { IO_TOP, "the I/O top (`snapgen_io`)"; });
with_station_ports!(block_table! { STATION, "the station (`snapgen_io_station`)"; });
with_axi_top_ports!(block_table! { AXI_TOP, "the AXI4-Lite top (`snapgen_axi`)"; });
with_interpolator_ports!(
    block_table! { INTERPOLATOR, "the path interpolator (`snapgen_interpolator`)"; }
);
with_step_dir_ports!(block_table! { STEP_DIR, "the step/dir generator (`snapgen_step_dir`)"; });
with_path_sequencer_ports!(
    block_table! { PATH_SEQUENCER, "the path sequencer (`snapgen_path_sequencer`)"; }
);
with_path_steppers_ports!(
    block_table! { PATH_STEPPERS, "the path steppers (`snapgen_path_steppers`)"; }
);
with_path_core_ports!(block_table! { PATH_CORE, "the path core (`snapgen_path_core`)"; });

/// What a board pin is wired to in the board top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PinUse {
    /// The fabric clock.
    Clock,
    /// The reset button (active high), synchronised in the board top.
    ResetButton,
    /// This port of the I/O top.
    Io(&'static str),
}

/// One pin of the board top, as a board file names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardPin {
    /// The board top's port (`led[0]`, `enc_a`, `enc_a[1]` …).
    pub port: String,
    /// Direction.
    pub dir: Dir,
    /// What it is wired to (for a per-axis pin of axis `k`, the I/O top's port of that axis).
    pub wired: PinUse,
    /// Axis, for a per-axis pin of a design with several axes.
    pub axis: Option<usize>,
    /// What it is for.
    pub doc: &'static str,
}

/// The board top's ports that are not the I/O top's own name: (I/O top port, board port).
/// LEDs are one vector `led`, in this order.
pub const BOARD_NAMES: [(&str, &str); 7] = [
    ("uart_rx", "uart_rxd"),
    ("uart_tx", "uart_txd"),
    ("amplifier", "amp_enable"),
    ("led_idle", "led[0]"),
    ("led_busy", "led[1]"),
    ("led_fault", "led[2]"),
    ("led_heartbeat", "led[3]"),
];

/// The clock input of every board top.
pub const BOARD_CLOCK: &str = "sysclk";
/// The reset button of every board top.
pub const BOARD_RESET: &str = "btn_reset";

/// The board top's pins for a design with `axes` axes: the clock, the reset button, then every
/// I/O top port except the reset and the debug outputs (per-axis ones once per axis, numbered
/// `name[k]` when there are several).
pub fn board_pins(axes: usize) -> Vec<BoardPin> {
    let mut v = vec![
        BoardPin {
            port: BOARD_CLOCK.into(),
            dir: Dir::In,
            wired: PinUse::Clock,
            axis: None,
            doc: "the clock (the [clock] table, not a [[pins]] entry)",
        },
        BoardPin {
            port: BOARD_RESET.into(),
            dir: Dir::In,
            wired: PinUse::ResetButton,
            axis: None,
            doc: "reset button, active high",
        },
    ];
    let name = |p: &Port| {
        BOARD_NAMES
            .iter()
            .find(|(io, _)| *io == p.name)
            .map_or(p.name, |(_, b)| b)
    };
    for p in IO_TOP
        .ports
        .iter()
        .filter(|p| !matches!(p.section, "reset" | "debug"))
    {
        if p.section == "axis" {
            for k in 0..axes {
                v.push(BoardPin {
                    port: if axes == 1 {
                        name(p).to_string()
                    } else {
                        format!("{}[{k}]", name(p))
                    },
                    dir: p.dir,
                    wired: PinUse::Io(p.name),
                    axis: (axes > 1).then_some(k),
                    doc: p.doc,
                });
            }
        } else {
            v.push(BoardPin {
                port: name(p).to_string(),
                dir: p.dir,
                wired: PinUse::Io(p.name),
                axis: None,
                doc: p.doc,
            });
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_sections_known() {
        for b in [
            MOTION_CORE,
            IO_TOP,
            STATION,
            AXI_TOP,
            INTERPOLATOR,
            STEP_DIR,
            PATH_SEQUENCER,
            PATH_STEPPERS,
            PATH_CORE,
        ] {
            let mut names: Vec<&str> = b.ports.iter().map(|p| p.name).collect();
            names.push(b.clock);
            let n = names.len();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), n);
            assert!(b.ports.iter().all(|p| p.bits >= 1));
        }
        assert_eq!(MOTION_CORE.port("x").map(|p| p.bits), Some(112));
        assert_eq!(MOTION_CORE.section("command").count(), 12);
        assert_eq!(IO_TOP.port("status").map(|p| p.bits), Some(240));
    }

    #[test]
    fn each_front_carries_the_stations_pins() {
        // Every station port but its link to the front and its registers for a snapshot is
        // the UART top's and the AXI top's port of the same name, direction and width.
        for p in STATION
            .ports
            .iter()
            .filter(|p| !matches!(p.section, "link" | "state"))
        {
            for front in [IO_TOP, AXI_TOP] {
                let q = front.port(p.name).unwrap_or_else(|| panic!("{}", p.name));
                assert_eq!((q.dir, q.bits), (p.dir, p.bits), "{}", p.name);
            }
        }
        assert_eq!(AXI_TOP.section("axi").count(), 18);
    }

    #[test]
    fn the_sequencer_drives_every_interpolator_input_but_its_reset() {
        // Wired by name in a design: each `interpolator` output of the sequencer is the
        // interpolator's input of that name and width, and every such input is driven.
        let driven: Vec<&Port> = PATH_SEQUENCER.section("interpolator").collect();
        for p in &driven {
            let q = INTERPOLATOR.port(p.name);
            let q = q.unwrap_or_else(|| panic!("{} is no interpolator port", p.name));
            let opposite = if p.dir == Dir::Out { Dir::In } else { Dir::Out };
            assert_eq!((q.dir, q.bits), (opposite, p.bits), "{}", p.name);
        }
        let inputs = INTERPOLATOR.ports.iter().filter(|p| p.dir == Dir::In);
        for q in inputs.filter(|q| q.name != "reset") {
            assert!(
                driven.iter().any(|p| p.name == q.name),
                "{} is not driven",
                q.name
            );
        }
    }

    #[test]
    fn the_path_core_is_the_motion_core_and_the_path_steppers() {
        // Every motion core port, and every path steppers port but those the core drives
        // (its tick and path length) and its reset (the core's), once, at the same width.
        let inner = |p: &&Port| !matches!(p.name, "tick" | "s" | "reset");
        let expected: Vec<(&str, Dir, u32)> = MOTION_CORE
            .ports
            .iter()
            .chain(
                PATH_STEPPERS
                    .ports
                    .iter()
                    .filter(|p| p.dir == Dir::Out || inner(p)),
            )
            .map(|p| (p.name, p.dir, p.bits))
            .collect();
        let got: Vec<(&str, Dir, u32)> = PATH_CORE
            .ports
            .iter()
            .map(|p| (p.name, p.dir, p.bits))
            .collect();
        let mut a = expected.clone();
        let mut b = got.clone();
        a.sort_by_key(|p| p.0);
        b.sort_by_key(|p| p.0);
        assert_eq!(a, b);
        assert_eq!(PATH_CORE.port("tick").map(|p| p.dir), Some(Dir::Out));
        assert_eq!(PATH_CORE.section("path").count(), 5);
    }

    #[test]
    fn board_pins_by_axis() {
        let one = board_pins(1);
        let names: Vec<&str> = one.iter().map(|p| p.port.as_str()).collect();
        assert!(
            names.contains(&"enc_a") && names.contains(&"led[3]") && names.contains(&"amp_enable")
        );
        assert!(!names.contains(&"status") && !names.contains(&"reset"));
        assert_eq!(one.len(), 17);
        let three = board_pins(3);
        assert!(three
            .iter()
            .any(|p| p.port == "pwm[2]" && p.axis == Some(2)));
        // 8 per-axis pins: 2 more axes add 16.
        assert_eq!(three.len(), 17 + 16);
    }
}
