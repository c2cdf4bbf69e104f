//! The I/O co-simulation's random host: what it sends and does, clock by clock — commands of
//! every kind with good and bad arguments, bursts past the reply queue, retries, bit errors,
//! cut frames, noise and line breaks, real moves uploaded and started, stops at random ticks,
//! switches and the emergency stop, configuration changes (among them controllers whose
//! integrator is seen in the duty) — reacting to the device's outputs.

use std::collections::VecDeque;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_host::protocol::{
    code, flag, AxisState, Command, Decoded, Decoder, ErrorId, Frame, Param, Reason, Reply, Status,
    DEVICE_MAX_PAYLOAD, START,
};
use snapgen_model::device::{Design, Device, IoInputs, IoOutputs};
use snapgen_model::format::Quantity;
use snapgen_model::peer::Peer;
use snapgen_model::{Format, Segment};
use snapgen_plan::{plan_from, Method, MoveRequest};
use snapgen_spec::rules::SWAP_MIN_LEAD;

use super::IoCosimReport;
use crate::moves::log_uniform;

/// The random host: what it sends and does, clock by clock.
pub(super) struct Stream {
    rng: StdRng,
    design: Design,
    /// Clocks to wait before the next action.
    wait: u64,
    seq: u8,
    last_frame: Option<Frame>,
    /// A line break in progress: clocks left.
    breaking: u64,
    decoder: Decoder,
    pub(super) report: IoCosimReport,
    last_state: u8,
    /// SWAP_PENDING on the last clock.
    last_swap_pending: bool,
    /// An armed swap was cancelled: START is sent once the axis is in Standstill again, before
    /// any upload (the standby bank was emptied: NO_PROGRAM).
    start_after_cancel: bool,
    /// Sequence numbers of START, STOP and HALT frames sent, to count their ACKs.
    pending: VecDeque<(u8, u8)>,
    /// Clocks since the stream began.
    now: u64,
    /// A command to send at a clock (a stop or halt in the middle of a move).
    scheduled: Option<(u64, Command)>,
    /// When the emergency stop and the limit switches go back to rest (they are pulses).
    release: [Option<u64>; 3],
}

impl Stream {
    pub(super) fn new(seed: u64, design: Design) -> Self {
        Stream {
            rng: StdRng::seed_from_u64(seed),
            design,
            wait: 50,
            seq: 0,
            last_frame: None,
            breaking: 0,
            decoder: Decoder::new(),
            report: IoCosimReport::default(),
            last_state: 0,
            last_swap_pending: false,
            start_after_cancel: false,
            pending: VecDeque::new(),
            now: 0,
            scheduled: None,
            release: [None; 3],
        }
    }

    fn next_seq(&mut self) -> u8 {
        self.seq = self.seq.wrapping_add(1).max(1);
        self.seq
    }

    /// Sends command `c` as a good frame.
    fn send(&mut self, peer: &mut Peer, c: Command) {
        let seq = self.next_seq();
        let f = c.to_frame(seq, &self.design.format);
        if matches!(c, Command::Start | Command::Stop | Command::Halt) {
            self.pending.push_back((seq, c.code()));
        }
        peer.send(&f.to_bytes());
        self.report.frames_sent += 1;
        self.last_frame = Some(f);
    }

