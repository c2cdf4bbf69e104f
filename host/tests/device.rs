//! The device model (`snapgen_model::device::Device`) asked through the host's codecs: every
//! command's reply and effect, retries, the reply queue, telemetry, the watchdog, limit
//! switches and the emergency stop, a move planned and played to its exact end, swaps.

use snapgen_host::protocol::{
    code, flag, AxisState, Command, Decoded, Decoder, ErrorId, Param, Reason, Reply,
};
use snapgen_model::device::*;
use snapgen_model::format::DEFAULT_FORMAT;
use snapgen_model::peer::Peer;
use snapgen_model::stop::StopLimits;
use snapgen_model::timing::Dividers;
use snapgen_model::ChainState;
use snapgen_plan::planner::{plan_from, Method, MoveRequest};

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

    fn status(&mut self) -> snapgen_host::protocol::Status {
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
    assert!(DEFAULT_FORMAT.matches_identity(&id));
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
fn powered_with(b: &mut Bench, segs: &[snapgen_model::program::Segment]) {
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
    use snapgen_model::program::Segment;
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
    use snapgen_model::program::Segment;
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
    use snapgen_model::program::Segment;
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

fn state(b: &mut Bench) -> snapgen_host::protocol::StateReply {
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
    use snapgen_model::program::Segment;
    use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
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

/// STOP and HALT sent at rest after a program ran to its end leave DONE set (the last program
/// did run to its end, docs/PROTOCOL.md) and CUT clear: a STOP once cleared DONE, so the host
/// could not tell the move had completed.
#[test]
fn a_stop_or_halt_at_rest_after_a_program_keeps_done() {
    let f = DEFAULT_FORMAT;
    let mut b = Bench::new();
    b.run(10);
    let p = plan_from(
        &MoveRequest {
            distance: 0.001,
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
    powered_with(&mut b, &p.program.segments);
    assert_eq!(b.ask(Command::Start), ack(&Command::Start));
    let at_rest = |b: &mut Bench| {
        let s = b.status();
        (s.state == AxisState::Standstill as u8 && !s.has(flag::PLAYING | flag::STOPPING))
            .then_some(s)
    };
    let s = loop {
        if let Some(s) = at_rest(&mut b) {
            break s;
        }
    };
    assert!(s.has(flag::DONE) && !s.has(flag::CUT), "{s:?}");
    for c in [Command::Stop, Command::Halt] {
        assert_eq!(b.ask(c), ack(&c));
        let s = loop {
            if let Some(s) = at_rest(&mut b) {
                break s;
            }
        };
        assert!(s.has(flag::DONE), "{c:?} at rest cleared DONE: {s:?}");
        assert!(!s.has(flag::CUT), "{c:?} at rest set CUT: {s:?}");
    }
}

/// INPUT_POLARITY set (while Disabled) so that the emergency stop reads active latches
/// ErrorStop with the amplifier off; it can be set back there (the amplifier is off and
/// nothing moves, as while Disabled), then RESET gives Disabled. It once needed a power
/// cycle: every Disabled-only parameter was refused in ErrorStop. With the amplifier on, or
/// with the axis moving, the parameter stays refused.
#[test]
fn an_emergency_stop_made_active_by_input_polarity_can_be_undone() {
    let mut b = Bench::new();
    b.run(10);
    let polarity = |value| Command::Configure {
        param: Param::InputPolarity,
        value,
    };
    // Bit 2 inverts the emergency stop: the idle input now reads active.
    assert_eq!(b.ask(polarity(4)), ack(&polarity(4)));
    b.run(50);
    let s = b.status();
    assert_eq!(
        (s.state, s.error),
        (AxisState::ErrorStop as u8, ErrorId::EmergencyStop as u8)
    );
    assert_eq!(b.ask(Command::Reset), nak(code::RESET, Reason::AxisError));
    assert_eq!(b.ask(polarity(0)), ack(&polarity(0)));
    b.run(50);
    assert_eq!(b.ask(Command::Reset), ack(&Command::Reset));
    let s = b.status();
    assert_eq!(s.state, AxisState::Disabled as u8);
    assert!(!s.has(flag::EMERGENCY_STOP));
    // Enabled, the parameter stays Disabled-only.
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
    assert_eq!(
        b.ask(polarity(0)),
        nak(code::CONFIGURE, Reason::NotDisabled)
    );
}

/// A STOP that cancels an armed swap also empties the standby bank: the program uploaded for
/// the swap's tick was planned from the state at that tick and must never play from another
/// (a START after the stop once played it from rest). NAK NO_PROGRAM after the stop.
#[test]
fn a_stop_that_cancels_a_swap_empties_the_standby_program() {
    use snapgen_model::program::Segment;
    let mut b = Bench::new();
    b.run(10);
    powered_with(&mut b, &[Segment { ticks: 10, snap: 0 }]);
    let st = state(&mut b);
    let c = Command::SwapAt {
        tick: st.ticks + 100_000,
    };
    assert_eq!(b.ask(c), ack(&c));
    assert!(b.status().has(flag::SWAP_PENDING));
    assert_eq!(b.ask(Command::Stop), ack(&Command::Stop));
    loop {
        let s = b.status();
        if s.state == AxisState::Standstill as u8 && !s.has(flag::STOPPING) {
            assert!(!s.has(flag::SWAP_PENDING));
            break;
        }
    }
    assert_eq!(b.ask(Command::Start), nak(code::START, Reason::NoProgram));
}
