//! `snapgen` for Python: the host's rest-to-rest planners (seed 000's order 4, orders 3 and 2,
//! seed 001's duration method) and its online planner (seed 002: from any exact chain state to
//! a position or a velocity, orders 3 and 2), with the exact program the fabric plays, its
//! per-tick registers as Python integers, and the trajectory sampled at times (one time, or a
//! NumPy array of them) in physical units. Names follow Ruckig's where the concepts match (`max_velocity`,
//! `duration`, `at_time`, `at_times`); a move that cannot be planned raises
//! `snapgen.PlanError` (a `ValueError`) with the planner's own message. [`board`]: a board
//! (virtual or on a serial port) behind the host's session, moves run as `snapgen send` runs
//! them; its failures raise `snapgen.BoardError` (a `RuntimeError`).
//!
//! Time: the fabric's output changes once per tick and holds between ticks, so the state at
//! time `t` is the state after the last tick `k` with `k · ts <= t`, clamped to the move
//! (`t < 0` gives the start, `t` from `duration` on the final state at rest).

mod board;

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use snapgen_model::chain::ChainState;
use snapgen_model::format::{Format, Quantity, DEFAULT_FORMAT, FRAC_BITS};
use snapgen_model::peaks::Peaks;
use snapgen_model::program::Program;
use snapgen_plan::online::{plan_online, OnlineLimits, OnlineOrder, OnlineTarget};
use snapgen_plan::{Method, MoveRequest};

create_exception!(
    snapgen,
    PlanError,
    PyValueError,
    "A move that cannot be planned (an input not finite or not positive, a ratio out of range, a move the format cannot hold); the message says what to change."
);

/// A planned move: the program the fabric plays from its start state and the trajectory it
/// makes.
#[pyclass(module = "snapgen", frozen)]
pub struct Trajectory {
    format: Format,
    start: ChainState,
    program: Program,
    order: u8,
    /// Exact peaks of every register over the program.
    peaks: Peaks,
}

/// A rest-to-rest plan as a trajectory (its exact peaks taken with it).
impl From<snapgen_plan::Plan> for Trajectory {
    fn from(p: snapgen_plan::Plan) -> Self {
        Trajectory {
            format: p.format,
            start: p.start,
            order: p.order(),
            peaks: p.peaks,
            program: p.program,
        }
    }
}

impl Trajectory {
    pub(crate) fn new(format: Format, start: ChainState, program: Program, order: u8) -> Self {
        let (peaks, _) = snapgen_model::peaks::peaks(&program, &start);
        Trajectory {
            format,
            start,
            program,
            order,
            peaks,
        }
    }
}

/// The format for a tick period and an output LSB, both checked.
fn format(ts: f64, lsb: f64) -> PyResult<Format> {
    for (name, v) in [("ts", ts), ("lsb", lsb)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(PlanError::new_err(format!(
                "{name} = {v}: give a positive, finite value (seconds for ts, units for lsb)"
            )));
        }
    }
    Ok(Format {
        ts,
        position_lsb: lsb,
        ..DEFAULT_FORMAT
    })
}

fn planned(request: MoveRequest, f: &Format) -> PyResult<Trajectory> {
    snapgen_plan::plan(&request, f)
        .map(Trajectory::from)
        .map_err(|e| PlanError::new_err(e.to_string()))
}

/// Plans a rest-to-rest move of `distance` units within the limits (units/s, units/s², …).
///
/// The order follows the limits given: `max_snap` (with the others) gives seed 000's order 4,
/// `max_jerk` order 3, `max_velocity` and `max_acceleration` alone order 2. `ts` is the tick
/// period (s) and `lsb` the size of one output position LSB (units), as on the board.
#[pyfunction]
#[pyo3(signature = (distance, *, max_velocity, max_acceleration, max_jerk=None, max_snap=None, ts=DEFAULT_FORMAT.ts, lsb=DEFAULT_FORMAT.position_lsb))]
fn plan(
    distance: f64,
    max_velocity: f64,
    max_acceleration: f64,
    max_jerk: Option<f64>,
    max_snap: Option<f64>,
    ts: f64,
    lsb: f64,
) -> PyResult<Trajectory> {
    let method = method(max_velocity, max_acceleration, max_jerk, max_snap)?;
    planned(MoveRequest { distance, method }, &format(ts, lsb)?)
}

