//! The fabric's command executor and axis state machine (`snapgen_hdl::executor::Executor`),
//! clock by clock. Every output is registered: what it decides on clock `c` takes effect on
//! clock `c + 1`.
//!
//! On each frame with a good CRC it checks the command (docs/PROTOCOL.md: code, length,
//! arguments, then the axis state), applies its effect (a segment write, a count, a start, a
//! stop, a configuration register, the amplifier, an error reset) and queues its reply; a bad
//! CRC or a dropped frame queues a NAK with sequence 0. A command with an effect whose code,
//! sequence and CRC equal the last such command's is a retry: its reply is queued again and
//! nothing else happens. A frame that arrives with the reply queue full is dropped unanswered
//! (and flagged).
//!
//! The axis state machine (PLCopen's, seed 000 Figure 1; [`AxisState`]) also moves by itself:
//! the emergency stop and the following error (ErrorStop, amplifier off, motion aborted at
//! once), motion toward an
//! active limit switch, an expired host watchdog or a program that ends with the axis not at
//! rest (ErrorStop through a controlled stop), and the end of a move or a stop at rest
//! (Standstill). Telemetry goes out every `TELEMETRY_PERIOD` ticks while the chain is driven
//! and once when it stops being driven.
//!
//! The axis *moves* while a program plays, a stop runs or any of v, a, j is not 0; while it
//! moves, POWER 0 and the parameters settable only at rest are refused (BUSY) whatever the
//! state.

use crate::core::BANK_DEPTH;
use crate::protocol::{
    code, command_spec, AxisState, ErrorId, Param, Reason, Settable, REPLY_QUEUE,
};
use crate::stop::StopLimits;

/// What a queued reply is; the payload is read when the reply is sent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum ReplyKind {
    /// IDENTITY.
    #[default]
    Identity = 0,
    /// ACK.
    Ack = 1,
    /// NAK (the reason in `aux`).
    Nak = 2,
    /// STATUS.
    Status = 3,
    /// STATE.
    State = 4,
    /// CONFIG (the parameter in `aux`).
    Config = 5,
    /// TELEMETRY (never queued: the transmitter sends it when nothing waits).
    Telemetry = 6,
}

impl ReplyKind {
    /// From the 3-bit field.
    pub fn from_bits(b: u8) -> Self {
        match b {
            0 => ReplyKind::Identity,
            1 => ReplyKind::Ack,
            2 => ReplyKind::Nak,
            3 => ReplyKind::Status,
            4 => ReplyKind::State,
            5 => ReplyKind::Config,
            _ => ReplyKind::Telemetry,
        }
    }
}

/// A queued reply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ReplyDesc {
    /// What it is.
    pub kind: ReplyKind,
    /// The command it answers (ACK, NAK).
    pub cmd: u8,
    /// Its sequence number.
    pub seq: u8,
    /// The NAK reason, or the CONFIG parameter.
    pub aux: u8,
}

/// The configuration registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Config {
    /// Clocks per tick − 1.
    pub tick_div: u32,
    /// PWM period (clocks).
    pub pwm_period: u16,
    /// Encoder filter (clocks).
    pub encoder_filter: u16,
    /// Telemetry period (ticks).
    pub telemetry_period: u32,
    /// The stop's limits.
    pub stop: StopLimits,
    /// Watchdog (ms).
    pub watchdog_ms: u32,
    /// Input polarity bits.
    pub input_polarity: u8,
    /// Input filter (clocks).
    pub input_filter: u16,
    /// The position controller's configuration.
    pub servo: crate::io::servo::ServoConfig,
}

