//! Identification of a motor and its load from a record of the commanded voltage and the
//! encoder's angle (issue 24, item 1; `snapgen identify`), pure: the record comes from a board
//! (`snapgen_host::identify`), the result becomes a plant file and gains.
//!
//! # The model fitted
//!
//! With the armature's inductance neglected (its time constant is far below the loop's, as in
//! [`crate::gains`]), the shaft's speed under a terminal voltage `u` is
//!
//! ```text
//! τ ω' + ω = K · (u − u_dz · sign i − u_c · sign ω)     (while ω ≠ 0 or the drive beats u_c)
//! K = Kt / (R b + Kt Ke),  τ = J R / (R b + Kt Ke),  u_c = R Tc / Kt,  R i ≈ u − ω / K
//! ```
//!
//! `K` (rad/s per V), `τ` (s), the Coulomb friction as a voltage `u_c`, and the voltage the
//! bridge's dead time costs `u_dz` (`Vs · t_dead / T_pwm`: each period's turn-on is late by the
//! dead time while the bridge drives the current, early while the current regenerates, so it
//! acts against the current, not the voltage; no PWM pulse, no loss: `u = 0` gives 0; a ripple
//! that crosses zero in each period loses nothing: [`Electrical`]). The two frictions differ
//! only where the current reverses while the shaft still turns (braking), so the record
//! separates them poorly: by default the dead time is the amplifier's, given, and the rest is
//! fitted.
//!
//! # The method: a state-variable filter and least squares
//!
//! The angle and the regressors pass through one low-pass `F(s) = λ² / (s + λ)²`, whose states
//! give `F·θ`, `s·F·θ` and `s²·F·θ` without differentiating the encoder's counts; on the
//! filtered signals the model is linear in `(τ, K, K·u_dz, K·u_c)`:
//!
//! ```text
//! s·F·θ = −τ · s²·F·θ + K · F·u − K·u_dz · F·sign i − K·u_c · F·sign ω
//! ```
//!
//! solved by least squares over the samples where the shaft has been moving for the filter's
//! memory (where it sticks, friction is whatever holds it and the equation does not apply).
//! `sign ω` is taken from a central difference of the angle, `sign i` from `u − ω/K` with the
//! last pass's `K` (a first pass without the dead time, then four). The fit's quality is
//! the share of the filtered speed's variation the equation explains (100 %: all), and the same
//! of the model simulated on its own from the recorded voltage (its speed, filtered alike).

use snapgen_model::{ChainState, Format};
use snapgen_plan::{plan_from, Method, MoveRequest, Plan, PlanError};

use crate::params::{Physical, PlantParams};

/// A record: segments of uniformly spaced samples (a move each), the commanded voltage held
/// from each sample to the next.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Record {
    /// Sample period (s).
    pub period: f64,
    /// One encoder count (rad): the angle's resolution.
    pub count_rad: f64,
    /// The armature and the bridge (none: the dead time's loss is taken by the current's sign
    /// alone).
    pub electrical: Option<Electrical>,
    /// The segments.
    pub segments: Vec<Segment>,
}

/// What the data sheet and the board say of the armature and the bridge: the current's ripple
/// in a PWM period, `ΔI = Vs·D·(1 − D) / (L·f_pwm)` at duty `D`, decides whether the dead
/// time's loss acts: the turn-on edge loses it while the current there (the period's lowest)
/// is driven, the turn-off edge gains it while the current there (the highest) regenerates, so
/// a ripple that crosses zero in each period loses nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Electrical {
    /// Terminal resistance (Ω).
    pub r: f64,
    /// Terminal inductance (H).
    pub l: f64,
    /// Supply (V).
    pub vs: f64,
    /// PWM frequency (Hz).
    pub pwm_hz: f64,
}

impl Electrical {
    /// Half the ripple, as a voltage across R, at the voltage `u`.
    fn half_ripple_v(&self, u: f64) -> f64 {
        let d = (u.abs() / self.vs).min(1.0);
        self.r * self.vs * d * (1.0 - d) / (2.0 * self.l * self.pwm_hz)
    }
}