/// The method the limits given select: order 4 with `max_snap` (and `max_jerk`), 3 with
/// `max_jerk`, else 2.
fn method(
    max_velocity: f64,
    max_acceleration: f64,
    max_jerk: Option<f64>,
    max_snap: Option<f64>,
) -> PyResult<Method> {
    Ok(match (max_jerk, max_snap) {
        (Some(jmax), Some(dmax)) => Method::Order4 {
            vmax: max_velocity,
            amax: max_acceleration,
            jmax,
            dmax,
        },
        (Some(jmax), None) => Method::Order3 {
            vmax: max_velocity,
            amax: max_acceleration,
            jmax,
        },
        (None, None) => Method::Order2 {
            vmax: max_velocity,
            amax: max_acceleration,
        },
        (None, Some(_)) => return Err(PlanError::new_err(
            "max_snap without max_jerk: an order-4 move needs both (or drop max_snap for order 2)",
        )),
    })
}

/// Plans seed 001's duration-based S-curve: `distance` units in `duration` seconds, the
/// acceleration phases `gamma · duration`, their jerk phases `phi` of those (both in (0, 0.5]).
#[pyfunction]
#[pyo3(signature = (distance, *, duration, gamma, phi, ts=DEFAULT_FORMAT.ts, lsb=DEFAULT_FORMAT.position_lsb))]
fn plan_duration(
    distance: f64,
    duration: f64,
    gamma: f64,
    phi: f64,
    ts: f64,
    lsb: f64,
) -> PyResult<Trajectory> {
    let method = Method::Duration {
        duration,
        gamma,
        phi,
    };
    planned(MoveRequest { distance, method }, &format(ts, lsb)?)
}

/// Plans online from any exact chain state (seed 002; PLCopen MC_MoveAbsolute and
/// MC_MoveVelocity): from `registers`, the raw `(x, v, a, j)` a trajectory's `registers_at`
/// gives, to rest at `target_position` (absolute units: cell `round(target_position / lsb)`),
/// passing it at `target_velocity` (units/s) when that is not 0 — or, without a
/// `target_position`, to holding `target_velocity`. Order 3 with `max_jerk`, else 2;
/// `max_acceleration` applies while |v| grows, `max_deceleration` (default: the acceleration)
/// while it shrinks. The end is exact: at rest in the target's cell, or at the target
/// velocity's raw value with a = j = 0.
#[pyfunction]
#[pyo3(signature = (registers, *, max_velocity, max_acceleration, max_deceleration=None, max_jerk=None, target_position=None, target_velocity=0.0, ts=DEFAULT_FORMAT.ts, lsb=DEFAULT_FORMAT.position_lsb))]
#[allow(clippy::too_many_arguments)]
fn replan(
    registers: (i128, i128, i128, i128),
    max_velocity: f64,
    max_acceleration: f64,
    max_deceleration: Option<f64>,
    max_jerk: Option<f64>,
    target_position: Option<f64>,
    target_velocity: f64,
    ts: f64,
    lsb: f64,
) -> PyResult<Trajectory> {
    let f = format(ts, lsb)?;
    let (x, v, a, j) = registers;
    let start = ChainState { x, v, a, j };
    // Registers the board can hold: each within its width (what registers_at gives).
    let w = f.widths;
    for (name, value, bits) in [("x", x, w.x), ("v", v, w.v), ("a", a, w.a), ("j", j, w.j)] {
        if snapgen_model::chain::wrap(value, bits) != value {
            return Err(PlanError::new_err(format!(
                "registers: {name} = {value} does not fit the board's {bits}-bit register: give the raw registers a trajectory's registers_at or a board's state returns"
            )));
        }
    }
    let target = match target_position {
        Some(p) if !p.is_finite() => {
            return Err(PlanError::new_err(format!(
                "target_position = {p}: give a finite position (units)"
            )))
        }
        Some(p) => OnlineTarget::Position {
            cell: snapgen_plan::planner::fmath::round(p / lsb) as i128,
            velocity: target_velocity,
        },
        None => OnlineTarget::Velocity(target_velocity),
    };
    let (order, jerk) = match max_jerk {
        Some(j) => (OnlineOrder::Three, j),
        None => (OnlineOrder::Two, f64::INFINITY),
    };
    let limits = OnlineLimits {
        velocity: max_velocity,
        acceleration: max_acceleration,
        deceleration: max_deceleration.unwrap_or(max_acceleration),
        jerk,
    };
    let p = plan_online(&start, &target, &limits, order, &f)
        .map_err(|e| PlanError::new_err(e.to_string()))?;
    Ok(Trajectory::new(f, p.start, p.program, order.number()))
}