    /// A controller whose integrator is seen in the duty: its clamp reached within a few
    /// samples (INTEGRAL_LIMIT up to a few counts, in counts · 2^-16), its term worth 0.5 to 200
    /// PWM clocks at the clamp (Ki · INTEGRAL_LIMIT / 2^48), the output unsaturated
    /// (proportional and derivative up to some 7 clocks a count: Kp · 2^16 / 2^48, no
    /// feed-forward); while Disabled, the
    /// controller turned on with a following limit it does not reach and the amplifier on.
    fn tuned_controller(&mut self, peer: &mut Peer, disabled: bool) {
        let r = &mut self.rng;
        let limit = log_uniform(r, 1e3, 3e5);
        let ki = (log_uniform(r, 0.5, 200.0) * 2f64.powi(48) / limit).min(Param::Ki.max() as f64);
        let kp = log_uniform(r, 1e6, 3e10) as i128;
        let kd = [0, kp][r.gen_range(0..2)];
        let period = [1, 2, 5][r.gen_range(0..3)];
        self.send_configs(
            peer,
            &[
                (Param::OutputLimit, 32767),
                (Param::PwmPeriod, 1000),
                (Param::Kv, 0),
                (Param::Ka, 0),
                (Param::Kd, kd),
                (Param::Kp, kp),
                (Param::IntegralLimit, limit as i128),
                (Param::Ki, ki as i128),
            ],
        );
        if disabled {
            self.send_configs(
                peer,
                &[
                    (Param::ServoPeriod, period),
                    (Param::FollowingLimit, 100_000),
                ],
            );
            self.send(peer, Command::Power { on: true });
        }
    }

    /// A random configuration write, mostly sensible values.
    fn configure(&mut self, peer: &mut Peer, disabled: bool) {
        let r = &mut self.rng;
        let gain = |r: &mut StdRng| -> i128 {
            match r.gen_range(0..4) {
                0 => 0,
                1 => (1i128 << snapgen_model::io::servo::GAIN_BITS) - 1,
                _ => log_uniform(r, 1.0, 1.4e14) as i128,
            }
        };
        let (param, value) = match r.gen_range(0..17) {
            16 => return self.tuned_controller(peer, disabled),
            // The controller: its rate and following limit (Disabled only), gains, limits.
            10 => (Param::ServoPeriod, [0, 1, 1, 2, 5][r.gen_range(0..5)]),
            11 => (
                Param::FollowingLimit,
                [0, 1, 3, 50, 100_000][r.gen_range(0..5)],
            ),
            12 => (
                [Param::Kp, Param::Ki, Param::Kd, Param::Kv, Param::Ka][r.gen_range(0..5)],
                gain(r),
            ),
            13 => (Param::IntegralLimit, gain(r)),
            14 => (Param::OutputLimit, [0, 10, 150, 32767][r.gen_range(0..4)]),
            15 if r.gen_bool(0.5) => (Param::Kp, gain(r)),
            15 => (Param::DFilter, r.gen_range(0..16)),
            0 => (Param::TelemetryPeriod, r.gen_range(0..60)),
            1 => (Param::WatchdogMs, [0, 1, 3, 10, 1000][r.gen_range(0..5)]),
            2 | 3 => {
                let s = stop_limits(r);
                return self.send_configs(peer, &[(Param::StopJerk, s.0), (Param::StopAccel, s.1)]);
            }
            // Any polarity of the limits (a wrong one reads a switch as active); the emergency
            // stop's bit kept as wired (a wrong one latches ErrorStop until the reset pin).
            4 => (
                Param::InputPolarity,
                r.gen_range(0..4) | i128::from(self.design.input_polarity & 4),
            ),
            5 => (Param::InputFilter, r.gen_range(0..20)),
            6 => (Param::PwmPeriod, r.gen_range(0..200)),
            7 => (Param::EncoderFilter, r.gen_range(0..4)),
            8 => (Param::TickDivider, [15, 15, 7, 40, 200][r.gen_range(0..5)]),
            // Out of range (BAD_ARGUMENT).
            _ => (Param::InputPolarity, 8 + r.gen_range(0..100)),
        };
        self.send(peer, Command::Configure { param, value });
    }

    fn send_configs(&mut self, peer: &mut Peer, list: &[(Param, i128)]) {
        for &(param, value) in list {
            self.send(peer, Command::Configure { param, value });
        }
    }

