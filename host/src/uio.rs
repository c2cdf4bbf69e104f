//! The host on the board's own processor: a station behind AXI4-Lite registers
//! (`snapgen_axi.v`, docs/AXI.md) as a [`Transport`], so that the same [`FramedLink`], session,
//! driver and PLCopen axis that talk over a serial port talk over the memory map.
//!
//! [`RegisterTransport`] writes a frame's bytes to `COMMAND` and reads the replies from
//! `REPLY`, waiting on the interrupt (cause REPLY) when nothing waits; it works over any
//! [`Registers`]: [`Uio`], a Linux UIO device (`/dev/uioN`: `mmap` of its first map, the
//! interrupt by `read`), or a simulated memory map (`snapgen_sim::axi_board`, the Verilated AXI
//! design). Everything above `Registers::read`/`write` is the same code on the board and in
//! the tests.
//!
//! [`FramedLink`]: crate::link::FramedLink

use snapgen_spec::axi::{offset_of, ID_MAGIC, IRQ_REPLY, MAP_VERSION, REPLY_VALID, SPAN};
use snapgen_spec::wire::PROTOCOL_VERSION;
use snapgen_spec::{StateReply, Status};

use crate::link::{LinkError, Transport};

/// A window onto the station's 32-bit registers (byte offsets of docs/AXI.md).
pub trait Registers {
    /// Reads the word at byte offset `offset`.
    fn read(&mut self, offset: u32) -> Result<u32, LinkError>;
    /// Writes the word at byte offset `offset`.
    fn write(&mut self, offset: u32, value: u32) -> Result<(), LinkError>;
    /// Waits at most `seconds` for the interrupt; true if it came.
    fn wait_irq(&mut self, seconds: f64) -> Result<bool, LinkError>;
    /// The host's clock (s).
    fn now(&self) -> f64;
    /// Lets `seconds` pass.
    fn sleep(&mut self, seconds: f64);
    /// Seconds one register write takes, about (the host's latency estimates).
    fn access_time(&self) -> f64;
}

/// Most reply bytes one [`Transport::read`] takes.
const MAX_READ: usize = 512;

/// The command stream over a station's registers.
pub struct RegisterTransport<R> {
    regs: R,
}

impl<R: Registers> RegisterTransport<R> {
    /// Checks that `regs` is a snapgen station of this map and protocol (`ID`, `VERSION`) and
    /// takes the interrupt: its REPLY cause alone is enabled (a latched cause left enabled
    /// would hold the line high and wake every wait).
    pub fn open(mut regs: R) -> Result<Self, LinkError> {
        let id = regs.read(offset_of("ID"))?;
        if id != ID_MAGIC {
            return Err(LinkError::Io(format!(
                "no snapgen station there: ID reads {id:#010x}, not {ID_MAGIC:#010x} (\"snap\"): check the UIO device and that the bitstream holds snapgen_axi"
            )));
        }
        let version = regs.read(offset_of("VERSION"))?;
        let (map, protocol) = (version & 0xFFFF, version >> 16);
        if map != MAP_VERSION || protocol != u32::from(PROTOCOL_VERSION) {
            return Err(LinkError::Io(format!(
                "the station's register map is version {map} with protocol {protocol}; this host speaks map {MAP_VERSION}, protocol {PROTOCOL_VERSION}: build the bitstream and the host from the same snapgen"
            )));
        }
        regs.write(offset_of("IRQ_ENABLE"), IRQ_REPLY)?;
        Ok(RegisterTransport { regs })
    }

    /// The registers.
    pub fn registers(&self) -> &R {
        &self.regs
    }

    /// The registers, to access one directly.
    pub fn registers_mut(&mut self) -> &mut R {
        &mut self.regs
    }

    /// The registers, the transport given up.
    pub fn into_registers(self) -> R {
        self.regs
    }

    /// The status block and the chain's registers at one moment (`SNAPSHOT`, then its
    /// words), without a frame.
    pub fn snapshot(&mut self) -> Result<(Status, StateReply), LinkError> {
        self.regs.write(offset_of("SNAPSHOT"), 0)?;
        let mut words = |name: &str, n: u32| -> Result<Vec<u32>, LinkError> {
            (0..n)
                .map(|k| self.regs.read(offset_of(name) + 4 * k))
                .collect()
        };
        let status_words = words("STATUS", (Status::BYTES as u32).div_ceil(4))?;
        let bytes: Vec<u8> = status_words.iter().flat_map(|w| w.to_le_bytes()).collect();
        let status = Status::from_payload(&bytes[..Status::BYTES])
            .ok_or_else(|| LinkError::Io("the status block's length".into()))?;
        let wide = |w: Vec<u32>| -> i128 {
            w.iter()
                .enumerate()
                .fold(0u128, |v, (k, &x)| v | u128::from(x) << (32 * k)) as i128
        };
        let ticks = wide(words("TICKS", 2)?) as u64;
        let state = StateReply {
            ticks,
            x: wide(words("X", 4)?),
            v: wide(words("V", 4)?),
            a: wide(words("A", 4)?),
            j: wide(words("J", 4)?),
        };
        Ok((status, state))
    }
}