impl Config {
    /// After reset: the generated tick divider and input polarity, the watchdog's default,
    /// everything else 0.
    pub fn after_reset(tick_div: u32, input_polarity: u8) -> Self {
        Config {
            tick_div,
            watchdog_ms: crate::protocol::DEFAULT_WATCHDOG_MS,
            input_polarity,
            servo: crate::io::servo::ServoConfig {
                output_limit: i16::MAX as u16,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// The value of `p`.
    pub fn get(&self, p: Param) -> i128 {
        match p {
            Param::TickDivider => i128::from(self.tick_div),
            Param::PwmPeriod => i128::from(self.pwm_period),
            Param::EncoderFilter => i128::from(self.encoder_filter),
            Param::TelemetryPeriod => i128::from(self.telemetry_period),
            Param::StopJerk => self.stop.jerk,
            Param::StopAccel => self.stop.accel,
            Param::WatchdogMs => i128::from(self.watchdog_ms),
            Param::InputPolarity => i128::from(self.input_polarity),
            Param::InputFilter => i128::from(self.input_filter),
            Param::ServoPeriod => i128::from(self.servo.period),
            Param::Kp => i128::from(self.servo.kp),
            Param::Ki => i128::from(self.servo.ki),
            Param::Kd => i128::from(self.servo.kd),
            Param::Kv => i128::from(self.servo.kv),
            Param::Ka => i128::from(self.servo.ka),
            Param::IntegralLimit => i128::from(self.servo.integral_limit),
            Param::OutputLimit => i128::from(self.servo.output_limit),
            Param::FollowingLimit => i128::from(self.servo.following_limit),
            Param::DFilter => i128::from(self.servo.d_filter),
        }
    }

    /// The position controller's parameters: the two set only while Disabled first.
    pub const SERVO_PARAMS: [Param; 10] = [
        Param::ServoPeriod,
        Param::FollowingLimit,
        Param::Kp,
        Param::Ki,
        Param::Kd,
        Param::Kv,
        Param::Ka,
        Param::IntegralLimit,
        Param::OutputLimit,
        Param::DFilter,
    ];

    /// What CONFIGURE writes for the controller configuration `servo`, in
    /// [`Self::SERVO_PARAMS`]' order (through [`Self::get`]: one mapping of fields to
    /// parameters for the device and for every host).
    pub fn servo_writes(servo: &crate::io::servo::ServoConfig) -> [(Param, i128); 10] {
        let c = Config {
            servo: *servo,
            ..Default::default()
        };
        Self::SERVO_PARAMS.map(|p| (p, c.get(p)))
    }

    /// Sets `p` to `v` (in range: CONFIGURE checks it).
    pub fn set(&mut self, p: Param, v: i128) {
        match p {
            Param::TickDivider => self.tick_div = v as u32,
            Param::PwmPeriod => self.pwm_period = v as u16,
            Param::EncoderFilter => self.encoder_filter = v as u16,
            Param::TelemetryPeriod => self.telemetry_period = v as u32,
            Param::StopJerk => self.stop.jerk = v,
            Param::StopAccel => self.stop.accel = v,
            Param::WatchdogMs => self.watchdog_ms = v as u32,
            Param::InputPolarity => self.input_polarity = v as u8,
            Param::InputFilter => self.input_filter = v as u16,
            Param::ServoPeriod => self.servo.period = v as u16,
            Param::Kp => self.servo.kp = v as i64,
            Param::Ki => self.servo.ki = v as i64,
            Param::Kd => self.servo.kd = v as i64,
            Param::Kv => self.servo.kv = v as i64,
            Param::Ka => self.servo.ka = v as i64,
            Param::IntegralLimit => self.servo.integral_limit = v as i64,
            Param::OutputLimit => self.servo.output_limit = v as u16,
            Param::FollowingLimit => self.servo.following_limit = v as u32,
            Param::DFilter => self.servo.d_filter = v as u8,
        }
    }
}

/// Inputs of one clock (every one a registered output of another block).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExecutorInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// The frame receiver's outputs.
    pub rx: crate::io::frame_rx::FrameRxOutputs,
    /// UART framing error.
    pub line_error: bool,
    /// Core: a program plays.
    pub busy: bool,
    /// Core: a controlled stop runs.
    pub stopping: bool,
    /// Core: the standby program's segment count.
    pub standby_count: u8,
    /// Core: the tick enable.
    pub tick: bool,
    /// Core: the chain is at rest (v = a = j = 0).
    pub at_rest: bool,
    /// Core: the axis heads forward.
    pub heading_positive: bool,
    /// Core: the axis heads backward.
    pub heading_negative: bool,
    /// The encoder's count of illegal transitions.
    pub encoder_errors: u16,
    /// The reply queue is full.
    pub queue_full: bool,
    /// Positive limit input (filtered, polarity applied).
    pub limit_positive: bool,
    /// Negative limit input.
    pub limit_negative: bool,
    /// Emergency-stop input.
    pub emergency_stop: bool,
    /// The controller: the following error is beyond its limit.
    pub following_fault: bool,
    /// The controller skipped a sample.
    pub servo_overrun: bool,
    /// Core: the time base (ticks since reset).
    pub ticks: u64,
    /// Core: a program swap is armed.
    pub swap_pending: bool,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExecutorOutputs {
    /// Core: write one segment.
    pub write_enable: bool,
    /// Core: segment address.
    pub write_address: u8,
    /// Core: segment ticks.
    pub write_ticks: u32,
    /// Core: segment snap.
    pub write_snap: i128,
    /// Core: set the count.
    pub count_enable: bool,
    /// Core: count.
    pub count_value: u8,
    /// Core: start.
    pub start: bool,
    /// Core: arm a program swap for the tick after `swap_last`.
    pub swap: bool,
    /// Core: the low 32 bits of the swap's tick minus one (held until the next SWAP_AT).
    pub swap_last: u32,
    /// Core: controlled stop.
    pub stop: bool,
    /// Core: abort (emergency stop, following error).
    pub abort: bool,
    /// Core: the reference takes the encoder's position, at rest (POWER 1 from Disabled).
    pub load: bool,
    /// The configuration.
    pub config: Config,
    /// The axis state.
    pub state: AxisState,
    /// Why in ErrorStop.
    pub error: ErrorId,
    /// The amplifier is enabled.
    pub amplifier: bool,
    /// A UART framing error was seen.
    pub uart_error: bool,
    /// A frame was dropped with the reply queue full.
    pub reply_overflow: bool,
    /// The controller skipped a sample.
    pub servo_overrun: bool,
    /// The encoder's error count when RESET last cleared the sticky flags: the status shows
    /// an encoder error while the count differs.
    pub encoder_errors_seen: u16,
    /// Frames with a bad CRC.
    pub bad_crc: u16,
    /// Frames with a bad length, an unknown command or cut short.
    pub bad_frames: u16,
    /// Pulse: queue this reply.
    pub reply: Option<ReplyDesc>,
    /// Pulse: send telemetry.
    pub telemetry: bool,
}

/// The executor.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Executor {
    out: ExecutorOutputs,
    /// The generated tick divider (after reset).
    tick_div_default: u32,
    /// The generated input polarity (after reset).
    polarity_default: u8,
    /// Clocks per millisecond (the watchdog's prescaler).
    clocks_per_ms: u32,
    /// The last command with an effect: code, sequence, CRC, its reply.
    last: Option<(u8, u8, u16, ReplyDesc)>,
    prescale: u32,
    watchdog_count: u32,
    telemetry_left: u32,
    was_driven: bool,
    /// The sign of the standby program's first snap (segment 0): +1, −1 or 0.
    first_direction: i8,
    /// A SWAP_AT's tick less the time base, registered every clock from the received
    /// payload (taken as an 8-byte one): one clock old when the frame is executed, so no
    /// 64-bit subtraction lies in the command's decision path.
    swap_lead: u64,
}

impl Executor {
    /// An executor for a design generated with `tick_div`, `clocks_per_ms` and
    /// `input_polarity`, in its power-up state (apply a reset).
    pub fn new(tick_div: u32, clocks_per_ms: u32, input_polarity: u8) -> Self {
        Executor {
            tick_div_default: tick_div,
            polarity_default: input_polarity,
            clocks_per_ms,
            ..Default::default()
        }
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> ExecutorOutputs {
        self.out
    }

    /// One clock.
    pub fn clock(&mut self, i: &ExecutorInputs) -> ExecutorOutputs {
        let before = self.out;
        // Pulses last one clock.
        self.out.write_enable = false;
        self.out.count_enable = false;
        self.out.start = false;
        self.out.swap = false;
        self.out.stop = false;
        self.out.abort = false;
        self.out.load = false;
        self.out.reply = None;
        self.out.telemetry = false;
        if i.reset {
            self.out = ExecutorOutputs {
                config: Config::after_reset(self.tick_div_default, self.polarity_default),
                ..Default::default()
            };
            self.last = None;
            self.prescale = 0;
            self.watchdog_count = 0;
            self.telemetry_left = 0;
            self.was_driven = false;
            self.first_direction = 0;
            self.swap_lead = 0;
            return self.out;
        }
        let s = before.state;
        let cfg = before.config;

        // Telemetry while the chain is driven, and once when it stops being driven, from the
        // period and countdown before this clock (a CONFIGURE of the period, below, restarts
        // the countdown and takes effect from the next clock).
        let driven = i.busy || i.stopping;
        let period = cfg.telemetry_period;
        if period != 0 {
            if i.tick && driven {
                if self.telemetry_left <= 1 {
                    self.out.telemetry = true;
                    self.telemetry_left = period;
                } else {
                    self.telemetry_left -= 1;
                }
            }
            if self.was_driven && !driven {
                self.out.telemetry = true;
                self.telemetry_left = period;
            }
        }
        self.was_driven = driven;

        // The watchdog: milliseconds since the last good frame.
        let expired = cfg.watchdog_ms != 0 && self.watchdog_count >= cfg.watchdog_ms;
        if i.rx.frame {
            self.prescale = 0;
            self.watchdog_count = 0;
        } else if self.prescale + 1 >= self.clocks_per_ms {
            self.prescale = 0;
            self.watchdog_count = self.watchdog_count.saturating_add(1);
        } else {
            self.prescale += 1;
        }

        // Frames.
        let o = &mut self.out;
        if i.line_error {
            o.uart_error = true;
        }
        if i.servo_overrun {
            o.servo_overrun = true;
        }
        if i.rx.bad_crc {
            o.bad_crc = o.bad_crc.wrapping_add(1);
            self.queue(i, nak(0, 0, Reason::BadCrc));
        } else if i.rx.dropped {
            o.bad_frames = o.bad_frames.wrapping_add(1);
            self.queue(i, nak(0, 0, Reason::Framing));
        } else if i.rx.frame {
            self.command(i, s, cfg);
        }
        let o = &mut self.out;

        // The axis by itself: the end of a move or a stop (at rest: Standstill; a program that
        // ended moving: a controlled stop into ErrorStop), then the errors (the emergency stop
        // last: it overrides everything).
        // (A swap armed while the axis rests is a start still to come.)
        let settling = before.start || before.stop || before.swap;
        if matches!(
            o.state,
            AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::Stopping
        ) && s == o.state
            && !i.busy
            && !i.stopping
            && !settling
            && (!i.at_rest || !i.swap_pending)
        {
            if i.at_rest {
                o.state = AxisState::Standstill;
            } else {
                o.stop = true;
                o.state = AxisState::ErrorStop;
                o.error = ErrorId::ProgramEnd;
            }
        }
        if expired && matches!(s, AxisState::DiscreteMotion | AxisState::ContinuousMotion) {
            o.stop = true;
            o.state = AxisState::ErrorStop;
            o.error = ErrorId::Watchdog;
        }
        if s != AxisState::ErrorStop && s != AxisState::Disabled {
            let toward = if i.limit_positive && i.heading_positive {
                Some(ErrorId::LimitPositive)
            } else if i.limit_negative && i.heading_negative {
                Some(ErrorId::LimitNegative)
            } else {
                None
            };
            if let Some(e) = toward {
                o.stop = true;
                o.state = AxisState::ErrorStop;
                o.error = e;
            }
        }
        if i.following_fault && o.amplifier {
            o.abort = true;
            o.stop = false;
            o.start = false;
            o.swap = false;
            o.amplifier = false;
            o.state = AxisState::ErrorStop;
            o.error = ErrorId::FollowingError;
        }
        if i.emergency_stop
            && !(s == AxisState::ErrorStop && before.error == ErrorId::EmergencyStop)
        {
            o.abort = true;
            o.stop = false;
            o.start = false;
            o.swap = false;
            o.amplifier = false;
            o.state = AxisState::ErrorStop;
            o.error = ErrorId::EmergencyStop;
        }

        self.swap_lead = swap_tick_field(&i.rx).wrapping_sub(i.ticks);
        self.out
    }

    /// Queues `r` unless the queue is full (then the overflow is flagged).
    fn queue(&mut self, i: &ExecutorInputs, r: ReplyDesc) -> bool {
        if i.queue_full {
            self.out.reply_overflow = true;
            false
        } else {
            self.out.reply = Some(r);
            true
        }
    }

    /// A frame with a good CRC.
    fn command(&mut self, i: &ExecutorInputs, s: AxisState, cfg: Config) {
        let rx = &i.rx;
        let (c, seq) = (rx.cmd, rx.seq);
        if i.queue_full {
            self.out.reply_overflow = true;
            return;
        }
        let Some(spec) = command_spec(c) else {
            self.out.bad_frames = self.out.bad_frames.wrapping_add(1);
            self.out.reply = Some(nak(c, seq, Reason::UnknownCommand));
            return;
        };
        if rx.len != spec.len {
            self.out.bad_frames = self.out.bad_frames.wrapping_add(1);
            self.out.reply = Some(nak(c, seq, Reason::BadLength));
            return;
        }
        if spec.effect {
            if let Some((lc, ls, lcrc, reply)) = self.last {
                if (lc, ls, lcrc) == (c, seq, rx.crc) {
                    // A retry: the same answer, no effect.
                    self.out.reply = Some(reply);
                    return;
                }
            }
        }
        let ack = ReplyDesc {
            kind: ReplyKind::Ack,
            cmd: c,
            seq,
            aux: 0,
        };
        if c == code::PING {
            // A new host session: no command before it is retried.
            self.last = None;
        }
        let reply = match self.check(i, s, cfg) {
            Err(reason) => nak(c, seq, reason),
            Ok(()) => match c {
                code::PING => data(ReplyKind::Identity, c, seq, 0),
                code::READ_STATUS => data(ReplyKind::Status, c, seq, 0),
                code::READ_STATE => data(ReplyKind::State, c, seq, 0),
                code::READ_CONFIG => data(ReplyKind::Config, c, seq, rx.byte(0)),
                _ => {
                    self.effect(i, s);
                    ack
                }
            },
        };
        self.out.reply = Some(reply);
        if spec.effect {
            self.last = Some((c, seq, rx.crc, reply));
        }
    }

    /// Arguments and axis state: why the command is refused, if it is.
    fn check(&self, i: &ExecutorInputs, s: AxisState, cfg: Config) -> Result<(), Reason> {
        let rx = &i.rx;
        let arg0 = rx.byte(0);
        let moving = i.busy || i.stopping || !i.at_rest;
        let toward_limit = (self.first_direction > 0 && i.limit_positive)
            || (self.first_direction < 0 && i.limit_negative);
        let refuse = match rx.cmd {
            code::LOAD_SEGMENT if usize::from(arg0) >= BANK_DEPTH || rx.field(1, 4) == 0 => {
                Some(Reason::BadArgument)
            }
            code::COMMIT if usize::from(arg0) > BANK_DEPTH => Some(Reason::BadArgument),
            code::LOAD_SEGMENT | code::COMMIT if i.swap_pending => Some(Reason::SwapPending),
            code::SWAP_AT if self.swap_lead as i64 >= SWAP_REACH => Some(Reason::BadArgument),
            code::START => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ if i.busy => Some(Reason::Busy),
                _ if i.stopping => Some(Reason::Stopping),
                _ if i.swap_pending => Some(Reason::SwapPending),
                _ if i.standby_count == 0 => Some(Reason::NoProgram),
                _ if !i.at_rest => Some(Reason::Busy),
                _ if toward_limit => Some(Reason::Limit),
                _ => None,
            },
            code::SWAP_AT => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ if i.stopping => Some(Reason::Stopping),
                _ if i.swap_pending => Some(Reason::SwapPending),
                _ if i.standby_count == 0 => Some(Reason::NoProgram),
                // The lead is one clock old and the core arms one clock later: the time base
                // may have ticked twice by then, and the core wants three ticks of lead.
                _ if (self.swap_lead as i64) < SWAP_MIN_LEAD => Some(Reason::Late),
                _ if i.at_rest && !i.busy && toward_limit => Some(Reason::Limit),
                _ => None,
            },
            code::STOP if s == AxisState::Disabled => Some(Reason::NotEnabled),
            code::HALT => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ => None,
            },
            code::CONFIGURE => {
                let value = signed_wide(rx.field(1, 13));
                match Param::from_byte(arg0) {
                    None => Some(Reason::BadArgument),
                    Some(p) if value < 0 || value > p.max() => Some(Reason::BadArgument),
                    Some(p) => match p.settable() {
                        Settable::AtRest if moving => Some(Reason::Busy),
                        Settable::Disabled if s != AxisState::Disabled => Some(Reason::NotDisabled),
                        _ if s != AxisState::Disabled && !stop_pair_valid(cfg, p, value) => {
                            Some(Reason::BadArgument)
                        }
                        _ => None,
                    },
                }
            }
            code::READ_CONFIG if Param::from_byte(arg0).is_none() => Some(Reason::BadArgument),
            code::POWER => match arg0 {
                2.. => Some(Reason::BadArgument),
                1 if s == AxisState::ErrorStop => Some(Reason::AxisError),
                1 if s == AxisState::Disabled
                    && (!cfg.stop.valid()
                        || (cfg.servo.period != 0 && cfg.servo.following_limit == 0)) =>
                {
                    Some(Reason::NotConfigured)
                }
                0 if moving => Some(Reason::Busy),
                _ => None,
            },
            code::RESET if s == AxisState::ErrorStop && (moving || i.emergency_stop) => {
                Some(Reason::AxisError)
            }
            _ => None,
        };
        refuse.map_or(Ok(()), Err)
    }

