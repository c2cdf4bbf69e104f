//! A board from Python: the device model or the Verilated I/O top as a virtual board (time is
//! the board's own clocks), or a real one on a serial port — behind the host's one link and
//! session, and moves run by the host's `send_move` (`snapgen send`): planned from the board's
//! exact registers with its Ts and format, uploaded, started, followed and checked bit for bit
//! where they end.

use pyo3::create_exception;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use snapgen_host::link::{FramedLink, RetryPolicy, Transport};
use snapgen_host::protocol::Command;
use snapgen_host::send::{send_move, NoProgress, SendOptions};
use snapgen_host::serial::SerialTransport;
use snapgen_host::session::{Failure, Session};
use snapgen_model::device::Design;
use snapgen_model::format::DEFAULT_FORMAT;
use snapgen_plan::MoveRequest;
use snapgen_sim::board::VirtualBoard;
use snapgen_sim::host_link::BoardTransport;

use crate::{PlanError, Trajectory};

create_exception!(
    snapgen,
    BoardError,
    PyRuntimeError,
    "The link or the board failed: no reply, a refusal (NAK), an axis error, a move that did not end where it was planned; the message says which and what to check."
);

type AnySession = Session<FramedLink<Box<dyn Transport>>>;

/// The host's failure as a Python exception: the user's input a `PlanError`, the link's or
/// the board's a `BoardError`.
fn failure(f: Failure) -> PyErr {
    match f {
        Failure::Input(e) => PlanError::new_err(e.to_string()),
        Failure::Host(e) => BoardError::new_err(e.to_string()),
    }
}

/// A board and the host's session with it.
#[pyclass(module = "snapgen", unsendable)]
pub struct Board {
    session: AnySession,
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

fn open(transport: Box<dyn Transport>, lsb: f64) -> PyResult<Board> {
    if !(lsb.is_finite() && lsb > 0.0) {
        return Err(PlanError::new_err(format!(
            "lsb = {lsb}: give the size of one output position LSB in units (> 0)"
        )));
    }
    let link = FramedLink::new(transport, RetryPolicy::default(), 0);
    let session = Session::open(link, lsb).map_err(failure)?;
    Ok(Board { session })
}

/// A virtual board's design: the default clock and Ts at `baud`.
fn design(baud: u32) -> PyResult<Design> {
    snapgen_sim::board::virtual_design(baud)
        .map_err(|e| PlanError::new_err(format!("a board at {baud} baud: {e}")))
}

#[pymethods]
impl Board {
    /// A virtual board running the device model (the clock-accurate twin of the I/O top) at
    /// the default clock and Ts, its UART at `baud`; time passes in its clocks.
    #[staticmethod]
    #[pyo3(signature = (*, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn model(baud: u32, lsb: f64) -> PyResult<Board> {
        let board = VirtualBoard::model(&design(baud)?);
        open(Box::new(BoardTransport::new(board)), lsb)
    }

    /// A virtual board running the Verilated I/O top (needs Verilator and a C++ compiler; the
    /// build is cached).
    #[staticmethod]
    #[pyo3(signature = (*, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn fabric(baud: u32, lsb: f64) -> PyResult<Board> {
        let board = VirtualBoard::fabric(&design(baud)?)
            .map_err(|e| BoardError::new_err(format!("cannot build the Verilated I/O top: {e}")))?;
        open(Box::new(BoardTransport::new(board)), lsb)
    }

    /// A real board on serial port `port` at `baud` (its UART's rate).
    #[staticmethod]
    #[pyo3(signature = (port, *, baud=115_200, lsb=DEFAULT_FORMAT.position_lsb))]
    fn serial(port: &str, baud: u32, lsb: f64) -> PyResult<Board> {
        let t =
            SerialTransport::open(port, baud).map_err(|e| BoardError::new_err(e.to_string()))?;
        open(Box::new(t), lsb)
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
        Ok(MoveReport {
            trajectory: Py::new(py, Trajectory::from(r.plan))?,
            end_registers: (r.state.x, r.state.v, r.state.a, r.state.j),
            ticks: r.status.tick_count,
            stopped: r.stop.is_some(),
            warnings: r.warnings,
        })
    }
}