    /// A move from where the model stands, uploaded and started (the device decides whether
    /// it accepts it).
    fn upload_move(&mut self, peer: &mut Peer, dev: &Device) {
        let r = &mut self.rng;
        let ts = [1e-3, 1e-4][r.gen_range(0..2)];
        let f = Format::with_ts(ts);
        let req = random_move(r);
        let Ok(plan) = plan_from(&req, &f, dev.core().chain()) else {
            return;
        };
        if plan.ticks_total() > 4000 || plan.program.segments.is_empty() {
            return;
        }
        for (k, s) in plan.program.segments.iter().enumerate() {
            self.send(
                peer,
                Command::LoadSegment {
                    index: k as u8,
                    segment: *s,
                },
            );
        }
        let count = plan.program.segments.len() as u8;
        self.send(peer, Command::Commit { count });
        if self.rng.gen_bool(0.4) {
            // A program swap instead of a start (from rest, or mid-move: a replan), for a tick
            // from well before to well after the upload's airtime: late ones are refused.
            let per_tick = u64::from(self.design.dividers.tick_div) + 1;
            let airtime =
                (u64::from(count) + 2) * 30 * 10 * u64::from(self.design.dividers.uart_divisor);
            let lead = (airtime as f64 * self.rng.gen_range(0.2..3.0)) as u64 / per_tick;
            let tick = dev.core().outputs().ticks + lead;
            self.send(peer, Command::SwapAt { tick });
            return;
        }
        self.send(peer, Command::Start);
        if self.rng.gen_bool(0.2) {
            // Again: the program was consumed (NO_PROGRAM), or it plays (BUSY).
            self.send(peer, Command::Start);
        }
        // Half of the moves get a stop or a halt at a random clock of their run.
        if self.rng.gen_bool(0.5) {
            let run = plan.ticks_total() * (u64::from(self.design.dividers.tick_div) + 1);
            let upload = 12 * u64::from(self.design.dividers.uart_divisor) * 30;
            let at = self.now + upload + log_uniform(&mut self.rng, 10.0, run as f64 + 10.0) as u64;
            let c = if self.rng.gen_bool(0.7) {
                Command::Stop
            } else {
                Command::Halt
            };
            self.scheduled = Some((at, c));
        }
    }

    /// Bytes of a damaged frame, or noise.
    fn damaged(&mut self, peer: &mut Peer) {
        let r = &mut self.rng;
        let c = random_command(r, &self.design.format, 0);
        let seq = self.seq.wrapping_add(1).max(1);
        self.seq = seq;
        let mut bytes = c.to_frame(seq, &self.design.format).to_bytes();
        match r.gen_range(0..7) {
            5 => {
                // A good CRC on an unknown command.
                let cmd = loop {
                    let c = r.gen::<u8>();
                    if snapgen_host::protocol::command_spec(c).is_none() {
                        break c;
                    }
                };
                let n = r.gen_range(0..4);
                let payload = (0..n).map(|_| r.gen::<u8>()).collect();
                bytes = Frame { cmd, seq, payload }.to_bytes();
            }
            6 => {
                // A good CRC on a known command with the wrong length.
                let mut f = c.to_frame(seq, &self.design.format);
                if f.payload.is_empty() || r.gen_bool(0.5) {
                    f.payload.push(r.gen());
                } else {
                    f.payload.pop();
                }
                bytes = f.to_bytes();
            }
            0 => {
                // One bit flipped anywhere.
                let k = r.gen_range(0..bytes.len());
                bytes[k] ^= 1 << r.gen_range(0..8);
            }
            1 => {
                // Cut short: the rest never comes (the receiver times out).
                bytes.truncate(r.gen_range(1..bytes.len()));
                self.wait = u64::from(self.design.dividers.frame_timeout)
                    + 200 * u64::from(self.design.dividers.uart_divisor);
            }
            2 => {
                // An over-long length.
                bytes = vec![START, r.gen_range(DEVICE_MAX_PAYLOAD as u8 + 1..=255)];
                bytes.extend((0..r.gen_range(0..40)).map(|_| r.gen::<u8>()));
            }
            3 => {
                // Noise.
                bytes = (0..r.gen_range(1..30)).map(|_| r.gen::<u8>()).collect();
            }
            _ => {
                // A good frame whose length byte lies (within the device's maximum).
                bytes[1] = r.gen_range(0..=DEVICE_MAX_PAYLOAD as u8);
            }
        }
        peer.send(&bytes);
        self.report.damaged_sent += 1;
    }

