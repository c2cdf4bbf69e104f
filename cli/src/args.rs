//! The arguments several subcommands share: a move to plan (`plan`, `trace`, `plot`, `send`)
//! and its translation into a [`MoveRequest`] and a [`Format`]; the motor, the controller,
//! the fabric's timing, the board, and a serial link with the host's retry policy.

use std::path::{Path, PathBuf};

use clap::Args;
use snapgen_host::driver::RunOptions;
use snapgen_host::link::{FramedLink, LinkError, RetryPolicy, Transport};
use snapgen_host::serial::{session_seq, SerialTransport};
use snapgen_host::session::{Failure, Session};
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plan::{Method, MoveRequest, Plan};
use snapgen_plant::gains::{LoopDesign, LoopTiming};
use snapgen_plant::PlantParams;

use crate::error::InputError;

/// A command-line mistake that clap cannot see: a flag that the chosen method does not use,
/// or one that it needs. Exit code 2, like clap's own usage errors.
#[derive(Debug, thiserror::Error)]
pub enum ArgError {
    /// A needed flag is missing.
    #[error("{method} needs --{flag}")]
    Missing {
        /// The method.
        method: &'static str,
        /// The flag.
        flag: &'static str,
    },
    /// A flag the method does not use.
    #[error("--{flag} is not used by {method}: remove it")]
    Unused {
        /// The method.
        method: &'static str,
        /// The flag.
        flag: &'static str,
    },
}

/// How to plan a move. Units: positions in user units (m, rad, …), times in seconds.
#[derive(Args, Debug, Clone)]
pub struct PlanArgs {
    /// Profile order: 4 (snap-limited, seed 000), 3 (jerk-limited S-curve) or 2 (trapezoid).
    #[arg(long, value_parser = clap::value_parser!(u8).range(2..=4))]
    pub order: Option<u8>,
    /// Signed distance to move (units).
    #[arg(long, allow_hyphen_values = true)]
    pub distance: f64,
    /// Velocity limit (units/s).
    #[arg(long, allow_hyphen_values = true)]
    pub vmax: Option<f64>,
    /// Acceleration limit (units/s²).
    #[arg(long, allow_hyphen_values = true)]
    pub amax: Option<f64>,
    /// Jerk limit (units/s³); orders 4 and 3.
    #[arg(long, allow_hyphen_values = true)]
    pub jmax: Option<f64>,
    /// Snap limit (units/s⁴); order 4.
    #[arg(long, allow_hyphen_values = true)]
    pub dmax: Option<f64>,
    /// Seed 001 duration-based S-curve: the move's duration T (s). Needs --gamma and --phi.
    #[arg(long, allow_hyphen_values = true)]
    pub duration: Option<f64>,
    /// Seed 001 acceleration-time factor γ ∈ (0, 0.5]: T_acc = γ·T.
    #[arg(long, allow_hyphen_values = true)]
    pub gamma: Option<f64>,
    /// Seed 001 jerk-time factor φ ∈ (0, 0.5]: T_jerk = φ·T_acc.
    #[arg(long, allow_hyphen_values = true)]
    pub phi: Option<f64>,
    /// Tick (sampling) period Ts (s) [default: 1e-5; `send`: the board's, and a different
    /// one is refused].
    #[arg(long, allow_hyphen_values = true)]
    pub ts: Option<f64>,
    /// Physical size of one output position LSB (units) [default: 1e-6; `send --motor`: one
    /// count of the motor's encoder, in rad].
    #[arg(long, allow_hyphen_values = true)]
    pub lsb: Option<f64>,
}

fn need(method: &'static str, flag: &'static str, v: Option<f64>) -> Result<f64, ArgError> {
    v.ok_or(ArgError::Missing { method, flag })
}

fn unused(method: &'static str, flag: &'static str, v: Option<f64>) -> Result<(), ArgError> {
    match v {
        Some(_) => Err(ArgError::Unused { method, flag }),
        None => Ok(()),
    }
}

impl PlanArgs {
    /// The format these arguments select.
    pub fn format(&self) -> Format {
        Format {
            ts: self.ts.unwrap_or(DEFAULT_FORMAT.ts),
            position_lsb: self.lsb.unwrap_or(DEFAULT_FORMAT.position_lsb),
            ..DEFAULT_FORMAT
        }
    }

