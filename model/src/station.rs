//! The station: everything of the I/O top but its transport (`snapgen_hdl::station::Station`,
//! `snapgen_io_station`), clock by clock. A front hands it the command stream's bytes and
//! takes its replies' bytes: the UART of [`crate::device::Device`] (`snapgen_io`), the
//! AXI4-Lite slave of [`crate::io::axi`] (`snapgen_axi`).
//!
//! ```text
//! link_valid/data → FIFO → FrameRx → Executor ─→ MotionCore (sequencer, stop unit, chain)
//!                                      │  ↑ status, registers
//!                                      ↓  │
//! reply_ready/data ← FIFO ← ReplyTx ← ReplyQueue
//! enc_a/b/i → Quadrature → encoder count;  limit±, e-stop → input filters → Executor
//! chain x, v, a + encoder count → Servo (PID + feed-forward) → duty → PWM → pwm/dir
//! (off without the amplifier);  amplifier enable
//! ```
//!
//! Every block is a model of its own (`crate::io`, `crate::core`); each clock, every block's
//! inputs are computed from the registered outputs of the blocks before the edge, then every
//! block steps, exactly as the synchronous hardware does.

use crate::core::{CoreInputs, CoreModel, CoreOutputs};
use crate::device::Design;
use crate::io::executor::{Executor, ExecutorInputs};
use crate::io::fifo::ByteFifo;
use crate::io::frame_rx::{FrameRx, FrameRxInputs};
use crate::io::pwm::{Pwm, PwmInputs};
use crate::io::quadrature::{QuadInputs, QuadOutputs, Quadrature};
use crate::io::reply_queue::ReplyQueue;
use crate::io::reply_tx::{status, Live, ReplyTx, ReplyTxInputs, StatusInputs};
use crate::io::servo::{Servo, ServoInputs};
use crate::io::FilteredInput;
pub use crate::ports::{StationInputs, StationOutputs};
use snapgen_spec::{AxisState, Identity, StateReply, Status};

/// A front's outputs: `$front { <the station's pins and status from $s>, $($extra)* }` (the
/// pins every front passes through, named once).
macro_rules! station_pins {
    ($s:expr, $front:ident { $($extra:tt)* }) => {
        $front {
            led_idle: $s.led_idle,
            led_busy: $s.led_busy,
            led_fault: $s.led_fault,
            led_heartbeat: $s.led_heartbeat,
            pwm: $s.pwm,
            dir: $s.dir,
            amplifier: $s.amplifier,
            status: $s.status,
            $($extra)*
        }
    };
}
pub(crate) use station_pins;

/// The station's inputs: `StationInputs { <the pins from the front's inputs $i>, $($link)* }`
/// (the pins every front passes through, named once).
macro_rules! station_inputs {
    ($i:expr, { $($link:tt)* }) => {
        $crate::ports::StationInputs {
            reset: $i.reset,
            estop: $i.estop,
            enc_a: $i.enc_a,
            enc_b: $i.enc_b,
            enc_i: $i.enc_i,
            limit_pos: $i.limit_pos,
            limit_neg: $i.limit_neg,
            $($link)*
        }
    };
}
pub(crate) use station_inputs;

/// The station model.
#[derive(Clone, Debug)]
pub struct Station {
    design: Design,
    identity: Identity,
    rx_fifo: ByteFifo,
    frame_rx: FrameRx,
    exec: Executor,
    core: CoreModel,
    queue: ReplyQueue,
    reply_tx: ReplyTx,
    tx_fifo: ByteFifo,
    quad: Quadrature,
    quad_out: QuadOutputs,
    pwm: Pwm,
    servo: Servo,
    limit_positive: FilteredInput,
    limit_negative: FilteredInput,
    emergency_stop: FilteredInput,
    heartbeat: u32,
}

impl Station {
    /// A station in its power-up state (every register 0); apply a reset before use.
    pub fn new(design: &Design) -> Self {
        let d = design.dividers;
        Station {
            design: *design,
            identity: design.identity(),
            rx_fifo: ByteFifo::new(),
            frame_rx: FrameRx::new(),
            exec: Executor::new(d.tick_div, d.clocks_per_ms, design.input_polarity),
            core: CoreModel::new(&design.format),
            queue: ReplyQueue::new(),
            reply_tx: ReplyTx::new(),
            tx_fifo: ByteFifo::new(),
            quad: Quadrature::with_width(32),
            quad_out: QuadOutputs::default(),
            pwm: Pwm::new(),
            servo: Servo::new(),
            limit_positive: FilteredInput::new(false),
            limit_negative: FilteredInput::new(false),
            emergency_stop: FilteredInput::new(false),
            heartbeat: 0,
        }
    }

    /// The design.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// The core model.
    pub fn core(&self) -> &CoreModel {
        &self.core
    }

    /// The command executor's outputs (its reply pulse marks the clock a frame is executed).
    pub fn executor_outputs(&self) -> crate::io::executor::ExecutorOutputs {
        self.exec.outputs()
    }

    /// True while part of a frame has been received.
    pub fn mid_frame(&self) -> bool {
        self.frame_rx.mid_frame()
    }

    /// The limit and emergency-stop levels the executor sees (filtered, polarity applied).
    fn inputs_seen(&self) -> (bool, bool, bool) {
        let pol = self.exec.outputs().config.input_polarity;
        (
            self.limit_positive.level ^ (pol & 1 != 0),
            self.limit_negative.level ^ (pol & 2 != 0),
            self.emergency_stop.level ^ (pol & 4 != 0),
        )
    }