impl<R: Registers> Transport for RegisterTransport<R> {
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        bytes
            .iter()
            .try_for_each(|&b| self.regs.write(offset_of("COMMAND"), u32::from(b)))
    }

    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
        let before = out.len();
        let deadline = self.regs.now() + wait;
        loop {
            let v = self.regs.read(offset_of("REPLY"))?;
            if v & REPLY_VALID != 0 {
                out.push(v as u8);
                // A bounded take: a fast telemetry stream must not keep the host here.
                if out.len() - before >= MAX_READ {
                    return Ok(());
                }
                continue;
            }
            let left = deadline - self.regs.now();
            if out.len() > before || left <= 0.0 {
                return Ok(());
            }
            if !self.regs.wait_irq(left)? {
                // Nothing came: take the interrupt again, in case the station was reset
                // meanwhile (its IRQ_ENABLE cleared).
                self.regs.write(offset_of("IRQ_ENABLE"), IRQ_REPLY)?;
                return Ok(());
            }
        }
    }

    fn now(&self) -> f64 {
        self.regs.now()
    }

    fn sleep(&mut self, seconds: f64) {
        self.regs.sleep(seconds);
    }

    fn byte_time(&self) -> f64 {
        self.regs.access_time()
    }
}

/// A Linux UIO device (`/dev/uioN`) bound to the station: its first map `mmap`ed, the
/// interrupt waited for by `read` (re-armed by writing 1, as the `uio_pdrv_genirq` driver
/// expects). The device-tree node and the steps on the board: docs/AXI.md.
///
/// The device is locked for this host alone (`flock`): a second `snapgen` on the same station
/// would mix its bytes into this one's frames. Without an interrupt in the device tree (the
/// unmask write fails), replies are polled every [`POLL_S`] instead.
#[cfg(target_os = "linux")]
pub struct Uio {
    file: nix::fcntl::Flock<std::fs::File>,
    base: std::ptr::NonNull<u32>,
    len: usize,
    start: std::time::Instant,
    irq: bool,
}

/// The poll period of a UIO device without an interrupt (s).
#[cfg(target_os = "linux")]
pub const POLL_S: f64 = 50e-6;

#[cfg(target_os = "linux")]
impl Uio {
    /// Opens `path` (`/dev/uioN`) and maps its first region.
    pub fn open(path: &std::path::Path) -> Result<Self, LinkError> {
        use std::num::NonZeroUsize;

        use nix::sys::mman::{mmap, MapFlags, ProtFlags};

        let io = |what: &str, e: &dyn std::fmt::Display| {
            LinkError::Io(format!("{}: {what}: {e}", path.display()))
        };
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| io("cannot open the UIO device (is the uio_pdrv_genirq driver bound to the station's node? docs/AXI.md)", &e))?;
        let file = nix::fcntl::Flock::lock(file, nix::fcntl::FlockArg::LockExclusiveNonblock)
            .map_err(|(_, e)| {
                io(
                    "another host holds the station (its UIO device is locked)",
                    &e,
                )
            })?;
        let len = map_size(path).unwrap_or(4096).max(SPAN as usize);
        let len_nz = NonZeroUsize::new(len).expect("the map spans bytes");
        // SAFETY: a shared mapping of the device's registers, the whole of its first map;
        // only read and written through volatile word accesses within `len`.
        let ptr = unsafe {
            mmap(
                None,
                len_nz,
                ProtFlags::PROT_READ | ProtFlags::PROT_WRITE,
                MapFlags::MAP_SHARED,
                &*file,
                0,
            )
        }
        .map_err(|e| io("cannot map its registers", &e))?;
        let mut uio = Uio {
            file,
            base: ptr.cast(),
            len,
            start: std::time::Instant::now(),
            irq: true,
        };
        // An interrupt to unmask, or polling.
        uio.irq = std::io::Write::write_all(&mut *uio.file, &1u32.to_ne_bytes()).is_ok();
        Ok(uio)
    }

    fn word(&self, offset: u32) -> Result<*mut u32, LinkError> {
        let at = offset as usize;
        // Within the register map (the slave decodes 8 address bits: past it, an access would
        // reach a register again) and the mapping.
        if at % 4 != 0 || at + 4 > (SPAN as usize).min(self.len) {
            return Err(LinkError::Io(format!(
                "register offset {offset:#x} outside the station's map ({SPAN:#x} bytes)"
            )));
        }
        // SAFETY: within the mapping (checked above), word-aligned.
        Ok(unsafe { self.base.as_ptr().add(at / 4) })
    }
}

