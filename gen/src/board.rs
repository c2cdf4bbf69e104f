//! `snapgen board --pty`: a virtual board behind a pseudo-terminal.
//!
//! Behind it runs either the fabric — the Verilated I/O top (`--fabric`, the default): UART
//! command interface, motion core, encoder decoder, PWM — or the device model
//! (`snapgen_model::device::Device`, `--model`), so that `snapgen send --port <path>` runs
//! exactly as against a real board. Simulated time runs at `--clocks-per-second` of wall time;
//! the tick divider is set so that Ts = 10 µs in real time. The fabric's UART runs at 16 clocks
//! per bit (the real board's top uses 1085 for 115 200 baud at 125 MHz).

use std::io::Write;
use std::os::fd::{AsFd, AsRawFd, OwnedFd};
use std::time::{Duration, Instant};

use anyhow::Context;
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use snapgen_model::device::{Device, DeviceConfig};
use snapgen_model::DEFAULT_FORMAT;

/// A partial frame older than this is dropped.
const INTER_BYTE_TIMEOUT: Duration = Duration::from_millis(20);

/// Output bytes kept while nobody reads the pseudo-terminal.
const MAX_PENDING: usize = 64 * 1024;

/// Board settings.
#[derive(Clone, Copy, Debug)]
pub struct BoardOptions {
    /// Simulated fabric clocks per second of wall time.
    pub clocks_per_second: u64,
    /// Run the Verilated I/O top (true) or the device model (false).
    pub fabric: bool,
}

/// What serves the protocol.
trait Target {
    fn receive(&mut self, bytes: &[u8]);
    fn run(&mut self, clocks: u64);
    fn take_output(&mut self) -> Vec<u8>;
    /// A partial frame is held (host-side inter-byte timeout for the model).
    fn mid_frame(&self) -> bool;
    fn timeout(&mut self);
}

impl Target for Device {
    fn receive(&mut self, bytes: &[u8]) {
        Device::receive(self, bytes)
    }
    fn run(&mut self, clocks: u64) {
        Device::run(self, clocks)
    }
    fn take_output(&mut self) -> Vec<u8> {
        Device::take_output(self)
    }
    fn mid_frame(&self) -> bool {
        Device::mid_frame(self)
    }
    fn timeout(&mut self) {
        Device::timeout(self)
    }
}

impl Target for snapgen_sim::board::FabricBoard {
    fn receive(&mut self, bytes: &[u8]) {
        snapgen_sim::board::FabricBoard::receive(self, bytes)
    }
    fn run(&mut self, clocks: u64) {
        snapgen_sim::board::FabricBoard::run(self, clocks)
    }
    fn take_output(&mut self) -> Vec<u8> {
        snapgen_sim::board::FabricBoard::take_output(self)
    }
    // The fabric times out partial frames itself.
    fn mid_frame(&self) -> bool {
        false
    }
    fn timeout(&mut self) {}
}

/// UART clocks per bit of the virtual fabric board.
const VIRTUAL_UART_DIVISOR: u16 = 16;

fn target(opts: &BoardOptions) -> anyhow::Result<Box<dyn Target>> {
    // Ts = 10 µs of wall time: clocks per tick = clocks_per_second / 100 000.
    let tick_div = (opts.clocks_per_second / 100_000).max(1) as u32 - 1;
    if !opts.fabric {
        return Ok(Box::new(Device::new(
            &DEFAULT_FORMAT,
            DeviceConfig {
                tick_div,
                ..Default::default()
            },
        )));
    }
    let cfg = snapgen_hdl::io_top::IoTopConfig {
        uart_divisor: VIRTUAL_UART_DIVISOR,
        frame_timeout: (opts.clocks_per_second / 50) as u32,
        tick_div,
        heartbeat_bit: 20,
    };
    let verilog = snapgen_hdl::verilog::io_top_verilog(cfg);
    let built = snapgen_sim::build::build_io(&verilog)?;
    Ok(Box::new(snapgen_sim::board::FabricBoard::open(
        &built.library,
        snapgen_sim::board::FabricBoardConfig {
            uart_divisor: VIRTUAL_UART_DIVISOR,
        },
    )?))
}

fn path_of(fd: &OwnedFd) -> anyhow::Result<String> {
    let link = std::fs::read_link(format!("/proc/self/fd/{}", fd.as_raw_fd()))
        .context("cannot find the pseudo-terminal's path")?;
    Ok(link.to_string_lossy().into_owned())
}

/// Runs the board until killed; prints the device path on the first line of stdout.
pub fn run(opts: BoardOptions) -> anyhow::Result<()> {
    let pty = openpty(None, None).context("cannot open a pseudo-terminal")?;
    // Raw mode on both ends: bytes pass unchanged.
    for fd in [&pty.master, &pty.slave] {
        let mut t = tcgetattr(fd).context("tcgetattr")?;
        cfmakeraw(&mut t);
        tcsetattr(fd, SetArg::TCSANOW, &t).context("tcsetattr")?;
    }
    let path = path_of(&pty.slave)?;
    let mut device = target(&opts)?;
    eprintln!(
        "virtual board on {path}: {} at {} clocks/s (Ctrl-C to stop)",
        if opts.fabric {
            "Verilated I/O top"
        } else {
            "device model"
        },
        opts.clocks_per_second
    );
    // The path goes out once the board is ready (the fabric may have needed a build).
    println!("{path}");
    std::io::stdout().flush()?;
    let master = pty.master;
    // Keep the slave open: the pty stays usable between clients.
    let _slave = pty.slave;
    let start = Instant::now();
    let mut clocks_done: u64 = 0;
    let mut buf = [0u8; 4096];
    let mut last_byte = Instant::now();
    let debug = std::env::var_os("SNAPGEN_BOARD_DEBUG").is_some();
    let mut pending: Vec<u8> = Vec::new();
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
                Ok(n) if n > 0 => {
                    // A gap before these bytes ends a partial frame first.
                    if device.mid_frame() && last_byte.elapsed() > INTER_BYTE_TIMEOUT {
                        device.timeout();
                    }
                    if debug {
                        eprintln!(
                            "rx {:02x?} mid_frame_before={}",
                            &buf[..n],
                            device.mid_frame()
                        );
                    }
                    device.receive(&buf[..n]);
                    last_byte = Instant::now();
                }
                // EIO while no client has the slave open: wait.
                _ => std::thread::sleep(Duration::from_millis(1)),
            }
        }
        // Inter-byte timeout: a frame cut short is dropped (NAK FRAMING), so a corrupted
        // length byte cannot swallow the frames that follow.
        if device.mid_frame() && last_byte.elapsed() > INTER_BYTE_TIMEOUT {
            device.timeout();
        }
        let due = (start.elapsed().as_secs_f64() * opts.clocks_per_second as f64) as u64;
        if due > clocks_done {
            device.run(due - clocks_done);
            clocks_done = due;
        }
        // Non-blocking output: while nobody reads the other end, bytes wait here (up to a
        // bound, like a UART's transmit FIFO that overflows) instead of stalling the board.
        pending.extend(device.take_output());
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
