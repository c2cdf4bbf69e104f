//! Host-side planners: from a move request to a checked integer [`Program`].
//!
//! Planning is two steps, kept apart:
//! 1. a *continuous* planner (pure `f64`, in tick units) picks the phase times, rounding each up
//!    to a whole tick and recomputing the amplitude after every rounding — seed 000 for order 4
//!    ([`order4`]), the same procedure one and two orders lower ([`order3`], [`order2`]), or seed
//!    001's duration-based method ([`duration`]);
//! 2. the quantizer ([`quantize`]) picks the integer amplitude on the discrete chain so that the
//!    output position lands exactly on the target and every limit holds on the integer trace.

pub mod duration;
pub mod order2;
pub mod order3;
pub mod order4;
pub mod quantize;

use ethnum::I256;
use serde::{Deserialize, Serialize};

use crate::chain::ChainState;
use crate::error::PlanError;
use crate::format::{Format, Quantity, FRAC_BITS};
use crate::peaks::{peaks, Peaks};
use crate::program::Program;
pub use duration::{DurationInput, DurationValues};
use quantize::{div_ceil, unit_response, unit_ticks, Shape};

/// Phase times in ticks. Order 4: `d` = t_d, `j` = t_j, `a` = t_a, `v` = t_v (seed 000);
/// order 3: `j`, `a`, `v` (jerk, constant acceleration, cruise; `d` = 0); order 2: `a`, `v`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PhaseTicks {
    /// Snap phase t_d.
    pub d: u64,
    /// Jerk phase t_j.
    pub j: u64,
    /// Acceleration phase t_a.
    pub a: u64,
    /// Cruise t_v.
    pub v: u64,
}

/// What a continuous planner returns: rounded phase times and the amplitude recomputed from
/// them (tick units: snap·Ts⁴, jerk·Ts³ or acceleration·Ts²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuousProfile {
    /// Phase times.
    pub phases: PhaseTicks,
    /// Amplitude in tick units.
    pub amplitude: f64,
}

/// Rounds a time in ticks up to a whole tick (seed 000 eq 3). A tolerance of 1e-6 tick absorbs
/// floating-point noise, so a phase computed as 3.0000000002 ticks is 3 ticks, not 4; negative
/// or NaN times are 0.
pub fn ceil_ticks(t: f64) -> u64 {
    if t.is_nan() || t <= 1e-6 {
        0
    } else if t >= 1e18 {
        u64::MAX / 4
    } else {
        (t - 1e-6).ceil() as u64
    }
}

/// [`ceil_ticks`], at least one tick.
pub fn ceil_ticks_min1(t: f64) -> u64 {
    ceil_ticks(t).max(1)
}

/// How a move is planned.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Method {
    /// Seed 000: snap-limited, order 4.
    Order4 {
        /// Velocity limit (unit/s).
        vmax: f64,
        /// Acceleration limit (unit/s²).
        amax: f64,
        /// Jerk limit (unit/s³).
        jmax: f64,
        /// Snap limit (unit/s⁴).
        dmax: f64,
    },
    /// Jerk-limited seven-segment S-curve, order 3.
    Order3 {
        /// Velocity limit.
        vmax: f64,
        /// Acceleration limit.
        amax: f64,
        /// Jerk limit.
        jmax: f64,
    },
    /// Acceleration-limited trapezoid, order 2.
    Order2 {
        /// Velocity limit.
        vmax: f64,
        /// Acceleration limit.
        amax: f64,
    },
    /// Seed 001: duration-based S-curve.
    Duration {
        /// Duration T (s).
        duration: f64,
        /// γ ∈ (0, 0.5].
        gamma: f64,
        /// φ ∈ (0, 0.5].
        phi: f64,
    },
}

impl Method {
    /// The profile order (highest limited derivative).
    pub fn order(&self) -> u8 {
        match self {
            Method::Order4 { .. } => 4,
            Method::Order3 { .. } | Method::Duration { .. } => 3,
            Method::Order2 { .. } => 2,
        }
    }

