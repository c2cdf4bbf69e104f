//! A board from Python: a virtual one (the device model or the Verilated I/O top behind its
//! UART; the AXI4-Lite top's model or the Verilated AXI top, its model in lockstep, behind the
//! host's UIO link on a simulated memory map; time is the board's own clocks), or a real one on
//! a serial port or through its UIO device on a Zynq — behind the host's one link and session.
//! Moves run by the host's `send_move` (`snapgen send`): planned from the board's exact
//! registers with its Ts and format, uploaded, started, followed and checked bit for bit where
//! they end; timed scripts of PLCopen commands by the host axis (`snapgen online`).

use pyo3::create_exception;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use snapgen_host::driver::RunOptions;
use snapgen_host::link::{FramedLink, LinkError, RetryPolicy, Transport};
use snapgen_host::online::{self, PlayError, Script};
use snapgen_host::protocol::Command;
use snapgen_host::send::{send_move, NoProgress, SendOptions};
use snapgen_host::serial::{session_seq, SerialTransport};
use snapgen_host::session::{Failure, Session};
use snapgen_host::uio::RegisterTransport;
use snapgen_model::device::Design;
use snapgen_model::format::DEFAULT_FORMAT;
use snapgen_plan::MoveRequest;
use snapgen_sim::axi_board::{axi_transport, AxiBoard};
use snapgen_sim::board::VirtualBoard;
use snapgen_sim::host_link::BoardTransport;

use crate::{PlanError, Trajectory};

create_exception!(
    snapgen,
    BoardError,
    PyRuntimeError,
    "The link or the board failed: no reply, a refusal (NAK), an axis error, a move that did not end where it was planned; the message says which and what to check."
);

/// What the host talks through: a virtual board behind its UART or its AXI4-Lite registers
/// (kept by type, for their clocks and mismatches), or a real board's port or UIO device.
enum Medium {
    Uart(Box<BoardTransport>),
    Axi(Box<RegisterTransport<AxiBoard>>),
    Direct(Box<dyn Transport>),
}

impl Medium {
    fn as_dyn(&self) -> &dyn Transport {
        match self {
            Medium::Uart(t) => t.as_ref(),
            Medium::Axi(t) => t.as_ref(),
            Medium::Direct(t) => t.as_ref(),
        }
    }

    fn as_dyn_mut(&mut self) -> &mut dyn Transport {
        match self {
            Medium::Uart(t) => t.as_mut(),
            Medium::Axi(t) => t.as_mut(),
            Medium::Direct(t) => t.as_mut(),
        }
    }
}

impl Transport for Medium {
    fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.as_dyn_mut().write(bytes)
    }
    fn read(&mut self, wait: f64, out: &mut Vec<u8>) -> Result<(), LinkError> {
        self.as_dyn_mut().read(wait, out)
    }
    fn now(&self) -> f64 {
        self.as_dyn().now()
    }
    fn sleep(&mut self, seconds: f64) {
        self.as_dyn_mut().sleep(seconds)
    }
    fn byte_time(&self) -> f64 {
        self.as_dyn().byte_time()
    }
}

type AnySession = Session<FramedLink<Medium>>;

/// The host's failure as a Python exception: the user's input a `PlanError`, the link's or
/// the board's a `BoardError`.
fn failure(f: Failure) -> PyErr {
    match f {
        Failure::Input(e) => PlanError::new_err(e.to_string()),
        Failure::Host(e) => BoardError::new_err(e.to_string()),
    }
}