    /// The effect of an accepted command.
    fn effect(&mut self, i: &ExecutorInputs, s: AxisState) {
        let rx = &i.rx;
        let o = &mut self.out;
        match rx.cmd {
            code::LOAD_SEGMENT => {
                o.write_enable = true;
                o.write_address = rx.byte(0) & 0x1f;
                o.write_ticks = rx.field(1, 4) as u32;
                o.write_snap = signed_wide(rx.field(5, 13));
                if o.write_address == 0 {
                    self.first_direction = o.write_snap.signum() as i8;
                }
            }
            code::COMMIT => {
                o.count_enable = true;
                o.count_value = rx.byte(0) & 0x3f;
            }
            code::START => {
                o.start = true;
                o.state = AxisState::DiscreteMotion;
                // The banks swap: the new standby program is empty.
                self.first_direction = 0;
            }
            code::SWAP_AT => {
                o.swap = true;
                o.swap_last = (rx.field(0, 8) as u64).wrapping_sub(1) as u32;
                o.state = AxisState::DiscreteMotion;
                // The banks swap at the tick; no upload is taken before that.
                self.first_direction = 0;
            }
            code::STOP if s != AxisState::ErrorStop => {
                o.stop = true;
                o.state = AxisState::Stopping;
            }
            code::HALT if matches!(s, AxisState::DiscreteMotion | AxisState::ContinuousMotion) => {
                o.stop = true;
            }
            code::CONFIGURE => {
                let p = Param::from_byte(rx.byte(0)).expect("checked");
                o.config.set(p, signed_wide(rx.field(1, 13)));
                if p == Param::TelemetryPeriod {
                    self.telemetry_left = o.config.telemetry_period;
                }
            }
            code::POWER => match (rx.byte(0) == 1, s) {
                (true, AxisState::Disabled) => {
                    o.amplifier = true;
                    o.state = AxisState::Standstill;
                    // MC_Power: the axis holds where it is.
                    o.load = true;
                }
                (true, _) => {}
                (false, st) => {
                    o.amplifier = false;
                    if st == AxisState::Standstill {
                        o.state = AxisState::Disabled;
                    }
                }
            },
            code::RESET => {
                // The sticky flags clear in any state.
                o.uart_error = false;
                o.reply_overflow = false;
                o.servo_overrun = false;
                o.encoder_errors_seen = i.encoder_errors;
                if s == AxisState::ErrorStop {
                    o.error = ErrorId::None;
                    o.state = if o.amplifier {
                        AxisState::Standstill
                    } else {
                        AxisState::Disabled
                    };
                }
            }
            _ => {}
        }
    }
}