    /// The requested limits as `(quantity, flag name, value)`.
    fn limits(&self) -> Limits {
        let mut l = Limits::default();
        match *self {
            Method::Order4 {
                vmax,
                amax,
                jmax,
                dmax,
            } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
                l.push(Quantity::Jerk, "jmax", jmax);
                l.push(Quantity::Snap, "dmax", dmax);
            }
            Method::Order3 { vmax, amax, jmax } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
                l.push(Quantity::Jerk, "jmax", jmax);
            }
            Method::Order2 { vmax, amax } => {
                l.push(Quantity::Velocity, "vmax", vmax);
                l.push(Quantity::Acceleration, "amax", amax);
            }
            Method::Duration { .. } => {}
        }
        l
    }

    fn shape(&self) -> Shape {
        match self.order() {
            4 => Shape::Snap4,
            3 => Shape::Jerk3,
            _ => Shape::Accel2,
        }
    }
}

/// Up to four requested limits, on the stack.
#[derive(Clone, Copy, Default)]
struct Limits {
    items: [(Quantity, &'static str, f64); 4],
    len: usize,
}

impl Limits {
    fn push(&mut self, q: Quantity, name: &'static str, value: f64) {
        self.items[self.len] = (q, name, value);
        self.len += 1;
    }

    fn iter(&self) -> impl Iterator<Item = (Quantity, &'static str, f64)> + '_ {
        self.items[..self.len].iter().copied()
    }
}

/// A point-to-point move: a signed distance and how to plan it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MoveRequest {
    /// Signed distance (units).
    pub distance: f64,
    /// Planning method and its limits.
    pub method: Method,
}

/// A planned, checked move.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Format the program is for.
    pub format: Format,
    /// What was asked.
    pub request: MoveRequest,
    /// Phase times in ticks, including any cruise extension.
    pub phases: PhaseTicks,
    /// Cruise ticks the quantizer added so that the integer trace respects the limits.
    pub cruise_extension: u64,
    /// Amplitude from the continuous planner after its last recomputation (physical: unit/s⁴,
    /// unit/s³ or unit/s² for orders 4, 3, 2; signed by direction).
    pub continuous_amplitude: f64,
    /// The integer amplitude in the program (signed by direction).
    pub amplitude_raw: i128,
    /// Target, in whole output LSBs relative to the start cell.
    pub target_lsb: i128,
    /// Chain state before the move.
    pub start: ChainState,
    /// Chain state after the move (exact, from the closed form).
    pub final_state: ChainState,
    /// Exact peaks of every register over the move.
    pub peaks: Peaks,
    /// The program for the fabric.
    pub program: Program,
    /// Seed 001 values (duration method only).
    pub duration_values: Option<DurationValues>,
    /// Index of the cruise segment (constant velocity, jerk and acceleration zero), if the
    /// move has one: a controlled stop ends it early and decelerates as planned.
    pub cruise_segment: Option<usize>,
}

impl Plan {
    /// Profile order.
    pub fn order(&self) -> u8 {
        self.request.method.order()
    }

    /// Ticks the program lasts.
    pub fn ticks_total(&self) -> u64 {
        self.program.total_ticks()
    }

    /// Where the move stands when the sequencer finishes after `played` ticks: the planned end,
    /// or — after a controlled stop, which cuts the cruise short (the fabric always plays at
    /// least one cruise tick) — the same program with that many fewer cruise ticks.
    pub fn end_after(&self, played: u64) -> ChainState {
        let total = self.ticks_total();
        match self.cruise_segment {
            Some(c) if played < total => {
                let mut p = self.program.clone();
                let cut = (total - played).min(u64::from(p.segments[c].ticks) - 1);
                p.segments[c].ticks -= cut as u32;
                self.start.run_program(&p, &self.format.widths)
            }
            _ => self.final_state,
        }
    }