    /// The move these arguments describe.
    pub fn request(&self) -> Result<MoveRequest, ArgError> {
        let method = if self.duration.is_some() {
            const M: &str = "the duration-based method (--duration)";
            if let Some(order) = self.order {
                if order != 3 {
                    return Err(ArgError::Unused {
                        method: M,
                        flag: "order",
                    });
                }
            }
            unused(M, "vmax", self.vmax)?;
            unused(M, "amax", self.amax)?;
            unused(M, "jmax", self.jmax)?;
            unused(M, "dmax", self.dmax)?;
            Method::Duration {
                duration: need(M, "duration", self.duration)?,
                gamma: need(M, "gamma", self.gamma)?,
                phi: need(M, "phi", self.phi)?,
            }
        } else {
            let order = self.order.unwrap_or(4);
            let m: &'static str = match order {
                4 => "order 4",
                3 => "order 3",
                _ => "order 2",
            };
            unused(m, "gamma", self.gamma)?;
            unused(m, "phi", self.phi)?;
            let vmax = need(m, "vmax", self.vmax)?;
            let amax = need(m, "amax", self.amax)?;
            match order {
                4 => Method::Order4 {
                    vmax,
                    amax,
                    jmax: need(m, "jmax", self.jmax)?,
                    dmax: need(m, "dmax", self.dmax)?,
                },
                3 => {
                    unused(m, "dmax", self.dmax)?;
                    Method::Order3 {
                        vmax,
                        amax,
                        jmax: need(m, "jmax", self.jmax)?,
                    }
                }
                _ => {
                    unused(m, "dmax", self.dmax)?;
                    unused(m, "jmax", self.jmax)?;
                    Method::Order2 { vmax, amax }
                }
            }
        };
        Ok(MoveRequest {
            distance: self.distance,
            method,
        })
    }
}

/// The plant: a motor file, or the default one.
#[derive(Args, Debug, Clone)]
pub struct MotorArgs {
    /// A plant file (TOML, docs/PLANT.md) [default: plant/motors/re40-148877.toml, built in].
    #[arg(long)]
    pub motor: Option<PathBuf>,
}

impl MotorArgs {
    /// The plant.
    pub fn load(&self) -> Result<PlantParams, InputError> {
        match &self.motor {
            Some(f) => load_plant(f),
            None => Ok(PlantParams::default_plant()),
        }
    }
}

/// A `--motor [FILE]` that may be given without a file (`default`): the default plant, a
/// plant file, or none.
pub fn optional_motor(motor: Option<&Path>) -> Result<Option<PlantParams>, InputError> {
    match motor {
        None => Ok(None),
        Some(f) if f.as_os_str() == "default" => Ok(Some(PlantParams::default_plant())),
        Some(f) => load_plant(f).map(Some),
    }
}

fn load_plant(f: &Path) -> Result<PlantParams, InputError> {
    PlantParams::from_file(f).map_err(|e| InputError::Board(e.to_string()))
}

/// The controller's rate and design.
#[derive(Args, Debug, Clone)]
pub struct ServoArgs {
    /// The controller's sample rate (Hz): SERVO_PERIOD = 1 / (rate · Ts) ticks.
    #[arg(long, default_value_t = 10_000.0)]
    pub loop_hz: f64,
    /// PWM frequency (Hz): PWM_PERIOD = clock / rate.
    #[arg(long, default_value_t = 20_000.0)]
    pub pwm_hz: f64,
    /// Closed-loop bandwidth (Hz), at most a twentieth of the sample rate.
    #[arg(long, default_value_t = LoopDesign::default().bandwidth_hz)]
    pub bandwidth_hz: f64,
    /// Damping of the complex pole pair.
    #[arg(long, default_value_t = LoopDesign::default().damping)]
    pub damping: f64,
    /// No velocity and acceleration feed-forward.
    #[arg(long)]
    pub no_feed_forward: bool,
    /// No integrator: a PD controller (two poles placed at the bandwidth, no integral action).
    #[arg(long)]
    pub no_integrator: bool,
    /// Following-error limit (rad): beyond it the amplifier goes off (FOLLOWING_ERROR).
    #[arg(long, default_value_t = LoopDesign::default().following_limit_rad)]
    pub following_limit_rad: f64,
}