/// How far ahead of the time base a SWAP_AT may lie: the core compares the low 32 bits.
pub const SWAP_REACH: i64 = 1 << 31;

/// The least lead a SWAP_AT is accepted with, over the time base on the clock before the one
/// that executes it (docs/PROTOCOL.md, "Program swaps").
pub const SWAP_MIN_LEAD: i64 = 5;

/// SWAP_AT's `tick`, read from the received payload as if it were an 8-byte one (the last 8
/// bytes received), as the fabric wires it.
fn swap_tick_field(rx: &crate::io::frame_rx::FrameRxOutputs) -> u64 {
    (0..8).fold(0u64, |acc, k| {
        acc | (u64::from(rx.payload[7 - k]) << (8 * k))
    })
}

/// False when setting `p` to `value` would leave the stop limits unusable
/// (`0 < jerk ≤ accel` fails): refused while the axis is enabled.
fn stop_pair_valid(cfg: Config, p: Param, value: i128) -> bool {
    let mut limits = cfg.stop;
    match p {
        Param::StopJerk => limits.jerk = value,
        Param::StopAccel => limits.accel = value,
        _ => return true,
    }
    limits.valid()
}

/// A 104-bit two's-complement value (13 bytes) as i128.
pub fn signed_wide(raw: u128) -> i128 {
    crate::chain::wrap(raw as i128, 104)
}