/// Samples without a gap.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Segment {
    /// The encoder's angle at each sample (rad).
    pub angle: Vec<f64>,
    /// The voltage commanded from each sample to the next (V).
    pub volts: Vec<f64>,
}

/// The identified model.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Model {
    /// `K`: steady speed per volt (rad/s per V).
    pub gain: f64,
    /// `τ`: the mechanical time constant with the load (s).
    pub tau: f64,
    /// `u_c`: Coulomb friction as the voltage that balances it (V).
    pub coulomb_v: f64,
    /// `u_dz`: the amplifier's dead zone (V).
    pub dead_zone_v: f64,
}

impl Model {
    /// The model of a plant (what identification should find).
    pub fn of(p: &Physical, pwm_hz: f64) -> Self {
        let den = p.r * p.b + p.kt * p.ke;
        Model {
            gain: p.kt / den,
            tau: p.j * p.r / den,
            coulomb_v: p.r * p.tc / p.kt,
            dead_zone_v: p.vs * p.dead_time * pwm_hz,
        }
    }
}

/// What identification found.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Fit {
    /// The model.
    pub model: Model,
    /// Samples the least squares used.
    pub samples: usize,
    /// Share of the filtered speed's variation the fitted equation explains (%).
    pub equation_fit_percent: f64,
    /// The same for the model simulated alone from the recorded voltage (%).
    pub simulation_fit_percent: f64,
    /// The filter's corner (Hz).
    pub filter_hz: f64,
    /// Samples the voltages were taken ahead of the angles (0 or 1: see [`identify`]).
    pub voltage_lead: u8,
    /// The dead time's voltage was fitted (not given).
    pub dead_zone_fitted: bool,
}

/// Why nothing could be identified.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum IdentifyError {
    /// Too little motion in the record.
    #[error("only {moving} samples with the shaft moving (at least {needed} are needed): give the excitation more travel or a longer record")]
    TooLittleMotion {
        /// Samples usable.
        moving: usize,
        /// Needed.
        needed: usize,
    },
    /// The sample period or the count is not positive.
    #[error("a record needs a positive sample period and encoder count (got {period} s and {count} rad)")]
    BadRecord {
        /// Period.
        period: f64,
        /// Count.
        count: f64,
    },
    /// The least squares found no model with a positive gain and time constant.
    #[error("the record does not fit a motor (K = {gain} rad/s/V, τ = {tau} s): check that the voltage and the angle have the same sign convention and that the motor moved")]
    NotAMotor {
        /// K found.
        gain: f64,
        /// τ found.
        tau: f64,
    },
    /// The plant file cannot hold what was found.
    #[error("{0}")]
    Plant(String),
}

/// How far, how fast and how hard the excitation may move the shaft (rad, rad/s, rad/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The largest excursion from where it starts, one way (rad).
    pub travel: f64,
    /// The largest speed.
    pub speed: f64,
    /// The largest acceleration.
    pub accel: f64,
}

/// The excitation: eight S-curve moves out and back within `[start, start + travel]` (to
/// `travel` and its fractions), at speeds from an eighth to all of `speed` and accelerations
/// from a twentieth to all of `accel` (jerk 20 × accel): slow moves for the frictions, hard
/// ones for the inertia, braking for the dead time. Every one ends exactly at rest.
pub fn excitation(format: &Format, b: &Bounds) -> Result<Vec<Plan>, PlanError> {
    // (distance, speed, acceleration) as fractions of the bounds.
    const MOVES: [(f64, f64, f64); 8] = [
        (0.75, 0.25, 0.1),
        (-0.75, 0.625, 0.4),
        (0.375, 0.125, 0.025),
        (-0.375, 0.75, 0.75),
        (0.25, 0.05, 0.2),
        (-0.25, 0.025, 0.05),
        (1.0, 1.0, 0.15),
        (-1.0, 0.375, 1.0),
    ];
    let mut at = ChainState::at_rest(format.home_raw());
    let mut out = Vec::new();
    for (d, v, a) in MOVES {
        let plan = plan_from(
            &MoveRequest {
                distance: d * b.travel,
                method: Method::Order3 {
                    vmax: v * b.speed,
                    amax: a * b.accel,
                    jmax: 20.0 * a * b.accel,
                },
            },
            format,
            at,
        )?;
        at = plan.final_state;
        out.push(plan);
    }
    Ok(out)
}