impl ServoArgs {
    /// Bandwidth, damping, feed-forward and following limit.
    pub fn design(&self) -> LoopDesign {
        LoopDesign {
            bandwidth_hz: self.bandwidth_hz,
            damping: self.damping,
            feed_forward: !self.no_feed_forward,
            integrator: !self.no_integrator,
            following_limit_rad: self.following_limit_rad,
            ..Default::default()
        }
    }

    /// The loop's timing at `clock_hz` and `ts`, checked.
    pub fn timing(&self, clock_hz: f64, ts: f64) -> Result<LoopTiming, InputError> {
        let bad = |m: String| Err(InputError::Board(m));
        if !(ts.is_finite() && ts > 0.0) {
            return bad(format!("--ts {ts}: give a positive tick period in seconds"));
        }
        let ticks = (1.0 / (self.loop_hz * ts)).round();
        if !(self.loop_hz.is_finite() && self.loop_hz > 0.0 && (1.0..=65535.0).contains(&ticks)) {
            return bad(format!(
                "--loop-hz {}: at Ts {ts} s that is {ticks} ticks per sample; give a rate of 1 to 65 535 ticks",
                self.loop_hz
            ));
        }
        let clocks = (clock_hz / self.pwm_hz).round();
        if !(self.pwm_hz.is_finite() && self.pwm_hz > 0.0 && (2.0..=32767.0).contains(&clocks)) {
            return bad(format!(
                "--pwm-hz {}: at {clock_hz} Hz that is {clocks} clocks per period; give a rate with 2 to 32 767",
                self.pwm_hz
            ));
        }
        Ok(LoopTiming {
            ts,
            servo_period: ticks as u16,
            pwm_period: clocks as u16,
        })
    }
}

/// The fabric's clock, UART baud rate and tick period (docs/HDL.md, "Timing").
#[derive(Args, Debug, Clone)]
pub struct TimingArgs {
    /// Fabric clock frequency in Hz [default: the board's oscillator, or 125e6].
    #[arg(long)]
    pub clock_hz: Option<f64>,
    /// UART baud rate (8N1).
    #[arg(long, default_value_t = snapgen_model::timing::DEFAULT_BAUD)]
    pub baud: u32,
    /// Tick period Ts after reset, in seconds (a whole number of clocks).
    #[arg(long, default_value_t = DEFAULT_FORMAT.ts)]
    pub ts: f64,
}

impl TimingArgs {
    /// The timing, with the clock of `board` unless `--clock-hz` says otherwise; checked.
    pub fn resolve(
        &self,
        board_clock_hz: Option<u64>,
        input_polarity: u8,
    ) -> Result<(Timing, Design), InputError> {
        let clock_hz = match self.clock_hz {
            Some(f) if !(f.is_finite() && f >= 1.0 && f.fract() == 0.0 && f < 1e12) => {
                return Err(InputError::Board(format!(
                    "--clock-hz {f}: give a whole number of Hz, e.g. 125e6"
                )))
            }
            Some(f) => f as u64,
            None => board_clock_hz.unwrap_or(snapgen_model::timing::DEFAULT_CLOCK_HZ),
        };
        let t = Timing {
            clock_hz,
            baud: self.baud,
            ts: self.ts,
        };
        let mut d = Design::from_timing(&DEFAULT_FORMAT, &t)
            .map_err(|e| InputError::Board(e.to_string()))?;
        d.input_polarity = input_polarity;
        Ok((t, snapgen_hdl::verilog::io_design(&d)))
    }
}

/// Which board: a built-in one by name, or a user's description.
#[derive(Args, Debug, Clone)]
pub struct BoardArgs {
    /// Built-in board name.
    #[arg(long, default_value = "zybo-z7-10", conflicts_with = "board_file")]
    pub board: String,
    /// A board description of your own (TOML, schema in docs/BOARDS.md).
    #[arg(long)]
    pub board_file: Option<PathBuf>,
}

impl BoardArgs {
    /// The board description.
    pub fn load(&self) -> Result<crate::board_spec::Board, InputError> {
        match &self.board_file {
            Some(f) => crate::board_spec::from_file(f),
            None => crate::board_spec::builtin(&self.board),
        }
        .map_err(|e| InputError::Board(e.to_string()))
    }
}

