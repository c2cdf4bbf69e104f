//! `snapgen experiment seed001 --mismatch [CASE …]`: the controller tuned on one plant runs
//! plants that differ from it (issue 24, item 2). The gains (and the feed-forward, which
//! inverts the model) are derived once from the plant file; each case applies its factors
//! (`snapgen_plant::mismatch`) to the plant the loop integrates. For each case, the S-curve and
//! the trapezoid of seed 001 on the fabric-rate loop: the encoder's error at T, the true
//! shaft's beside it, the peak and RMS error, the settling time, whether the following-error
//! limit tripped and the board's own peak following error.

use serde::Serialize;

use snapgen_plant::gains::{derive, LoopTiming};
use snapgen_plant::metrics::MoveFigures;
use snapgen_plant::mismatch::{Mismatch, NOMINAL, SWEEP};
use snapgen_plant::seed001::{profiles, SETTLE_BAND};

use super::{in_parallel, run_profile, servo_ticks, Board, LoopSetup, Options, Setup};
use crate::error::{InputError, Mismatched};

/// One profile on one mismatched plant.
#[derive(Clone, Debug, Serialize)]
pub struct CaseProfile {
    /// `scurve` or `trapezoid`.
    pub name: &'static str,
    /// The figures (the encoder's and the shaft's errors).
    #[serde(flatten)]
    pub figures: MoveFigures,
    /// The following-error limit tripped (the amplifier went off).
    pub tripped: bool,
    /// The largest following error at a controller sample (rad).
    pub following_peak_rad: f64,
    /// The board's registers end on the plan's, bit for bit.
    pub landed_exactly: bool,
}

/// One case.
#[derive(Clone, Debug, Serialize)]
pub struct Case {
    /// What differs (`R +40 %, J −30 %`).
    pub case: String,
    /// Resistance factor.
    pub resistance: f64,
    /// Inertia factor.
    pub inertia: f64,
    /// Friction factor.
    pub friction: f64,
    /// The profiles.
    pub profiles: Vec<CaseProfile>,
}

/// The sweep.
#[derive(Clone, Debug, Serialize)]
pub struct MismatchReport {
    /// `seed001-mismatch`.
    pub experiment: &'static str,
    /// Where it ran.
    pub board: Board,
    /// The plant the gains come from.
    pub motor: String,
    /// The loop's rate (Hz).
    pub loop_hz: f64,
    /// The following-error limit (rad).
    pub following_limit_rad: f64,
    /// The cases.
    pub cases: Vec<Case>,
    /// Clocks the fabric's outputs differed from the model's (`fabric` only).
    pub mismatches: Option<u64>,
    /// Clocks simulated.
    pub clocks: u64,
    /// Wall time (s).
    pub seconds: f64,
}

/// Reads the cases (none: the standard sweep), the nominal plant first as the reference.
pub fn cases(given: &[String]) -> Result<Vec<Mismatch>, InputError> {
    if given.is_empty() {
        return Ok(SWEEP.to_vec());
    }
    let mut out = vec![NOMINAL];
    for c in given {
        let m = Mismatch::parse(c).map_err(|e| InputError::Board(e.to_string()))?;
        if !out.contains(&m) {
            out.push(m);
        }
    }
    Ok(out)
}

