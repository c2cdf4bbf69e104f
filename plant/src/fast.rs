//! A fast closed loop for tuning and sweeps: the controller's bit-exact law
//! (`snapgen_model::io::servo::ServoLaw`), the chain stepped per tick with a program's snaps,
//! a PWM and the plant ([`crate::Plant`]) — without the fabric's UART, executor or clock-level
//! blocks. It is event-driven: between a tick, a PWM edge and the start of a PWM period the
//! bridge's pins are constant and the plant is advanced by whole runs of clocks.
//!
//! Its timing is the fabric's up to a few clocks: a sample is taken on every `SERVO_PERIOD`-th
//! tick from the registers before that tick and the encoder's count at that instant (the
//! fabric's decoder sees it 3 clocks later); its duty is latched by the PWM at the first period
//! start at least `LATENCY` clocks later. The device-level loop (`snapgen_sim::closed_loop`,
//! the device model or the Verilated I/O top, every clock) is the reference; the two agree on
//! an experiment's figures to a few percent (tested there).
//!
//! A sample whose following error is beyond `FOLLOWING_LIMIT` trips the loop as it trips the
//! fabric (FOLLOWING_ERROR): the amplifier is off from that instant, the reference holds and
//! nothing drives the motor again ([`FastLoop::tripped`]).

use std::collections::VecDeque;

use snapgen_model::io::servo::{ServoConfig, ServoLaw, LATENCY};
use snapgen_model::{ChainState, Format, Program, Widths, FRAC_BITS};

use crate::params::Physical;
use crate::plant::{BridgePins, Plant, StepError};

/// One record of a closed loop, at a controller sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoopSample {
    /// Time since the loop started (s).
    pub t: f64,
    /// The reference position (rad): the chain's position register.
    pub reference: f64,
    /// The encoder's position (rad).
    pub encoder: f64,
    /// The shaft's true angle (rad).
    pub theta: f64,
    /// The shaft's speed (rad/s).
    pub omega: f64,
    /// The duty the controller commands (PWM clocks).
    pub duty: i16,
    /// The bridge's average voltage over the last plant step (V).
    pub volts: f64,
}

impl LoopSample {
    /// The tracking error the encoder shows (rad): reference − encoder.
    pub fn error(&self) -> f64 {
        self.reference - self.encoder
    }

    /// The true shaft's error (rad): reference − shaft angle.
    pub fn shaft_error(&self) -> f64 {
        self.reference - self.theta
    }
}

/// The fabric's timing for a loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FabricTiming {
    /// Fabric clock (Hz).
    pub clock_hz: f64,
    /// Clocks per tick.
    pub clocks_per_tick: u64,
    /// PWM period (clocks).
    pub pwm_period: u16,
}

/// The fast loop.
#[derive(Clone, Debug)]
pub struct FastLoop {
    plant: Plant,
    law: ServoLaw,
    cfg: ServoConfig,
    widths: Widths,
    timing: FabricTiming,
    rad_per_count: f64,
    chain: ChainState,
    snaps: VecDeque<(u32, i128)>,
    clock: u64,
    next_tick: u64,
    divider: u16,
    /// Duties waiting for their clock.
    pending: VecDeque<(u64, i16)>,
    duty_reg: i16,
    /// The PWM's latched on-time and direction for the current period.
    on: u64,
    negative: bool,
    period_start: u64,
    tripped: Option<f64>,
    /// Clocks between a sample and its duty beyond the fabric's LATENCY (a host's loop).
    delay_clocks: u64,
}

impl FastLoop {
    /// A loop at rest at 0 with the controller configured as `cfg` (the amplifier on).
    pub fn new(
        p: &Physical,
        format: &Format,
        timing: FabricTiming,
        cfg: ServoConfig,
        step_s: f64,
    ) -> Result<Self, StepError> {
        Ok(FastLoop {
            plant: Plant::new(p, timing.clock_hz, step_s)?,
            law: ServoLaw::default(),
            cfg,
            widths: format.widths,
            timing,
            rad_per_count: p.rad_per_count(),
            chain: ChainState::at_rest(format.home_raw()),
            snaps: VecDeque::new(),
            clock: 0,
            next_tick: timing.clocks_per_tick,
            divider: 0,
            pending: VecDeque::new(),
            duty_reg: 0,
            on: 0,
            negative: false,
            period_start: 0,
            tripped: None,
            delay_clocks: 0,
        })
    }

