//! The virtual board on the fabric: the Verilated I/O top (UART command interface, motion core,
//! encoder decoder, PWM) driven clock by clock. Host bytes become a UART line waveform (the
//! model's transmitter); the core's UART output is decoded by the model's receiver; the
//! encoder pins follow the reference position as an ideal motor would, one count per output
//! LSB (at most one quadrature step per clock).

use std::ffi::c_void;
use std::path::Path;

use libloading::Library;
use snapgen_model::io::uart::{UartRx, UartTx};

use crate::SimError;

type NewFn = unsafe extern "C" fn() -> *mut c_void;
type FreeFn = unsafe extern "C" fn(*mut c_void);
type RunFn = unsafe extern "C" fn(*mut c_void, u64, *const u8, *mut u8, *mut i32);
type AbiFn = unsafe extern "C" fn() -> u32;

/// Settings the I/O top was generated with (`snapgen_hdl::io_top::IoTopConfig`).
#[derive(Clone, Copy, Debug)]
pub struct FabricBoardConfig {
    /// Clocks per UART bit.
    pub uart_divisor: u16,
}

/// The Verilated I/O top with its UART and encoder peers.
pub struct FabricBoard {
    handle: *mut c_void,
    free: FreeFn,
    run: RunFn,
    cfg: FabricBoardConfig,
    host_tx: UartTx,
    host_rx: UartRx,
    queue: std::collections::VecDeque<u8>,
    sending: bool,
    received: Vec<u8>,
    encoder: i64,
    target: i64,
    reset_clocks: u64,
    ins: Vec<u8>,
    outs: Vec<u8>,
    pos: Vec<i32>,
    _lib: Library,
}

// Used from one thread at a time.
unsafe impl Send for FabricBoard {}

impl FabricBoard {
    /// Loads the board library and resets the core.
    pub fn open(library: &Path, cfg: FabricBoardConfig) -> Result<Self, SimError> {
        let err = |reason: String| SimError::Load {
            path: library.to_path_buf(),
            reason,
        };
        // SAFETY: the library was built from our own io_harness.cpp (ABI checked).
        unsafe {
            let lib = Library::new(library).map_err(|e| err(e.to_string()))?;
            let abi: AbiFn = *lib
                .get::<AbiFn>(b"snapgen_io_abi\0")
                .map_err(|e| err(e.to_string()))?;
            if abi() != 0x10001 {
                return Err(err(format!("harness ABI {:#x}", abi())));
            }
            let new: NewFn = *lib
                .get(b"snapgen_io_new\0")
                .map_err(|e| err(e.to_string()))?;
            let free: FreeFn = *lib
                .get(b"snapgen_io_free\0")
                .map_err(|e| err(e.to_string()))?;
            let run: RunFn = *lib
                .get(b"snapgen_io_run\0")
                .map_err(|e| err(e.to_string()))?;
            let handle = new();
            Ok(FabricBoard {
                handle,
                free,
                run,
                cfg,
                host_tx: UartTx::new(),
                host_rx: UartRx::new(),
                queue: Default::default(),
                sending: false,
                received: Vec::new(),
                encoder: 0,
                target: 0,
                reset_clocks: 4,
                ins: Vec::new(),
                outs: Vec::new(),
                pos: Vec::new(),
                _lib: lib,
            })
        }
    }

    /// Bytes from the host, sent on the UART line in order.
    pub fn receive(&mut self, bytes: &[u8]) {
        self.queue.extend(bytes);
    }

    /// Bytes the core sent.
    pub fn take_output(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.received)
    }

    /// Quadrature levels (A, B) of an encoder count: Gray order 00 → 01 → 11 → 10.
    fn levels(count: i64) -> (bool, bool) {
        match count.rem_euclid(4) {
            0 => (false, false),
            1 => (false, true),
            2 => (true, true),
            _ => (true, false),
        }
    }

    /// Runs `clocks` fabric clocks.
    pub fn run(&mut self, clocks: u64) {
        const CHUNK: u64 = 4096;
        let mut left = clocks;
        while left > 0 {
            let n = left.min(CHUNK) as usize;
            self.ins.clear();
            // The host's UART line and the encoder pins are computed a chunk ahead from the
            // state at the chunk's start; the encoder target is the last reference seen.
            for _ in 0..n {
                let next = self.queue.front().copied();
                let o = self.host_tx.clock(
                    next.is_some() && !self.sending,
                    next.unwrap_or(0),
                    self.cfg.uart_divisor,
                );
                if !self.sending && next.is_some() && o.busy {
                    self.queue.pop_front();
                }
                self.sending = o.busy;
                if self.encoder < self.target {
                    self.encoder += 1;
                } else if self.encoder > self.target {
                    self.encoder -= 1;
                }
                let (a, b) = Self::levels(self.encoder);
                let reset = self.reset_clocks > 0;
                self.reset_clocks = self.reset_clocks.saturating_sub(1);
                self.ins.push(
                    u8::from(reset) | u8::from(o.tx) << 1 | u8::from(a) << 2 | u8::from(b) << 3,
                );
            }
            self.outs.resize(n, 0);
            self.pos.resize(n, 0);
            // SAFETY: the buffers hold n entries each; the handle is live.
            unsafe {
                (self.run)(
                    self.handle,
                    n as u64,
                    self.ins.as_ptr(),
                    self.outs.as_mut_ptr(),
                    self.pos.as_mut_ptr(),
                )
            };
            for k in 0..n {
                let r = self
                    .host_rx
                    .clock(self.outs[k] & 1 == 1, self.cfg.uart_divisor);
                if r.valid {
                    self.received.push(r.data);
                }
            }
            self.target = i64::from(self.pos[n - 1]);
            left -= n as u64;
        }
    }
}

impl Drop for FabricBoard {
    fn drop(&mut self) {
        // SAFETY: the handle came from snapgen_io_new and is freed once.
        unsafe { (self.free)(self.handle) }
    }
}
