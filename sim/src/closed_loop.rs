//! The closed loop at device level: the Verilated I/O top drives a simulated motor
//! (`snapgen_plant::Plant`) through its PWM, direction and amplifier-enable pins and reads the
//! motor's encoder, while the device model, fed the same pins on every clock, must produce the
//! same outputs — PWM, direction, amplifier, the UART and the whole status block — on every
//! clock. The host's own code on the UART (`snapgen_host`: a session over this loop as its
//! byte medium, [`Transport`]) configures the axis, reads it back, uploads programs and starts
//! them, as `snapgen send` does.
//!
//! Clock by clock, one plant step at a time: the pins of the step's clocks (the host's UART
//! line, the encoder heading for the plant's count, the index) are known before it (the plant
//! moves only at the end of a step), so the fabric runs them in one call; then every clock's
//! outputs are compared with the model's, the bridge reads the fabric's pins clock by clock,
//! and the motor is integrated. Without the fabric (`fabric: false`) the model drives the
//! motor: the same loop, model only.

use snapgen_host::limits::{stop_limits, LimitSource};
use snapgen_host::link::{FramedLink, LinkError, RetryPolicy, Transport};
use snapgen_host::protocol::{Command, Param};
use snapgen_host::session::{Failure, HostError, InputError, Session};
use snapgen_model::device::{Design, Device, IoInputs, IoOutputs};
use snapgen_model::io::servo::ServoConfig;
use snapgen_model::peer::Peer;
use snapgen_model::stop::StopLimits;
use snapgen_model::{Format, Program, FRAC_BITS};
use snapgen_plant::fast::LoopSample;
use snapgen_plant::plant::StepError;
use snapgen_plant::{BridgePins, Physical, Plant};

use crate::build::build_io;
use crate::io::{
    decode_outputs, encode_inputs, encode_outputs, first_difference, FabricIo, IoSignal, IN_WORDS,
    OUT_WORDS,
};
use crate::SimError;

/// The first clock where the fabric and the model disagreed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopMismatch {
    /// Clock.
    pub clock: u64,
    /// The first signal that differs.
    pub signal: IoSignal,
    /// The model's value.
    pub expected: u128,
    /// The fabric's.
    pub actual: u128,
}

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum LoopError {
    /// Verilator or the library.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The plant's step.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The host's session with the board: the link, a refusal (NAK), a configuration that
    /// did not read back, or a board whose protocol or format the host cannot plan for (the
    /// input's to fix).
    #[error(transparent)]
    Host(#[from] Failure),
}

impl From<HostError> for LoopError {
    fn from(e: HostError) -> Self {
        LoopError::Host(Failure::Host(e))
    }
}

/// The axis's configuration for a closed loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisSetup {
    /// PWM period (clocks).
    pub pwm_period: u16,
    /// The controller.
    pub servo: ServoConfig,
    /// The stop's limits (raw).
    pub stop: StopLimits,
}

impl AxisSetup {
    /// The stop limits of this crate's loops, the experiment's and the benchmarks': a
    /// deceleration of 500 and a jerk of 5000 (units/s², units/s³ of `format`, radians for a
    /// motor's shaft), raw by the host's one rule ([`snapgen_host::limits::stop_limits`]).
    pub fn stop_limits(format: &Format) -> Result<StopLimits, InputError> {
        let given = |flag, value| LimitSource {
            flag,
            given: Some(value),
            peak: 1,
        };
        let (limits, _warnings) = stop_limits(
            given("stop deceleration", 500.0),
            given("stop jerk", 5000.0),
            format,
        )?;
        Ok(limits)
    }
}

/// The closed loop.
pub struct ClosedLoop {
    design: Design,
    dev: Device,
    fabric: Option<FabricIo>,
    peer: Peer,
    plant: Plant,
    rad_per_count: f64,
    /// Bytes the host has received from the board and not read yet.
    received: Vec<u8>,
    inputs: Vec<IoInputs>,
    words: Vec<[u32; IN_WORDS]>,
    outs: Vec<u32>,
    clock: u64,
    mismatches: u64,
    first_mismatch: Option<LoopMismatch>,
    record_every: u64,
    samples: Vec<LoopSample>,
    fault: Option<(u64, IoSignal, u32)>,
    /// Clocks at which a program began to play (the model core's `busy` rising).
    starts: Vec<u64>,
    was_busy: bool,
}

