//! `snapgen board --pty`: a virtual board behind a pseudo-terminal.
//!
//! Behind it runs the fabric — the Verilated I/O top (the default) — or the device model
//! (`--model`), in real time: the design's clock frequency in simulated clocks per second of
//! wall time, so its UART runs at the baud rate its identity reports, its tick at the Ts it
//! reports and its watchdog in real milliseconds. `snapgen send --port <path>` runs exactly as
//! against a real board.
//!
//! The default virtual design runs a 1.5 MHz clock (what the simulation keeps up with in real
//! time): 115 200 baud is 13 clocks per bit (115 385 baud, 0.16 % off), and Ts = 100 µs is 150
//! clocks, long enough that the stop unit's decision (about 140 clocks) never makes a
//! stopping tick wait.

use std::io::Write;
use std::os::fd::{AsFd, AsRawFd, OwnedFd};
use std::time::{Duration, Instant};

use anyhow::Context;
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use snapgen_model::device::Design;
use snapgen_sim::board::VirtualBoard;

use crate::args::{optional_motor, TimingArgs};

/// A virtual board behind a pseudo-terminal.
#[derive(clap::Args)]
pub struct Args {
    /// Open a pseudo-terminal (the only transport so far).
    #[arg(long, required = true)]
    pty: bool,
    /// Serve the device model instead of the Verilated fabric.
    #[arg(long)]
    model: bool,
    /// The virtual board's clock in Hz (it must run in real time: a few MHz at most).
    #[arg(long, default_value_t = VIRTUAL_CLOCK_HZ)]
    clock_hz: f64,
    /// UART baud rate (8N1).
    #[arg(long, default_value_t = snapgen_model::timing::DEFAULT_BAUD)]
    baud: u32,
    /// Tick period Ts after reset, in seconds (a whole number of clocks).
    #[arg(long, default_value_t = VIRTUAL_TS)]
    ts: f64,
    /// A simulated motor on the board's PWM and encoder instead of the ideal follower:
    /// `--motor` (or `--motor default`) for the default one, `--motor FILE` for a plant
    /// file (docs/PLANT.md).
    #[arg(long, num_args = 0..=1, default_missing_value = "default")]
    motor: Option<std::path::PathBuf>,
}

/// Runs the subcommand (until stopped).
pub fn run(a: Args) -> anyhow::Result<()> {
    let timing = TimingArgs {
        clock_hz: Some(a.clock_hz),
        baud: a.baud,
        ts: a.ts,
    };
    let (_, design) = timing.resolve(None, 0)?;
    serve(BoardOptions {
        design,
        fabric: !a.model,
        motor: optional_motor(a.motor.as_deref())?,
    })
}

/// Output bytes kept while nobody reads the pseudo-terminal.
const MAX_PENDING: usize = 64 * 1024;

/// The virtual board's default clock (Hz).
pub const VIRTUAL_CLOCK_HZ: f64 = 1.5e6;
/// The virtual board's default Ts (s).
pub const VIRTUAL_TS: f64 = 1e-4;
/// The simulated motor's integration step (s; docs/PLANT.md).
pub const MOTOR_STEP_S: f64 = 1e-6;

/// Board settings.
#[derive(Clone, Debug)]
pub struct BoardOptions {
    /// The design to run (checked and hashed).
    pub design: Design,
    /// Run the Verilated I/O top (true) or the device model (false).
    pub fabric: bool,
    /// A simulated motor instead of the ideal follower.
    pub motor: Option<snapgen_plant::PlantParams>,
}

fn path_of(fd: &OwnedFd) -> anyhow::Result<String> {
    let link = std::fs::read_link(format!("/proc/self/fd/{}", fd.as_raw_fd()))
        .context("cannot find the pseudo-terminal's path")?;
    Ok(link.to_string_lossy().into_owned())
}