/// What became of a command of a played script.
#[pyclass(module = "snapgen", frozen, get_all)]
#[derive(Clone)]
pub struct CommandOutcome {
    /// The event's index in the script.
    event: usize,
    /// Its time (ms from the script's start).
    at_ms: f64,
    /// `MC_MoveAbsolute`, `MC_MoveVelocity` or `MC_Halt`.
    command: &'static str,
    /// `Done`, `CommandAborted`, `Busy`, `Active`, `InVelocity`, `Error` (`NotGiven`: its
    /// position was never reached).
    outcome: &'static str,
    /// Its ErrorID when refused (`invalid_input`, `planner`, `board`, `link_too_slow`,
    /// `diverged`: docs/ONLINE.md).
    error_id: Option<&'static str>,
    /// The refusal's message.
    error: Option<String>,
    /// What the axis noted about it.
    note: Option<String>,
    /// The tick it was due on (its time, or when its position was reached), when taken.
    due_tick: Option<u64>,
    /// The tick of the swap that realised it (the first tick that obeyed it), if one did.
    swap_tick: Option<u64>,
    /// From the tick it was due to the first tick that obeyed it (ms), when it had one.
    latency_ms: Option<f64>,
}

/// What became of a feed-override change of a played script.
#[pyclass(module = "snapgen", frozen, get_all)]
#[derive(Clone)]
pub struct OverrideOutcome {
    /// The event's index in the script.
    event: usize,
    /// Its time (ms from the script's start).
    at_ms: f64,
    /// The feed override (0–2).
    factor: f64,
    /// Refused (its ErrorID), or taken.
    error_id: Option<&'static str>,
    /// The refusal's message.
    error: Option<String>,
    /// The tick it was due on.
    due_tick: Option<u64>,
    /// The tick of the swap that realised it, if one did.
    swap_tick: Option<u64>,
    /// From the tick it was due to the first tick that obeyed it (ms), when it had one.
    latency_ms: Option<f64>,
}

/// What a played script did.
#[pyclass(module = "snapgen", frozen, get_all)]
pub struct OnlineReport {
    /// Each command's outcome, in the script's order.
    commands: Vec<CommandOutcome>,
    /// Each feed-override change taken.
    overrides: Vec<OverrideOutcome>,
    /// Program swaps (replans).
    replans: usize,
    /// More swaps that uploaded the rest of a change longer than the program memory.
    extension_swaps: u32,
    /// Ticks from the script's start to its last state read.
    ticks: u64,
    /// The board's raw `(x, v, a, j)` at its last state read.
    end_registers: (i128, i128, i128, i128),
    /// Its position (output LSBs).
    end_lsb: i128,
    /// Where the last command not refused ends (output LSBs), if it ends on a position.
    target_lsb: Option<i128>,
    /// States read back and compared bit for bit with the host's prediction.
    state_checks: u64,
    /// What the stop-limit rule warned about.
    warnings: Vec<String>,
}

/// A board and the host's session with it.
#[pyclass(module = "snapgen", unsendable)]
pub struct Board {
    session: AnySession,
    /// The driver's run options for the medium (a memory-mapped one needs less lead).
    run: RunOptions,
    /// A Verilated top with its model in lockstep.
    lockstep: bool,
}

/// The outcome of a move on a board.
#[pyclass(module = "snapgen", frozen, get_all)]
pub struct MoveReport {
    /// The move as planned and uploaded (from the board's registers, with its Ts).
    trajectory: Py<Trajectory>,
    /// The board's raw `(x, v, a, j)` after it.
    end_registers: (i128, i128, i128, i128),
    /// The board's tick count at its end.
    ticks: u32,
    /// Cut short by a controlled stop (`stop_after`).
    stopped: bool,
    /// What the host warned about (stop limits).
    warnings: Vec<String>,
}

/// A session with the board behind `transport`: the driver's run options `run` for its medium
/// (a memory-mapped one needs less lead), `lockstep` when a Verilated top runs beside its model.
fn open(transport: Medium, run: RunOptions, lockstep: bool, lsb: f64) -> PyResult<Board> {
    if !(lsb.is_finite() && lsb > 0.0) {
        return Err(PlanError::new_err(format!(
            "lsb = {lsb}: give the size of one output position LSB in units (> 0)"
        )));
    }
    // A real board's sequence numbers start where no earlier session's did (the CLI's rule); a
    // simulation repeats from 0.
    let seq = match transport {
        Medium::Direct(_) => session_seq(),
        _ => 0,
    };
    let link = FramedLink::new(transport, RetryPolicy::default(), seq);
    let session = Session::open(link, lsb).map_err(failure)?;
    Ok(Board {
        session,
        run,
        lockstep,
    })
}

