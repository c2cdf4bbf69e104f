//! The PLCopen host axis on the virtual board (device model, the design's real clock and UART):
//! every buffer mode, MC_Halt, MC_MoveVelocity and the override, each run checked on every
//! poll against the host's prediction by the driver, and here against an independent tick by
//! tick replay of what the board played.

use snapgen_host::axis::{AxisErrorId, BufferMode, Goal, MotionCommand, Outcome};
use snapgen_host::driver::{Action, Event, RunOptions, RunReport};
use snapgen_host::link::{FramedLink, Link, LinkError};
use snapgen_host::online::{play as play_script, PlayOptions};
use snapgen_host::protocol::{Command, Reply, Status};
use snapgen_host::session::Session;
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::{ChainState, DEFAULT_FORMAT};
use snapgen_plan::online::OnlineOrder;
use snapgen_sim::board::VirtualBoard;
use snapgen_sim::host_link::{board_link, BoardTransport};

/// The co-simulation design (1 MHz clock, 16 clocks a tick, 125 000 baud): fast to simulate,
/// with the same ratio of link time to motion time as a real board within a few times.
fn design() -> Design {
    snapgen_sim::io_cosim::cosim_design()
}

/// The default board: 125 MHz, Ts = 10 µs, 115 200 baud.
fn real_design(baud: u32) -> Design {
    Design::from_timing(
        &DEFAULT_FORMAT,
        &Timing {
            baud,
            ..Timing::default()
        },
    )
    .unwrap()
}

fn mv(position: f64, velocity: f64, mode: BufferMode) -> MotionCommand {
    MotionCommand::MoveAbsolute {
        position,
        velocity,
        acceleration: 4000.0,
        deceleration: 3000.0,
        jerk: 500_000.0,
        buffer_mode: mode,
        path: None,
    }
}

fn at(ms: f64, c: MotionCommand) -> Event {
    Event {
        at_ms: ms,
        at_position: None,
        action: Action::Command(c),
    }
}

/// A feed-rate override to `k` at `ms`.
fn feed(ms: f64, k: f64) -> Event {
    Event {
        at_ms: ms,
        at_position: None,
        action: Action::Override { r#override: k },
    }
}

fn play(script: &[Event], order: OnlineOrder) -> RunReport {
    play_on(VirtualBoard::model(&design()), script, order).0
}

type BoardSession = Session<FramedLink<BoardTransport>>;

/// Plays `script` on `board` as every host does (`snapgen_host::online::play`: PING, the
/// stop limits written, POWER 1, the driver's run); the session after it.
fn play_on(board: VirtualBoard, script: &[Event], order: OnlineOrder) -> (RunReport, BoardSession) {
    let lsb = board.design().format.position_lsb;
    let mut session = Session::open(board_link(board), lsb).unwrap();
    let opts = PlayOptions {
        order,
        stop_deceleration: Some(3000.0),
        stop_jerk: Some(500_000.0),
        run: RunOptions::default(),
    };
    let (report, _, _) = play_script(&mut session, script, &opts).unwrap();
    (report, session)
}

fn outcomes(r: &RunReport) -> Vec<Outcome> {
    r.axis.commands.iter().map(|c| c.outcome.clone()).collect()
}

/// Replays the timeline tick by tick with the chain (not the closed form the host predicts
/// with): the last state, and whether the velocity ever changed sign, and the largest |v|.
fn replay(r: &RunReport) -> (ChainState, bool, i128) {
    let f = r.axis.settings.format;
    assert_eq!(f.widths, DEFAULT_FORMAT.widths);
    let t = &r.axis.timeline;
    let mut s = t.origin.1;
    let mut reversed = false;
    let mut sign = 0;
    let mut vmax = 0;
    let mut tick = t.origin.0;
    for p in &t.parts {
        // Between parts (before the first, after a move that ended at rest or holds a
        // velocity) the chain runs with snap 0.
        assert!(p.start_tick >= tick, "parts do not overlap");
        for _ in tick..p.start_tick {
            s = s.step(0, &f.widths);
        }
        tick = p.start_tick;
        assert_eq!(p.start, s, "each part starts where the one before ended");
        for seg in &p.program.segments {
            for _ in 0..seg.ticks {
                s = s.step(seg.snap, &f.widths);
                if s.v != 0 {
                    if sign != 0 && s.v.signum() != sign {
                        reversed = true;
                    }
                    sign = s.v.signum();
                }
                vmax = vmax.max(s.v.abs());
            }
        }
        tick += p.program.total_ticks();
        assert_eq!(s, p.end, "a part ends in the state it was planned to");
    }
    (s, reversed, vmax)
}

fn cell(mm: f64) -> i128 {
    (mm / DEFAULT_FORMAT.position_lsb).round() as i128
}

/// The board's registers at the end equal the replay's, at rest on `mm`.
fn lands_on(r: &RunReport, mm: f64) {
    let (end, _, _) = replay(r);
    let last = r.last;
    assert_eq!((last.x, last.v, last.a, last.j), (end.x, 0, 0, 0));
    assert_eq!(DEFAULT_FORMAT.output_lsb(last.x), cell(mm));
    // Several reads compared (one a poll period, 2 ms; a change is planned from the poll that
    // found it due, without reading again).
    assert!(
        r.checks >= 5,
        "the driver compared the board's state {} times",
        r.checks
    );
}

#[test]
fn an_aborting_move_takes_over_mid_move() {
    let r = play(
        &[
            at(0.0, mv(20.0, 200.0, BufferMode::Aborting)),
            at(40.0, mv(5.0, 150.0, BufferMode::Aborting)),
        ],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::CommandAborted, Outcome::Done]);
    assert_eq!(r.swaps.len(), 2);
    lands_on(&r, 5.0);
}