    /// The next action, when the last one's wait is over.
    fn act(&mut self, peer: &mut Peer, dev: &Device) {
        let r = &mut self.rng;
        let choice = r.gen_range(0..100);
        let st = dev.status();
        if self.start_after_cancel && st.state == AxisState::Standstill as u8 {
            self.start_after_cancel = false;
            self.send(peer, Command::Start);
            return;
        }
        match choice {
            // Get the axis going: stop limits, power, a move.
            0..=14 => {
                if st.state == AxisState::ErrorStop as u8 {
                    self.send(peer, Command::Reset);
                } else if st.state == AxisState::Disabled as u8 || !st.has(flag::AMPLIFIER) {
                    let s = stop_limits(&mut self.rng);
                    self.send_configs(peer, &[(Param::StopJerk, s.0), (Param::StopAccel, s.1)]);
                    // Mostly with the controller off again (a stalled-motor test left it on), or
                    // on with gains whose integrator is seen.
                    match self.rng.gen_range(0..10) {
                        0..=5 => {
                            self.send(
                                peer,
                                Command::Configure {
                                    param: Param::ServoPeriod,
                                    value: 0,
                                },
                            );
                            self.send(peer, Command::Power { on: true });
                        }
                        6..=7 => self.tuned_controller(peer, true),
                        _ => self.send(peer, Command::Power { on: true }),
                    }
                } else {
                    self.upload_move(peer, dev);
                }
            }
            15..=29 => self.upload_move(peer, dev),
            30..=37 => {
                let c = if r.gen_bool(0.6) {
                    Command::Stop
                } else {
                    Command::Halt
                };
                self.send(peer, c);
            }
            38..=49 => {
                let c = random_command(r, &self.design.format, dev.core().outputs().ticks);
                if (matches!(c, Command::SwapAt { .. }) || self.rng.gen_bool(0.1))
                    && self.scheduled.is_none()
                    && self.release.iter().all(Option::is_none)
                    && self.rng.gen_bool(0.7)
                {
                    self.schedule_swap_at_the_edge(peer, dev);
                } else {
                    self.send(peer, c);
                }
            }
            50..=54 => {
                // A burst of reads, sometimes past the reply queue.
                let n = r.gen_range(2..24);
                for _ in 0..n {
                    let c = [
                        Command::ReadStatus,
                        Command::Ping,
                        Command::ReadState,
                        Command::ReadConfig {
                            param: Param::StopJerk,
                        },
                    ][self.rng.gen_range(0..4)];
                    self.send(peer, c);
                }
            }
            55..=59 => {
                // A retry: the same frame again (answered again, not executed again), or the
                // same sequence with another payload (executed).
                if let Some(mut f) = self.last_frame.clone() {
                    if r.gen_bool(0.3) && !f.payload.is_empty() {
                        let k = r.gen_range(0..f.payload.len());
                        f.payload[k] ^= 1;
                    }
                    peer.send(&f.to_bytes());
                    self.report.frames_sent += 1;
                }
            }
            60..=69 => self.damaged(peer),
            70..=77 => self.configure(peer, st.state == AxisState::Disabled as u8),
            78..=80 => {
                // A line break: the receiver sees a framing error.
                self.breaking = u64::from(self.design.dividers.uart_divisor) * r.gen_range(10..40);
            }
            // The switches as pulses of random length.
            81..=84 => {
                peer.limit_positive = true;
                self.release[0] = Some(self.now + log_uniform(r, 10.0, 30_000.0) as u64);
            }
            85..=88 => {
                peer.limit_negative = true;
                self.release[1] = Some(self.now + log_uniform(r, 10.0, 30_000.0) as u64);
            }
            89 => {
                peer.emergency_stop = true;
                self.release[2] = Some(self.now + log_uniform(r, 10.0, 20_000.0) as u64);
            }
            90..=91 => self.send(peer, Command::Reset),
            92 => {
                let on = r.gen_bool(0.3);
                self.send(peer, Command::Power { on });
            }
            93 => peer.follow = !peer.follow,
            // The reset pin, now and then (everything restarts; the queue and flags clear).
            94 if r.gen_bool(0.2) => peer.reset_clocks = r.gen_range(1..4),
            // A watchdog that expires while a move runs: a short watchdog, a move, silence.
            95..=96 => {
                let ms = r.gen_range(1..4);
                self.send(
                    peer,
                    Command::Configure {
                        param: Param::WatchdogMs,
                        value: ms,
                    },
                );
                self.upload_move(peer, dev);
                self.scheduled = None;
                self.wait = 30_000;
            }
            // A stalled motor: the controller on with a small following limit, a move with
            // the encoder held (the following-error fault), or the motor free again.
            97..=98 => {
                if st.state == AxisState::Disabled as u8 {
                    let s = stop_limits(r);
                    let configs = [
                        (Param::ServoPeriod, [1, 2][r.gen_range(0..2)]),
                        (Param::FollowingLimit, [1, 2, 5][r.gen_range(0..3)]),
                        (Param::Kp, 50i128 << 32),
                        (Param::PwmPeriod, 100),
                        (Param::StopJerk, s.0),
                        (Param::StopAccel, s.1),
                    ];
                    self.send_configs(peer, &configs);
                    self.send(peer, Command::Power { on: true });
                    peer.follow = false;
                    // A long move of constant snap: the error passes the limit early.
                    self.send(
                        peer,
                        Command::LoadSegment {
                            index: 0,
                            segment: Segment {
                                ticks: 100_000,
                                snap: 1 << 40,
                            },
                        },
                    );
                    self.send(peer, Command::Commit { count: 1 });
                    self.send(peer, Command::Start);
                } else {
                    peer.follow = true;
                    self.send(peer, Command::Power { on: false });
                }
            }
            // Idle: telemetry, watchdog expiry, moves running to their end.
            _ => self.wait = log_uniform(r, 100.0, 60_000.0) as u64,
        }
        if self.wait == 0 {
            self.wait = match self.rng.gen_range(0..10) {
                0..=3 => 0,
                4..=7 => self.rng.gen_range(1..300),
                _ => log_uniform(&mut self.rng, 300.0, 20_000.0) as u64,
            };
        }
    }