/// A virtual board behind its UART (`lockstep`: a Verilated top beside its model).
fn open_uart(board: VirtualBoard, lockstep: bool, lsb: f64) -> PyResult<Board> {
    let t = BoardTransport::new(board);
    open(
        Medium::Uart(Box::new(t)),
        RunOptions::default(),
        lockstep,
        lsb,
    )
}

/// A virtual AXI board through the UIO link's code (`lockstep`: a Verilated top beside its
/// model).
fn open_axi(board: AxiBoard, lockstep: bool, lsb: f64) -> PyResult<Board> {
    let t = axi_transport(board).map_err(|e| BoardError::new_err(e.to_string()))?;
    open(
        Medium::Axi(Box::new(t)),
        RunOptions::memory_mapped(),
        lockstep,
        lsb,
    )
}

/// A virtual board's design: the default clock and Ts at `baud`.
fn design(baud: u32) -> PyResult<Design> {
    snapgen_sim::board::virtual_design(baud)
        .map_err(|e| PlanError::new_err(format!("a board at {baud} baud: {e}")))
}

impl Board {
    /// On a board with a Verilated top and its model in lockstep, a `BoardError` when they have
    /// differed on any clock (the promise is none; the CLI exits 1 the same way).
    fn check_lockstep(&self) -> PyResult<()> {
        let (n, first) = match self.session.link.transport() {
            Medium::Uart(t) if self.lockstep => (
                t.board().mismatches(),
                t.board().first_mismatch().map(|m| format!("{m:?}")),
            ),
            Medium::Axi(t) if self.lockstep => (
                t.registers().mismatches(),
                t.registers().first_mismatch().map(|m| m.to_string()),
            ),
            _ => return Ok(()),
        };
        if n == 0 {
            return Ok(());
        }
        Err(BoardError::new_err(format!(
            "the Verilated top and its model differed on {n} clocks, the first: {}",
            first.unwrap_or_default()
        )))
    }
}