/// The size of `/dev/uioN`'s first map, from sysfs.
#[cfg(target_os = "linux")]
fn map_size(path: &std::path::Path) -> Option<usize> {
    let name = path.file_name()?.to_str()?;
    let text = std::fs::read_to_string(format!("/sys/class/uio/{name}/maps/map0/size")).ok()?;
    usize::from_str_radix(text.trim().trim_start_matches("0x"), 16).ok()
}

#[cfg(target_os = "linux")]
impl Registers for Uio {
    fn read(&mut self, offset: u32) -> Result<u32, LinkError> {
        let p = self.word(offset)?;
        // SAFETY: a mapped, aligned device register.
        Ok(unsafe { std::ptr::read_volatile(p) })
    }

    fn write(&mut self, offset: u32, value: u32) -> Result<(), LinkError> {
        let p = self.word(offset)?;
        // SAFETY: a mapped, aligned device register.
        unsafe { std::ptr::write_volatile(p, value) };
        Ok(())
    }

    fn wait_irq(&mut self, seconds: f64) -> Result<bool, LinkError> {
        use std::io::{Read, Write};
        use std::os::fd::AsFd;

        use nix::errno::Errno;
        use nix::poll::{poll, PollFd, PollFlags, PollTimeout};

        if !self.irq {
            // No interrupt: look again after a poll period.
            self.sleep(seconds.min(POLL_S));
            return Ok(true);
        }
        let err = |e: &dyn std::fmt::Display| LinkError::Io(format!("UIO interrupt: {e}"));
        // Unmask the interrupt, then wait for it.
        self.file
            .write_all(&1u32.to_ne_bytes())
            .map_err(|e| err(&e))?;
        let ms = (seconds * 1e3).ceil().clamp(0.0, f64::from(i32::MAX)) as i32;
        let timeout = PollTimeout::try_from(ms).unwrap_or(PollTimeout::MAX);
        let n = loop {
            let mut fds = [PollFd::new(self.file.as_fd(), PollFlags::POLLIN)];
            match poll(&mut fds, timeout) {
                // A signal: wait again (the caller's deadline bounds the whole).
                Err(Errno::EINTR) => continue,
                r => break r.map_err(|e| err(&e))?,
            }
        };
        if n == 0 {
            return Ok(false);
        }
        let mut count = [0u8; 4];
        self.file.read_exact(&mut count).map_err(|e| err(&e))?;
        Ok(true)
    }

    fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    fn sleep(&mut self, seconds: f64) {
        std::thread::sleep(std::time::Duration::from_secs_f64(seconds.max(0.0)));
    }

    fn access_time(&self) -> f64 {
        // An estimate for a Zynq-7000's general-purpose AXI port (not measured on a board):
        // a few hundred nanoseconds a word.
        3e-7
    }
}

#[cfg(target_os = "linux")]
impl Drop for Uio {
    fn drop(&mut self) {
        // SAFETY: the mapping made in `open`, unmapped once.
        let _ = unsafe { nix::sys::mman::munmap(self.base.cast(), self.len) };
    }
}

/// The station behind the UIO device `path` (`/dev/uioN`), checked and ready for the framed
/// protocol: what `--uio` and Python's `Board.uio` open.
#[cfg(target_os = "linux")]
pub fn open_station(path: &std::path::Path) -> Result<Box<dyn Transport>, LinkError> {
    Ok(Box::new(RegisterTransport::open(Uio::open(path)?)?))
}

/// UIO devices are Linux's.
#[cfg(not(target_os = "linux"))]
pub fn open_station(path: &std::path::Path) -> Result<Box<dyn Transport>, LinkError> {
    Err(LinkError::Io(format!(
        "{}: UIO devices are Linux's (a Zynq running Linux)",
        path.display()
    )))
}