impl ClosedLoop {
    /// A loop of `design` (on the Verilated I/O top when `fabric`, built or found in the build
    /// cache) around the plant `p` stepped every `step_s`, recording a sample every
    /// `record_every` clocks. The board comes out of reset; the motor rests at angle 0.
    pub fn new(
        design: &Design,
        p: &Physical,
        step_s: f64,
        fabric: bool,
        record_every: u64,
    ) -> Result<Self, LoopError> {
        let plant = Plant::new(p, f64::from(design.clock_hz), step_s)?;
        let fabric = if fabric {
            let built = build_io(&snapgen_hdl::verilog::io_sources_text(design), false)?;
            Some(FabricIo::open(&built.library, None)?)
        } else {
            None
        };
        let mut peer = Peer::new(design.dividers.uart_divisor);
        peer.wiring = design.input_polarity;
        peer.index_period = if p.index { p.counts_per_rev } else { 0 };
        peer.drive_encoder(0);
        Ok(ClosedLoop {
            design: *design,
            dev: Device::new(design),
            fabric,
            peer,
            rad_per_count: p.rad_per_count(),
            plant,
            received: Vec::new(),
            inputs: Vec::new(),
            words: Vec::new(),
            outs: Vec::new(),
            clock: 0,
            mismatches: 0,
            first_mismatch: None,
            record_every: record_every.max(1),
            samples: Vec::new(),
            fault: None,
            starts: Vec::new(),
            was_busy: false,
        })
    }

    /// Test hook: flip `bit` of `signal` in the fabric's outputs at `clock`.
    pub fn inject_fault(&mut self, clock: u64, signal: IoSignal, bit: u32) {
        self.fault = Some((clock, signal, bit));
    }

    /// True when the Verilated I/O top drives the motor.
    pub fn on_fabric(&self) -> bool {
        self.fabric.is_some()
    }

    /// Clocks whose outputs differed (fabric against model).
    pub fn mismatches(&self) -> u64 {
        self.mismatches
    }

    /// The first of them.
    pub fn first_mismatch(&self) -> Option<LoopMismatch> {
        self.first_mismatch
    }

    /// Clocks run.
    pub fn clocks(&self) -> u64 {
        self.clock
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.clock as f64 / f64::from(self.design.clock_hz)
    }