/// The state-variable filter `λ²/(s+λ)²` over one segment: `(F x, s F x, s² F x)` at each
/// sample; the input is smooth between samples (`smooth`: a cubic through the samples, their
/// slopes by central differences — the angle) or held (`!smooth`: a voltage, a sign).
fn filter(x: &[f64], h: f64, lambda: f64, smooth: bool) -> Vec<[f64; 3]> {
    let sub = ((lambda * h / 0.05).ceil() as usize).max(1);
    let dt = h / sub as f64;
    let f = |s: [f64; 2], u: f64| [s[1], lambda * lambda * (u - s[0]) - 2.0 * lambda * s[1]];
    let n = x.len();
    let at_k = |k: usize| x[k.min(n.saturating_sub(1))];
    let slope = |k: usize| {
        if n < 2 {
            0.0
        } else if k == 0 {
            x[1] - x[0]
        } else if k + 1 >= n {
            x[n - 1] - x[n - 2]
        } else {
            0.5 * (x[k + 1] - x[k - 1])
        }
    };
    let mut s = [x.first().copied().unwrap_or(0.0), 0.0];
    let mut out = Vec::with_capacity(n);
    for (k, &u) in x.iter().enumerate() {
        out.push([s[0], s[1], f(s, u)[1]]);
        let (p0, p1, m0, m1) = (u, at_k(k + 1), slope(k), slope((k + 1).min(n - 1)));
        // Cubic Hermite between sample k and k + 1, `t` in samples.
        let at = |t: f64| {
            if !smooth {
                return u;
            }
            let (t2, t3) = (t * t, t * t * t);
            (2.0 * t3 - 3.0 * t2 + 1.0) * p0
                + (t3 - 2.0 * t2 + t) * m0
                + (-2.0 * t3 + 3.0 * t2) * p1
                + (t3 - t2) * m1
        };
        for m in 0..sub {
            let t = |d: f64| (m as f64 + d) / sub as f64;
            let (u0, u1, u2) = (at(t(0.0)), at(t(0.5)), at(t(1.0)));
            let add = |a: [f64; 2], b: [f64; 2], c: f64| [a[0] + c * b[0], a[1] + c * b[1]];
            let k1 = f(s, u0);
            let k2 = f(add(s, k1, dt / 2.0), u1);
            let k3 = f(add(s, k2, dt / 2.0), u1);
            let k4 = f(add(s, k3, dt), u2);
            s = [
                s[0] + dt / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
                s[1] + dt / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            ];
        }
    }
    out
}

/// The dead time's loss: `u_dz` (at most the pulse, `|u|`) against the current. The current is
/// the armature's, `R i = u − loss − Ke ω` with `Ke ω ≈ ω / K` (exact without viscous
/// friction). A ripple that crosses zero in each period loses nothing; between the two, the
/// loss is what holds the period's lowest current at zero (losing more would let it cross,
/// losing less would leave it above): `R·i = ±R·ΔI/2`. Without the electrical data, the loss
/// is taken by the current's sign alone.
fn dead_time_loss(u: f64, speed: f64, gain: f64, dz: f64, e: Option<&Electrical>) -> f64 {
    if u == 0.0 {
        return 0.0;
    }
    let dz = dz.min(u.abs());
    let a = u - speed / gain;
    match e {
        None => dz * a.signum(),
        Some(e) => a.signum() * (a.abs() - e.half_ripple_v(u)).clamp(0.0, dz),
    }
}

