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
use crate::io::executor::{Executor, ExecutorInputs, ReplyQueue};
use crate::io::fifo::ByteFifo;
use crate::io::frame_rx::{FrameRx, FrameRxInputs};
use crate::io::pwm::{Pwm, PwmInputs};
use crate::io::quadrature::{QuadInputs, QuadOutputs, Quadrature};
use crate::io::reply_tx::{status, Live, ReplyTx, ReplyTxInputs, StatusInputs};
use crate::io::servo::{Servo, ServoInputs};
use crate::io::uart::{RxOutputs, UartRx, UartTx};
use crate::io::FilteredInput;
use crate::program::Program;
use crate::protocol::{Identity, StateReply, Status, PROTOCOL_VERSION};
use crate::timing::{Dividers, Timing, TimingError};

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
        let w = f.widths.as_array();
        Identity {
            protocol: PROTOCOL_VERSION,
            design_hash: self.design_hash,
            clock_hz: self.clock_hz,
            baud: self.baud,
            tick_divider: self.dividers.tick_div,
            widths: w.map(|b| b as u8),
            frac_bits: crate::FRAC_BITS as u8,
            tick_bits: f.tick_bits as u8,
            max_segments: f.max_segments as u8,
            snap_bytes: Program::snap_bytes(f) as u8,
            stop: Default::default(),
        }
    }
}

/// The pins of one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IoInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// UART receive line (idles high).
    pub uart_rx: bool,
    /// Encoder A.
    pub enc_a: bool,
    /// Encoder B.
    pub enc_b: bool,
    /// Encoder index.
    pub enc_i: bool,
    /// Positive limit switch (raw, before polarity).
    pub limit_positive: bool,
    /// Negative limit switch.
    pub limit_negative: bool,
    /// Emergency stop.
    pub emergency_stop: bool,
}

