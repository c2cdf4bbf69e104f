//! The device: the whole I/O top (`snapgen_hdl::io_top::IoTop`), clock by clock — what a board
//! running the snapgen fabric does with its pins. It is the reference the Verilated I/O top is
//! compared with on every clock (every bit of `uart_tx`, PWM, direction, amplifier enable,
//! LEDs and the status block), and what `snapgen board --pty --model` serves.
//!
//! ```text
//! uart_rx → UartRx → FIFO → FrameRx → Executor ─→ MotionCore (sequencer, stop unit, chain)
//!                                        │  ↑ status, registers
//!                                        ↓  │
//! uart_tx ← UartTx ← FIFO ← ReplyTx ← ReplyQueue
//! enc_a/b/i → Quadrature → encoder count;  limit±, e-stop → input filters → Executor
//! chain x, v, a + encoder count → Servo (PID + feed-forward) → duty → PWM → pwm/dir
//! (off without the amplifier);  amplifier enable
//! ```
//!
//! Every block is a model of its own (`crate::io`, `crate::core`); each clock, every block's
//! inputs are computed from the registered outputs of the blocks before the edge, then every
//! block steps, exactly as the synchronous hardware does.

use crate::core::{CoreInputs, CoreModel, CoreOutputs};
use crate::format::Format;
use crate::io::executor::{Executor, ExecutorInputs};
use crate::io::fifo::ByteFifo;
use crate::io::frame_rx::{FrameRx, FrameRxInputs};
use crate::io::pwm::{Pwm, PwmInputs};
use crate::io::quadrature::{QuadInputs, QuadOutputs, Quadrature};
use crate::io::reply_queue::ReplyQueue;
use crate::io::reply_tx::{status, Live, ReplyTx, ReplyTxInputs, StatusInputs};
use crate::io::servo::{Servo, ServoInputs};
use crate::io::uart::{RxOutputs, UartRx, UartTx};
use crate::io::FilteredInput;
pub use crate::ports::{IoInputs, IoOutputs};
use crate::program::Program;
use crate::timing::{Dividers, Timing, TimingError};
use snapgen_spec::wire::PROTOCOL_VERSION;
use snapgen_spec::{AxisState, Identity, StateReply, Status};

/// What a design was generated with: its format, dividers and identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// The fixed-point format.
    pub format: Format,
    /// The clock, UART and tick dividers.
    pub dividers: Dividers,
    /// Fabric clock (Hz).
    pub clock_hz: u32,
    /// UART baud rate.
    pub baud: u32,
    /// Hash of the generated design (docs/HDL.md).
    pub design_hash: u32,
    /// The limit and emergency-stop inputs' polarity after reset (`INPUT_POLARITY`: bit 0
    /// inverts limit+, bit 1 limit−, bit 2 the emergency stop), from the board file.
    pub input_polarity: u8,
}

/// FNV-1a, 32 bits (offset basis 0x811C9DC5, prime 0x01000193): the design hash.
pub fn fnv1a32(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811C_9DC5u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    })
}

impl Design {
    /// The design of `timing` in `format`, with design hash 0 (the generator computes the
    /// real one from its Verilog). Its `baud` is the rate the UART really runs at:
    /// `clock / divisor`, rounded (115 207 for 115 200 baud from 125 MHz).
    pub fn from_timing(format: &Format, timing: &Timing) -> Result<Self, TimingError> {
        let dividers = timing.dividers()?;
        Ok(Design {
            format: *format,
            dividers,
            clock_hz: timing.clock_hz as u32,
            baud: (timing.clock_hz as f64 / f64::from(dividers.uart_divisor)).round() as u32,
            design_hash: 0,
            input_polarity: 0,
        })
    }

    /// The tick period after reset (s).
    pub fn ts(&self) -> f64 {
        (f64::from(self.dividers.tick_div) + 1.0) / f64::from(self.clock_hz)
    }

    /// The identity the design reports (its tick divider and stop limits are live values).
    pub fn identity(&self) -> Identity {
        let f = &self.format;
        let w = f.widths;
        Identity {
            protocol: PROTOCOL_VERSION,
            design_hash: self.design_hash,
            clock_hz: self.clock_hz,
            baud: self.baud,
            tick_divider: self.dividers.tick_div,
            x_bits: w.x as u8,
            v_bits: w.v as u8,
            a_bits: w.a as u8,
            j_bits: w.j as u8,
            d_bits: w.d as u8,
            frac_bits: crate::FRAC_BITS as u8,
            tick_bits: f.tick_bits as u8,
            max_segments: f.max_segments as u8,
            snap_bytes: Program::snap_bytes(f) as u8,
            stop_jerk: 0,
            stop_accel: 0,
        }
    }
}