    /// The device model.
    pub fn device(&self) -> &Device {
        &self.dev
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// When each program began to play (s): the clock its first tick's program was taken.
    pub fn starts(&self) -> Vec<f64> {
        let hz = f64::from(self.design.clock_hz);
        self.starts.iter().map(|&c| c as f64 / hz).collect()
    }

    /// The samples recorded so far (taken out).
    pub fn take_samples(&mut self) -> Vec<LoopSample> {
        std::mem::take(&mut self.samples)
    }

    /// Runs at least `clocks` clocks (whole plant steps).
    pub fn run(&mut self, clocks: u64) {
        let end = self.clock + clocks;
        while self.clock < end {
            self.step();
        }
    }

    /// Runs until `t` seconds of simulated time.
    pub fn run_until(&mut self, t: f64) {
        let end = (t * f64::from(self.design.clock_hz)).round() as u64;
        while self.clock < end {
            self.step();
        }
    }

    /// One plant step.
    fn step(&mut self) {
        let n = self.plant.step_clocks() as usize;
        self.inputs.clear();
        self.words.clear();
        for _ in 0..n {
            let i = self.peer.inputs();
            self.words.push(encode_inputs(&i));
            self.inputs.push(i);
        }
        if let Some(fab) = self.fabric.as_mut() {
            fab.run(&self.words, &mut self.outs);
        }
        for k in 0..n {
            let om = self.dev.clock(&self.inputs[k]);
            let o = match &self.fabric {
                None => om,
                Some(_) => {
                    let words = &mut self.outs[k * OUT_WORDS..(k + 1) * OUT_WORDS];
                    if let Some((at, signal, bit)) = self.fault {
                        if at == self.clock {
                            signal.flip(words, bit);
                        }
                    }
                    let want = encode_outputs(&om);
                    if let Some((signal, expected, actual)) = first_difference(words, &want) {
                        self.mismatches += 1;
                        if self.first_mismatch.is_none() {
                            self.first_mismatch = Some(LoopMismatch {
                                clock: self.clock,
                                signal,
                                expected,
                                actual,
                            });
                        }
                    }
                    decode_outputs(words)
                }
            };
            let busy = self.dev.core().busy();
            if busy && !self.was_busy {
                self.starts.push(self.clock);
            }
            self.was_busy = busy;
            self.peer.observe(&o);
            self.plant.clock(BridgePins {
                pwm: o.pwm,
                dir: o.dir,
                enable: o.amplifier,
            });
            self.clock += 1;
            if self.clock % self.record_every == 0 {
                self.record(&o);
            }
        }
        self.peer.drive_encoder(self.plant.count());
        self.received.extend(self.peer.take_received());
    }

    fn record(&mut self, o: &IoOutputs) {
        let st = self.plant.state();
        let x = self.dev.core().chain().x;
        let d = self.rad_per_count;
        self.samples.push(LoopSample {
            t: self.time(),
            reference: x as f64 / 2f64.powi(FRAC_BITS as i32) * d - 0.5 * d,
            encoder: f64::from(o.status.encoder) * d,
            theta: st.theta,
            omega: st.omega,
            duty: o.status.duty,
            volts: self.plant.volts(),
        });
    }

    /// A session of the host with the board (PING, the board's format; `snapgen_host`'s own
    /// code over this loop as its byte medium, with the one retry policy). Bytes a session
    /// before it left unread (telemetry, a late answer) are dropped first, so they are never
    /// taken for this session's replies; its PING clears the board's memory of the last
    /// sequence number.
    pub fn host(&mut self) -> Result<Session<FramedLink<&mut ClosedLoop>>, Failure> {
        self.received.clear();
        let lsb = self.design.format.position_lsb;
        Session::open(FramedLink::new(self, RetryPolicy::default(), 1), lsb)
    }

    /// Configures the axis (PWM; the controller's parameters, each read back; the stop
    /// limits, by the host's one rule for writing them; the watchdog off: the loop's host
    /// polls at its own pace) and powers it: an axis that cannot be powered (ErrorStop) is an
    /// error, the board's NAK.
    pub fn setup(&mut self, s: &AxisSetup) -> Result<(), LoopError> {
        let mut host = self.host()?;
        // WATCHDOG_MS and PWM_PERIOD are written without a read-back. Measured: with them read
        // back too (two more frames before the first move), the first move starts at another
        // phase of the tick and PWM, and from there the tuned loop of this crate's tests
        // settles into a stick-slip limit cycle of about ±5 counts instead of within one
        // count (`moves_on_the_fabric_match_the_model_and_track`). That hunting is the
        // controller's (issue 24), not the host's.
        let write = |param, value| Command::Configure { param, value };
        host.expect_ack(&write(Param::WatchdogMs, 0))?;
        host.expect_ack(&write(Param::PwmPeriod, i128::from(s.pwm_period)))?;
        for (param, value) in s.servo.writes() {
            host.configure(param, value)?;
        }
        host.set_stop_limits(s.stop)?;
        host.expect_ack(&Command::Power { on: true })?;
        Ok(())
    }

    /// Uploads `program` and starts it.
    pub fn start(&mut self, program: &Program) -> Result<(), LoopError> {
        let mut host = self.host()?;
        for (k, s) in program.segments.iter().enumerate() {
            host.expect_ack(&Command::LoadSegment {
                index: k as u8,
                segment: *s,
            })?;
        }
        host.expect_ack(&Command::Commit {
            count: program.segments.len() as u8,
        })?;
        host.expect_ack(&Command::Start)?;
        Ok(())
    }
}

/// The loop as the host's byte medium: bytes go over the board's UART at its baud rate, and
/// time is the loop's own (its clocks, the motor integrated meanwhile).
impl Transport for ClosedLoop {
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.peer.send(bytes);
        Ok(())
    }

    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
        let until = self.time() + wait.max(0.0);
        while self.received.is_empty() && self.time() < until {
            self.step();
        }
        out.append(&mut self.received);
        Ok(())
    }

    fn now(&self) -> f64 {
        self.time()
    }

    fn sleep(&mut self, seconds: f64) {
        let t = self.time() + seconds.max(0.0);
        self.run_until(t);
    }

    fn byte_time(&self) -> f64 {
        10.0 * f64::from(self.design.dividers.uart_divisor) / f64::from(self.design.clock_hz)
    }
}