    /// A SWAP_AT aimed at the edge of its lateness check: copies of the device and of the
    /// host's line are run ahead with the frame sent after 1 to 16 clocks (the clocks until
    /// it is executed do not depend on the tick it carries), a delay is chosen for which the
    /// time base ticked on the clock before the one whose time base the check reads (the
    /// fabric then corrects its registered difference by that tick), and the frame is
    /// scheduled with its tick SWAP_MIN_LEAD − 1, SWAP_MIN_LEAD or SWAP_MIN_LEAD + 1 ticks
    /// beyond that time base: LATE, armed, armed (docs/PROTOCOL.md). Nothing is sent when no
    /// delay gives that.
    fn schedule_swap_at_the_edge(&mut self, peer: &Peer, dev: &Device) {
        let frame = Command::SwapAt { tick: 0 }.to_frame(0, &self.design.format);
        let bytes = frame.to_bytes();
        let airtime = bytes.len() as u64 * 10 * u64::from(self.design.dividers.uart_divisor);
        for delay in 1..=16u64 {
            let (mut p, mut d) = (peer.clone(), dev.clone());
            // The time base before each clock's edge (what the executor reads live).
            let mut ticks: Vec<u64> = Vec::new();
            for k in 0..delay + airtime + 200 {
                if k == delay {
                    p.send(&bytes);
                }
                ticks.push(d.core().outputs().ticks);
                let o = d.clock(&p.inputs());
                p.observe(&o);
                if d.executor_outputs()
                    .reply
                    .is_some_and(|r| r.cmd == code::SWAP_AT)
                {
                    // Executed on clock e: the check reads the time base of clock e − 1.
                    let e = ticks.len() - 1;
                    if e >= 2 && ticks[e - 1] == ticks[e - 2] + 1 {
                        let lead = SWAP_MIN_LEAD as u64 + self.rng.gen_range(0..3) - 1;
                        let tick = ticks[e - 1] + lead;
                        self.scheduled = Some((self.now + delay, Command::SwapAt { tick }));
                        // (Nothing else is sent before it.)
                        self.wait = delay;
                        self.report.swaps_aimed += 1;
                        return;
                    }
                    break;
                }
            }
        }
    }