    /// Duration in seconds.
    pub fn duration_s(&self) -> f64 {
        self.ticks_total() as f64 * self.format.ts
    }

    /// Raw position of the centre of the target cell.
    pub fn target_raw(&self) -> i128 {
        let cell = self.format.output_lsb(self.start.x) + self.target_lsb;
        (cell << FRAC_BITS) + self.format.half_lsb_raw()
    }

    /// Final position register minus the centre of the target cell (internal LSBs);
    /// its magnitude is below half an output LSB.
    pub fn residual_raw(&self) -> i128 {
        self.final_state.x - self.target_raw()
    }

    /// Output LSBs between the final output position and the target cell (0 for every
    /// accepted plan).
    pub fn final_error_lsb(&self) -> i128 {
        self.format.output_lsb(self.final_state.x)
            - self.format.output_lsb(self.start.x)
            - self.target_lsb
    }

    /// Physical target: the requested distance rounded to whole output LSBs.
    pub fn target_physical(&self) -> f64 {
        self.target_lsb as f64 * self.format.position_lsb
    }

    /// Final output position minus the requested distance (physical). At most half an output
    /// LSB: the rounding of the request to the output grid.
    pub fn final_position_error(&self) -> f64 {
        (self.target_lsb + self.final_error_lsb()) as f64 * self.format.position_lsb
            - self.request.distance
    }

    /// Peak magnitude of `q` over the move, physical.
    pub fn peak_physical(&self, q: Quantity) -> f64 {
        let raw = match q {
            Quantity::Position => self.peaks.x,
            Quantity::Velocity => self.peaks.v,
            Quantity::Acceleration => self.peaks.a,
            Quantity::Jerk => self.peaks.j,
            Quantity::Snap => self.peaks.d,
        };
        raw.as_f64() / self.format.scale(q)
    }

    /// Final value of `q`, physical (position relative to the start cell's centre).
    pub fn final_physical(&self, q: Quantity) -> f64 {
        let f = &self.format;
        match q {
            Quantity::Position => {
                f.position_physical(self.final_state.x) - f.position_physical(self.start.x)
            }
            Quantity::Velocity => f.to_physical(q, self.final_state.v),
            Quantity::Acceleration => f.to_physical(q, self.final_state.a),
            Quantity::Jerk => f.to_physical(q, self.final_state.j),
            Quantity::Snap => 0.0,
        }
    }
}

fn finite(name: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PlanError::NotFinite { name, value })
    }
}

fn positive(name: &'static str, value: f64) -> Result<f64, PlanError> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::NotPositive { name, value })
    }
}

fn ratio(name: &'static str, value: f64) -> Result<f64, PlanError> {
    finite(name, value)?;
    if value > 0.0 && value <= 0.5 {
        Ok(value)
    } else {
        Err(PlanError::OutOfRange {
            name,
            value,
            min: 0.0,
            max: 0.5,
        })
    }
}

/// Checks every input of a request; returns it unchanged.
pub fn validate(request: &MoveRequest, format: &Format) -> Result<(), PlanError> {
    format.validate()?;
    finite("distance", request.distance)?;
    match request.method {
        Method::Duration {
            duration,
            gamma,
            phi,
        } => {
            positive("duration", duration)?;
            ratio("gamma", gamma)?;
            ratio("phi", phi)?;
        }
        m => {
            for (_, name, value) in m.limits().iter() {
                positive(name, value)?;
            }
        }
    }
    Ok(())
}

/// Plans a move from rest at the centre of output cell 0 (the chain's reset state).
pub fn plan(request: &MoveRequest, format: &Format) -> Result<Plan, PlanError> {
    plan_from(request, format, ChainState::at_rest(format.home_raw()))
}