/// A link to a board — a serial port, or the station's AXI4-Lite registers through a UIO
/// device on the board's own processor — with the host's retry policy (docs/PROTOCOL.md,
/// "Retries").
#[derive(Args, Debug, Clone)]
pub struct LinkArgs {
    /// Serial device (a real board's USB-UART, or the path `snapgen board --pty` prints).
    #[arg(long, required_unless_present = "uio", conflicts_with = "uio")]
    pub port: Option<String>,
    /// The station's UIO device instead of a serial port (`/dev/uioN`, on a Zynq running the
    /// AXI4-Lite design: docs/AXI.md).
    #[arg(long)]
    pub uio: Option<PathBuf>,
    /// Baud rate (serial port).
    #[arg(long, default_value_t = 115_200)]
    pub baud: u32,
    /// Reply timeout per attempt, in milliseconds (above the board's inter-byte timeout and a
    /// frame's airtime).
    #[arg(long, default_value_t = (snapgen_spec::rules::HOST_REPLY_TIMEOUT_S * 1e3) as u64)]
    pub timeout_ms: u64,
    /// Retries after a lost reply or a corrupted frame.
    #[arg(long, default_value_t = snapgen_spec::rules::HOST_RETRIES)]
    pub retries: u32,
}

/// A real board instead of a virtual one (`--port` or `--uio`), and the baud rate: the
/// port's, or the virtual board's UART where it has one. (`--board` conflicts with both.)
#[derive(Args, Debug, Clone)]
pub struct BoardLinkArgs {
    /// A real board's serial port instead of a virtual board.
    #[arg(long, conflicts_with = "uio")]
    pub port: Option<String>,
    /// A real board's station through its UIO device (`/dev/uioN`, on the board's own
    /// processor: docs/AXI.md) instead of a virtual board.
    #[arg(long)]
    pub uio: Option<PathBuf>,
    /// Baud rate: the virtual board's UART (its design) or the port's.
    #[arg(long, default_value_t = 115_200)]
    pub baud: u32,
}

impl BoardLinkArgs {
    /// The real board's medium, or None: a virtual board.
    pub fn direct(&self) -> Result<Option<DirectLink>, Failure> {
        direct_link(self.port.as_deref(), self.uio.as_deref(), self.baud)
    }
}

/// A session with a board on a serial port or a UIO device.
pub type BoardSession = Session<FramedLink<Box<dyn Transport>>>;

impl LinkArgs {
    /// Opens the port (or the UIO device) and begins a session (PING, the board's format;
    /// `position_lsb` is the host's scale).
    pub fn open(&self, position_lsb: f64) -> Result<BoardSession, Failure> {
        let policy = RetryPolicy {
            timeout: self.timeout_ms as f64 / 1e3,
            retries: self.retries,
            ..Default::default()
        };
        let Some((t, _)) = direct_link(self.port.as_deref(), self.uio.as_deref(), self.baud)?
        else {
            return Err(LinkError::Io("give --port PORT or --uio /dev/uioN".into()).into());
        };
        Session::open(FramedLink::new(t, policy, session_seq()), position_lsb)
    }
}

/// A real board's medium and the driver's run options for it (a memory-mapped link needs less
/// lead than a serial one).
pub type DirectLink = (Box<dyn Transport>, RunOptions);

/// A real board given by `--port` or `--uio` (None: neither, a virtual board).
pub fn direct_link(
    port: Option<&str>,
    uio: Option<&Path>,
    baud: u32,
) -> Result<Option<DirectLink>, Failure> {
    Ok(match (port, uio) {
        (_, Some(uio)) => Some((
            snapgen_host::uio::open_station(uio)?,
            RunOptions::memory_mapped(),
        )),
        (Some(port), None) => Some((
            Box::new(SerialTransport::open(port, baud)?),
            RunOptions::default(),
        )),
        (None, None) => None,
    })
}

impl PlanArgs {
    /// The move planned.
    pub fn plan(&self) -> Result<Plan, InputError> {
        let request = self.request()?;
        Ok(snapgen_plan::plan(&request, &self.format())?)
    }
}