impl Trajectory {
    /// The tick a time falls in, clamped to the move: the last `k` with `k · ts <= t` (the
    /// product in floating point, as `duration` is computed, so `at_time(duration)` is the
    /// end; `t / ts` alone can round below a whole number of ticks).
    fn tick_at(&self, t: f64) -> PyResult<u64> {
        if t.is_nan() {
            return Err(PyValueError::new_err("t is NaN: give a time in seconds"));
        }
        let ticks = self.program.total_ticks();
        let ts = self.format.ts;
        if t <= 0.0 {
            return Ok(0);
        }
        if t >= ticks as f64 * ts {
            return Ok(ticks);
        }
        let mut k = (t / ts).floor().clamp(0.0, ticks as f64) as u64;
        while k < ticks && (k + 1) as f64 * ts <= t {
            k += 1;
        }
        while k > 0 && k as f64 * ts > t {
            k -= 1;
        }
        Ok(k)
    }

    fn state_after(&self, k: u64) -> ChainState {
        self.start
            .after_ticks(&self.program, k, &self.format.widths)
    }

    /// Position (from the start), velocity, acceleration and jerk, physical.
    fn physical(&self, s: &ChainState) -> (f64, f64, f64, f64) {
        let f = &self.format;
        (
            f.position_physical(s.x) - f.position_physical(self.start.x),
            f.to_physical(Quantity::Velocity, s.v),
            f.to_physical(Quantity::Acceleration, s.a),
            f.to_physical(Quantity::Jerk, s.j),
        )
    }
}

#[pymethods]
impl Trajectory {
    /// The move's duration in seconds (its ticks times ts).
    #[getter]
    fn duration(&self) -> f64 {
        self.program.total_ticks() as f64 * self.format.ts
    }

    /// The move's length in ticks.
    #[getter]
    fn ticks(&self) -> u64 {
        self.program.total_ticks()
    }

    /// The tick period (s).
    #[getter]
    fn ts(&self) -> f64 {
        self.format.ts
    }

    /// The profile's order: 4 (snap-limited), 3 (jerk-limited) or 2 (acceleration-limited).
    #[getter]
    fn order(&self) -> u8 {
        self.order
    }

    /// Where the move ends, in units from its start (a rest-to-rest move: the asked distance
    /// on the output LSB grid).
    #[getter]
    fn target_position(&self) -> f64 {
        let end = self.state_after(self.program.total_ticks());
        self.physical(&end).0
    }

    /// Where the move starts, in absolute units (from the centre of output cell 0): add it to
    /// `at_time`'s positions for absolute ones.
    #[getter]
    fn start_position(&self) -> f64 {
        self.format.position_physical(self.start.x)
    }

    /// The program the fabric plays: `(ticks, snap)` per segment, the snap as the raw integer
    /// fed to the chain on each of those ticks.
    #[getter]
    fn program(&self) -> Vec<(u32, i128)> {
        self.program
            .segments
            .iter()
            .map(|s| (s.ticks, s.snap))
            .collect()
    }

    /// The chain's registers `(x, v, a, j)` before the move, raw (exact integers).
    #[getter]
    fn start_registers(&self) -> (i128, i128, i128, i128) {
        let s = self.start;
        (s.x, s.v, s.a, s.j)
    }