#[pymethods]
impl Board {
    /// A virtual board running the device model (the clock-accurate twin of the I/O top) at
    /// the default clock and Ts, its UART at `baud`; time passes in its clocks.
    #[staticmethod]
    #[pyo3(signature = (*, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn model(baud: u32, lsb: f64) -> PyResult<Board> {
        open_uart(VirtualBoard::model(&design(baud)?), false, lsb)
    }

    /// A virtual board running the Verilated I/O top, the device model in lockstep (every
    /// output of every clock compared: `mismatches`; needs Verilator and a C++ compiler; the
    /// build is cached).
    #[staticmethod]
    #[pyo3(signature = (*, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn fabric(baud: u32, lsb: f64) -> PyResult<Board> {
        let board = VirtualBoard::lockstep(&design(baud)?)
            .map_err(|e| BoardError::new_err(format!("cannot build the Verilated I/O top: {e}")))?;
        open_uart(board, true, lsb)
    }

    /// A real board on serial port `port` at `baud` (its UART's rate).
    #[staticmethod]
    #[pyo3(signature = (port, *, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn serial(port: &str, baud: u32, lsb: f64) -> PyResult<Board> {
        let t =
            SerialTransport::open(port, baud).map_err(|e| BoardError::new_err(e.to_string()))?;
        open(
            Medium::Direct(Box::new(t)),
            RunOptions::default(),
            false,
            lsb,
        )
    }

    /// A virtual board running the AXI4-Lite top's model (the station's registers, the same
    /// command executor as behind the UART), reached through the host's UIO link on a
    /// simulated memory map: the code a Zynq's ARM runs, up to the `mmap`.
    #[staticmethod]
    #[pyo3(signature = (*, lsb=DEFAULT_FORMAT.position_lsb))]
    fn axi_model(lsb: f64) -> PyResult<Board> {
        open_axi(AxiBoard::model(&design(115_200)?), false, lsb)
    }

    /// The Verilated AXI4-Lite top with its model in lockstep (every output of every clock
    /// compared: `mismatches`), through the UIO link's code on a simulated memory map (needs
    /// Verilator and a C++ compiler; the build is cached).
    #[staticmethod]
    #[pyo3(signature = (*, lsb=DEFAULT_FORMAT.position_lsb))]
    fn axi_fabric(lsb: f64) -> PyResult<Board> {
        let board = AxiBoard::lockstep(&design(115_200)?).map_err(|e| {
            BoardError::new_err(format!("cannot build the Verilated AXI4-Lite top: {e}"))
        })?;
        open_axi(board, true, lsb)
    }

    /// A real board's station through its UIO device (`/dev/uioN`, on a Zynq running the
    /// AXI4-Lite design: docs/AXI.md). Linux only.
    #[staticmethod]
    #[pyo3(signature = (path, *, lsb=DEFAULT_FORMAT.position_lsb))]
    fn uio(path: std::path::PathBuf, lsb: f64) -> PyResult<Board> {
        let t = snapgen_host::uio::open_station(&path)
            .map_err(|e| BoardError::new_err(e.to_string()))?;
        open(Medium::Direct(t), RunOptions::memory_mapped(), false, lsb)
    }

    /// Clocks on which the Verilated top and its model in lockstep differed (`fabric`,
    /// `axi_fabric`: every output of every clock compared; 0 is the promise); None on a board
    /// without both.
    #[getter]
    fn mismatches(&self) -> Option<u64> {
        if !self.lockstep {
            return None;
        }
        match self.session.link.transport() {
            Medium::Uart(t) => Some(t.board().mismatches()),
            Medium::Axi(t) => Some(t.registers().mismatches()),
            Medium::Direct(_) => None,
        }
    }

    /// Plays a timed script of PLCopen commands (MC_MoveAbsolute with its buffer modes,
    /// MC_MoveVelocity, MC_Halt, the feed override; docs/ONLINE.md) through the host axis, as
    /// `snapgen online` does: `script` is its TOML text or the same fields as a dict
    /// (`{"order": 3, "event": [{"at_ms": 0, "kind": "move_absolute", ...}]}`). The stop
    /// limits are written (the script's, or its largest deceleration and jerk), the axis
    /// powered, every change planned from the exact state at a swap tick, uploaded and armed;
    /// every state read back is compared bit for bit with the host's prediction (a difference
    /// stops the axis and raises `BoardError`), and on `fabric` and `axi_fabric` boards the
    /// Verilated top with its model on every clock (`BoardError` when they differed). A script
    /// that breaks a rule raises `PlanError`.
    fn play(&mut self, py: Python<'_>, script: &Bound<'_, PyAny>) -> PyResult<OnlineReport> {
        let script = if let Ok(text) = script.extract::<String>() {
            Script::from_toml(&text)
        } else {
            let json: String = py
                .import("json")?
                .call_method1("dumps", (script,))?
                .extract()?;
            Script::from_json(&json)
        }
        .map_err(|e| PlanError::new_err(e.to_string()))?;
        let (r, _, warnings) =
            online::play(&mut self.session, &script.events, &script.options(self.run)).map_err(
                |e| match e {
                    PlayError::Setup(f) => failure(f),
                    e => BoardError::new_err(e.to_string()),
                },
            )?;
        self.check_lockstep()?;
        let f = r.axis.settings.format;
        Ok(OnlineReport {
            commands: online::command_lines(&r, &script.events)
                .into_iter()
                .map(|c| CommandOutcome {
                    event: c.event,
                    at_ms: c.at_ms,
                    command: c.command,
                    outcome: c.outcome,
                    error_id: c.error_id,
                    error: c.error,
                    note: c.note,
                    due_tick: c.due_tick,
                    swap_tick: c.swap_tick,
                    latency_ms: c.latency_ms,
                })
                .collect(),
            overrides: online::override_lines(&r, &script.events)
                .into_iter()
                .map(|o| OverrideOutcome {
                    event: o.event,
                    at_ms: o.at_ms,
                    factor: o.factor,
                    error_id: o.error_id,
                    error: o.error,
                    due_tick: o.due_tick,
                    swap_tick: o.swap_tick,
                    latency_ms: o.latency_ms,
                })
                .collect(),
            replans: r.swaps.len(),
            extension_swaps: r.extensions,
            ticks: r.last.ticks - r.start_tick,
            end_registers: (r.last.x, r.last.v, r.last.a, r.last.j),
            end_lsb: f.output_lsb(r.last.x),
            target_lsb: online::target_lsb(&r),
            state_checks: r.checks,
            warnings,
        })
    }

    /// The board's tick period (s), read from it.
    #[getter]
    fn ts(&self) -> f64 {
        self.session.format.ts
    }

    /// The board's fabric clock (Hz), read from it.
    #[getter]
    fn clock_hz(&self) -> u32 {
        self.session.identity.clock_hz
    }

    /// The link's clock (s): a virtual board's own time, or the wall clock.
    #[getter]
    fn time(&self) -> f64 {
        use snapgen_host::link::Link;
        self.session.link.now()
    }

    /// The board's tick count and raw `(x, v, a, j)`: `(ticks, x, v, a, j)`.
    fn state(&mut self) -> PyResult<(u64, i128, i128, i128, i128)> {
        let s = self
            .session
            .state()
            .map_err(|e| BoardError::new_err(e.to_string()))?;
        Ok((s.ticks, s.x, s.v, s.a, s.j))
    }

    /// A controlled stop (STOP): the board brings the axis to rest within its stop limits.
    fn stop(&mut self) -> PyResult<()> {
        self.session
            .expect_ack(&Command::Stop)
            .map_err(|e| BoardError::new_err(e.to_string()))
    }

    /// Moves `distance` units from where the axis stands, as `snapgen send` does: planned
    /// with the board's Ts and format from its exact registers (the limits as in `plan`),
    /// the stop limits (`stop_decel`, `stop_jerk`; default: the move's peaks), the watchdog
    /// (ms) and the telemetry written and read back, uploaded, started, followed; the end
    /// checked bit for bit (raises `BoardError` otherwise). `stop_after` (s) sends a
    /// controlled stop that long after the start.
    #[pyo3(signature = (distance, *, max_velocity, max_acceleration, max_jerk=None, max_snap=None, stop_decel=None, stop_jerk=None, stop_after=None, watchdog_ms=1000, reset=false))]
    #[allow(clippy::too_many_arguments)]
    fn move_by(
        &mut self,
        py: Python<'_>,
        distance: f64,
        max_velocity: f64,
        max_acceleration: f64,
        max_jerk: Option<f64>,
        max_snap: Option<f64>,
        stop_decel: Option<f64>,
        stop_jerk: Option<f64>,
        stop_after: Option<f64>,
        watchdog_ms: u32,
        reset: bool,
    ) -> PyResult<MoveReport> {
        let method = crate::method(max_velocity, max_acceleration, max_jerk, max_snap)?;
        if let Some(t) = stop_after {
            if !(t.is_finite() && t >= 0.0) {
                return Err(PlanError::new_err(format!(
                    "stop_after = {t}: give the seconds after the start to send the stop (>= 0)"
                )));
            }
        }
        let opts = SendOptions {
            ts: None,
            stop_decel,
            stop_jerk,
            reset,
            watchdog_ms,
            servo: None,
            settle_lsb: 2,
            stop_after,
        };
        let request = MoveRequest { distance, method };
        let r = send_move(&mut self.session, &request, &opts, &mut NoProgress).map_err(failure)?;
        self.check_lockstep()?;
        Ok(MoveReport {
            trajectory: Py::new(py, Trajectory::from(r.plan))?,
            end_registers: (r.state.x, r.state.v, r.state.a, r.state.j),
            ticks: r.status.tick_count,
            stopped: r.stop.is_some(),
            warnings: r.warnings,
        })
    }
}