    /// The controller as a host runs it (seed 001's Raspberry Pi): each duty reaches the PWM
    /// `seconds` later than the fabric's own controller's would (the encoder's count sent over
    /// the wire, the control computed, the command sent back), rounded to clocks.
    /// A delay that is not a finite number of seconds ≥ 0 is taken as none.
    pub fn with_transport_delay(mut self, seconds: f64) -> Self {
        let clocks = seconds * self.timing.clock_hz;
        self.delay_clocks = if clocks.is_finite() && clocks > 0.0 {
            clocks.round().min(1e15) as u64
        } else {
            0
        };
        self
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The chain's registers.
    pub fn chain(&self) -> ChainState {
        self.chain
    }

    /// Plays `program` from the next tick on (after what is queued); returns when it starts
    /// (s: the next tick, when nothing is queued).
    pub fn play(&mut self, program: &Program) -> f64 {
        self.snaps
            .extend(program.segments.iter().map(|s| (s.ticks, s.snap)));
        self.next_tick as f64 / self.timing.clock_hz
    }

    /// When a sample's following error passed `FOLLOWING_LIMIT` (s), if it did: the amplifier
    /// has been off since.
    pub fn tripped(&self) -> Option<f64> {
        self.tripped
    }

    /// True while a program plays.
    pub fn playing(&self) -> bool {
        !self.snaps.is_empty()
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.clock as f64 / self.timing.clock_hz
    }

    fn pins(&self, clock: u64) -> BridgePins {
        let phase = clock - self.period_start;
        BridgePins {
            pwm: phase < self.on,
            dir: self.negative,
            enable: self.tripped.is_none(),
        }
    }

    /// Runs until `t` seconds, calling `sink` at every controller sample.
    pub fn run_until(&mut self, t: f64, mut sink: impl FnMut(&LoopSample)) {
        let end = (t * self.timing.clock_hz).round() as u64;
        let period = u64::from(self.timing.pwm_period.max(1));
        while self.clock < end {
            // The next event: a tick, the PWM's falling edge, a new period, the end.
            let off = self.period_start + self.on;
            let mut next = self.next_tick.min(self.period_start + period).min(end);
            if off > self.clock {
                next = next.min(off);
            }
            let pins = self.pins(self.clock);
            self.plant.hold(pins, next - self.clock);
            self.clock = next;
            if self.clock == self.period_start + period {
                // The period restarts: latch the duty register as it stands.
                while self
                    .pending
                    .front()
                    .is_some_and(|(at, _)| *at <= self.clock)
                {
                    self.duty_reg = self.pending.pop_front().map_or(0, |(_, d)| d);
                }
                self.period_start = self.clock;
                self.on = u64::from(self.duty_reg.unsigned_abs()).min(period);
                self.negative = self.duty_reg < 0;
            }
            if self.clock == self.next_tick {
                self.tick(&mut sink);
                self.next_tick += self.timing.clocks_per_tick;
            }
        }
    }

    fn tick(&mut self, sink: &mut impl FnMut(&LoopSample)) {
        // The sample, from the registers before this tick.
        if self.cfg.servo_period != 0 {
            if self.divider == 0 {
                let count = self.plant.count();
                let mut s =
                    self.law
                        .sample(&self.cfg, self.chain.x, self.chain.v, self.chain.a, count);
                if s.fault && self.tripped.is_none() {
                    // FOLLOWING_ERROR: the amplifier off at once, the reference holds.
                    self.tripped = Some(self.time());
                    self.snaps.clear();
                    self.pending.clear();
                    self.duty_reg = 0;
                }
                if self.tripped.is_some() {
                    s.duty = 0;
                } else {
                    self.pending
                        .push_back((self.clock + u64::from(LATENCY) + self.delay_clocks, s.duty));
                }
                let st = self.plant.state();
                sink(&LoopSample {
                    t: self.time(),
                    reference: (self.chain.x as f64) / 2f64.powi(FRAC_BITS as i32)
                        * self.rad_per_count
                        - 0.5 * self.rad_per_count,
                    encoder: count as f64 * self.rad_per_count,
                    theta: st.theta,
                    omega: st.omega,
                    duty: s.duty,
                    volts: self.plant.volts(),
                });
                self.divider = self.cfg.servo_period - 1;
            } else {
                self.divider -= 1;
            }
        }
        // The chain steps with the program's snap (it holds once tripped: the program is gone
        // and the chain is at rest or brought there by the snaps already taken).
        if self.tripped.is_some() {
            return;
        }
        let d = match self.snaps.front_mut() {
            Some((left, snap)) => {
                let d = *snap;
                *left -= 1;
                if *left == 0 {
                    self.snaps.pop_front();
                }
                d
            }
            None => 0,
        };
        self.chain = self.chain.step(d, &self.widths);
    }
}