    /// The chain's registers `(x, v, a, j)` after `tick` ticks, raw (exact integers, as the
    /// fabric holds them); past the end, the final state.
    fn registers_at(&self, tick: u64) -> (i128, i128, i128, i128) {
        let s = self.state_after(tick.min(self.program.total_ticks()));
        (s.x, s.v, s.a, s.j)
    }

    /// The raw register's value per physical unit for `quantity` ("position" per unit,
    /// "velocity" per unit/s, … "snap" per unit/s⁴): raw / scale is the physical value.
    fn scale(&self, quantity: &str) -> PyResult<f64> {
        let q = match quantity {
            "position" => Quantity::Position,
            "velocity" => Quantity::Velocity,
            "acceleration" => Quantity::Acceleration,
            "jerk" => Quantity::Jerk,
            "snap" => Quantity::Snap,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "quantity {quantity:?}: use position, velocity, acceleration, jerk or snap"
                )))
            }
        };
        Ok(self.format.scale(q))
    }

    /// Position (units from the start), velocity, acceleration and jerk at time `t` (s): the
    /// state after the last tick `k` with `k · ts <= t`, clamped to the move (NaN: an error).
    fn at_time(&self, t: f64) -> PyResult<(f64, f64, f64, f64)> {
        Ok(self.physical(&self.state_after(self.tick_at(t)?)))
    }

    /// [`at_time`] for every time of a NumPy array: four arrays (position, velocity,
    /// acceleration, jerk) of its length.
    #[allow(clippy::type_complexity)]
    fn at_times<'py>(
        &self,
        py: Python<'py>,
        times: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let times = times.as_array();
        let n = times.len();
        let (mut p, mut v, mut a, mut j) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for &t in times.iter() {
            let s = self.physical(&self.state_after(self.tick_at(t)?));
            p.push(s.0);
            v.push(s.1);
            a.push(s.2);
            j.push(s.3);
        }
        Ok((
            PyArray1::from_vec(py, p),
            PyArray1::from_vec(py, v),
            PyArray1::from_vec(py, a),
            PyArray1::from_vec(py, j),
        ))
    }

    /// The largest magnitude of each quantity over the move, physical: a dict with
    /// "velocity", "acceleration", "jerk" and "snap" (exact: from the integer chain).
    fn peaks(&self) -> std::collections::BTreeMap<&'static str, f64> {
        [
            ("velocity", Quantity::Velocity),
            ("acceleration", Quantity::Acceleration),
            ("jerk", Quantity::Jerk),
            ("snap", Quantity::Snap),
        ]
        .into_iter()
        .map(|(name, q)| {
            let raw = match q {
                Quantity::Velocity => self.peaks.v,
                Quantity::Acceleration => self.peaks.a,
                Quantity::Jerk => self.peaks.j,
                _ => self.peaks.d,
            };
            (name, raw.as_f64() / self.format.scale(q))
        })
        .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Trajectory(order={}, duration={:.6} s, ticks={}, target_position={})",
            self.order,
            self.duration(),
            self.ticks(),
            self.target_position()
        )
    }
}

/// The module.
#[pymodule]
fn snapgen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Trajectory>()?;
    m.add_class::<board::Board>()?;
    m.add_class::<board::MoveReport>()?;
    m.add_class::<board::OnlineReport>()?;
    m.add_class::<board::CommandOutcome>()?;
    m.add_class::<board::OverrideOutcome>()?;
    m.add("BoardError", m.py().get_type::<board::BoardError>())?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan_duration, m)?)?;
    m.add_function(wrap_pyfunction!(replan, m)?)?;
    m.add("PlanError", m.py().get_type::<PlanError>())?;
    m.add("DEFAULT_TS", DEFAULT_FORMAT.ts)?;
    m.add("DEFAULT_LSB", DEFAULT_FORMAT.position_lsb)?;
    m.add("FRAC_BITS", FRAC_BITS)?;
    Ok(())
}