/// Runs the board until killed; prints the device path on the first line of stdout.
pub fn serve(opts: BoardOptions) -> anyhow::Result<()> {
    let pty = openpty(None, None).context("cannot open a pseudo-terminal")?;
    // Raw mode on both ends: bytes pass unchanged.
    for fd in [&pty.master, &pty.slave] {
        let mut t = tcgetattr(fd).context("tcgetattr")?;
        cfmakeraw(&mut t);
        tcsetattr(fd, SetArg::TCSANOW, &t).context("tcsetattr")?;
    }
    let path = path_of(&pty.slave)?;
    let d = opts.design;
    let mut board = if opts.fabric {
        VirtualBoard::fabric(&d)?
    } else {
        VirtualBoard::model(&d)
    };
    if let Some(m) = &opts.motor {
        board = board.with_motor(&m.physical(), MOTOR_STEP_S)?;
        eprintln!(
            "motor: {} with {}; {} counts per turn: plan with --lsb {} (rad) and give send --motor",
            m.motor.name,
            m.load.description,
            m.physical().counts_per_rev,
            m.physical().rad_per_count()
        );
    }
    eprintln!(
        "virtual board on {path}: {} at {} Hz, {} baud, Ts {} s, design hash {:#010x} (Ctrl-C to stop)",
        if opts.fabric {
            "Verilated I/O top"
        } else {
            "device model"
        },
        d.clock_hz,
        d.baud,
        d.ts(),
        d.design_hash
    );
    // The path goes out once the board is ready (the fabric may have needed a build).
    println!("{path}");
    std::io::stdout().flush()?;
    let master = pty.master;
    // Keep the slave open: the pty stays usable between clients.
    let _slave = pty.slave;
    let start = Instant::now();
    let clock_hz = f64::from(d.clock_hz);
    // At most this much simulated time per round, so input is read often even when the
    // simulation falls behind.
    let max_round = (clock_hz / 50.0) as u64;
    let mut buf = [0u8; 4096];
    let mut pending: Vec<u8> = Vec::new();
    let mut warned = false;
    let flags =
        nix::fcntl::fcntl(master.as_raw_fd(), nix::fcntl::FcntlArg::F_GETFL).context("fcntl")?;
    nix::fcntl::fcntl(
        master.as_raw_fd(),
        nix::fcntl::FcntlArg::F_SETFL(
            nix::fcntl::OFlag::from_bits_truncate(flags) | nix::fcntl::OFlag::O_NONBLOCK,
        ),
    )
    .context("fcntl")?;
    loop {
        let mut fds = [PollFd::new(master.as_fd(), PollFlags::POLLIN)];
        let ready = poll(&mut fds, PollTimeout::from(1u8)).unwrap_or(0);
        if ready > 0
            && fds[0]
                .revents()
                .is_some_and(|r| r.contains(PollFlags::POLLIN))
        {
            match nix::unistd::read(master.as_raw_fd(), &mut buf) {
                Ok(n) if n > 0 => board.receive(&buf[..n]),
                // EIO while no client has the slave open: wait.
                _ => std::thread::sleep(Duration::from_millis(1)),
            }
        }
        let due = (start.elapsed().as_secs_f64() * clock_hz) as u64;
        if due > board.clocks() {
            let behind = due - board.clocks();
            if behind > 2 * max_round && !warned {
                eprintln!(
                    "warning: the simulation runs slower than real time ({:.0} ms behind): its clock, UART and ticks are slower than the design says",
                    behind as f64 / clock_hz * 1e3
                );
                warned = true;
            }
            board.run(behind.min(max_round));
        }
        // Non-blocking output: while nobody reads the other end, bytes wait here (up to a
        // bound, like a UART's transmit FIFO that overflows) instead of stalling the board.
        pending.extend(board.take_output());
        if pending.len() > MAX_PENDING {
            let drop = pending.len() - MAX_PENDING;
            pending.drain(..drop);
        }
        while !pending.is_empty() {
            match nix::unistd::write(&master, &pending) {
                Ok(n) => {
                    pending.drain(..n);
                }
                Err(nix::errno::Errno::EAGAIN) => break,
                Err(e) => return Err(e).context("cannot write to the pseudo-terminal"),
            }
        }
    }
}