#[test]
fn a_buffered_move_follows_at_rest() {
    let r = play(
        &[
            at(0.0, mv(10.0, 200.0, BufferMode::Aborting)),
            at(10.0, mv(-4.0, 100.0, BufferMode::Buffered)),
        ],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::Done, Outcome::Done]);
    // The first ends at rest on its target before the second begins.
    let p = &r.axis.timeline.parts;
    let first = p.iter().rev().find(|p| p.command == 0).unwrap();
    assert_eq!((first.end.v, first.end.a, first.end.j), (0, 0, 0));
    assert_eq!(DEFAULT_FORMAT.output_lsb(first.end.x), cell(10.0));
    lands_on(&r, -4.0);
}

#[test]
fn every_blending_mode_passes_the_first_target_at_its_velocity() {
    // (mode, first velocity, second velocity, expected blend velocity)
    for (mode, v1, v2, vb) in [
        (BufferMode::BlendingLow, 200.0, 100.0, 100.0),
        (BufferMode::BlendingPrevious, 200.0, 100.0, 200.0),
        (BufferMode::BlendingNext, 100.0, 150.0, 150.0),
        (BufferMode::BlendingHigh, 100.0, 150.0, 150.0),
    ] {
        let r = play(
            &[
                at(0.0, mv(30.0, v1, BufferMode::Aborting)),
                at(0.0, mv(45.0, v2, mode)),
            ],
            OnlineOrder::Three,
        );
        assert_eq!(outcomes(&r), [Outcome::Done, Outcome::Done], "{mode:?}");
        let first = r
            .axis
            .timeline
            .parts
            .iter()
            .rev()
            .find(|p| p.command == 0)
            .unwrap();
        assert_eq!(
            first.goal,
            Goal::Position {
                cell: cell(30.0),
                velocity: vb
            },
            "{mode:?}"
        );
        let v = r
            .axis
            .settings
            .format
            .to_physical(snapgen_model::Quantity::Velocity, first.end.v);
        assert!(
            (v - vb).abs() < 1e-9,
            "{mode:?}: {v} at the blend point, want {vb}"
        );
        assert_eq!((first.end.a, first.end.j), (0, 0));
        assert_eq!(DEFAULT_FORMAT.output_lsb(first.end.x), cell(30.0));
        let (_, reversed, _) = replay(&r);
        assert!(!reversed, "{mode:?}");
        lands_on(&r, 45.0);
    }
}