fn nak(cmd: u8, seq: u8, reason: Reason) -> ReplyDesc {
    ReplyDesc {
        kind: ReplyKind::Nak,
        cmd,
        seq,
        aux: reason as u8,
    }
}

fn data(kind: ReplyKind, cmd: u8, seq: u8, aux: u8) -> ReplyDesc {
    ReplyDesc {
        kind,
        cmd,
        seq,
        aux,
    }
}

/// The reply queue (`snapgen_hdl::reply_queue::ReplyQueue`): [`REPLY_QUEUE`] descriptors,
/// first in first out; a write when full is lost (the executor does not write then).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReplyQueue {
    items: std::collections::VecDeque<ReplyDesc>,
}

impl ReplyQueue {
    /// Empty.
    pub fn new() -> Self {
        Self::default()
    }

    /// The head, if any.
    pub fn head(&self) -> Option<ReplyDesc> {
        self.items.front().copied()
    }

    /// True when full.
    pub fn full(&self) -> bool {
        self.items.len() == REPLY_QUEUE
    }

    /// One clock: pop the head if `pop`, then push `push` if not full.
    pub fn clock(&mut self, reset: bool, push: Option<ReplyDesc>, pop: bool) {
        if reset {
            self.items.clear();
            return;
        }
        let was_full = self.full();
        if pop {
            self.items.pop_front();
        }
        if let Some(r) = push {
            if !was_full {
                self.items.push_back(r);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::servo::ServoConfig;

    /// What a host writes for a controller configuration, replayed through CONFIGURE's
    /// setter, is that configuration: every field has its parameter, and only one.
    #[test]
    fn servo_writes_round_trip_through_configure() {
        let want = ServoConfig {
            period: 3,
            kp: 11,
            ki: 12,
            kd: 13,
            kv: 14,
            ka: 15,
            integral_limit: 16,
            output_limit: 17,
            following_limit: 18,
            d_filter: 4,
        };
        let mut c = Config::default();
        let writes = Config::servo_writes(&want);
        for (p, v) in writes {
            c.set(p, v);
        }
        assert_eq!(c.servo, want);
        let mut params: Vec<u8> = writes.iter().map(|(p, _)| *p as u8).collect();
        params.sort_unstable();
        params.dedup();
        assert_eq!(params.len(), writes.len());
    }
}
