//! `snapgen` for Python: the host's rest-to-rest planners (seed 000's order 4, orders 3 and 2,
//! seed 001's duration method) with the exact program the fabric plays, its per-tick registers
//! as Python integers, and the trajectory sampled at times (one time, or a NumPy array of them)
//! in physical units. Names follow Ruckig's where the concepts match (`max_velocity`,
//! `duration`, `at_time`, `at_times`); a move that cannot be planned raises
//! `snapgen.PlanError` (a `ValueError`) with the planner's own message. No I/O: boards are
//! driven by the `snapgen` command-line tool.
//!
//! Time: the fabric's output changes once per tick and holds between ticks, so the state at
//! time `t` is the state after `floor(t / ts)` ticks, clamped to the move (`t < 0` gives the
//! start, `t` past the end the final state at rest).

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use snapgen_model::chain::ChainState;
use snapgen_model::format::{Format, Quantity, DEFAULT_FORMAT};
use snapgen_plan::{Method, MoveRequest, Plan};

create_exception!(
    snapgen,
    PlanError,
    PyValueError,
    "A move that cannot be planned (an input not finite or not positive, a ratio out of range, a move the format cannot hold); the message says what to change."
);

/// A planned move: the program the fabric plays and the trajectory it makes.
#[pyclass(module = "snapgen", frozen)]
struct Trajectory {
    plan: Plan,
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
        .map(|plan| Trajectory { plan })
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
    let method = match (max_jerk, max_snap) {
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
    };
    planned(MoveRequest { distance, method }, &format(ts, lsb)?)
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

impl Trajectory {
    /// The tick a time falls in, clamped to the move.
    fn tick_at(&self, t: f64) -> u64 {
        let ticks = self.plan.ticks_total();
        if t.is_nan() || t <= 0.0 {
            return 0;
        }
        let k = (t / self.plan.format.ts).floor();
        if k >= ticks as f64 {
            ticks
        } else {
            k as u64
        }
    }

    fn state_after(&self, k: u64) -> ChainState {
        self.plan
            .start
            .after_ticks(&self.plan.program, k, &self.plan.format.widths)
    }

    /// Position (from the start), velocity, acceleration and jerk, physical.
    fn physical(&self, s: &ChainState) -> (f64, f64, f64, f64) {
        let f = &self.plan.format;
        (
            f.position_physical(s.x) - f.position_physical(self.plan.start.x),
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
        self.plan.duration_s()
    }

    /// The move's length in ticks.
    #[getter]
    fn ticks(&self) -> u64 {
        self.plan.ticks_total()
    }

    /// The tick period (s).
    #[getter]
    fn ts(&self) -> f64 {
        self.plan.format.ts
    }

    /// The profile's order: 4 (snap-limited), 3 (jerk-limited) or 2 (acceleration-limited).
    #[getter]
    fn order(&self) -> u8 {
        self.plan.order()
    }

    /// The distance the move ends at, in units: the asked one on the output LSB grid.
    #[getter]
    fn target_position(&self) -> f64 {
        self.plan.target_physical()
    }

    /// The program the fabric plays: `(ticks, snap)` per segment, the snap as the raw integer
    /// fed to the chain on each of those ticks.
    #[getter]
    fn program(&self) -> Vec<(u32, i128)> {
        self.plan
            .program
            .segments
            .iter()
            .map(|s| (s.ticks, s.snap))
            .collect()
    }

    /// The chain's registers `(x, v, a, j)` before the move, raw (exact integers).
    #[getter]
    fn start_registers(&self) -> (i128, i128, i128, i128) {
        let s = self.plan.start;
        (s.x, s.v, s.a, s.j)
    }

    /// The chain's registers `(x, v, a, j)` after `tick` ticks, raw (exact integers, as the
    /// fabric holds them); past the end, the final state.
    fn registers_at(&self, tick: u64) -> (i128, i128, i128, i128) {
        let s = self.state_after(tick.min(self.plan.ticks_total()));
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
        Ok(self.plan.format.scale(q))
    }

    /// Position (units from the start), velocity, acceleration and jerk at time `t` (s): the
    /// state after `floor(t / ts)` ticks, clamped to the move.
    fn at_time(&self, t: f64) -> (f64, f64, f64, f64) {
        self.physical(&self.state_after(self.tick_at(t)))
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
            let s = self.physical(&self.state_after(self.tick_at(t)));
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
        .map(|(name, q)| (name, self.plan.peak_physical(q)))
        .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Trajectory(order={}, duration={:.6} s, ticks={}, target_position={})",
            self.plan.order(),
            self.plan.duration_s(),
            self.plan.ticks_total(),
            self.plan.target_physical()
        )
    }
}

/// The module.
#[pymodule]
fn snapgen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Trajectory>()?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan_duration, m)?)?;
    m.add("PlanError", m.py().get_type::<PlanError>())?;
    m.add("DEFAULT_TS", DEFAULT_FORMAT.ts)?;
    m.add("DEFAULT_LSB", DEFAULT_FORMAT.position_lsb)?;
    Ok(())
}