/// The device model.
#[derive(Clone, Debug)]
pub struct Device {
    design: Design,
    identity: Identity,
    uart_rx: UartRx,
    uart_rx_out: RxOutputs,
    rx_fifo: ByteFifo,
    frame_rx: FrameRx,
    exec: Executor,
    core: CoreModel,
    queue: ReplyQueue,
    reply_tx: ReplyTx,
    tx_fifo: ByteFifo,
    uart_tx: UartTx,
    uart_tx_line: bool,
    quad: Quadrature,
    quad_out: QuadOutputs,
    pwm: Pwm,
    servo: Servo,
    limit_positive: FilteredInput,
    limit_negative: FilteredInput,
    emergency_stop: FilteredInput,
    heartbeat: u32,
}

impl Device {
    /// A device in its power-up state (every register 0, lines idle); apply a reset before
    /// use ([`Device::powered_up`] does).
    pub fn new(design: &Design) -> Self {
        let d = design.dividers;
        Device {
            design: *design,
            identity: design.identity(),
            uart_rx: UartRx::new(),
            uart_rx_out: RxOutputs::default(),
            rx_fifo: ByteFifo::new(),
            frame_rx: FrameRx::new(),
            exec: Executor::new(d.tick_div, d.clocks_per_ms, design.input_polarity),
            core: CoreModel::new(&design.format),
            queue: ReplyQueue::new(),
            reply_tx: ReplyTx::new(),
            tx_fifo: ByteFifo::new(),
            uart_tx: UartTx::new(),
            uart_tx_line: true,
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

    /// A device after `clocks` clocks of reset (lines idle).
    pub fn powered_up(design: &Design, clocks: u32) -> Self {
        let mut d = Device::new(design);
        let reset = IoInputs {
            reset: true,
            uart_rx: true,
            ..Default::default()
        };
        for _ in 0..clocks {
            d.clock(&reset);
        }
        d
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
    pub fn outputs(&self) -> IoOutputs {
        let c = self.core.outputs();
        let e = self.exec.outputs();
        let p = self.pwm.outputs(e.config.pwm_period != 0, !e.amplifier);
        let st = self.status();
        IoOutputs {
            uart_tx: self.uart_tx_line,
            pwm: p.pwm,
            dir: p.dir,
            amplifier: e.amplifier,
            led_idle: !c.busy && !c.stopping,
            led_busy: c.busy || c.stopping,
            led_fault: e.state == AxisState::ErrorStop
                || e.uart_error
                || self.quad_out.errors != e.encoder_errors_seen,
            led_heartbeat: (self.heartbeat >> self.design.dividers.heartbeat_bit) & 1 == 1,
            status: st,
        }
    }

    /// One rising clock edge with the pins `i`; returns the outputs after it.
    pub fn clock(&mut self, i: &IoInputs) -> IoOutputs {
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
            line_error: self.uart_rx_out.framing_error,
            timeout: dv.frame_timeout,
        };
        let exec_in = ExecutorInputs {
            reset,
            rx: self.frame_rx.outputs(),
            line_error: self.uart_rx_out.framing_error,
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
        let send = !tx_head.empty && !self.uart_tx.busy();
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
        let rx_valid = self.uart_rx_out.valid;
        let rx_data = self.uart_rx_out.data;
        self.uart_rx_out = self.uart_rx.clock(i.uart_rx, dv.uart_divisor);
        self.rx_fifo.clock(rx_valid, rx_data, !rx_head.empty);
        self.frame_rx.clock(&frame_in);
        self.exec.clock(&exec_in);
        self.core.edge(&core_in);
        self.queue.clock(reset, exec_out.reply, tx_out.pop);
        self.reply_tx.clock(&tx_in, &live);
        self.tx_fifo
            .clock(tx_out.fifo_write, tx_out.fifo_data, send);
        self.uart_tx_line = self.uart_tx.clock(send, tx_head.data, dv.uart_divisor).tx;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a32_check_values() {
        // The published test vectors of FNV-1a 32.
        assert_eq!(fnv1a32(b""), 0x811C_9DC5);
        assert_eq!(fnv1a32(b"a"), 0xE40C_292C);
        assert_eq!(fnv1a32(b"foobar"), 0xBF9C_F968);
    }
}