/// Plans a move from `start`, which must be at rest (v = a = j = 0). The target is the centre
/// of the output cell `distance` away from the start's cell, so a residual left by an earlier
/// move never accumulates.
pub fn plan_from(
    request: &MoveRequest,
    format: &Format,
    start: ChainState,
) -> Result<Plan, PlanError> {
    validate(request, format)?;
    let f = *format;
    let m = request.method;
    // Position range: output cells representable by the position register, with one cell of
    // headroom on each side.
    let cells = (1i128 << (f.widths.x - FRAC_BITS - 1)) - 1;
    let max_distance = f.max_distance();
    let target_f = (request.distance / f.position_lsb).round();
    let start_cell = f.output_lsb(start.x);
    if target_f.abs() > (cells - 1) as f64 || (start_cell + target_f as i128).abs() > cells - 1 {
        return Err(PlanError::DistanceOutOfRange {
            distance: request.distance,
            max: max_distance,
        });
    }
    let target_lsb = target_f as i128;
    let mut plan = Plan {
        format: f,
        request: *request,
        phases: PhaseTicks::default(),
        cruise_extension: 0,
        continuous_amplitude: 0.0,
        amplitude_raw: 0,
        target_lsb,
        start,
        final_state: start,
        peaks: Peaks::default(),
        program: Program::empty(),
        duration_values: None,
        cruise_segment: None,
    };
    if let Method::Duration {
        duration,
        gamma,
        phi,
    } = m
    {
        plan.duration_values = Some(duration::values(&DurationInput {
            distance: request.distance,
            duration,
            gamma,
            phi,
        }));
    }
    // Distance from the start register to the centre of the target cell.
    let x_total = I256::from(plan.target_raw()) - I256::from(start.x);
    if x_total == 0 {
        let (pk, _) = peaks(&plan.program, &start);
        plan.peaks = pk;
        return Ok(plan);
    }
    let sign: i128 = if x_total < 0 { -1 } else { 1 };
    let x_abs = x_total.abs();
    // The continuous planner works on the distance the integer plan actually covers.
    let dist = x_abs.as_f64() * f.internal_lsb();
    let ts = f.ts;
    let cont = match m {
        Method::Order4 {
            vmax,
            amax,
            jmax,
            dmax,
        } => order4::plan(&order4::TickLimits4 {
            x: dist,
            v: vmax * ts,
            a: amax * ts.powi(2),
            j: jmax * ts.powi(3),
            d: dmax * ts.powi(4),
        }),
        Method::Order3 { vmax, amax, jmax } => order3::plan(&order3::TickLimits3 {
            x: dist,
            v: vmax * ts,
            a: amax * ts.powi(2),
            j: jmax * ts.powi(3),
        }),
        Method::Order2 { vmax, amax } => order2::plan(&order2::TickLimits2 {
            x: dist,
            v: vmax * ts,
            a: amax * ts.powi(2),
        }),
        Method::Duration {
            duration,
            gamma,
            phi,
        } => duration::plan(
            &DurationInput {
                distance: dist,
                duration,
                gamma,
                phi,
            },
            ts,
        )?,
    };
    let amp_q = match m.order() {
        4 => Quantity::Snap,
        3 => Quantity::Jerk,
        _ => Quantity::Acceleration,
    };
    plan.continuous_amplitude = sign as f64 * cont.amplitude / ts.powi(amp_q_power(amp_q));
    quantize_into(&mut plan, cont.phases, sign, x_abs)?;
    Ok(plan)
}

fn amp_q_power(q: Quantity) -> i32 {
    match q {
        Quantity::Snap => 4,
        Quantity::Jerk => 3,
        Quantity::Acceleration => 2,
        Quantity::Velocity => 1,
        Quantity::Position => 0,
    }
}

