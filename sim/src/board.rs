//! A virtual board: the Verilated I/O top ([`crate::io::FabricIo`]) or the device model
//! (`snapgen_model::device::Device`), clock by clock, with the world around it
//! (`snapgen_model::peer::Peer`): host bytes become a UART line waveform at the design's baud
//! rate, the board's UART output is decoded back into bytes, the encoder follows the reference
//! position as an ideal motor would — or a simulated motor (`snapgen_plant::Plant`) turns under
//! the board's PWM and drives the encoder ([`VirtualBoard::with_motor`]) — and the limit and
//! emergency-stop inputs hold their level.

use snapgen_model::device::{Design, Device, IoOutputs};
use snapgen_model::peer::Peer;
use snapgen_plant::plant::StepError;
use snapgen_plant::{BridgePins, Physical, Plant};

use crate::build::build_io;
use crate::io::{
    decode_outputs, encode_inputs, encode_outputs, first_difference, FabricIo, IoSignal, IN_WORDS,
    OUT_WORDS,
};
use crate::SimError;

/// Clocks the fabric runs per call: the peer computes their pins ahead (the encoder follows
/// the position of the chunk before, at most this many clocks late).
const CHUNK: u64 = 256;

/// What runs the board.
enum Backend {
    /// The device model.
    Model(Box<Device>),
    /// The Verilated I/O top.
    Fabric(FabricIo),
    /// The Verilated I/O top driving the pins, the device model beside it on the same inputs,
    /// every output compared on every clock.
    Lockstep(FabricIo, Box<Device>),
}

/// The first clock the fabric's outputs differed from the model's (lockstep boards).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardMismatch {
    /// Clock.
    pub clock: u64,
    /// The first differing signal.
    pub signal: IoSignal,
    /// The model's value.
    pub expected: u128,
    /// The fabric's.
    pub actual: u128,
}

/// A virtual board's design: the default format, clock and Ts, its UART at `baud`, hashed as
/// its Verilog is (the design `snapgen board`, `online`, `path` and the Python package's
/// virtual boards run).
pub fn virtual_design(baud: u32) -> Result<Design, snapgen_model::timing::TimingError> {
    let t = snapgen_model::timing::Timing {
        baud,
        ..Default::default()
    };
    let d = Design::from_timing(&snapgen_model::DEFAULT_FORMAT, &t)?;
    Ok(snapgen_hdl::verilog::io_design(&d))
}

/// A virtual board.
pub struct VirtualBoard {
    design: Design,
    peer: Peer,
    backend: Backend,
    clocks: u64,
    ins: Vec<[u32; IN_WORDS]>,
    outs: Vec<u32>,
    motor: Option<Plant>,
    mismatches: u64,
    first_mismatch: Option<BoardMismatch>,
    fault: Option<(u64, IoSignal, u32)>,
}

impl VirtualBoard {
    /// The device model of `design`.
    pub fn model(design: &Design) -> Self {
        Self::with(design, Backend::Model(Box::new(Device::new(design))))
    }

    /// The Verilated I/O top of `design` (built, or found in the build cache).
    pub fn fabric(design: &Design) -> Result<Self, SimError> {
        let verilog = snapgen_hdl::verilog::io_sources_text(design);
        let built = build_io(&verilog, false)?;
        Ok(Self::with(
            design,
            Backend::Fabric(FabricIo::open(&built.library, None)?),
        ))
    }

    /// The Verilated I/O top of `design` with the device model in lockstep: every output of
    /// every clock compared ([`VirtualBoard::mismatches`]); the fabric drives the pins.
    pub fn lockstep(design: &Design) -> Result<Self, SimError> {
        let verilog = snapgen_hdl::verilog::io_sources_text(design);
        let built = build_io(&verilog, false)?;
        Ok(Self::with(
            design,
            Backend::Lockstep(
                FabricIo::open(&built.library, None)?,
                Box::new(Device::new(design)),
            ),
        ))
    }

    /// Clocks whose outputs differed, fabric against model (lockstep boards; 0 otherwise).
    pub fn mismatches(&self) -> u64 {
        self.mismatches
    }

    /// The first of them.
    pub fn first_mismatch(&self) -> Option<BoardMismatch> {
        self.first_mismatch
    }

    /// Test hook (lockstep boards): flip `bit` of `signal` in the fabric's outputs at `clock`,
    /// to show that a one-bit difference is counted.
    pub fn inject_fault(&mut self, clock: u64, signal: IoSignal, bit: u32) {
        self.fault = Some((clock, signal, bit));
    }

