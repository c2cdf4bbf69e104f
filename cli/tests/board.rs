//! End to end: `snapgen send` over a pseudo-terminal to `snapgen board --pty`, on the device
//! model and on the Verilated fabric, with a bare protocol client beside it that checks what
//! `send` reports.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use snapgen_host::protocol::{
    AxisState, Command as Cmd, Decoded, Decoder, ErrorId, Identity, Param, Reason, Reply,
    StateReply, Status,
};
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plan::{Method, MoveRequest};

mod common;
use common::assert_ok;

/// The virtual board's Ts (its default design).
const BOARD_TS: f64 = 1e-4;

/// A running virtual board, killed on drop.
struct Board {
    child: Child,
    port: String,
}

impl Board {
    /// A board serving the Verilated fabric (`fabric`) or the device model.
    fn start_on(fabric: bool) -> Board {
        Board::start_with(fabric, &[])
    }

    /// The same with more arguments (`--motor`).
    fn start_with(fabric: bool, extra: &[&str]) -> Board {
        let mut args = vec!["board", "--pty"];
        if !fabric {
            args.push("--model");
        }
        args.extend_from_slice(extra);
        let mut child = Command::new(env!("CARGO_BIN_EXE_snapgen"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start the board");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        Board {
            child,
            port: line.trim().to_string(),
        }
    }

    /// A bare protocol client, independent of `snapgen send`.
    fn ask(&self, c: Cmd, seq: u8) -> Reply {
        // The port's exclusive lock can still be held for a moment by the last request's
        // handle on a loaded machine: a few tries.
        let open = || {
            serialport::new(&self.port, 115_200)
                .timeout(Duration::from_millis(20))
                .open()
        };
        let mut port = (0..50)
            .find_map(|_| {
                open().ok().or_else(|| {
                    std::thread::sleep(Duration::from_millis(20));
                    None
                })
            })
            .unwrap_or_else(|| open().unwrap());
        port.write_all(&c.to_frame(seq, &DEFAULT_FORMAT).to_bytes())
            .unwrap();
        let mut d = Decoder::new();
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut buf = [0u8; 256];
        while Instant::now() < deadline {
            if let Ok(n) = port.read(&mut buf) {
                for &b in &buf[..n] {
                    if let Some(Decoded::Frame(f)) = d.push(b) {
                        if f.seq == seq {
                            return Reply::from_frame(&f).unwrap();
                        }
                    }
                }
            }
        }
        panic!("no reply to {c:?}");
    }

    fn ack(&self, c: Cmd, seq: u8) {
        assert_eq!(self.ask(c, seq), Reply::Ack { cmd: c.code() }, "{c:?}");
    }

    fn status(&self, seq: u8) -> Status {
        match self.ask(Cmd::ReadStatus, seq) {
            Reply::Status(s) => s,
            r => panic!("{r:?}"),
        }
    }

    fn state(&self, seq: u8) -> StateReply {
        match self.ask(Cmd::ReadState, seq) {
            Reply::State(s) => s,
            r => panic!("{r:?}"),
        }
    }

    fn identity(&self, seq: u8) -> Identity {
        match self.ask(Cmd::Ping, seq) {
            Reply::Identity(i) => i,
            r => panic!("{r:?}"),
        }
    }
}

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn send(port: &str, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(["send", "--port", port])
        .args(extra)
        .output()
        .unwrap()
}

const S_CURVE: [&str; 7] = ["--order", "3", "--vmax", "0.5", "--amax", "5", "--jmax"];

fn ok(out: &std::process::Output) -> String {
    assert_ok(out);
    String::from_utf8_lossy(&out.stdout).to_string()
}

#[test]
fn positive_and_negative_moves_land_where_the_model_says() {
    moves_land_where_the_model_says(false);
}

#[test]
fn on_the_fabric_positive_and_negative_moves_land_where_the_model_says() {
    moves_land_where_the_model_says(true);
}

fn moves_land_where_the_model_says(fabric: bool) {
    let board = Board::start_on(fabric);
    // The board says what it is: the virtual design, its UART at the rate it really runs.
    let id = board.identity(200);
    assert_eq!((id.clock_hz, id.tick_divider), (1_500_000, 149));
    assert_eq!(id.baud, 115_385, "1.5 MHz / 13 clocks per bit");
    assert!(DEFAULT_FORMAT.matches_identity(&id));
    let f = Format::with_ts(BOARD_TS);
    let m = Method::Order3 {
        vmax: 0.5,
        amax: 5.0,
        jmax: 100.0,
    };
    let mut x = snapgen_model::ChainState::at_rest(DEFAULT_FORMAT.home_raw());
    for (distance, cell) in [("0.02", 20_000), ("-0.035", -15_000)] {
        let mut args: Vec<&str> = S_CURVE.to_vec();
        args.extend(["100", "--distance", distance]);
        let text = ok(&send(&board.port, &args));
        assert!(text.contains("match the plan bit for bit"), "{text}");
        // The model, planned independently here with the board's Ts, ends on the same
        // registers, bit for bit.
        let p = snapgen_plan::plan_from(
            &MoveRequest {
                distance: distance.parse().unwrap(),
                method: m,
            },
            &f,
            x,
        )
        .unwrap();
        x = p.final_state;
        let st = board.state(201);
        assert_eq!((st.x, st.v, st.a, st.j), (x.x, 0, 0, 0));
        let s = board.status(202);
        assert_eq!((s.position, s.encoder), (cell, cell));
        assert_eq!(s.axis(), Some(AxisState::Standstill));
        assert!(s.has(snapgen_host::protocol::flag::DONE));
    }
    // The stop limits `send` configured read back as the plan's peaks.
    assert!(matches!(
        board.ask(Cmd::ReadConfig { param: Param::StopJerk }, 203),
        Reply::Config { value, .. } if value > 0
    ));
}

#[test]
fn a_ts_other_than_the_boards_is_refused_before_anything_moves() {
    let board = Board::start_on(false);
    let before = board.state(1);
    let mut args: Vec<&str> = S_CURVE.to_vec();
    args.extend(["100", "--distance", "0.01", "--ts", "1e-5"]);
    let out = send(&board.port, &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--ts 0.00001 s, but the board ticks every 0.0001 s"),
        "{err}"
    );
    // Nothing was configured, uploaded or started.
    let s = board.status(2);
    assert_eq!(s.axis(), Some(AxisState::Disabled));
    assert_eq!(
        board.ask(
            Cmd::ReadConfig {
                param: Param::StopJerk
            },
            3
        ),
        Reply::Config {
            param: Param::StopJerk,
            value: 0
        }
    );
    let after = board.state(4);
    assert_eq!((after.x, after.v), (before.x, before.v));
    // Not a number of seconds at all: refused the same way.
    let mut args: Vec<&str> = S_CURVE.to_vec();
    args.extend(["100", "--distance", "0.01", "--ts", "NaN"]);
    let out = send(&board.port, &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--ts NaN: give a positive number"), "{err}");
    // The board's own Ts is accepted, and send sets the watchdog (read back) as it moves.
    assert_eq!(
        board.ask(
            Cmd::Configure {
                param: Param::WatchdogMs,
                value: 0
            },
            5
        ),
        Reply::Ack { cmd: 0x08 }
    );
    let mut args: Vec<&str> = S_CURVE.to_vec();
    args.extend(["100", "--distance", "0.01", "--ts", "1e-4"]);
    ok(&send(&board.port, &args));
    assert_eq!(
        board.ask(
            Cmd::ReadConfig {
                param: Param::WatchdogMs
            },
            6
        ),
        Reply::Config {
            param: Param::WatchdogMs,
            value: 1000
        }
    );
}

#[test]
fn a_corrupted_upload_is_nakked_and_nothing_moves() {
    corrupted_upload(false);
}

#[test]
fn on_the_fabric_a_corrupted_upload_is_nakked_and_nothing_moves() {
    corrupted_upload(true);
}

fn corrupted_upload(fabric: bool) {
    let board = Board::start_on(fabric);
    let before = board.state(1);
    let mut args: Vec<&str> = S_CURVE.to_vec();
    args.extend([
        "100",
        "--distance",
        "0.01",
        "--corrupt-segment",
        "2",
        "--retries",
        "2",
    ]);
    let out = send(&board.port, &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("LOAD_SEGMENT 2") && err.contains("BAD_CRC"),
        "{err}"
    );
    // Past the device's inter-byte timeout, any partial frame is gone.
    std::thread::sleep(Duration::from_millis(100));
    let s = board.status(2);
    assert!(
        !s.has(snapgen_host::protocol::flag::PLAYING),
        "a move started"
    );
    assert_eq!(s.bad_crc, 3, "three corrupted attempts were counted");
    assert_eq!(board.state(3).x, before.x);
    // START without a committed program is refused.
    assert_eq!(
        board.ask(Cmd::Start, 4),
        Reply::Nak {
            cmd: Cmd::Start.code(),
            reason: Reason::NoProgram
        }
    );
}

#[test]
fn a_silent_port_times_out() {
    // A pseudo-terminal with nobody serving it: a board started and paused (SIGSTOP); the
    // drop kills it (SIGKILL ends a stopped process too).
    let paused = Board::start_on(false);
    Command::new("kill")
        .args(["-STOP", &paused.child.id().to_string()])
        .status()
        .unwrap();
    let out = send(
        &paused.port,
        &[
            "--order",
            "2",
            "--vmax",
            "1",
            "--amax",
            "1",
            "--distance",
            "0.1",
            "--retries",
            "1",
            "--timeout-ms",
            "50",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("no reply to PING"), "{err}");
}

/// `--stop-after-ms`: the board stops the move by itself, within the stop limits, and `send`
/// finds the tick the stop was taken on from where the axis ended (bit for bit).
#[test]
fn a_controlled_stop_ends_where_the_models_stop_does_on_the_fabric_and_the_model() {
    for fabric in [false, true] {
        let board = Board::start_on(fabric);
        // 0.2 units at 0.5 units/s: about 0.55 s with a 0.25 s cruise; stop 150 ms in.
        let text = ok(&send(
            &board.port,
            &[
                "--order",
                "3",
                "--vmax",
                "0.5",
                "--amax",
                "5",
                "--jmax",
                "100",
                "--distance",
                "0.2",
                "--stop-after-ms",
                "150",
            ],
        ));
        assert!(
            text.contains("match the model's stop bit for bit")
                && text.contains("within the stop limits"),
            "{text}"
        );
        let s = board.status(77);
        assert_eq!(s.axis(), Some(AxisState::Standstill));
        assert!(s.has(snapgen_host::protocol::flag::CUT), "{s:?}");
        assert!(s.position > 0 && s.position < 200_000, "{s:?}");
        let st = board.state(78);
        assert_eq!((st.v, st.a, st.j), (0, 0, 0));
    }
}

/// Starts a 2 s move on `board` with a bare client (stop limits the move's, the watchdog
/// `watchdog_ms`); returns the next sequence number.
fn start_long_move(board: &Board, watchdog_ms: i128) -> u8 {
    use snapgen_model::format::Quantity;
    let f = Format::with_ts(BOARD_TS);
    let p = snapgen_plan::plan(
        &MoveRequest {
            distance: 1.0,
            method: Method::Order3 {
                vmax: 0.5,
                amax: 5.0,
                jmax: 100.0,
            },
        },
        &f,
    )
    .unwrap();
    let raw = |q, v: f64| (v * f.scale(q)) as i128;
    let mut seq = 1u8;
    let mut next = || {
        seq += 1;
        seq
    };
    for c in [
        Cmd::Configure {
            param: Param::StopJerk,
            value: raw(Quantity::Jerk, 100.0),
        },
        Cmd::Configure {
            param: Param::StopAccel,
            value: raw(Quantity::Acceleration, 5.0),
        },
        Cmd::Configure {
            param: Param::WatchdogMs,
            value: watchdog_ms,
        },
        Cmd::Power { on: true },
    ] {
        board.ack(c, next());
    }
    for (k, s) in p.program.segments.iter().enumerate() {
        board.ack(
            Cmd::LoadSegment {
                index: k as u8,
                segment: *s,
            },
            next(),
        );
    }
    board.ack(
        Cmd::Commit {
            count: p.program.segments.len() as u8,
        },
        next(),
    );
    board.ack(Cmd::Start, next());
    next()
}

/// A host that goes silent mid-move: the board's watchdog stops the axis by itself (a
/// controlled stop), and it stays in ErrorStop until reset.
#[test]
fn a_host_that_dies_mid_move_is_stopped_by_the_watchdog() {
    let board = Board::start_on(true);
    let mut seq = start_long_move(&board, 100);
    let mut next = || {
        seq += 1;
        seq
    };
    // The host dies: nothing for 600 ms (a 2 s move).
    std::thread::sleep(Duration::from_millis(600));
    let s = board.status(next());
    assert_eq!(
        (s.axis(), ErrorId::from_byte(s.error)),
        (Some(AxisState::ErrorStop), Some(ErrorId::Watchdog)),
        "{s:?}"
    );
    assert!(!s.has(snapgen_host::protocol::flag::PLAYING));
    let st = board.state(next());
    assert_eq!((st.v, st.a, st.j), (0, 0, 0), "at rest after the stop");
    assert!(s.position > 0 && s.position < 1_000_000, "{s:?}");
    // No new motion until reset.
    assert_eq!(
        board.ask(Cmd::Start, next()),
        Reply::Nak {
            cmd: Cmd::Start.code(),
            reason: Reason::AxisError
        }
    );
    board.ack(Cmd::Reset, next());
    assert_eq!(board.status(next()).axis(), Some(AxisState::Standstill));
}

/// `snapgen stop` (MC_Stop from the host) on a move in progress: the board stops it by itself
/// and the command reports it at rest in Standstill.
#[test]
fn snapgen_stop_stops_a_move_in_progress() {
    let board = Board::start_on(false);
    let seq = start_long_move(&board, 1000);
    std::thread::sleep(Duration::from_millis(200));
    let out = Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(["stop", "--port", &board.port])
        .output()
        .unwrap();
    let text = ok(&out);
    assert!(
        text.contains("STOP from DISCRETE_MOTION: now STANDSTILL at rest"),
        "{text}"
    );
    let s = board.status(seq);
    assert!(s.has(snapgen_host::protocol::flag::CUT), "{s:?}");
    assert!(s.position > 0 && s.position < 1_000_000, "{s:?}");
    let st = board.state(seq.wrapping_add(1).max(1));
    assert_eq!((st.v, st.a, st.j), (0, 0, 0));
}

/// A motor behind the board: send configures the controller for it (gains from the plant),
/// the move lands bit for bit, and the report gives the real following error and settling.
#[test]
fn a_move_on_a_simulated_motor_reports_its_following_error() {
    let board = Board::start_with(false, &["--motor"]);
    let out = send(
        &board.port,
        &[
            "--motor",
            "--order",
            "3",
            "--vmax",
            "20",
            "--amax",
            "100",
            "--jmax",
            "1000",
            "--distance",
            "6.283",
        ],
    );
    let text = ok(&out);
    assert!(text.contains("at 8000 LSB"), "{text}");
    assert!(
        text.contains("the registers match the plan bit for bit"),
        "{text}"
    );
    let line = text
        .lines()
        .find(|l| l.starts_with("following error: peak "))
        .unwrap_or_else(|| panic!("{text}"));
    // A few counts of peak error on the 20 Hz loop; settled within the band.
    let peak: f64 = line["following error: peak ".len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(peak > 0.5 && peak < 30.0, "{line}");
    assert!(line.contains("within ±2 LSB"), "{line}");
    // The board's controller holds what send wrote.
    let c = board.ask(
        Cmd::ReadConfig {
            param: Param::ServoPeriod,
        },
        1,
    );
    assert!(
        matches!(c, Reply::Config { value, .. } if value > 0),
        "{c:?}"
    );
}

/// `snapgen online --port`: the host axis over a real serial link (the pseudo-terminal of the
/// virtual board, in real time), a move and a blending move then an override cut: every state
/// it read matched the plan, and it ends on the target.
#[test]
fn snapgen_online_plays_a_script_over_the_port() {
    let board = Board::start_on(false);
    let dir = std::env::temp_dir().join(format!("snapgen-online-port-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("script.toml");
    let mv = |at: f64, p: f64, v: f64, mode: &str| {
        format!(
            "[[event]]\nat_ms = {at}\nkind = \"move_absolute\"\nposition = {p}\nvelocity = {v}\nacceleration = 4.0\ndeceleration = 3.0\njerk = 50.0\nbuffer_mode = \"{mode}\"\n"
        )
    };
    let text = format!(
        "{}{}[[event]]\nat_ms = 300\noverride = 0.5\n",
        mv(0.0, 0.4, 0.5, "aborting"),
        mv(0.0, 0.6, 0.3, "blending_low")
    );
    std::fs::write(&script, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args([
            "online",
            "--script",
            script.to_str().unwrap(),
            "--port",
            &board.port,
            "--json",
        ])
        .output()
        .unwrap();
    let text = ok(&out);
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let outcomes: Vec<&str> = j["commands"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["outcome"].as_str().unwrap())
        .collect();
    assert_eq!(outcomes, ["Done", "Done"], "{text}");
    assert_eq!(j["target_lsb"].as_i64(), Some(600_000), "{text}");
    assert_eq!(j["final_lsb"], j["target_lsb"], "{text}");
    assert_eq!(j["final_raw"]["v"], "0");
    assert!(j["state_checks"].as_u64().unwrap() > 10, "{text}");
    assert!(j["replans"].as_u64().unwrap() >= 1, "{text}");
}
