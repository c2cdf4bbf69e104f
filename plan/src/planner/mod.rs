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
pub mod fmath;
pub mod order2;
pub mod order3;
pub mod order4;
pub mod quantize;
mod request;

pub use request::{validate, Method, MoveRequest};

use ethnum::I256;
use serde::{Deserialize, Serialize};

use crate::error::PlanError;
pub use duration::{DurationInput, DurationValues};
use quantize::{unit_response, unit_ticks};
use snapgen_model::chain::ChainState;
use snapgen_model::error::ProgramError;
use snapgen_model::format::{Format, Quantity, FRAC_BITS};
use snapgen_model::peaks::{peaks, Peaks};
use snapgen_model::program::Program;

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
    ceil_ticks_f(t) as u64
}

/// [`ceil_ticks`] as an f64 (a whole number): the continuous planners compute with it, and
/// skip two slow conversions per phase.
#[inline]
pub fn ceil_ticks_f(t: f64) -> f64 {
    if t.is_nan() || t <= 1e-6 {
        0.0
    } else if t >= 1e18 {
        (u64::MAX / 4) as f64
    } else {
        fmath::ceil(t - 1e-6)
    }
}

/// [`ceil_ticks_f`], at least one tick.
#[inline]
pub fn ceil_ticks_min1_f(t: f64) -> f64 {
    ceil_ticks_f(t).max(1.0)
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
}

impl Plan {
    /// A plan of nothing (an empty program) from `start`.
    fn empty(format: Format, request: MoveRequest, start: ChainState) -> Self {
        Plan {
            format,
            request,
            phases: PhaseTicks::default(),
            cruise_extension: 0,
            continuous_amplitude: 0.0,
            amplitude_raw: 0,
            target_lsb: 0,
            start,
            final_state: start,
            peaks: Peaks::default(),
            program: Program::empty(),
            duration_values: None,
        }
    }

    /// Back to [`Plan::empty`], keeping the program's memory.
    fn reset(&mut self, format: Format, request: MoveRequest, start: ChainState) {
        let mut program = std::mem::take(&mut self.program);
        program.segments.clear();
        *self = Plan {
            program,
            ..Plan::empty(format, request, start)
        };
    }

    /// Profile order.
    pub fn order(&self) -> u8 {
        self.request.method.order()
    }