/// Runs the sweep and prints it; exit 1 if the fabric and the model disagree.
pub fn run(o: &Options, given: &[String], json: bool) -> anyhow::Result<()> {
    let r = sweep(o, &cases(given)?)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", table(&r));
    }
    if r.mismatches.is_some_and(|m| m > 0) {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

/// The S-curve and the trapezoid on each case's plant, with the gains of `o.plant`.
pub fn sweep(o: &Options, cases: &[Mismatch]) -> anyhow::Result<MismatchReport> {
    let started = std::time::Instant::now();
    let nominal = o.plant.physical();
    let Setup {
        design,
        format: f,
        pwm_period,
    } = Setup::of(o)?;
    let servo_period = servo_ticks(&f, o.loop_hz);
    let gains = derive(
        &nominal,
        &o.design,
        &LoopTiming {
            ts: f.ts,
            servo_period,
            pwm_period,
        },
    )?;
    let window = if o.short { 0.5 } else { 1.2 };
    let mut all = profiles(&f, 0.05, window)?;
    all.retain(|p| matches!(p.name, "scurve" | "trapezoid"));
    let jobs: Vec<(usize, usize)> = (0..cases.len())
        .flat_map(|c| (0..all.len()).map(move |k| (c, k)))
        .collect();
    let done = in_parallel(&jobs, |&(c, k)| {
        let p = cases[c].apply(&nominal);
        let setup = LoopSetup {
            servo: gains.config,
            pwm_period,
            delay_s: 0.0,
        };
        run_profile(o, &design, &f, &p, &setup, &all[k])
            .map_err(|e| e.context(format!("{} with {}", all[k].name, cases[c])))
    });
    let (mut mismatches, mut clocks) = (0, 0);
    let mut out: Vec<Case> = cases
        .iter()
        .map(|m| Case {
            case: m.to_string(),
            resistance: m.resistance,
            inertia: m.inertia,
            friction: m.friction,
            profiles: Vec::new(),
        })
        .collect();
    for (&(c, _), r) in jobs.iter().zip(done) {
        let r = r?;
        mismatches += r.mismatches;
        clocks += r.clocks;
        out[c].profiles.push(CaseProfile {
            name: r.result.name,
            figures: r.result.figures,
            tripped: r.tripped,
            following_peak_rad: r.following_peak_rad,
            landed_exactly: r.result.landed_exactly,
        });
    }
    Ok(MismatchReport {
        experiment: "seed001-mismatch",
        board: o.board,
        motor: o.plant.motor.name.clone(),
        loop_hz: 1.0 / (f64::from(servo_period) * f.ts),
        following_limit_rad: f64::from(gains.config.following_limit) * nominal.rad_per_count(),
        cases: out,
        mismatches: (o.board == Board::Fabric).then_some(mismatches),
        clocks,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The table the command prints.
pub fn table(r: &MismatchReport) -> String {
    let mut s = format!(
        "seed 001 on a plant that is not the model: gains from {}, the loop at {:.0} Hz on {}\n\
         case                              profile     e(T) enc   e(T) shaft   peak e     RMS e     settle s  peak FE    tripped  landed\n",
        r.motor,
        r.loop_hz,
        r.board.describe(),
    );
    let opt = |v: Option<f64>| v.map_or("never".to_string(), |x| format!("{x:.3}"));
    for c in &r.cases {
        for (k, p) in c.profiles.iter().enumerate() {
            let f = &p.figures;
            s.push_str(&format!(
                "{:<33} {:<10} {:>9.4}   {:>9.4}   {:>8.4}   {:>8.5}   {:>7}   {:>7.4}   {:<7}  {}\n",
                if k == 0 { c.case.as_str() } else { "" },
                p.name,
                f.error_at_t_rad,
                f.shaft_error_at_t_rad,
                f.peak_error_rad,
                f.rms_error_rad,
                opt(f.settle_s),
                p.following_peak_rad,
                if p.tripped { "YES" } else { "no" },
                if p.landed_exactly { "exact" } else { "NO" }
            ));
        }
    }
    s.push_str(&format!(
        "\nerrors in rad, reference − encoder (enc) or − the true shaft angle (shaft); RMS over the move and its watch; settle: from T until |e| stays ≤ {SETTLE_BAND} rad; peak FE: the largest following error the controller saw; tripped: it passed the limit ({:.3} rad) and the amplifier went off.\n",
        r.following_limit_rad
    ));
    match r.mismatches {
        Some(m) => s.push_str(&format!(
            "{} clocks co-simulated, {m} mismatches (fabric against model, every output on every clock), {:.1} s\n",
            r.clocks, r.seconds
        )),
        None => s.push_str(&format!("{} clocks simulated, {:.1} s\n", r.clocks, r.seconds)),
    }
    s
}