    /// The pins for the next clock.
    pub(super) fn inputs(&mut self, peer: &mut Peer, dev: &Device) -> IoInputs {
        self.now += 1;
        if let Some((at, c)) = self.scheduled {
            if at <= self.now {
                self.scheduled = None;
                self.send(peer, c);
            }
        }
        for (k, at) in self.release.iter_mut().enumerate() {
            if at.is_some_and(|t| t <= self.now) {
                *at = None;
                match k {
                    0 => peer.limit_positive = false,
                    1 => peer.limit_negative = false,
                    _ => peer.emergency_stop = false,
                }
            }
        }
        if self.wait > 0 {
            self.wait -= 1;
        } else if !peer.sending() && self.breaking == 0 {
            self.act(peer, dev);
        }
        peer.line_break = self.breaking > 0;
        self.breaking = self.breaking.saturating_sub(1);
        peer.inputs()
    }

    /// What the host saw after a clock.
    pub(super) fn observe(&mut self, peer: &mut Peer, o: &IoOutputs) {
        peer.observe(o);
        let st: Status = o.status;
        if st.has(flag::STOPPING) {
            self.report.stopping_clocks += 1;
        }
        if st.has(flag::REPLY_OVERFLOW) {
            self.report.overflow_clocks += 1;
        }
        if st.has(flag::SWAP_PENDING) {
            self.report.swap_pending_clocks += 1;
        }
        let cancelled = [AxisState::Stopping as u8, AxisState::ErrorStop as u8];
        if self.last_swap_pending && !st.has(flag::SWAP_PENDING) && cancelled.contains(&st.state) {
            self.report.swaps_cancelled += 1;
            self.start_after_cancel = true;
        }
        self.last_swap_pending = st.has(flag::SWAP_PENDING);
        if st.state == AxisState::ErrorStop as u8 && self.last_state != st.state {
            IoCosimReport::bump(&mut self.report.errors, st.error);
            // The stalled motor is free again once the fault has stopped it.
            if st.error == ErrorId::FollowingError as u8 {
                peer.follow = true;
            }
        }
        self.last_state = st.state;
        for b in peer.take_received() {
            if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
                IoCosimReport::bump(&mut self.report.replies, f.cmd);
                match Reply::from_frame(&f) {
                    Some(Reply::Nak { cmd, reason }) => {
                        IoCosimReport::bump(&mut self.report.naks, reason as u8);
                        let frame_level = matches!(
                            reason,
                            Reason::BadCrc
                                | Reason::Framing
                                | Reason::BadLength
                                | Reason::UnknownCommand
                        );
                        if !frame_level
                            && !snapgen_spec::refusals::refusal_documented(cmd, reason)
                            && !self.report.undocumented.contains(&(cmd, reason as u8))
                        {
                            self.report.undocumented.push((cmd, reason as u8));
                        }
                    }
                    Some(Reply::Ack { cmd }) => {
                        // (Counted by their replies: a swap's ACK is its only one.)
                        if cmd == code::SWAP_AT {
                            self.report.swaps_armed += 1;
                        }
                        if let Some(k) = self.pending.iter().position(|&(s, _)| s == f.seq) {
                            self.pending.remove(k);
                            if cmd == code::START {
                                self.report.moves_started += 1;
                            } else if cmd != code::SWAP_AT {
                                self.report.stops_acked += 1;
                            }
                        }
                    }
                    _ => {}
                }
            }
        }
        while self.pending.len() > 64 {
            self.pending.pop_front();
        }
    }
}

