//! The fabric's command executor and axis state machine (`snapgen_hdl::executor::Executor`),
//! clock by clock. Every output is registered: what it decides on clock `c` takes effect on
//! clock `c + 1`. Its inputs are registered too, where they arrive: it decides on clock `c`
//! from the inputs of clock `c − 1` (the frame's strobes, the core's status, the reply queue,
//! the switches and faults, the frame's code, sequence and CRC), so no path runs from another
//! block through a decision in one clock. Two reads are live: the frame's length and payload
//! (complete and unchanged for hundreds of clocks around its strobe; what the decision needs
//! of them is decoded a clock ahead in the fabric) and the time base, of which SWAP_AT's lead
//! is registered on every clock as before.
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

use snapgen_spec::fields::{
    Field, COMMIT_FIELDS, CONFIG_FIELDS, LOAD_SEGMENT_FIELDS, POWER_FIELDS, SWAP_AT_FIELDS,
};
use snapgen_spec::rules::{SWAP_MIN_LEAD, SWAP_REACH};

use snapgen_spec::{AxisState, ErrorId, Param, Reason};

mod commands;

pub use crate::io::config::Config;
use crate::ports::{CoreCommand, CoreStatus};

/// The payload fields the executor reads, by name from the layouts.
const SEG_INDEX: Field = snapgen_spec::fields::field(&LOAD_SEGMENT_FIELDS, "index");
const SEG_TICKS: Field = snapgen_spec::fields::field(&LOAD_SEGMENT_FIELDS, "ticks");
const SEG_SNAP: Field = snapgen_spec::fields::field(&LOAD_SEGMENT_FIELDS, "snap");
const COMMIT_COUNT: Field = snapgen_spec::fields::field(&COMMIT_FIELDS, "count");
const CFG_PARAM: Field = snapgen_spec::fields::field(&CONFIG_FIELDS, "param");
const CFG_VALUE: Field = snapgen_spec::fields::field(&CONFIG_FIELDS, "value");
const POWER_ON: Field = snapgen_spec::fields::field(&POWER_FIELDS, "on");
const SWAP_TICK: Field = snapgen_spec::fields::field(&SWAP_AT_FIELDS, "tick");

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

/// Inputs of one clock (every one a registered output of another block; the executor registers
/// them again before it reads them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExecutorInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// The frame receiver's outputs.
    pub rx: crate::io::frame_rx::FrameRxOutputs,
    /// UART framing error.
    pub line_error: bool,
    /// The core's status outputs.
    pub core: CoreStatus,
    /// The encoder's count of illegal transitions.
    pub encoder_errors: u16,
    /// The reply queue is full.
    pub queue_full: bool,
    /// Positive limit input (filtered, polarity applied).
    pub limit_pos: bool,
    /// Negative limit input.
    pub limit_neg: bool,
    /// Emergency-stop input.
    pub estop: bool,
    /// The controller: the following error is beyond its limit.
    pub following_fault: bool,
    /// The controller skipped a sample.
    pub servo_overrun: bool,
}