/// The pins and the status block after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IoOutputs {
    /// UART transmit line.
    pub uart_tx: bool,
    /// PWM.
    pub pwm: bool,
    /// Direction.
    pub dir: bool,
    /// Amplifier enable.
    pub amplifier: bool,
    /// LED: idle.
    pub led_idle: bool,
    /// LED: busy.
    pub led_busy: bool,
    /// LED: fault.
    pub led_fault: bool,
    /// LED: heartbeat.
    pub led_heartbeat: bool,
    /// The status block as the device would report it now.
    pub status: Status,
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
            limit_positive: lp,
            limit_negative: ln,
            emergency_stop: es,
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
            led_fault: e.state == crate::protocol::AxisState::ErrorStop
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
            busy: core_out.busy,
            stopping: core_out.stopping,
            standby_count: core_out.standby_count,
            tick: core_out.tick,
            at_rest: core_out.at_rest,
            heading_positive: core_out.heading > 0,
            heading_negative: core_out.heading < 0,
            encoder_errors: self.quad_out.errors,
            queue_full: self.queue.full(),
            limit_positive: lp,
            limit_negative: ln,
            emergency_stop: es,
            following_fault: self.servo.outputs().fault,
            servo_overrun: self.servo.outputs().overrun,
            ticks: core_out.ticks,
            swap_pending: core_out.swap_pending,
        };
        let core_in = CoreInputs {
            reset,
            tick_div: exec_out.config.tick_div,
            start: exec_out.start,
            abort: exec_out.abort,
            stop: exec_out.stop,
            load: exec_out.load,
            load_position: self.quad_out.count as u32,
            stop_limits: exec_out.config.stop,
            write_enable: exec_out.write_enable,
            write_address: exec_out.write_address,
            write_ticks: exec_out.write_ticks,
            write_snap: exec_out.write_snap,
            count_enable: exec_out.count_enable,
            count_value: exec_out.count_value,
            swap: exec_out.swap,
            swap_last: exec_out.swap_last,
        };
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
            enable: exec_out.amplifier && !exec_out.load,
            tick: core_out.tick,
            start: exec_out.start,
            x: core_out.x,
            v: core_out.v,
            a: core_out.a,
            count: self.quad_out.count,
            config: exec_out.config.servo,
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
        // The core's tick is combinational on the executor's TICK_DIVIDER register: after this
        // edge it compares with the register's new value, as the fabric's does (without this,
        // the first tick after a CONFIGURE of the divider came a clock late).
        self.core.set_tick_div(self.exec.outputs().config.tick_div);
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
        self.limit_positive.clock(i.limit_positive, filter);
        self.limit_negative.clock(i.limit_negative, filter);
        self.emergency_stop.clock(i.emergency_stop, filter);
        self.heartbeat = self.heartbeat.wrapping_add(1);
        self.outputs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;

    #[test]
    fn fnv1a32_check_values() {
        // The published test vectors of FNV-1a 32.
        assert_eq!(fnv1a32(b""), 0x811C_9DC5);
        assert_eq!(fnv1a32(b"a"), 0xE40C_292C);
        assert_eq!(fnv1a32(b"foobar"), 0xBF9C_F968);
    }
    use crate::peer::Peer;
    use crate::planner::{plan_from, Method, MoveRequest};
    use crate::protocol::{
        code, flag, AxisState, Command, Decoded, Decoder, ErrorId, Param, Reason, Reply,
    };
    use crate::stop::StopLimits;
    use crate::ChainState;

    /// A small design: 16 clocks per UART bit, a tick every 8 clocks, 2 clocks per ms.
    fn design() -> Design {
        Design {
            format: DEFAULT_FORMAT,
            dividers: Dividers {
                uart_divisor: 16,
                tick_div: 7,
                frame_timeout: 2000,
                heartbeat_bit: 10,
                clocks_per_ms: 2000,
            },
            clock_hz: 2_000_000,
            baud: 125_000,
            design_hash: 0x1234_5678,
            input_polarity: 0,
        }
    }

    struct Bench {
        dev: Device,
        peer: Peer,
        seq: u8,
        decoder: Decoder,
        replies: Vec<(u8, Reply)>,
    }

    impl Bench {
        fn new() -> Self {
            let d = design();
            Bench {
                dev: Device::new(&d),
                peer: Peer::new(d.dividers.uart_divisor),
                seq: 0,
                decoder: Decoder::new(),
                replies: Vec::new(),
            }
        }

        fn run(&mut self, clocks: u64) {
            for _ in 0..clocks {
                let i = self.peer.inputs();
                let o = self.dev.clock(&i);
                self.peer.observe(&o);
            }
            for b in self.peer.take_received() {
                if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
                    self.replies
                        .push((f.seq, Reply::from_frame(&f).expect("a known reply")));
                }
            }
        }

        /// Sends `c` and runs until its reply arrives.
        fn ask(&mut self, c: Command) -> Reply {
            self.seq = self.seq.wrapping_add(1).max(1);
            let seq = self.seq;
            self.peer.send(&c.to_frame(seq, &DEFAULT_FORMAT).to_bytes());
            for _ in 0..4000 {
                self.run(50);
                if let Some(k) = self.replies.iter().position(|(s, _)| *s == seq) {
                    return self.replies.remove(k).1;
                }
            }
            panic!("no reply to {c:?}");
        }

        fn status(&mut self) -> crate::protocol::Status {
            match self.ask(Command::ReadStatus) {
                Reply::Status(s) => s,
                r => panic!("{r:?}"),
            }
        }
    }

    fn ack(c: &Command) -> Reply {
        Reply::Ack { cmd: c.code() }
    }

    #[test]
    fn identity_then_a_whole_move() {
        let mut b = Bench::new();
        b.run(10);
        let Reply::Identity(id) = b.ask(Command::Ping) else {
            panic!()
        };
        assert!(id.matches_format(&DEFAULT_FORMAT));
        assert_eq!((id.design_hash, id.tick_divider), (0x1234_5678, 7));
        // Disabled after reset, and POWER needs the stop limits.
        assert_eq!(b.status().state, AxisState::Disabled as u8);
        assert_eq!(
            b.ask(Command::Power { on: true }),
            Reply::Nak {
                cmd: 0x0B,
                reason: Reason::NotConfigured
            }
        );
        let p = plan_from(
            &MoveRequest {
                distance: 0.003,
                method: Method::Order3 {
                    vmax: 1.0,
                    amax: 100.0,
                    jmax: 1e5,
                },
            },
            &DEFAULT_FORMAT,
            ChainState::at_rest(DEFAULT_FORMAT.home_raw()),
        )
        .unwrap();
        let limits = StopLimits {
            jerk: 2 * p.amplitude_raw.abs(),
            accel: 1 << 90,
        };
        for c in [
            Command::Configure {
                param: Param::StopJerk,
                value: limits.jerk,
            },
            Command::Configure {
                param: Param::StopAccel,
                value: limits.accel,
            },
            Command::Configure {
                param: Param::TelemetryPeriod,
                value: i128::from(p.ticks_total() as u32 / 10),
            },
            Command::Power { on: true },
        ] {
            assert_eq!(b.ask(c), ack(&c), "{c:?}");
        }
        assert_eq!(
            b.ask(Command::ReadConfig {
                param: Param::StopJerk
            }),
            Reply::Config {
                param: Param::StopJerk,
                value: limits.jerk
            }
        );
        assert_eq!(b.status().state, AxisState::Standstill as u8);
        for (k, s) in p.program.segments.iter().enumerate() {
            let c = Command::LoadSegment {
                index: k as u8,
                segment: *s,
            };
            assert_eq!(b.ask(c), ack(&c));
        }
        let c = Command::Commit {
            count: p.program.segments.len() as u8,
        };
        assert_eq!(b.ask(c), ack(&c));
        assert_eq!(b.ask(Command::Start), ack(&Command::Start));
        let s = b.status();
        assert_eq!(s.state, AxisState::DiscreteMotion as u8);
        assert!(s.has(flag::PLAYING | flag::AMPLIFIER));
        b.run(8 * p.ticks_total() + 200);
        let s = b.status();
        assert_eq!(s.state, AxisState::Standstill as u8, "{s:?}");
        assert!(s.has(flag::DONE));
        let Reply::State(st) = b.ask(Command::ReadState) else {
            panic!()
        };
        assert_eq!(st.x, p.final_state.x);
        assert_eq!((st.v, st.a, st.j), (0, 0, 0));
        let telemetry = b
            .replies
            .iter()
            .filter(|(_, r)| matches!(r, Reply::Telemetry(_)))
            .count();
        // Every tenth of the move, and once at its end; but no faster than a frame's airtime
        // (30 bytes of 160 clocks: 600 ticks here), over which requests coalesce.
        let airtime_ticks = 30 * 160 / 8;
        let period = (p.ticks_total() / 10).max(airtime_ticks);
        let want = p.ticks_total() / period;
        assert!(
            (want..=want + 2).contains(&(telemetry as u64)),
            "{telemetry} telemetry frames over {} ticks",
            p.ticks_total()
        );
    }

    #[test]
    fn sixteen_commands_in_one_write_get_sixteen_replies() {
        let mut b = Bench::new();
        b.run(10);
        let mut bytes = Vec::new();
        for seq in 1..=16u8 {
            bytes.extend(
                Command::ReadStatus
                    .to_frame(seq, &DEFAULT_FORMAT)
                    .to_bytes(),
            );
        }
        b.peer.send(&bytes);
        b.run(16 * 30 * 16 * 10 + 16 * 10 * 16 * 10);
        let seqs: Vec<u8> = b.replies.iter().map(|(s, _)| *s).collect();
        assert_eq!(seqs, (1..=16).collect::<Vec<_>>());
    }

    #[test]
    fn the_emergency_stop_latches_error_stop_with_the_amplifier_off() {
        let mut b = Bench::new();
        b.run(10);
        for c in [
            Command::Configure {
                param: Param::StopJerk,
                value: 10,
            },
            Command::Configure {
                param: Param::StopAccel,
                value: 1000,
            },
            Command::Power { on: true },
        ] {
            assert_eq!(b.ask(c), ack(&c));
        }
        b.peer.emergency_stop = true;
        b.run(10);
        let s = b.status();
        assert_eq!(
            (s.state, s.error),
            (AxisState::ErrorStop as u8, ErrorId::EmergencyStop as u8)
        );
        assert!(!s.has(flag::AMPLIFIER) && s.has(flag::EMERGENCY_STOP));
        assert!(!b.dev.outputs().amplifier);
        // No reset while the input is active; then back to Disabled.
        assert_eq!(
            b.ask(Command::Reset),
            Reply::Nak {
                cmd: 0x0C,
                reason: Reason::AxisError
            }
        );
        b.peer.emergency_stop = false;
        b.run(10);
        assert_eq!(b.ask(Command::Reset), ack(&Command::Reset));
        assert_eq!(b.status().state, AxisState::Disabled as u8);
    }

    fn nak(cmd: u8, reason: Reason) -> Reply {
        Reply::Nak { cmd, reason }
    }

    /// Stop limits, POWER 1, and a program whose segments are `segs` (committed).
    fn powered_with(b: &mut Bench, segs: &[crate::program::Segment]) {
        for c in [
            Command::Configure {
                param: Param::StopJerk,
                value: 5,
            },
            Command::Configure {
                param: Param::StopAccel,
                value: 1000,
            },
            Command::Power { on: true },
        ] {
            assert_eq!(b.ask(c), ack(&c), "{c:?}");
        }
        for (k, s) in segs.iter().enumerate() {
            let c = Command::LoadSegment {
                index: k as u8,
                segment: *s,
            };
            assert_eq!(b.ask(c), ack(&c));
        }
        let c = Command::Commit {
            count: segs.len() as u8,
        };
        assert_eq!(b.ask(c), ack(&c));
    }

    #[test]
    fn a_program_that_ends_moving_is_stopped_and_nothing_unsafe_is_accepted_meanwhile() {
        use crate::program::Segment;
        let mut b = Bench::new();
        b.run(10);
        // One segment of constant snap: the program ends with v, a, j all non-zero.
        powered_with(&mut b, &[Segment { ticks: 20, snap: 3 }]);
        assert_eq!(b.ask(Command::Start), ack(&Command::Start));
        let s = loop {
            let s = b.status();
            if s.state == AxisState::ErrorStop as u8 {
                break s;
            }
            assert_eq!(s.state, AxisState::DiscreteMotion as u8, "{s:?}");
        };
        assert_eq!(s.error, ErrorId::ProgramEnd as u8);
        // While its stop runs (or the axis is not yet at rest): no POWER 0, no new Ts, no new
        // stop limits, no RESET.
        let moving = |b: &mut Bench| {
            let Reply::State(st) = b.ask(Command::ReadState) else {
                panic!()
            };
            (st.v, st.a, st.j) != (0, 0, 0) || b.status().has(flag::STOPPING)
        };
        if moving(&mut b) {
            assert_eq!(b.ask(Command::Power { on: false }), nak(0x0B, Reason::Busy));
            assert_eq!(
                b.ask(Command::Configure {
                    param: Param::TickDivider,
                    value: 9
                }),
                nak(0x08, Reason::Busy)
            );
        }
        // It ends exactly at rest; then RESET gives Standstill.
        while moving(&mut b) {}
        assert_eq!(b.ask(Command::Reset), ack(&Command::Reset));
        assert_eq!(b.status().state, AxisState::Standstill as u8);
    }

    #[test]
    fn stop_limits_cannot_be_made_unusable_and_inputs_cannot_be_masked_while_enabled() {
        let mut b = Bench::new();
        b.run(10);
        powered_with(&mut b, &[]);
        for (param, value, reason) in [
            (Param::StopJerk, 0, Reason::BadArgument),
            (Param::StopAccel, 0, Reason::BadArgument),
            (Param::StopJerk, 1001, Reason::BadArgument),
            (Param::StopAccel, 4, Reason::BadArgument),
            (Param::InputPolarity, 4, Reason::NotDisabled),
            (Param::InputFilter, 9, Reason::NotDisabled),
        ] {
            assert_eq!(
                b.ask(Command::Configure { param, value }),
                nak(0x08, reason),
                "{param:?} {value}"
            );
        }
        // A valid pair is fine; disabled, anything in range is.
        let c = Command::Configure {
            param: Param::StopJerk,
            value: 1000,
        };
        assert_eq!(b.ask(c), ack(&c));
        assert_eq!(
            b.ask(Command::Power { on: false }),
            ack(&Command::Power { on: false })
        );
        // (Inverting limit−: with its pin low it reads active; the e-stop's bit stays clear.)
        for (param, value) in [(Param::StopJerk, 0), (Param::InputPolarity, 2)] {
            let c = Command::Configure { param, value };
            assert_eq!(b.ask(c), ack(&c));
        }
        // And POWER 1 then wants valid limits again.
        assert_eq!(
            b.ask(Command::Power { on: true }),
            nak(0x0B, Reason::NotConfigured)
        );
    }

    #[test]
    fn a_start_toward_an_active_limit_is_refused_and_a_move_toward_it_trips_at_once() {
        use crate::program::Segment;
        let mut b = Bench::new();
        b.run(10);
        // Forward, then backward: each a single segment of constant snap.
        powered_with(&mut b, &[Segment { ticks: 50, snap: 2 }]);
        b.peer.limit_positive = true;
        b.run(20);
        assert_eq!(b.ask(Command::Start), nak(0x04, Reason::Limit));
        // A backward program is allowed with limit+ active ...
        let c = Command::LoadSegment {
            index: 0,
            segment: Segment {
                ticks: 1_000_000,
                snap: -2,
            },
        };
        assert_eq!(b.ask(c), ack(&c));
        assert_eq!(b.ask(Command::Start), ack(&Command::Start));
        // ... and the same backward move trips limit− from its first ticks (v is still 0
        // then: the heading is j's sign).
        b.peer.limit_negative = true;
        b.run(30);
        let s = b.status();
        assert_eq!(
            (s.state, s.error),
            (AxisState::ErrorStop as u8, ErrorId::LimitNegative as u8)
        );
    }

    #[test]
    fn ping_clears_the_retry_memory_and_reset_clears_the_sticky_flags() {
        let mut b = Bench::new();
        b.run(10);
        // A RESET with sequence 7 ...
        let frame = Command::Reset.to_frame(7, &DEFAULT_FORMAT).to_bytes();
        b.peer.send(&frame);
        b.run(3000);
        b.replies.clear();
        // ... a UART framing error (a break) sets UART_ERROR ...
        b.peer.line_break = true;
        b.run(200);
        b.peer.line_break = false;
        b.run(200);
        assert!(b.status().has(flag::UART_ERROR));
        // ... the same RESET frame again would be a retry (answered, not executed) ...
        b.peer.send(&frame);
        b.run(3000);
        assert!(b.status().has(flag::UART_ERROR));
        // ... but after a PING it runs, and clears the flag.
        b.ask(Command::Ping);
        b.replies.clear();
        b.peer.send(&frame);
        b.run(3000);
        assert!(!b.status().has(flag::UART_ERROR));
    }

    #[test]
    fn a_following_error_disables_the_amplifier_and_nothing_moves_until_cleared() {
        use crate::program::Segment;
        let mut b = Bench::new();
        b.run(10);
        // The controller on (proportional only), a following limit of 3 counts; the encoder
        // does not follow (a stalled motor).
        b.peer.follow = false;
        for (param, value) in [
            (Param::PwmPeriod, 100),
            (Param::ServoPeriod, 1),
            (Param::Kp, 10i128 << 32),
        ] {
            let c = Command::Configure { param, value };
            assert_eq!(b.ask(c), ack(&c));
        }
        // POWER needs the following limit with the controller on.
        let c = Command::Configure {
            param: Param::StopJerk,
            value: 5,
        };
        assert_eq!(b.ask(c), ack(&c));
        let c = Command::Configure {
            param: Param::StopAccel,
            value: 1000,
        };
        assert_eq!(b.ask(c), ack(&c));
        assert_eq!(
            b.ask(Command::Power { on: true }),
            nak(0x0B, Reason::NotConfigured)
        );
        let c = Command::Configure {
            param: Param::FollowingLimit,
            value: 3,
        };
        assert_eq!(b.ask(c), ack(&c));
        powered_with(
            &mut b,
            &[Segment {
                ticks: 100_000,
                snap: 1 << 40,
            }],
        );
        assert_eq!(b.ask(Command::Start), ack(&Command::Start));
        let s = loop {
            let s = b.status();
            if s.state == AxisState::ErrorStop as u8 {
                break s;
            }
        };
        assert_eq!(s.error, ErrorId::FollowingError as u8);
        assert!(!s.has(flag::AMPLIFIER));
        // The peak it saw is past the limit; the reference holds (v = a = j = 0).
        assert!(s.following_peak > 3 << 16, "{s:?}");
        let Reply::State(st) = b.ask(Command::ReadState) else {
            panic!()
        };
        assert_eq!((st.v, st.a, st.j), (0, 0, 0));
        // Nothing drives the motor: PWM and direction stay low, the duty is 0.
        for _ in 0..2000 {
            let o = b.dev.clock(&b.peer.inputs());
            assert!(!o.pwm && !o.dir && !o.amplifier && o.status.duty == 0);
        }
        assert_eq!(b.ask(Command::Start), nak(0x04, Reason::AxisError));
        // Cleared: RESET (Disabled), POWER 1 takes the encoder's position, at rest.
        assert_eq!(b.ask(Command::Reset), ack(&Command::Reset));
        assert_eq!(b.status().state, AxisState::Disabled as u8);
        assert_eq!(
            b.ask(Command::Power { on: true }),
            ack(&Command::Power { on: true })
        );
        let s = b.status();
        assert_eq!(
            (s.state, s.position),
            (AxisState::Standstill as u8, s.encoder)
        );
        let Reply::State(st) = b.ask(Command::ReadState) else {
            panic!()
        };
        assert_eq!(st.x, (i128::from(s.encoder) << 80) + (1 << 79));
    }

    fn state(b: &mut Bench) -> crate::protocol::StateReply {
        match b.ask(Command::ReadState) {
            Reply::State(st) => st,
            r => panic!("{r:?}"),
        }
    }

    /// A move started at a known tick by SWAP_AT from rest, replanned mid-move from the state
    /// the host predicts for a future tick, swapped there over the wire: it lands exactly where
    /// the online plan says. A late SWAP_AT, uploads and a second SWAP_AT while one is armed
    /// are refused and change nothing.
    #[test]
    fn a_replan_swaps_in_at_its_tick_over_the_wire() {
        use crate::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
        use crate::program::Segment;
        let f = DEFAULT_FORMAT;
        let w = f.widths;
        let mut b = Bench::new();
        b.run(10);
        let first = plan_from(
            &MoveRequest {
                distance: 0.05,
                method: Method::Order3 {
                    vmax: 1.0,
                    amax: 50.0,
                    jmax: 5e3,
                },
            },
            &f,
            ChainState::at_rest(f.home_raw()),
        )
        .unwrap();
        powered_with(&mut b, &first.program.segments);
        // From rest, at a tick the host chooses: it knows where the program begins.
        let st = state(&mut b);
        let from = ChainState::at_rest(st.x);
        assert_eq!((st.v, st.a, st.j), (0, 0, 0));
        // A STATE reply takes 1340 ticks on this wire, a SWAP_AT 280: lead by more.
        let begin = st.ticks + 4000;
        let c = Command::SwapAt { tick: begin };
        assert_eq!(b.ask(c), ack(&c));
        let s = b.status();
        assert!(s.has(flag::SWAP_PENDING) && !s.has(flag::PLAYING));
        assert_eq!(s.state, AxisState::DiscreteMotion as u8);
        let one = Command::LoadSegment {
            index: 0,
            segment: Segment { ticks: 1, snap: 1 },
        };
        assert_eq!(b.ask(one), nak(code::LOAD_SEGMENT, Reason::SwapPending));
        let again = Command::SwapAt { tick: begin + 1 };
        assert_eq!(b.ask(again), nak(code::SWAP_AT, Reason::SwapPending));
        while !b.status().has(flag::PLAYING) {}
        // Mid-move: replan from the state at a future tick, predicted by the host.
        let st = state(&mut b);
        assert!(st.ticks > begin);
        let at = st.ticks + 40_000;
        let predicted = from.after_ticks(&first.program, at - begin, &w);
        let cell = f.output_lsb(st.x) - 5_000;
        let limits = OnlineLimits {
            velocity: 0.8,
            acceleration: 40.0,
            deceleration: 30.0,
            jerk: 4e3,
        };
        let replan = plan_online(
            &predicted,
            &OnlineTarget::Position {
                cell,
                velocity: 0.0,
            },
            &limits,
            OnlineOrder::Three,
            &f,
        )
        .unwrap();
        for (k, s) in replan.program.segments.iter().enumerate() {
            let c = Command::LoadSegment {
                index: k as u8,
                segment: *s,
            };
            assert_eq!(b.ask(c), ack(&c));
        }
        let c = Command::Commit {
            count: replan.program.segments.len() as u8,
        };
        assert_eq!(b.ask(c), ack(&c));
        let c = Command::SwapAt { tick: at };
        assert_eq!(b.ask(c), ack(&c));
        while b.status().has(flag::SWAP_PENDING) {}
        // Too late: a tick the time base has passed. Refused, and nothing changes.
        assert_eq!(b.ask(one), ack(&one));
        let c = Command::Commit { count: 1 };
        assert_eq!(b.ask(c), ack(&c));
        let now = state(&mut b).ticks;
        let late = Command::SwapAt { tick: now };
        assert_eq!(b.ask(late), nak(code::SWAP_AT, Reason::Late));
        loop {
            let s = b.status();
            if s.state == AxisState::Standstill as u8 {
                break;
            }
            assert_eq!(s.state, AxisState::DiscreteMotion as u8, "{s:?}");
        }
        let end = state(&mut b);
        let want = replan.final_state;
        assert_eq!(
            (end.x, end.v, end.a, end.j),
            (want.x, want.v, want.a, want.j)
        );
        assert_eq!(f.output_lsb(end.x), cell);
        assert_eq!(b.status().flags & flag::SWAP_PENDING, 0);
    }
}