/// Stop limits (jerk, acceleration), raw, for moves like the stream's (planned at Ts = 1 ms):
/// mostly valid, now and then invalid (jerk above acceleration, or zero: POWER is then
/// refused).
pub(crate) fn stop_limits(r: &mut StdRng) -> (i128, i128) {
    let g = Format::with_ts(1e-3);
    let accel = (log_uniform(r, 0.5, 500.0) * g.scale(Quantity::Acceleration)) as i128;
    let jerk = (log_uniform(r, 5.0, 1e5) * g.scale(Quantity::Jerk)) as i128;
    match r.gen_range(0..20) {
        0 => (0, accel.max(1)),
        1 => (accel.max(1) + 1, accel.max(1)),
        _ => (jerk.clamp(1, accel.max(1)), accel.max(1)),
    }
}

/// A short move of order 2, 3 or 4 with random limits (distances 1 µm–20 mm of either sign at
/// 1 ms or 0.1 ms a tick: a few thousand ticks at most).
pub(crate) fn random_move(r: &mut StdRng) -> MoveRequest {
    let distance = log_uniform(r, 1e-6, 2e-2) * if r.gen_bool(0.5) { 1.0 } else { -1.0 };
    let v = log_uniform(r, 0.01, 2.0);
    let a = log_uniform(r, 0.5, 200.0);
    let method = match r.gen_range(0..3) {
        0 => Method::Order2 { vmax: v, amax: a },
        1 => Method::Order3 {
            vmax: v,
            amax: a,
            jmax: log_uniform(r, 5.0, 1e5),
        },
        _ => Method::Order4 {
            vmax: v,
            amax: a,
            jmax: log_uniform(r, 5.0, 1e5),
            dmax: log_uniform(r, 1e3, 1e8),
        },
    };
    MoveRequest { distance, method }
}

/// Any command with random arguments (good and bad).
pub(crate) fn random_command(r: &mut StdRng, f: &Format, ticks: u64) -> Command {
    let n = snapgen_spec::PARAMS.len() as u8;
    let param = Param::from_byte(r.gen_range(1..=n)).expect("1..=n are parameters");
    match r.gen_range(0..13) {
        0 => Command::Ping,
        1 => Command::LoadSegment {
            index: r.gen_range(0..f.max_segments as u8),
            segment: Segment {
                ticks: r.gen_range(1..50),
                snap: r.gen_range(-(1i128 << 60)..(1i128 << 60)),
            },
        },
        2 => Command::Commit {
            count: r.gen_range(0..=f.max_segments as u8),
        },
        3 => Command::Start,
        4 => Command::Stop,
        5 => Command::Halt,
        6 => Command::ReadStatus,
        7 => Command::ReadState,
        8 => Command::ReadConfig { param },
        9 => Command::Power {
            on: r.gen_bool(0.5),
        },
        10 => Command::Reset,
        // Anywhere (mostly too far: BAD_ARGUMENT), or near the time base (late or armed).
        11 => Command::SwapAt {
            tick: if r.gen_bool(0.3) {
                r.gen()
            } else {
                ticks.wrapping_add_signed(r.gen_range(-2000..20_000))
            },
        },
        // (INPUT_POLARITY is written by `Stream::configure`, which keeps the emergency stop's
        // bit as wired.)
        _ => Command::Configure {
            param: if param == Param::InputPolarity {
                Param::InputFilter
            } else {
                param
            },
            value: r.gen_range(0..100),
        },
    }
}