/// Solves `a x = b` (Gaussian elimination with partial pivoting).
fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    for c in 0..N {
        let p = (c..N).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..N {
            let k = a[r][c] / a[c][c];
            let pivot = a[c];
            for (v, p) in a[r].iter_mut().zip(pivot).skip(c) {
                *v -= k * p;
            }
            b[r] -= k * b[c];
        }
    }
    let mut x = [0.0; N];
    for r in (0..N).rev() {
        let s: f64 = (r + 1..N).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// The filtered signals of one segment that do not depend on the model.
struct Prepared {
    theta: Vec<[f64; 3]>,
    /// The speed from a central difference (rad/s).
    speed: Vec<f64>,
    /// `F·u`, `F·sign ω`.
    fu: Vec<[f64; 3]>,
    fsign: Vec<[f64; 3]>,
    /// The sample may enter the least squares.
    usable: Vec<bool>,
    volts: Vec<f64>,
}

fn prepare(seg: &Segment, r: &Record, lambda: f64) -> Prepared {
    let n = seg.angle.len().min(seg.volts.len());
    let theta = filter(&seg.angle[..n], r.period, lambda, true);
    // The speed from a central difference over ±w samples (w: about 2 ms).
    let w = ((2e-3 / r.period).round() as usize).clamp(1, 50);
    let min_speed = (3.0 * r.count_rad / (2.0 * w as f64 * r.period)).max(0.05);
    let mut speed = vec![0.0; n];
    for (k, s) in speed.iter_mut().enumerate() {
        let (a, b) = (k.saturating_sub(w), (k + w).min(n.saturating_sub(1)));
        if b > a {
            *s = (seg.angle[b] - seg.angle[a]) / ((b - a) as f64 * r.period);
        }
    }
    let sign: Vec<f64> = speed
        .iter()
        .map(|&s| if s.abs() < min_speed { 0.0 } else { s.signum() })
        .collect();
    // Usable: moving, with the same sign, for the filter's memory (about 6/λ) before it.
    let memory = ((6.0 / lambda) / r.period).ceil() as usize;
    let mut usable = vec![false; n];
    let mut run = 0usize;
    for k in 0..n {
        run = if sign[k] != 0.0 && (k == 0 || sign[k] == sign[k - 1]) {
            run + 1
        } else {
            0
        };
        usable[k] = run > memory && k + w < n;
    }
    let volts = seg.volts[..n].to_vec();
    Prepared {
        theta,
        fu: filter(&volts, r.period, lambda, false),
        fsign: filter(&sign, r.period, lambda, false),
        speed,
        usable,
        volts,
    }
}

/// Least squares with the current's sign from `gain` and the loss's shape from the dead zone
/// `dz` of the last pass: `(τ, K, K·u_dz, K·u_c)`, the residual's sum of squares and the rows
/// used. With `dead_zone` given, `u_dz` is that and not fitted.
fn least_squares(
    p: &[Prepared],
    r: &Record,
    lambda: f64,
    (gain, dz): (f64, f64),
    dead_zone: Option<f64>,
) -> Option<([f64; 4], f64, usize)> {
    let mut rows = Vec::new();
    for s in p {
        let sign_i: Vec<f64> = s
            .volts
            .iter()
            .zip(&s.speed)
            .map(|(&u, &w)| dead_time_loss(u, w, gain, dz, r.electrical.as_ref()) / dz)
            .collect();
        let fi = filter(&sign_i, r.period, lambda, false);
        for (k, fi) in fi.iter().enumerate() {
            if s.usable[k] {
                let row = [-s.theta[k][2], s.fu[k][0], -fi[0], -s.fsign[k][0]];
                rows.push((row, s.theta[k][1]));
            }
        }
    }
    let x = match dead_zone {
        None => normal(&rows, |r| r)?,
        Some(dz) => {
            let x = normal(&rows, |r| [r[0], r[1] + dz * r[2], r[3]])?;
            [x[0], x[1], x[1] * dz, x[2]]
        }
    };
    let ss = rows
        .iter()
        .map(|(row, y)| (y - (0..4).map(|i| row[i] * x[i]).sum::<f64>()).powi(2))
        .sum();
    Some((x, ss, rows.len()))
}

/// The least-squares solution of `row(r) · x = y` over `rows`.
fn normal<const N: usize>(
    rows: &[([f64; 4], f64)],
    row: impl Fn([f64; 4]) -> [f64; N],
) -> Option<[f64; N]> {
    let mut ata = [[0.0; N]; N];
    let mut atb = [0.0; N];
    for (r, y) in rows {
        let r = row(*r);
        for i in 0..N {
            for j in 0..N {
                ata[i][j] += r[i] * r[j];
            }
            atb[i] += r[i] * y;
        }
    }
    solve(ata, atb)
}

/// The model simulated from rest on a segment's voltages: its speed at each sample.
pub fn simulate(m: &Model, volts: &[f64], period: f64, e: Option<&Electrical>) -> Vec<f64> {
    let sub = ((period / (m.tau / 20.0)).ceil() as usize).clamp(1, 1000);
    let dt = period / sub as f64;
    let decay = (-dt / m.tau).exp();
    let mut w = 0.0f64;
    let mut out = Vec::with_capacity(volts.len());
    for &u in volts {
        out.push(w);
        for _ in 0..sub {
            let drive = u - dead_time_loss(u, w, m.gain, m.dead_zone_v, e);
            let dir = if w != 0.0 {
                w.signum()
            } else if drive.abs() > m.coulomb_v {
                drive.signum()
            } else {
                continue; // stuck
            };
            let target = m.gain * (drive - m.coulomb_v * dir);
            let next = target + (w - target) * decay;
            w = if next * dir < 0.0 { 0.0 } else { next };
        }
    }
    out
}

/// The model's speed simulated on every segment and filtered as the measured one is: the
/// measured and the predicted `s·F·θ`.
fn predicted(m: &Model, prepared: &[Prepared], r: &Record, lambda: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut measured, mut predicted) = (Vec::new(), Vec::new());
    for p in prepared {
        let w = simulate(m, &p.volts, r.period, r.electrical.as_ref());
        let fw = filter(&w, r.period, lambda, true);
        measured.extend(p.theta.iter().map(|t| t[1]));
        predicted.extend(fw.iter().map(|t| t[0]));
    }
    (measured, predicted)
}