/// Raw limits `(quantity, flag, floor(limit · scale))`, `None` where the register is the bound.
fn raw_limits(m: &Method, f: &Format) -> Result<Vec<(Quantity, Option<I256>)>, PlanError> {
    let mut out = Vec::new();
    for (q, _, value) in m.limits().iter() {
        let raw = value * f.scale(q);
        if raw < 1.0 {
            return Err(PlanError::LimitBelowResolution {
                quantity: q.name(),
                limit: value,
                lsb: 1.0 / f.scale(q),
                unit: q.unit(),
            });
        }
        out.push((
            q,
            if raw >= 2f64.powi(126) {
                None
            } else {
                Some(I256::from(raw.floor() as i128))
            },
        ));
    }
    Ok(out)
}

fn unit_peak(p: &Peaks, q: Quantity) -> I256 {
    match q {
        Quantity::Position => p.x,
        Quantity::Velocity => p.v,
        Quantity::Acceleration => p.a,
        Quantity::Jerk => p.j,
        Quantity::Snap => p.d,
    }
}

/// Step 2 of planning: see [`quantize`].
fn quantize_into(
    plan: &mut Plan,
    mut phases: PhaseTicks,
    sign: i128,
    x_abs: I256,
) -> Result<(), PlanError> {
    let f = plan.format;
    let m = plan.request.method;
    let shape = m.shape();
    let limits = raw_limits(&m, &f)?;
    let max_ticks = (1u64 << f.tick_bits) - 1;
    let too_long = |ticks: u128| PlanError::TooLong {
        ticks,
        seconds: ticks as f64 * f.ts,
        max_ticks,
    };
    let mut extension = 0u64;
    // At most a few rounds: the closed-form extension lands at K ≤ K_lim in one step, a second
    // round only re-checks.
    for _ in 0..4 {
        let ticks = unit_ticks(shape, &phases);
        if ticks > u128::from(max_ticks) {
            return Err(too_long(ticks));
        }
        let Some(unit) = unit_response(shape, &phases) else {
            return Err(PlanError::GainTooLarge {
                log2_gain: 127.0,
                frac: FRAC_BITS,
            });
        };
        let gain = unit.gain;
        // Largest amplitude allowed by every limit and by every register's width:
        // min(floor(bound / unit_peak)).
        let mut bounds: [(I256, Quantity, bool); 8] = [(I256::ZERO, Quantity::Snap, false); 8];
        let mut n = 0;
        for (q, raw) in &limits {
            if let Some(raw) = raw {
                bounds[n] = (*raw, *q, true);
                n += 1;
            }
        }
        for q in [
            Quantity::Velocity,
            Quantity::Acceleration,
            Quantity::Jerk,
            Quantity::Snap,
        ] {
            bounds[n] = (I256::from(Format::register_max(f.width(q))), q, false);
            n += 1;
        }
        // The tightest bound: compare bound/peak fractions by cross-multiplying (exact in
        // 256 bits), then divide once.
        let mut best: Option<(I256, I256, Quantity, bool)> = None;
        for &(bound, q, is_limit) in &bounds[..n] {
            let peak = unit_peak(&unit.peaks, q);
            if peak <= 0 {
                continue;
            }
            if best.is_none_or(|(b, p, _, _)| bound * p < b * peak) {
                best = Some((bound, peak, q, is_limit));
            }
        }
        // Both fit i128 (bounds ≤ 2^126, peaks come from i128).
        let k_lim = best.map(|(b, p, q, l)| (I256::from(b.as_i128() / p.as_i128()), q, l));
        let (k_lim, bound_q, is_limit) = k_lim.expect("the unit program has a snap peak");
        if k_lim < 1 {
            return Err(if is_limit {
                let (_, _, value) = m
                    .limits()
                    .iter()
                    .find(|(q, _, _)| *q == bound_q)
                    .expect("bound came from a limit");
                PlanError::LimitBelowResolution {
                    quantity: bound_q.name(),
                    limit: value,
                    lsb: unit_peak(&unit.peaks, bound_q).as_f64() / f.scale(bound_q),
                    unit: bound_q.unit(),
                }
            } else {
                PlanError::Overflow {
                    quantity: bound_q.name(),
                    needed: unit_peak(&unit.peaks, bound_q).as_f64().log2() + 1.0,
                    bits: f.width(bound_q),
                }
            });
        }
        if gain >= I256::ONE << FRAC_BITS {
            return Err(PlanError::GainTooLarge {
                log2_gain: gain.as_f64().log2(),
                frac: FRAC_BITS,
            });
        }
        // X < 2^112 and P < 2^80: round(X / P) in i128.
        let (x128, p128) = (x_abs.as_i128(), gain.as_i128());
        let k = I256::from((2 * x128 + p128) / (2 * p128));
        if k > k_lim {
            // Lengthen the cruise so that K_lim · P' ≥ X: each tick adds the cruise velocity.
            let cruise_v = unit.peaks.v;
            let more = div_ceil(x_abs - k_lim * gain, k_lim * cruise_v);
            let more =
                u64::try_from(more.as_u128().min(u128::from(u64::MAX / 4))).expect("clamped");
            phases.v += more.max(1);
            extension += more.max(1);
            continue;
        }
        let k = i128::try_from(k).expect("k ≤ k_lim ≤ register max");
        let amp = sign * k;
        let program = unit.pieces.to_program(amp);
        plan.cruise_segment =
            quantize::Pieces::cruise_segment(&program, quantize::cruise_ticks(shape, &phases));
        program.validate(&f)?;
        // The chain is linear and starts at rest, so the move's peaks are |K| times the unit
        // peaks, exactly; the position is monotonic, so its extremes are the two ends.
        let kk = I256::from(k);
        let start_x = I256::from(plan.start.x);
        let end = crate::peaks::ExactState {
            x: start_x + I256::from(sign) * kk * gain,
            ..Default::default()
        };
        let pk = Peaks {
            x: start_x.abs().max(end.x.abs()),
            v: kk * unit.peaks.v,
            a: kk * unit.peaks.a,
            j: kk * unit.peaks.j,
            d: kk * unit.peaks.d,
        };
        plan.final_state = end.to_chain().expect("peaks fit their registers");
        plan.peaks = pk;
        plan.program = program;
        plan.amplitude_raw = amp;
        plan.phases = phases;
        plan.cruise_extension = extension;
        return Ok(());
    }
    Err(too_long(unit_ticks(shape, &phases)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;

    fn order4(distance: f64) -> MoveRequest {
        MoveRequest {
            distance,
            method: Method::Order4 {
                vmax: 1.0,
                amax: 10.0,
                jmax: 100.0,
                dmax: 1000.0,
            },
        }
    }

    #[test]
    fn order4_lands_exactly_and_stops() {
        let p = plan(&order4(0.5), &DEFAULT_FORMAT).unwrap();
        assert!(p.final_state.is_at_rest());
        assert_eq!(p.final_error_lsb(), 0);
        assert!(p.residual_raw().abs() < DEFAULT_FORMAT.half_lsb_raw());
        assert!(p.program.segments.len() <= 15);
    }

    #[test]
    fn zero_distance_is_an_empty_program() {
        let p = plan(&order4(0.0), &DEFAULT_FORMAT).unwrap();
        assert!(p.program.segments.is_empty());
        assert_eq!(p.ticks_total(), 0);
    }

    #[test]
    fn bad_inputs_are_named() {
        let mut r = order4(1.0);
        r.method = Method::Order4 {
            vmax: -1.0,
            amax: 10.0,
            jmax: 100.0,
            dmax: 1000.0,
        };
        let e = plan(&r, &DEFAULT_FORMAT).unwrap_err();
        assert_eq!(e.to_string(), "vmax = -1 must be greater than 0");
        let e = plan(&order4(f64::NAN), &DEFAULT_FORMAT).unwrap_err();
        assert!(matches!(
            e,
            PlanError::NotFinite {
                name: "distance",
                ..
            }
        ));
    }
}
