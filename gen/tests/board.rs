//! End to end: `snapgen send` over a pseudo-terminal to `snapgen board --pty`.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use snapgen_model::protocol::{Command as Cmd, Decoded, Decoder, Reply, Status};
use snapgen_model::{plan, ChainState, Method, MoveRequest, DEFAULT_FORMAT};

/// A running virtual board, killed on drop.
struct Board {
    child: Child,
    port: String,
}

impl Board {
    /// A board serving the Verilated fabric (`fabric`) or the device model.
    fn start_on(fabric: bool) -> Board {
        let mut args = vec!["board", "--pty"];
        if !fabric {
            args.push("--model");
        }
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

    fn start() -> Board {
        Board::start_on(false)
    }

    /// A bare protocol client, independent of `snapgen send`.
    fn ask(&self, c: Cmd, seq: u8) -> Reply {
        let mut port = serialport::new(&self.port, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .unwrap();
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

    fn status(&self, seq: u8) -> Status {
        match self.ask(Cmd::ReadStatus, seq) {
            Reply::Status(s) => s,
            r => panic!("{r:?}"),
        }
    }

    fn position(&self, seq: u8) -> i128 {
        match self.ask(Cmd::ReadPosition, seq) {
            Reply::Position { x } => x,
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
    let m = Method::Order3 {
        vmax: 0.5,
        amax: 5.0,
        jmax: 100.0,
    };
    let mut x = ChainState::at_rest(DEFAULT_FORMAT.home_raw());
    for (distance, cell) in [("0.02", 20_000), ("-0.035", -15_000)] {
        let mut args: Vec<&str> = S_CURVE.to_vec();
        args.extend(["100", "--distance", distance]);
        let out = send(&board.port, &args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(text.contains("matches the plan bit for bit"), "{text}");
        // The model, planned independently here, ends on the same register, bit for bit.
        let p = snapgen_model::plan_from(
            &MoveRequest {
                distance: distance.parse().unwrap(),
                method: m,
            },
            &DEFAULT_FORMAT,
            x,
        )
        .unwrap();
        x = p.final_state;
        assert_eq!(board.position(201), x.x);
        let s = board.status(202);
        assert_eq!((s.position, s.encoder), (cell, cell));
        assert_eq!(s.state & 3, 2, "done and idle");
    }
    // Sanity: the first move alone, from home, is what `plan` gives.
    let first = plan(
        &MoveRequest {
            distance: 0.02,
            method: m,
        },
        &DEFAULT_FORMAT,
    )
    .unwrap();
    assert_eq!(first.target_lsb, 20_000);
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
    let before = board.position(1);
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
        err.contains("LOAD_SEGMENT 2") && err.contains("BadCrc"),
        "{err}"
    );
    // Past the device's inter-byte timeout, any partial frame is gone.
    std::thread::sleep(Duration::from_millis(100));
    let s = board.status(2);
    assert_eq!(s.state & 1, 0, "a move started");
    assert_eq!(s.bad_crc, 3, "three corrupted attempts were counted");
    assert_eq!(board.position(3), before);
    // START without a committed program is refused.
    assert!(matches!(
        board.ask(Cmd::Start, 4),
        Reply::Nak {
            reason: snapgen_model::protocol::Reason::NoProgram,
            ..
        }
    ));
}

#[test]
fn a_silent_port_times_out() {
    // A pseudo-terminal with nobody serving it.
    let paused = paused_board();
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

/// A board started and stopped at once leaves a pty path nobody answers on; a fresh board's
/// path is used while it is paused instead: simplest, start one and SIGSTOP it. The paused
/// board is returned so that its drop kills it (SIGKILL ends a stopped process too) rather
/// than leaving it behind after the test.
fn paused_board() -> Board {
    let board = Board::start();
    let pid = board.child.id();
    Command::new("kill")
        .args(["-STOP", &pid.to_string()])
        .status()
        .unwrap();
    board
}

#[test]
fn a_controlled_stop_ends_short_at_rest_on_the_fabric_and_the_model() {
    for fabric in [false, true] {
        let board = Board::start_on(fabric);
        // 0.2 units at 0.5 units/s: about 0.5 s with a 0.3 s cruise; stop 150 ms in.
        let out = send(
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
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(text.contains("controlled stop: cruise cut short"), "{text}");
        let s = board.status(77);
        assert_eq!(s.state & 7, 2, "done, not busy, not aborted");
        assert!(s.position > 0 && s.position < 200_000, "{s:?}");
    }
}