fn fit_percent(measured: &[f64], model: &[f64]) -> f64 {
    let n = measured.len().max(1) as f64;
    let mean = measured.iter().sum::<f64>() / n;
    let spread: f64 = measured.iter().map(|y| (y - mean).powi(2)).sum();
    let err: f64 = measured
        .iter()
        .zip(model)
        .map(|(y, m)| (y - m).powi(2))
        .sum();
    100.0 * (1.0 - (err / spread.max(1e-300)).sqrt())
}

/// Identifies the model from `r`: every parameter (`dead_zone: None`), or all but the dead
/// time's voltage, given (from the amplifier's known dead time: the record separates it from
/// Coulomb friction only where the current reverses, so a known one makes the friction
/// sharper: docs/PLANT.md, "Identification"). A board's record may pair each angle with the
/// voltage of the sample before (its frame taken before the controller's update on the same
/// tick): both pairings are fitted and the one that explains more is kept.
pub fn identify(r: &Record, dead_zone: Option<f64>) -> Result<Fit, IdentifyError> {
    let aligned = identify_aligned(r, dead_zone);
    let shifted = Record {
        segments: r
            .segments
            .iter()
            .map(|s| Segment {
                angle: s
                    .angle
                    .iter()
                    .copied()
                    .take(s.angle.len().saturating_sub(1))
                    .collect(),
                volts: s.volts.iter().copied().skip(1).collect(),
            })
            .collect(),
        ..r.clone()
    };
    match (aligned, identify_aligned(&shifted, dead_zone)) {
        (Ok(a), Ok(b)) if b.equation_fit_percent > a.equation_fit_percent => Ok(Fit {
            voltage_lead: 1,
            ..b
        }),
        (Ok(a), _) => Ok(a),
        (Err(_), Ok(b)) => Ok(Fit {
            voltage_lead: 1,
            ..b
        }),
        (Err(e), Err(_)) => Err(e),
    }
}