/// Outputs after a clock edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExecutorOutputs {
    /// The core's command inputs (pulses last one clock).
    pub command: CoreCommand,
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
    /// payload (taken as an 8-byte one) and the live time base: one clock old when the frame
    /// is executed, so no 64-bit subtraction lies in the command's decision path.
    swap_lead: u64,
    /// The watchdog had expired on the last clock.
    expired: bool,
    /// The inputs of the last clock, registered (0 after a reset).
    registered: ExecutorInputs,
    /// The start, stop and swap pulses sent two clocks ago: the core's status read on this
    /// clock (registered twice, once in the core and once here) does not show them yet.
    older_pulses: [bool; 3],
    /// A stop or an abort cancelled an armed swap on the last clock: the standby bank is
    /// emptied on this one (a clock later, so that the stop's decision does not reach the
    /// count's register in the same clock).
    empty_standby: bool,
    /// A CONFIGURE taken on the last clock: its parameter and value, written on this one (a
    /// clock later, so that the command's decision does not reach the enables of every
    /// parameter register in the same clock).
    configure: Option<(Param, i128)>,
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
    pub fn clock(&mut self, live: &ExecutorInputs) -> ExecutorOutputs {
        // What this clock reads: the inputs registered on the last clock, with the frame's
        // length and payload as they stand (its strobes, code, sequence and CRC registered).
        let registered = std::mem::replace(
            &mut self.registered,
            if live.reset {
                ExecutorInputs::default()
            } else {
                *live
            },
        );
        let i = &ExecutorInputs {
            reset: live.reset,
            rx: crate::io::frame_rx::FrameRxOutputs {
                len: live.rx.len,
                payload: live.rx.payload,
                ..registered.rx
            },
            ..registered
        };
        let before = self.out;
        let older = std::mem::replace(
            &mut self.older_pulses,
            if live.reset {
                [false; 3]
            } else {
                [
                    before.command.start,
                    before.command.stop,
                    before.command.swap,
                ]
            },
        );
        // Pulses last one clock; the values they carry are held (the core reads them with
        // their pulse only).
        let c = &mut self.out.command;
        c.write_enable = false;
        c.count_enable = false;
        c.start = false;
        c.swap = false;
        c.stop = false;
        c.abort_move = false;
        c.load = false;
        self.out.reply = None;
        self.out.telemetry = false;
        // The standby bank emptied for a swap cancelled on the last clock (a COMMIT taken on
        // this clock, below, writes the count after it).
        if std::mem::take(&mut self.empty_standby) {
            c.count_enable = true;
            c.count_value = 0;
        }
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
            self.expired = false;
            self.configure = None;
            return self.out;
        }
        let s = before.state;
        let cfg = before.config;

        // Telemetry while the chain is driven, and once when it stops being driven, from the
        // period and countdown before this clock (a CONFIGURE of the period, below, restarts
        // the countdown and takes effect from the next clock).
        let driven = i.core.busy || i.core.stopping;
        let was_driven = self.was_driven;
        let period = cfg.telemetry_period;
        if period != 0 {
            if i.core.tick && driven {
                if self.telemetry_left <= 1 {
                    self.out.telemetry = true;
                    self.telemetry_left = period;
                } else {
                    self.telemetry_left -= 1;
                }
            }
            if was_driven && !driven {
                self.out.telemetry = true;
                self.telemetry_left = period;
            }
        }

        // The watchdog: milliseconds since the last good frame.
        // (Registered: the count compared on the clock before decides on this one.)
        let expired = std::mem::replace(
            &mut self.expired,
            cfg.watchdog_ms != 0 && self.watchdog_count >= cfg.watchdog_ms,
        );
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
        }
        // The CONFIGURE taken on the last clock writes its parameter (and restarts the telemetry
        // countdown when it sets the period).
        if let Some((p, v)) = self.configure.take() {
            self.out.config.set(p, v);
            if p == Param::TelemetryPeriod {
                self.telemetry_left = self.out.config.telemetry_period;
            }
        }
        let executed = !i.rx.bad_crc && !i.rx.dropped && i.rx.frame && self.command(i, s, cfg);
        let o = &mut self.out;

        // The axis by itself: the end of a move or a stop (at rest: Standstill; a program that
        // ended moving: a controlled stop into ErrorStop), then the errors (the emergency stop
        // last: it overrides everything). Not on a clock a frame is executed (a clock later:
        // the end of a move does not wait on the command's decision).
        // (A swap armed while the axis rests is a start still to come.)
        // The status read here is two clocks old (the core's registers, then the executor's):
        // a start, stop or swap sent on either of the last two clocks does not show in it yet;
        // the core's `at_rest` is a register: a clock after the chain stopped being driven it
        // tells where the last tick left the chain.
        let settling = before.command.start
            || before.command.stop
            || before.command.swap
            || older.iter().any(|&p| p)
            || was_driven;
        if matches!(
            s,
            AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::Stopping
        ) && !executed
            && !i.core.busy
            && !i.core.stopping
            && !settling
            && (!i.core.at_rest || !i.core.swap_pending)
        {
            if i.core.at_rest {
                o.state = AxisState::Standstill;
            } else {
                o.command.stop = true;
                o.state = AxisState::ErrorStop;
                o.error = ErrorId::ProgramEnd;
            }
        }
        if expired && matches!(s, AxisState::DiscreteMotion | AxisState::ContinuousMotion) {
            o.command.stop = true;
            o.state = AxisState::ErrorStop;
            o.error = ErrorId::Watchdog;
        }
        if s != AxisState::ErrorStop && s != AxisState::Disabled {
            let toward = if i.limit_pos && i.core.heading_pos {
                Some(ErrorId::LimitPositive)
            } else if i.limit_neg && i.core.heading_neg {
                Some(ErrorId::LimitNegative)
            } else {
                None
            };
            if let Some(e) = toward {
                o.command.stop = true;
                o.state = AxisState::ErrorStop;
                o.error = e;
            }
        }
        // (The amplifier before this clock's command: a fault on the clock POWER 0 is taken
        // still counts.)
        if i.following_fault && before.amplifier {
            disable_at_once(o, ErrorId::FollowingError);
        }
        if i.estop && !(s == AxisState::ErrorStop && before.error == ErrorId::EmergencyStop) {
            disable_at_once(o, ErrorId::EmergencyStop);
        }
        // A stop or an abort cancels an armed swap, and its program, planned for the swap's
        // tick, never plays from another state: the standby bank is emptied on the next clock
        // (a swap sent on either of the last two clocks counts: the status does not show it
        // yet).
        self.empty_standby = (o.command.stop || o.command.abort_move)
            && (i.core.swap_pending || before.command.swap || older[2]);

        self.swap_lead = swap_tick_field(&live.rx).wrapping_sub(live.core.ticks);
        // (Registered last: the commands above read the value before this clock.)
        self.was_driven = driven;
        self.out
    }
}

/// SWAP_AT's `tick`, read from the received payload as if it were SWAP_AT's (the last bytes
/// received), as the fabric wires it.
fn swap_tick_field(rx: &crate::io::frame_rx::FrameRxOutputs) -> u64 {
    rx.get_as(&SWAP_TICK, snapgen_spec::fields::SwapAtArgs::BYTES) as u64
}

/// False when setting `p` to `value` would leave the stop limits unusable
/// (`0 < jerk ≤ accel` fails): refused while the axis is enabled.
fn stop_pair_valid(cfg: Config, p: Param, value: i128) -> bool {
    let mut limits = cfg.stop_limits();
    match p {
        Param::StopJerk => limits.jerk = value,
        Param::StopAccel => limits.accel = value,
        _ => return true,
    }
    limits.valid()
}

/// A fault that disables the amplifier at once (the following error, the emergency stop): the
/// move aborted (v, a and j zeroed), no stop, start or swap taken this clock, ErrorStop with
/// `error`.
fn disable_at_once(o: &mut ExecutorOutputs, error: ErrorId) {
    o.command.abort_move = true;
    o.command.stop = false;
    o.command.start = false;
    o.command.swap = false;
    o.amplifier = false;
    o.state = AxisState::ErrorStop;
    o.error = error;
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