    /// The status block, from the blocks' registered values.
    pub fn status(&self) -> Status {
        let (lp, ln, es) = self.inputs_seen();
        status(&StatusInputs {
            exec: &self.exec.outputs(),
            core: &self.core.outputs(),
            v_bits: self.design.format.widths.v,
            encoder: self.quad_out.count,
            encoder_error: self.quad_out.errors != self.exec.outputs().encoder_errors_seen,
            limit_pos: lp,
            limit_neg: ln,
            estop: es,
            servo: &self.servo.outputs(),
        })
    }

    /// The controller.
    pub fn servo(&self) -> &Servo {
        &self.servo
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> StationOutputs {
        let c = self.core.outputs();
        let e = self.exec.outputs();
        let p = self.pwm.outputs(e.config.pwm_period != 0, !e.amplifier);
        let tx = self.tx_fifo.outputs();
        StationOutputs {
            reply_ready: !tx.empty,
            reply_data: tx.data,
            led_idle: !c.busy && !c.stopping,
            led_busy: c.busy || c.stopping,
            led_fault: e.state == AxisState::ErrorStop
                || e.uart_error
                || self.quad_out.errors != e.encoder_errors_seen,
            led_heartbeat: (self.heartbeat >> self.design.dividers.heartbeat_bit) & 1 == 1,
            pwm: p.pwm,
            dir: p.dir,
            amplifier: e.amplifier,
            ticks: c.ticks,
            x: c.x,
            v: c.v,
            a: c.a,
            j: c.j,
            status: self.status(),
        }
    }

    /// One rising clock edge with the inputs `i`; returns the outputs after it.
    pub fn clock(&mut self, i: &StationInputs) -> StationOutputs {
        let dv = self.design.dividers;
        let reset = i.reset;
        // Every block's inputs, from the registered values before the edge.
        let core_out: CoreOutputs = self.core.outputs();
        let exec_out = self.exec.outputs();
        let rx_head = self.rx_fifo.outputs();
        let (lp, ln, es) = self.inputs_seen();
        let frame_in = FrameRxInputs {
            reset,
            data: rx_head.data,
            valid: !rx_head.empty,
            line_error: i.link_error,
            timeout: dv.frame_timeout,
        };
        let exec_in = ExecutorInputs {
            reset,
            rx: self.frame_rx.outputs(),
            line_error: i.link_error,
            core: core_out.status(),
            encoder_errors: self.quad_out.errors,
            queue_full: self.queue.full(),
            limit_pos: lp,
            limit_neg: ln,
            estop: es,
            following_fault: self.servo.outputs().fault,
            servo_overrun: self.servo.outputs().overrun,
        };
        let mut core_in = CoreInputs {
            reset,
            tick_div: exec_out.config.tick_divider,
            stop_jerk: exec_out.config.stop_jerk,
            stop_accel: exec_out.config.stop_accel,
            load_position: self.quad_out.count as u32,
            ..Default::default()
        };
        core_in.set_command(&exec_out.command);
        let tx_in = ReplyTxInputs {
            reset,
            head: self.queue.head(),
            telemetry: exec_out.telemetry,
            fifo_full: self.tx_fifo.outputs().full,
        };
        let live = Live {
            status: self.status(),
            state: StateReply {
                ticks: core_out.ticks,
                x: core_out.x,
                v: core_out.v,
                a: core_out.a,
                j: core_out.j,
            },
            config: exec_out.config,
            identity: self.identity,
        };
        let tx_out = self.reply_tx.outputs(&tx_in);
        let tx_head = self.tx_fifo.outputs();
        let take = !tx_head.empty && i.reply_take;
        let servo_in = ServoInputs {
            reset,
            // Not on the clock the reference loads the encoder's position (POWER 1): the first
            // sample comes after the load, never from the reference the motor left.
            enable: exec_out.amplifier && !exec_out.command.load,
            tick: core_out.tick,
            start: exec_out.command.start,
            x: core_out.x,
            v: core_out.v,
            a: core_out.a,
            count: self.quad_out.count,
            config: exec_out.config.servo(),
        };
        let pwm_in = PwmInputs {
            period: exec_out.config.pwm_period,
            duty: self.servo.outputs().duty,
            enable: exec_out.config.pwm_period != 0,
            fault: !exec_out.amplifier,
        };

        // The edge.
        self.rx_fifo
            .clock(i.link_valid, i.link_data, !rx_head.empty);
        self.frame_rx.clock(&frame_in);
        self.exec.clock(&exec_in);
        self.core.edge(&core_in);
        self.queue.clock(reset, exec_out.reply, tx_out.pop);
        self.reply_tx.clock(&tx_in, &live);
        self.tx_fifo
            .clock(tx_out.fifo_write, tx_out.fifo_data, take);
        self.quad_out = self.quad.clock(&QuadInputs {
            a: i.enc_a,
            b: i.enc_b,
            index: i.enc_i,
            filter: exec_out.config.encoder_filter,
            clear: reset,
        });
        self.pwm.clock(&pwm_in);
        self.servo.clock(&servo_in);
        let filter = exec_out.config.input_filter;
        self.limit_positive.clock(i.limit_pos, filter);
        self.limit_negative.clock(i.limit_neg, filter);
        self.emergency_stop.clock(i.estop, filter);
        self.heartbeat = self.heartbeat.wrapping_add(1);
        self.outputs()
    }
}