fn identify_aligned(r: &Record, dead_zone: Option<f64>) -> Result<Fit, IdentifyError> {
    if !(r.period > 0.0 && r.count_rad > 0.0 && r.period.is_finite()) {
        return Err(IdentifyError::BadRecord {
            period: r.period,
            count: r.count_rad,
        });
    }
    // The filter's corner: 30 Hz, or a tenth of the sample rate if that is lower.
    let filter_hz = (0.1 / r.period).min(30.0);
    let lambda = 2.0 * std::f64::consts::PI * filter_hz;
    let prepared: Vec<Prepared> = r.segments.iter().map(|s| prepare(s, r, lambda)).collect();
    let moving: usize = prepared
        .iter()
        .map(|p| p.usable.iter().filter(|&&u| u).count())
        .sum();
    let needed = 50;
    if moving < needed {
        return Err(IdentifyError::TooLittleMotion { moving, needed });
    }
    // The first pass's gain: speed per volt where both are largest.
    let (mut num, mut den) = (0.0, 0.0);
    for p in &prepared {
        for k in 0..p.volts.len() {
            if p.usable[k] {
                num += p.speed[k] * p.volts[k];
                den += p.volts[k] * p.volts[k];
            }
        }
    }
    let mut gain = if den > 0.0 { (num / den).abs() } else { 1.0 };
    let peak_u = prepared
        .iter()
        .flat_map(|p| p.volts.iter())
        .fold(0.0f64, |m, u| m.max(u.abs()));
    // The dead zone of the first pass with it: the given one, or 1 % of the largest voltage.
    let mut dz = dead_zone
        .unwrap_or(0.01 * peak_u)
        .max(1e-6 * peak_u.max(1e-9));
    let mut solved = None;
    // Pass 0 without the dead time (its sign needs K); then four with it.
    for pass in 0..5 {
        let mode = if pass == 0 { Some(0.0) } else { dead_zone };
        let (x, ss, rows) = least_squares(&prepared, r, lambda, (gain, dz), mode)
            .ok_or(IdentifyError::TooLittleMotion { moving, needed })?;
        // A time constant below a tenth of the sample period is not one the record shows.
        if !(x[1] > 0.0 && x[0] > 0.1 * r.period) {
            return Err(IdentifyError::NotAMotor {
                gain: x[1],
                tau: x[0],
            });
        }
        gain = x[1];
        if pass > 0 {
            dz = dead_zone.unwrap_or(x[2] / x[1]).max(1e-6 * peak_u);
        }
        solved = Some((x, ss, rows));
    }
    let (x, ss, samples) = solved.expect("the passes ran");
    let model = Model {
        gain: x[1],
        tau: x[0],
        dead_zone_v: dead_zone.unwrap_or((x[2] / x[1]).max(0.0)),
        coulomb_v: (x[3] / x[1]).max(0.0),
    };
    // The fits: the equation's on the rows used, the simulation's on every sample.
    let used: Vec<f64> = prepared
        .iter()
        .flat_map(|p| {
            (0..p.usable.len())
                .filter(|&k| p.usable[k])
                .map(|k| p.theta[k][1])
        })
        .collect();
    let mean = used.iter().sum::<f64>() / used.len() as f64;
    let spread: f64 = used.iter().map(|y| (y - mean).powi(2)).sum();
    let equation_fit_percent = 100.0 * (1.0 - (ss / spread.max(1e-300)).sqrt());
    let (measured, predicted) = predicted(&model, &prepared, r, lambda);
    Ok(Fit {
        model,
        samples,
        equation_fit_percent,
        simulation_fit_percent: fit_percent(&measured, &predicted),
        filter_hz,
        voltage_lead: 0,
        dead_zone_fitted: dead_zone.is_none(),
    })
}

