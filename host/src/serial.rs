//! A [`Transport`] over a serial port (a real board's UART through a USB adapter, or the
//! pseudo-terminal of `snapgen board --pty`): the host's clock is the wall clock.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use serialport::SerialPort;

use crate::link::{LinkError, Transport};

/// A serial port.
pub struct SerialTransport {
    port: Box<dyn SerialPort>,
    name: String,
    baud: u32,
    t0: Instant,
}

impl SerialTransport {
    /// Opens `port` at `baud` (8N1).
    pub fn open(port: &str, baud: u32) -> Result<Self, LinkError> {
        let p = serialport::new(port, baud)
            .timeout(Duration::from_millis(10))
            .open()
            .map_err(|e| LinkError::Io(format!("cannot open {port}: {e}")))?;
        Ok(SerialTransport {
            port: p,
            name: port.to_string(),
            baud,
            t0: Instant::now(),
        })
    }

    fn io(&self, e: std::io::Error) -> LinkError {
        LinkError::Io(format!("serial I/O on {}: {e}", self.name))
    }
}

impl Transport for SerialTransport {
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.port.write_all(bytes).map_err(|e| self.io(e))?;
        self.port.flush().map_err(|e| self.io(e))
    }

    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
        let deadline = Instant::now() + Duration::from_secs_f64(wait.max(0.0));
        let mut buf = [0u8; 512];
        loop {
            match self.port.read(&mut buf) {
                Ok(n) => {
                    out.extend_from_slice(&buf[..n]);
                    if n > 0 {
                        return Ok(());
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => return Err(self.io(e)),
            }
            if Instant::now() >= deadline {
                return Ok(());
            }
        }
    }

    fn now(&self) -> f64 {
        self.t0.elapsed().as_secs_f64()
    }

    fn sleep(&mut self, seconds: f64) {
        std::thread::sleep(Duration::from_secs_f64(seconds.max(0.0)));
    }

    fn byte_time(&self) -> f64 {
        10.0 / f64::from(self.baud)
    }
}

/// A first sequence number for a session on a real port (from the clock and the process
/// id), so that a session's commands are not taken for retries of an earlier session's even
/// by a board that did not see this session's PING.
pub fn session_seq() -> u8 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let h = snapgen_model::device::fnv1a32(
        &[nanos.to_le_bytes(), std::process::id().to_le_bytes()].concat(),
    );
    (h ^ (h >> 8) ^ (h >> 16) ^ (h >> 24)) as u8
}