    fn with(design: &Design, backend: Backend) -> Self {
        let mut peer = Peer::new(design.dividers.uart_divisor);
        // The switches wired as the design expects them.
        peer.wiring = design.input_polarity;
        VirtualBoard {
            design: *design,
            peer,
            backend,
            clocks: 0,
            ins: Vec::new(),
            outs: Vec::new(),
            motor: None,
            mismatches: 0,
            first_mismatch: None,
            fault: None,
        }
    }

    /// A simulated motor on the board's PWM, direction and amplifier pins, its encoder on the
    /// board's encoder pins (instead of the ideal follower), stepped every `step_s`.
    pub fn with_motor(mut self, p: &Physical, step_s: f64) -> Result<Self, StepError> {
        self.motor = Some(Plant::new(p, f64::from(self.design.clock_hz), step_s)?);
        self.peer.index_period = if p.index { p.counts_per_rev } else { 0 };
        self.peer.drive_encoder(0);
        Ok(self)
    }

    /// The motor, if there is one.
    pub fn motor(&self) -> Option<&Plant> {
        self.motor.as_ref()
    }

    /// The design it runs.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// Clocks run since power-up.
    pub fn clocks(&self) -> u64 {
        self.clocks
    }

    /// The world around the board: switches, encoder (public fields of [`Peer`]).
    pub fn peer(&mut self) -> &mut Peer {
        &mut self.peer
    }

    /// Bytes from the host, sent on the UART line in order.
    pub fn receive(&mut self, bytes: &[u8]) {
        self.peer.send(bytes);
    }

    /// Bytes the board sent.
    pub fn take_output(&mut self) -> Vec<u8> {
        self.peer.take_received()
    }

    /// The world's side of a clock's outputs: the host's receiver, and the motor.
    fn observe(peer: &mut Peer, motor: &mut Option<Plant>, o: &IoOutputs) {
        peer.observe(o);
        if let Some(m) = motor {
            m.clock(BridgePins {
                pwm: o.pwm,
                dir: o.dir,
                enable: o.amplifier,
            });
        }
    }

    /// Runs `clocks` fabric clocks.
    pub fn run(&mut self, clocks: u64) {
        // With a motor, the encoder's pins change only when it steps: one step per batch.
        let chunk = self
            .motor
            .as_ref()
            .map_or(CHUNK, |m| u64::from(m.step_clocks()));
        match &mut self.backend {
            Backend::Model(dev) => {
                for _ in 0..clocks {
                    let i = self.peer.inputs();
                    let o = dev.clock(&i);
                    Self::observe(&mut self.peer, &mut self.motor, &o);
                    if let Some(m) = &self.motor {
                        self.peer.drive_encoder(m.count());
                    }
                }
            }
            Backend::Fabric(_) | Backend::Lockstep(..) => {
                let (fab, mut model) = match &mut self.backend {
                    Backend::Fabric(f) => (f, None),
                    Backend::Lockstep(f, d) => (f, Some(d)),
                    Backend::Model(_) => unreachable!("matched above"),
                };
                let mut left = clocks;
                let mut clock = self.clocks;
                let mut model_ins = Vec::new();
                while left > 0 {
                    let n = left.min(chunk) as usize;
                    self.ins.clear();
                    model_ins.clear();
                    for _ in 0..n {
                        let i = self.peer.inputs();
                        self.ins.push(encode_inputs(&i));
                        model_ins.push(i);
                    }
                    fab.run(&self.ins, &mut self.outs);
                    for (k, i) in model_ins.iter().enumerate() {
                        let words = &mut self.outs[k * OUT_WORDS..(k + 1) * OUT_WORDS];
                        if let Some(dev) = model.as_mut() {
                            if let Some((at, signal, bit)) = self.fault {
                                if at == clock {
                                    signal.flip(words, bit);
                                }
                            }
                            let want = encode_outputs(&dev.clock(i));
                            if let Some((signal, expected, actual)) = first_difference(words, &want)
                            {
                                self.mismatches += 1;
                                if self.first_mismatch.is_none() {
                                    self.first_mismatch = Some(BoardMismatch {
                                        clock,
                                        signal,
                                        expected,
                                        actual,
                                    });
                                }
                            }
                        }
                        let o = decode_outputs(words);
                        Self::observe(&mut self.peer, &mut self.motor, &o);
                        clock += 1;
                    }
                    if let Some(m) = &self.motor {
                        self.peer.drive_encoder(m.count());
                    }
                    left -= n as u64;
                }
            }
        }
        self.clocks += clocks;
    }
}