    /// Ticks the program lasts.
    pub fn ticks_total(&self) -> u64 {
        self.program.total_ticks()
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
    let mut plan = Plan::empty(*format, *request, start);
    plan_into(request, format, start, &mut plan)?;
    Ok(plan)
}

/// [`plan_from`] into an existing plan, reusing its program's memory: what a host that plans
/// move after move (or a benchmark) calls, as Ruckig's `calculate` fills a trajectory it is
/// given. On an error `plan` holds no valid move.
pub fn plan_into(
    request: &MoveRequest,
    format: &Format,
    start: ChainState,
    plan: &mut Plan,
) -> Result<(), PlanError> {
    validate(request, format)?;
    let f = *format;
    let m = request.method;
    // Position range: output cells representable by the position register, with one cell of
    // headroom on each side.
    let cells = (1i64 << (f.widths.x - FRAC_BITS - 1)) - 1;
    let target_f = fmath::round(request.distance / f.position_lsb);
    let start_cell = f.output_lsb(start.x);
    if target_f.abs() > (cells - 1) as f64
        || (start_cell + target_f as i64 as i128).abs() > i128::from(cells - 1)
    {
        return Err(PlanError::DistanceOutOfRange {
            distance: request.distance,
            max: f.max_distance(),
        });
    }
    plan.reset(f, *request, start);
    plan.target_lsb = target_f as i64 as i128;
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
    // Distance from the start register to the centre of the target cell (< 2^112).
    let x_total = plan.target_raw() - start.x;
    if x_total == 0 {
        let (pk, _) = peaks(&plan.program, &start);
        plan.peaks = pk;
        return Ok(());
    }
    let sign: i128 = if x_total < 0 { -1 } else { 1 };
    let x_abs = x_total.unsigned_abs();
    // The continuous planner works on the distance the integer plan actually covers.
    let dist = to_f64(x_abs) * f.internal_lsb();
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
            a: amax * (ts * ts),
            j: jmax * (ts * ts * ts),
            d: dmax * (ts * ts * ts * ts),
        }),
        Method::Order3 { vmax, amax, jmax } => order3::plan(&order3::TickLimits3 {
            x: dist,
            v: vmax * ts,
            a: amax * (ts * ts),
            j: jmax * (ts * ts * ts),
        }),
        Method::Order2 { vmax, amax } => order2::plan(&order2::TickLimits2 {
            x: dist,
            v: vmax * ts,
            a: amax * (ts * ts),
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
    plan.continuous_amplitude = sign as f64 * cont.amplitude / ts_power(ts, amp_q);
    quantize_into(plan, cont.phases, sign, x_abs)
}

/// `Ts^n` for the power of `Ts` in `q`'s tick units, by plain multiplication.
fn ts_power(ts: f64, q: Quantity) -> f64 {
    match q {
        Quantity::Snap => ts * ts * ts * ts,
        Quantity::Jerk => ts * ts * ts,
        Quantity::Acceleration => ts * ts,
        Quantity::Velocity => ts,
        Quantity::Position => 1.0,
    }
}

/// Raw limits `(quantity, floor(limit · scale))`, `None` where the register is the bound.
fn raw_limits(m: &Method, f: &Format) -> Result<[(Quantity, Option<u128>); 4], PlanError> {
    let mut out = [(Quantity::Position, None); 4];
    for (k, (q, _, value)) in m.limits().iter().enumerate() {
        let raw = value * f.scale(q);
        if raw < 1.0 {
            return Err(PlanError::LimitBelowResolution {
                quantity: q.name(),
                limit: value,
                lsb: 1.0 / f.scale(q),
                unit: q.unit(),
            });
        }
        out[k] = (
            q,
            if raw >= 2f64.powi(126) {
                None
            } else {
                Some(to_u128(fmath::floor(raw)))
            },
        );
    }
    Ok(out)
}

/// A non-negative f64 below 2^127 as u128, truncated (a hardware conversion below 2^64; the
/// software one above).
#[inline]
fn to_u128(x: f64) -> u128 {
    if x < 18_446_744_073_709_551_616.0 {
        x as u64 as u128
    } else {
        x as u128
    }
}

/// `u` as an f64, by two hardware conversions (the software `u128 → f64` is slower); within
/// an ulp or two, which is all the callers need (a first comparison, then exact integers).
#[inline]
fn to_f64(u: u128) -> f64 {
    if u >> 64 == 0 {
        u as u64 as f64
    } else {
        ((u >> 64) as u64 as f64) * 18_446_744_073_709_551_616.0 + (u as u64 as f64)
    }
}

/// Step 2 of planning: see [`quantize`].
fn quantize_into(
    plan: &mut Plan,
    mut phases: PhaseTicks,
    sign: i128,
    x_abs: u128,
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
    // The bound on each quantity's peak: its requested limit or its register's width,
    // whichever is smaller (and which of the two it is, for the error message).
    let mut bounds = [(0u128, Quantity::Snap, false); 4];
    for (b, q) in bounds.iter_mut().zip([
        Quantity::Velocity,
        Quantity::Acceleration,
        Quantity::Jerk,
        Quantity::Snap,
    ]) {
        let register = Format::register_max(f.width(q)) as u128;
        *b = match limits.iter().find(|(lq, raw)| *lq == q && raw.is_some()) {
            Some(&(_, Some(raw))) if raw <= register => (raw, q, true),
            _ => (register, q, false),
        };
    }
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
        // Largest amplitude allowed by every bound: K_lim = min(floor(bound / unit_peak)),
        // exact.
        let mut best: Option<(u128, Quantity, bool)> = None;
        for &(bound, q, is_limit) in &bounds {
            if let Some(k) = bound.checked_div(unit.peaks.get(q)) {
                if best.is_none_or(|(kb, _, _)| k < kb) {
                    best = Some((k, q, is_limit));
                }
            }
        }
        let (k_lim, bound_q, is_limit) = best.expect("the unit program has a snap peak");
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
                    lsb: unit.peaks.get(bound_q) as f64 / f.scale(bound_q),
                    unit: bound_q.unit(),
                }
            } else {
                PlanError::Overflow {
                    quantity: bound_q.name(),
                    needed: (unit.peaks.get(bound_q) as f64).log2() + 1.0,
                    bits: f.width(bound_q),
                }
            });
        }
        if gain >= 1u128 << FRAC_BITS {
            return Err(PlanError::GainTooLarge {
                log2_gain: (gain as f64).log2(),
                frac: FRAC_BITS,
            });
        }
        // X < 2^112 and P < 2^80: K = round(X / P) = floor((2X + P) / 2P).
        let k = (2 * x_abs + gain) / (2 * gain);
        if k > k_lim {
            // Lengthen the cruise so that K_lim · P' ≥ X: each tick adds the cruise velocity.
            let cruise_v = unit.peaks.v;
            let more = (x_abs - k_lim * gain).div_ceil(k_lim * cruise_v);
            let more = u64::try_from(more.min(u128::from(u64::MAX / 4))).expect("clamped");
            phases.v += more.max(1);
            extension += more.max(1);
            continue;
        }
        let k = k as i128;
        let amp = sign * k;
        unit.pieces.write_program(amp, &mut plan.program);
        let program = &plan.program;
        // Every segment fits the format: the tick total and each bound were checked above;
        // only the memory depth is left (a unit program has at most 17 segments).
        if program.segments.len() > f.max_segments {
            return Err(ProgramError::TooManySegments {
                count: program.segments.len(),
                max: f.max_segments,
            }
            .into());
        }
        debug_assert_eq!(program.validate(&f), Ok(()));
        // The chain is linear and starts at rest, so the move's peaks are |K| times the unit
        // peaks, exactly (each within its bound, so in i128); the position is monotonic, so its
        // extremes are the two ends.
        let scaled = |p: u128| I256::from(k * p as i128);
        let end_x = plan.start.x + sign * k * gain as i128;
        plan.peaks = Peaks {
            x: I256::from(plan.start.x.abs().max(end_x.abs())),
            v: scaled(unit.peaks.v),
            a: scaled(unit.peaks.a),
            j: scaled(unit.peaks.j),
            d: scaled(unit.peaks.d),
        };
        plan.final_state = ChainState::at_rest(end_x);
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
    use snapgen_model::format::DEFAULT_FORMAT;

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