impl Fit {
    /// A plant file with this model: the motor's data-sheet constants (resistance, inductance,
    /// torque and speed constants) and the amplifier and encoder kept from `base`; the load's
    /// inertia, the viscous and Coulomb friction and the dead time from the fit (the
    /// viscous friction from `K` against `Kt / (Kt Ke)`: 0 if `K` is at or above it).
    pub fn plant(
        &self,
        base: &PlantParams,
        pwm_hz: f64,
        source: &str,
    ) -> Result<PlantParams, IdentifyError> {
        if base.amplifier.kind != crate::params::AmplifierKind::Voltage {
            return Err(IdentifyError::Plant(
                "the model fitted is an H-bridge's: a current-mode drive's plant file cannot be written from it".into(),
            ));
        }
        let p = base.physical();
        let m = &self.model;
        let b = ((p.kt / m.gain - p.kt * p.ke) / p.r).max(0.0);
        let den = p.r * b + p.kt * p.ke;
        let j = m.tau * den / p.r;
        let rotor = base.motor.rotor_inertia_gcm2 * 1e-7;
        if j <= rotor {
            return Err(IdentifyError::Plant(format!(
                "the fitted inertia {j:.4e} kg·m² is not above the rotor's {rotor:.4e} from {}: the data sheet's resistance or torque constant does not match this motor",
                base.motor.name
            )));
        }
        let tc = m.coulomb_v * p.kt / p.r;
        let mut out = base.clone();
        out.motor.viscous_friction_nm_s_per_rad = b;
        out.motor.no_load_current_ma = tc / p.kt * 1e3;
        // Keep the data sheet's consistency rule true with the new no-load current.
        out.motor.no_load_speed_rpm = (out.motor.nominal_voltage_v - p.r * tc / p.kt) / p.ke * 60.0
            / (2.0 * std::f64::consts::PI);
        out.load.inertia_kg_m2 = j - rotor;
        out.load.description = format!("identified: {source}");
        out.amplifier.dead_time_ns = m.dead_zone_v / (p.vs * pwm_hz) * 1e9;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record made by the identified model itself: identification finds it again.
    #[test]
    fn a_record_of_the_model_is_identified_exactly() {
        let truth = Model {
            gain: 15.0,
            tau: 0.04,
            coulomb_v: 0.08,
            dead_zone_v: 0.3,
        };
        let period = 1e-4;
        let mut segments = Vec::new();
        // Drives with braking (the voltage reverses while the shaft turns) and pauses.
        for (amp, f) in [(3.0, 2.0), (-5.0, 3.0), (1.5, 5.0)] {
            let volts: Vec<f64> = (0..8000)
                .map(|k| {
                    let t = k as f64 * period;
                    let u = amp * (0.3 + (2.0 * std::f64::consts::PI * f * t).sin());
                    if u.abs() < 0.2 {
                        0.0
                    } else {
                        u
                    }
                })
                .collect();
            let w = simulate(&truth, &volts, period, None);
            let mut theta = 0.0;
            let angle: Vec<f64> = w
                .iter()
                .map(|w| {
                    let a = theta;
                    theta += w * period;
                    a
                })
                .collect();
            segments.push(Segment { angle, volts });
        }
        let r = Record {
            period,
            count_rad: 1e-9,
            electrical: None,
            segments,
        };
        let fit = identify(&r, None).unwrap();
        let m = fit.model;
        assert!((m.gain / truth.gain - 1.0).abs() < 0.01, "{fit:?}");
        assert!((m.tau / truth.tau - 1.0).abs() < 0.02, "{fit:?}");
        assert!((m.coulomb_v - truth.coulomb_v).abs() < 0.02, "{fit:?}");
        assert!((m.dead_zone_v - truth.dead_zone_v).abs() < 0.02, "{fit:?}");
        assert!(fit.simulation_fit_percent > 95.0, "{fit:?}");
    }

    #[test]
    fn bad_records_are_refused() {
        let e = identify(&Record::default(), None).unwrap_err();
        assert!(matches!(e, IdentifyError::BadRecord { .. }));
        let still = Record {
            period: 1e-3,
            count_rad: 1e-3,
            electrical: None,
            segments: vec![Segment {
                angle: vec![0.0; 1000],
                volts: vec![0.0; 1000],
            }],
        };
        assert!(matches!(
            identify(&still, None).unwrap_err(),
            IdentifyError::TooLittleMotion { .. }
        ));
    }
}