#[test]
fn a_blend_into_a_reversal_stops_at_the_first_target() {
    let r = play(
        &[
            at(0.0, mv(30.0, 200.0, BufferMode::Aborting)),
            at(5.0, mv(2.0, 100.0, BufferMode::BlendingHigh)),
        ],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::Done, Outcome::Done]);
    let first = r
        .axis
        .timeline
        .parts
        .iter()
        .rev()
        .find(|p| p.command == 0)
        .unwrap();
    assert_eq!(first.end.v, 0);
    lands_on(&r, 2.0);
}

#[test]
fn an_override_cut_slows_without_reversal_and_still_lands() {
    for order in [OnlineOrder::Three, OnlineOrder::Two] {
        let r = play(
            &[
                at(0.0, mv(30.0, 300.0, BufferMode::Aborting)),
                Event {
                    at_position: None,
                    at_ms: 60.0,
                    action: Action::Override { r#override: 0.1 },
                },
                Event {
                    at_position: None,
                    at_ms: 120.0,
                    action: Action::Override { r#override: 2.0 },
                },
            ],
            order,
        );
        assert_eq!(outcomes(&r), [Outcome::Done], "{order:?}");
        let (_, reversed, vmax) = replay(&r);
        assert!(!reversed, "{order:?}: the velocity changed sign");
        // 200 % of 300 mm/s at most.
        let v = r
            .axis
            .settings
            .format
            .to_physical(snapgen_model::Quantity::Velocity, vmax);
        assert!(v <= 600.0 + 1e-9, "{order:?}: {v} mm/s");
        lands_on(&r, 30.0);
    }
}

#[test]
fn an_override_of_zero_pauses_on_the_path_and_resumes() {
    // 60 mm: on the co-simulation link (125 000 baud) the override may take effect 100+ ms
    // late, behind the move's own uploads, and must still find room to stop on the path (a
    // stop that would pass the target ends on it instead: the compose.rs unit tests).
    let r = play(
        &[
            at(0.0, mv(60.0, 200.0, BufferMode::Aborting)),
            Event {
                at_position: None,
                at_ms: 30.0,
                action: Action::Override { r#override: 0.0 },
            },
            Event {
                at_position: None,
                at_ms: 500.0,
                action: Action::Override { r#override: 1.0 },
            },
        ],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::Done]);
    // It came to rest short of the target, then went on.
    let paused = r.axis.timeline.parts.iter().find(|p| p.paused).unwrap();
    assert_eq!((paused.end.v, paused.end.a, paused.end.j), (0, 0, 0));
    assert!(DEFAULT_FORMAT.output_lsb(paused.end.x) < cell(60.0));
    let (_, reversed, _) = replay(&r);
    assert!(!reversed);
    lands_on(&r, 60.0);
}

#[test]
fn a_halt_aborts_and_stops_and_a_velocity_is_held_until_aborted() {
    let r = play(
        &[
            at(0.0, mv(50.0, 300.0, BufferMode::Aborting)),
            at(
                40.0,
                MotionCommand::Halt {
                    deceleration: 2000.0,
                    jerk: 100_000.0,
                },
            ),
        ],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::CommandAborted, Outcome::Done]);
    let (end, reversed, _) = replay(&r);
    assert!(!reversed);
    assert_eq!((r.last.x, r.last.v, r.last.a, r.last.j), (end.x, 0, 0, 0));

    let vel = MotionCommand::MoveVelocity {
        velocity: -80.0,
        acceleration: 4000.0,
        deceleration: 3000.0,
        jerk: 500_000.0,
    };
    let r = play(
        &[at(0.0, vel), at(60.0, mv(1.0, 100.0, BufferMode::Aborting))],
        OnlineOrder::Three,
    );
    assert_eq!(outcomes(&r), [Outcome::CommandAborted, Outcome::Done]);
    lands_on(&r, 1.0);
}

#[test]
fn bad_inputs_are_errors_and_move_nothing() {
    let r = play(
        &[
            at(0.0, mv(5.0, -1.0, BufferMode::Aborting)),
            Event {
                at_position: None,
                at_ms: 1.0,
                action: Action::Override { r#override: 2.5 },
            },
            at(2.0, mv(1e9, 100.0, BufferMode::Aborting)),
        ],
        OnlineOrder::Three,
    );
    let o = outcomes(&r);
    assert!(
        matches!(o[0], Outcome::Error(_)) && matches!(o[1], Outcome::Error(_)),
        "{o:?}"
    );
    assert_eq!(r.refused_overrides.len(), 1);
    assert!(r.swaps.is_empty());
    assert_eq!((r.last.v, r.last.a, r.last.j), (0, 0, 0));
}

/// The latency from a command to the first tick that obeys it, on the default board (125 MHz,
/// Ts = 10 µs) at 115 200 baud and at 3 000 000 baud: tens of milliseconds, then a few.
#[test]
fn latency_is_tens_of_ms_at_115200_and_a_few_at_3_mbaud() {
    // The second command comes after the first one's swap has fired (a command that comes
    // while a swap is armed waits for it).
    let script = [
        at(0.0, mv(4.0, 50.0, BufferMode::Aborting)),
        at(100.0, mv(6.0, 100.0, BufferMode::Aborting)),
    ];
    for (baud, most_ms) in [(115_200, 100.0), (3_000_000, 5.0)] {
        let d = real_design(baud);
        let r = play_on(VirtualBoard::model(&d), &script, OnlineOrder::Three).0;
        assert_eq!(outcomes(&r)[1], Outcome::Done);
        assert_eq!(r.swaps.len(), 2);
        for s in &r.swaps {
            let ms = s.latency_ticks as f64 * d.ts() * 1e3;
            assert!(ms < most_ms, "{baud} baud: {ms} ms");
        }
        lands_on(&r, 6.0);
    }
}

/// An override's latency on a long move (seed 002's set-speed changes): its first upload is
/// a head of the change (the rest follows as an extension, uploaded when it can wait no
/// longer), so it takes effect within tens of milliseconds at 115 200 baud and a few at
/// 921 600 baud, even when it follows another change by 60 ms. An override that comes while
/// such an upload is on the wire waits for it: the bound at 921 600 baud allows for one.
#[test]
fn an_override_takes_effect_within_tens_of_ms_at_115200_and_a_few_at_921600() {
    let script = [
        at(0.0, mv(100.0, 200.0, BufferMode::Aborting)),
        feed(40.0, 0.5),
        feed(100.0, 1.5),
        feed(160.0, 0.75),
    ];
    for (baud, most_ms) in [(115_200, 50.0), (921_600, 12.0)] {
        let d = real_design(baud);
        let r = play_on(VirtualBoard::model(&d), &script, OnlineOrder::Three).0;
        assert_eq!(outcomes(&r), [Outcome::Done]);
        assert!(r.refused_overrides.is_empty());
        let overrides: Vec<_> = r.swaps.iter().filter(|s| s.events[0] > 0).collect();
        assert_eq!(overrides.len(), 3, "{baud} baud: one swap per override");
        for s in overrides {
            let ms = s.latency_ticks as f64 * d.ts() * 1e3;
            assert!(ms < most_ms, "{baud} baud: {ms} ms");
            assert!(
                s.segments < d.format.max_segments,
                "{baud} baud: a head, not the whole program"
            );
        }
        lands_on(&r, 100.0);
    }
}

/// A link that measures the longest silence between the end of one request and the start
/// of the next (the host's clock).
struct GapLink<L: Link> {
    inner: L,
    last_end: Option<f64>,
    longest: f64,
}

impl<L: Link> Link for GapLink<L> {
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError> {
        if let Some(t) = self.last_end {
            self.longest = self.longest.max(self.inner.now() - t);
        }
        let r = self.inner.ask(c);
        self.last_end = Some(self.inner.now());
        r
    }
    fn set_format(&mut self, f: &snapgen_model::Format) {
        self.inner.set_format(f)
    }
    fn take_telemetry(&mut self) -> Option<Status> {
        self.inner.take_telemetry()
    }
    fn drain_telemetry(&mut self) -> Vec<Status> {
        self.inner.drain_telemetry()
    }
    fn now(&self) -> f64 {
        self.inner.now()
    }
    fn wait(&mut self, s: f64) {
        self.inner.wait(s)
    }
    fn byte_time(&self) -> f64 {
        self.inner.byte_time()
    }
}

/// The driver feeds the board's watchdog: it is never silent longer than its poll period,
/// not even while it waits for an armed swap before a change (it once slept until the swap's
/// tick, which on a slow tick — Ts = 1 ms, where a swap's lead of some hundred ticks is
/// tenths of a second — let a 1 s watchdog expire mid-move: ErrorStop).
#[test]
fn the_driver_is_never_silent_longer_than_its_poll_period() {
    let script = [
        at(0.0, mv(100.0, 200.0, BufferMode::Aborting)),
        feed(40.0, 0.5),
        feed(60.0, 1.5),
        feed(300.0, 0.8),
        feed(310.0, 1.2),
    ];
    let d = Design::from_timing(
        &DEFAULT_FORMAT,
        &Timing {
            clock_hz: 1_000_000,
            baud: 125_000,
            ts: 1e-3,
        },
    )
    .unwrap();
    let link = GapLink {
        inner: board_link(VirtualBoard::model(&d)),
        last_end: None,
        longest: 0.0,
    };
    let mut session = Session::open(link, d.format.position_lsb).unwrap();
    let opts = PlayOptions {
        order: OnlineOrder::Three,
        stop_deceleration: Some(3000.0),
        stop_jerk: Some(500_000.0),
        run: RunOptions::default(),
    };
    let (r, _, _) = play_script(&mut session, &script, &opts).unwrap();
    assert_eq!(outcomes(&r), [Outcome::Done]);
    let poll_s = opts.run.poll_ms * 1e-3;
    let longest = session.link.longest;
    // One tick of rounding: waits are whole ticks.
    assert!(
        longest <= poll_s + d.ts() * 1.01,
        "silent for {:.1} ms (poll period {} ms)",
        longest * 1e3,
        opts.run.poll_ms
    );
}

/// The same host axis on the Verilated I/O top with the device model in lockstep: 0
/// mismatches; the same run with one output bit flipped on one clock is caught.
#[test]
fn on_the_fabric_every_output_matches_and_a_flipped_bit_is_caught() {
    let script = [
        at(0.0, mv(8.0, 150.0, BufferMode::Aborting)),
        at(0.0, mv(12.0, 100.0, BufferMode::BlendingLow)),
        Event {
            at_position: None,
            at_ms: 40.0,
            action: Action::Override { r#override: 0.5 },
        },
    ];
    let d = design();
    let (r, s) = play_on(
        VirtualBoard::lockstep(&d).unwrap(),
        &script,
        OnlineOrder::Three,
    );
    let board = s.link.transport().board();
    assert_eq!(board.mismatches(), 0, "{:?}", board.first_mismatch());
    assert_eq!(outcomes(&r), [Outcome::Done, Outcome::Done]);
    lands_on(&r, 12.0);

    let mut board = VirtualBoard::lockstep(&d).unwrap();
    let pin = snapgen_sim::io::IoSignal::all().next().unwrap();
    board.inject_fault(5_000, pin, 0);
    let (_, s) = play_on(board, &script, OnlineOrder::Three);
    let board = s.link.transport().board();
    assert_eq!(board.mismatches(), 1);
    assert_eq!(board.first_mismatch().unwrap().clock, 5_000);
}

/// Random scripts on the model board: random moves with random buffer modes, velocities,
/// halts and override changes at random times (mid-jerk, mid-acceleration, at cruise). The
/// driver compares every state it reads with the plan; here every run is replayed tick by tick
/// and must end where its timeline says, at rest when its last command was a move or a halt.
#[test]
fn random_scripts_land_where_the_plan_says() {
    let mut seed = 0x2026_1123_u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut swaps, mut errors, mut commands) = (0, 0, 0);
    for _ in 0..60 {
        let mut t = 0.0;
        let mut events = Vec::new();
        for _ in 0..6 {
            t += (rnd() * 60.0).floor();
            let modes = BufferMode::ALL;
            let r = rnd();
            let action = if r < 0.55 {
                let mode = modes[(rnd() * 6.0) as usize % 6];
                Action::Command(MotionCommand::MoveAbsolute {
                    position: (rnd() * 40.0 - 20.0).round(),
                    velocity: 20.0 + rnd() * 280.0,
                    acceleration: 1000.0 + rnd() * 4000.0,
                    deceleration: 1000.0 + rnd() * 4000.0,
                    jerk: 5e4 + rnd() * 5e5,
                    buffer_mode: mode,
                    path: None,
                })
            } else if r < 0.65 {
                Action::Command(MotionCommand::MoveVelocity {
                    velocity: rnd() * 200.0 - 100.0,
                    acceleration: 2000.0,
                    deceleration: 2000.0,
                    jerk: 2e5,
                })
            } else if r < 0.75 {
                Action::Command(MotionCommand::Halt {
                    deceleration: 1000.0 + rnd() * 3000.0,
                    jerk: 1e5 + rnd() * 4e5,
                })
            } else {
                Action::Override {
                    r#override: (rnd() * 2.0 * 20.0).round() / 20.0,
                }
            };
            events.push(Event {
                at_ms: t,
                at_position: None,
                action,
            });
        }
        // End at rest somewhere known.
        events.push(at(t + 30.0, mv(3.0, 100.0, BufferMode::Aborting)));
        events.push(Event {
            at_position: None,
            at_ms: t + 31.0,
            action: Action::Override { r#override: 1.0 },
        });
        let r = play(&events, OnlineOrder::Three);
        swaps += r.swaps.len();
        commands += r.axis.commands.len();
        for c in &r.axis.commands {
            if let Outcome::Error(e) = &c.outcome {
                errors += 1;
                eprintln!("refused: {e}");
                assert!(
                    matches!(e, AxisErrorId::LinkTooSlow { .. }),
                    "a command refused by more than the link: {e}"
                );
            }
        }
        let (end, _, _) = replay(&r);
        let last = r.last;
        assert_eq!(
            (last.x, last.v, last.a, last.j),
            (end.x, end.v, end.a, end.j)
        );
        if r.axis.commands.last().unwrap().outcome == Outcome::Done {
            lands_on(&r, 3.0);
        }
    }
    eprintln!("{commands} commands, {swaps} swaps, {errors} refused");
    assert!(swaps >= 200, "{swaps} swaps");
    // Only a change the slow co-simulation link cannot upload in time is refused (measured:
    // 2 of 334): an Error, and nothing changes on the board.
    assert!(errors * 50 < commands, "{errors} of {commands} refused");
}

/// A change whose program is longer than the program memory goes up in several uploads; when
/// the link cannot upload the rest before the board has played what it holds (many short
/// moves due together on the slow co-simulation link), the change is refused whole with
/// LinkTooSlow and nothing changes on the board; the same script on a fast link is played.
#[test]
fn a_change_the_link_cannot_keep_up_with_is_refused_whole() {
    let script: Vec<Event> = (1..=6)
        .map(|k| at(0.0, mv(0.05 * k as f64, 100.0, BufferMode::Buffered)))
        .collect();
    let r = play(&script, OnlineOrder::Three);
    let slow = |o: &Outcome| matches!(o, Outcome::Error(AxisErrorId::LinkTooSlow { .. }));
    assert!(outcomes(&r).iter().all(slow), "{:?}", outcomes(&r));
    assert!(r.swaps.is_empty());
    assert_eq!((r.last.v, r.last.a, r.last.j), (0, 0, 0));
    assert_eq!(
        r.last.x, r.axis.timeline.origin.1.x,
        "the axis did not move"
    );
    // At 3 Mbaud on the default board the rest goes up in time.
    let d = real_design(3_000_000);
    let r = play_on(VirtualBoard::model(&d), &script, OnlineOrder::Three).0;
    assert!(
        outcomes(&r).iter().all(|o| *o == Outcome::Done),
        "{:?}",
        outcomes(&r)
    );
    assert!(r.extensions > 0, "the program went up in one upload");
    lands_on(&r, 0.3);
}
