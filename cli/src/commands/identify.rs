//! `snapgen identify`: the motor and its load measured on the board (issue 24, item 1). A
//! bounded excitation (`snapgen_plant::identify::excitation`: eight S-curve moves within
//! `--travel`, `--speed` and `--accel`) runs through the fabric's own position loop, tuned
//! at a low bandwidth from the data sheet's plant (`--motor`), its following-error limit armed;
//! TELEMETRY records the encoder and the duty of every controller sample
//! (`snapgen_host::identify`); the model is fitted to the record
//! (`snapgen_plant::identify`), written as a plant file (`--out`) and turned into the gains
//! for the loop you will run (`--loop-hz`, `--bandwidth-hz`…: `snapgen gains --motor FILE`
//! prints the same).
//!
//! On a real board (`--port` or `--uio`), or on the virtual one: the Verilated I/O top with
//! the device model in lockstep (`--board fabric`, every output on every clock) or the device
//! model alone (`--board model`), around a simulated motor that is `--plant FILE` (default:
//! `--motor`) with `--mismatch` factors, so that what is found can be held against what is
//! there.

use std::path::PathBuf;

use anyhow::Context;
use serde::Serialize;

use snapgen_host::identify::{record, to_record, Excitation};
use snapgen_host::limits::{stop_limits, LimitSource};
use snapgen_host::link::{FramedLink, Link, RetryPolicy};
use snapgen_host::serial::session_seq;
use snapgen_host::session::Session;
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::DEFAULT_FORMAT;
use snapgen_plant::gains::{derive, LoopDesign};
use snapgen_plant::identify::{excitation, identify, Bounds, Fit, Model};
use snapgen_plant::mismatch::Mismatch;
use snapgen_plant::PlantParams;
use snapgen_sim::closed_loop::ClosedLoop;

use super::send::{servo_setup, MotorOptions};
use crate::args::{BoardLinkArgs, MotorArgs, ServoArgs};
use crate::error::{failure, loop_failure, InputError, Mismatched};

/// Where the excitation runs without `--port`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Virtual {
    /// The Verilated I/O top, the device model in lockstep.
    Fabric,
    /// The device model alone.
    Model,
}

/// Identify the motor and its load on a board.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    link: BoardLinkArgs,
    /// Without --port: the virtual board.
    #[arg(long, value_enum, default_value = "fabric", conflicts_with_all = ["port", "uio"])]
    board: Virtual,
    /// The virtual board's motor (a plant file) [default: --motor].
    #[arg(long, conflicts_with_all = ["port", "uio"])]
    plant: Option<PathBuf>,
    /// The virtual board's motor differs from --plant by these factors (r=…,j=…,friction=…).
    #[arg(long, conflicts_with_all = ["port", "uio"])]
    mismatch: Option<String>,
    /// The excitation's largest excursion from where the shaft stands, one way (rad); with
    /// --port or --uio it must be given (the machine's room, not a default) [virtual board:
    /// 8].
    #[arg(long)]
    travel: Option<f64>,
    /// The largest duty the excitation's controller may command, a share of the PWM period
    /// (its OUTPUT_LIMIT).
    #[arg(long, default_value_t = 0.3)]
    max_duty: f64,
    /// Its largest speed (rad/s).
    #[arg(long, default_value_t = 40.0)]
    speed: f64,
    /// Its largest acceleration (rad/s²).
    #[arg(long, default_value_t = 2000.0)]
    accel: f64,
    /// The excitation's controller rate (Hz), which is the record's: one TELEMETRY frame a
    /// sample (a frame takes about 3 ms at 115 200 baud).
    #[arg(long, default_value_t = 250.0)]
    sample_hz: f64,
    /// The excitation's controller bandwidth (Hz), from the data sheet's plant.
    #[arg(long, default_value_t = 5.0)]
    excitation_bandwidth_hz: f64,
    /// The excitation's following-error limit (rad): beyond it the board switches the
    /// amplifier off and identification stops.
    #[arg(long, default_value_t = 0.5)]
    excitation_following_rad: f64,
    /// Fit the amplifier's dead time too (by default it is the plant file's, known from the
    /// gate driver: the record separates it from Coulomb friction poorly).
    #[arg(long)]
    fit_dead_time: bool,
    /// The identified plant file.
    #[arg(long, default_value = "out/identified.toml")]
    out: PathBuf,
    /// The virtual board's clock (Hz).
    #[arg(long, default_value_t = super::experiment::EXPERIMENT_CLOCK_HZ)]
    clock_hz: f64,
    /// The virtual board's Ts (s).
    #[arg(long, default_value_t = DEFAULT_FORMAT.ts)]
    ts: f64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// The data sheet: the motor's electrical constants, the amplifier and the encoder (kept
    /// in the file written), and the load and friction the excitation's controller starts from.
    #[command(flatten)]
    motor: MotorArgs,
    /// The gains printed for the identified plant (the loop you will run).
    #[command(flatten)]
    servo: ServoArgs,
}

/// What identification found.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The fit.
    pub fit: Fit,
    /// The data sheet's model (what the excitation's controller assumed).
    pub data_sheet: Model,
    /// The virtual board's motor's model (None on a real board).
    pub truth: Option<Model>,
    /// Samples recorded.
    pub samples: usize,
    /// The board's clock (Hz) and Ts (s): the gains printed are for them.
    pub clock_hz: u32,
    /// Ts.
    pub ts: f64,
    /// Runs of consecutive samples (a frame lost on the wire splits a run).
    pub runs: usize,
    /// The plant file written.
    pub plant_file: PathBuf,
    /// Clocks the fabric's outputs differed from the model's (`--board fabric` only).
    pub mismatches: Option<u64>,
}

/// Runs the subcommand: exit 1 if the fabric and the model disagree.
pub fn run(a: Args) -> anyhow::Result<()> {
    let guess = a.motor.load()?;
    let g = guess.physical();
    if guess.amplifier.kind != snapgen_plant::params::AmplifierKind::Voltage {
        return Err(InputError::Board(format!(
            "{}: identification fits an H-bridge's model (voltage in, speed out); a current-mode drive is not identified yet: give a plant file with amplifier.kind = \"voltage\"",
            guess.motor.name
        ))
        .into());
    }
    let real = a.link.port.is_some() || a.link.uio.is_some();
    let travel = match (a.travel, real) {
        (Some(t), _) => t,
        (None, false) => 8.0,
        (None, true) => {
            return Err(InputError::Board(
                "--travel: give the excitation's excursion in rad, what the machine has room for on both sides of where it stands (see the coast distance this prints)".into(),
            )
            .into())
        }
    };
    let bounds = Bounds {
        travel,
        speed: a.speed,
        accel: a.accel,
    };
    if !(a.max_duty.is_finite() && a.max_duty > 0.0 && a.max_duty <= 1.0) {
        return Err(InputError::Board(format!(
            "--max-duty {}: give a share of the PWM period in (0, 1]",
            a.max_duty
        ))
        .into());
    }
    // One TELEMETRY frame a sample: the wire must carry it in less than a sample.
    let frame_s = 10.0 * (snapgen_spec::Status::BYTES + snapgen_spec::wire::OVERHEAD) as f64
        / f64::from(a.link.baud);
    if a.sample_hz * frame_s > 0.8 {
        return Err(InputError::Board(format!(
            "--sample-hz {}: a TELEMETRY frame takes {:.2} ms at {} baud, more than 80 % of a sample: give at most {:.0} Hz or a faster baud",
            a.sample_hz,
            frame_s * 1e3,
            a.link.baud,
            0.8 / frame_s
        ))
        .into());
    }
    // If the loop trips at full speed the amplifier is off and the shaft coasts against its
    // Coulomb friction alone: J ω² / (2 Tc).
    let coast = if g.tc > 0.0 {
        g.j * a.speed * a.speed / (2.0 * g.tc)
    } else {
        f64::INFINITY
    };
    eprintln!(
        "identify: moves within {travel} rad of where the shaft stands, up to {} rad/s and {} rad/s², duty at most {:.0} %; a trip at full speed lets the shaft coast about {coast:.1} rad more (the data sheet's inertia and friction)",
        a.speed,
        a.accel,
        a.max_duty * 100.0
    );
    for (flag, v) in [
        ("--travel", travel),
        ("--speed", a.speed),
        ("--accel", a.accel),
        ("--sample-hz", a.sample_hz),
        ("--excitation-following-rad", a.excitation_following_rad),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(InputError::Board(format!("{flag} {v}: give a positive number")).into());
        }
    }
    let (report, fitted) = match a.link.direct().map_err(failure)? {
        Some((t, _)) => {
            let link = FramedLink::new(t, RetryPolicy::default(), session_seq());
            let mut s = Session::open(link, g.rad_per_count()).map_err(failure)?;
            measure(&a, &guess, &bounds, &mut s, None)?
        }
        None => {
            let truth_file = match &a.plant {
                Some(f) => {
                    PlantParams::from_file(f).map_err(|e| InputError::Board(e.to_string()))?
                }
                None => guess.clone(),
            };
            let m = match &a.mismatch {
                Some(c) => Mismatch::parse(c).map_err(|e| InputError::Board(e.to_string()))?,
                None => snapgen_plant::mismatch::NOMINAL,
            };
            let truth = m.apply(&truth_file.physical());
            let design = snapgen_hdl::verilog::io_design(
                &Design::from_timing(
                    &DEFAULT_FORMAT,
                    &Timing {
                        clock_hz: a.clock_hz as u64,
                        baud: a.link.baud,
                        ts: a.ts,
                    },
                )
                .context("the virtual board's timing")?,
            );
            let fabric = a.board == Virtual::Fabric;
            let mut l =
                ClosedLoop::new(&design, &truth, 1e-6, fabric, u64::MAX).map_err(loop_failure)?;
            l.run(1000);
            let (mut r, fitted) = {
                let mut s = l.host().map_err(failure)?;
                measure(&a, &guess, &bounds, &mut s, Some(&truth))?
            };
            r.mismatches = fabric.then(|| l.mismatches());
            (r, fitted)
        }
    };
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let head = format!(
        "Identified by `snapgen identify` ({} samples; the model alone follows {:.1} % of the speed's variation).\nThe motor's electrical constants, the amplifier and the encoder are the data sheet's ({});\nthe load's inertia and the frictions{} are measured.",
        report.samples,
        report.fit.simulation_fit_percent,
        guess.motor.name,
        if report.fit.dead_zone_fitted { ", and the dead time," } else { "" }
    );
    let text = fitted.to_toml(&head);
    // The file must be one the other commands read: a fit that leaves the data sheet's rules
    // (a dead time past 10 µs, a friction past the nominal voltage) is refused, not written.
    PlantParams::parse(&text, &a.out.display().to_string()).map_err(|e| {
        InputError::Board(format!(
            "the fitted plant is not a valid plant file ({e}): check the record (the fit explains {:.1} %)",
            report.fit.simulation_fit_percent
        ))
    })?;
    std::fs::write(&a.out, text).with_context(|| format!("cannot write {}", a.out.display()))?;
    let timing = a.servo.timing(f64::from(report.clock_hz), report.ts)?;
    let gains = derive(&fitted.physical(), &a.servo.design(), &timing)
        .map_err(|e| InputError::Board(e.to_string()))?;
    if a.json {
        let mut v = serde_json::to_value(&report)?;
        v["gains"] = super::gains::gains_json(&fitted, &timing, &gains);
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print!("{}", table(&report));
        print!("{}", super::gains::gains_text(&fitted, &timing, &gains));
    }
    if report.mismatches.is_some_and(|m| m > 0) {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

fn options(a: &Args, guess: &PlantParams) -> MotorOptions {
    MotorOptions {
        plant: guess.clone(),
        design: LoopDesign {
            bandwidth_hz: a.excitation_bandwidth_hz,
            following_limit_rad: a.excitation_following_rad,
            ..a.servo.design()
        },
        loop_hz: a.sample_hz,
        pwm_hz: a.servo.pwm_hz,
    }
}

/// Plays the excitation on the board of `s`, fits the record; the report and the plant file's
/// contents.
fn measure<L: Link>(
    a: &Args,
    guess: &PlantParams,
    bounds: &Bounds,
    s: &mut Session<L>,
    truth: Option<&snapgen_plant::Physical>,
) -> anyhow::Result<(Report, PlantParams)> {
    let g = guess.physical();
    let mut setup = servo_setup(s, &options(a, guess)).map_err(InputError::Host)?;
    setup.config.output_limit =
        ((a.max_duty * f64::from(setup.pwm_period)).round() as u16).clamp(1, setup.pwm_period);
    // The board's format, one output LSB an encoder count.
    let f = snapgen_model::Format {
        position_lsb: g.rad_per_count(),
        ..s.format
    };
    let source = |flag, v| LimitSource {
        flag,
        given: Some(v),
        peak: 1,
    };
    let (stop, _) = stop_limits(
        source("--accel", bounds.accel),
        source("--accel (× 20 as jerk)", 20.0 * bounds.accel),
        &f,
    )
    .map_err(InputError::Host)?;
    let moves = excitation(&f, bounds).map_err(InputError::from)?;
    let e = Excitation {
        pwm_period: setup.pwm_period,
        servo: setup.config,
        stop,
        moves: moves.iter().map(|p| p.program.clone()).collect(),
        settle_s: 0.1,
    };
    let frames = record(s, &e).map_err(|e| failure(e.into()))?;
    let pwm_hz = f64::from(s.identity.clock_hz) / f64::from(setup.pwm_period);
    let rec = to_record(&frames, &e, &g, f.ts, s.identity.clock_hz);
    let samples = rec.segments.iter().map(|s| s.angle.len()).sum();
    let data_sheet = Model::of(&g, pwm_hz);
    let known = (!a.fit_dead_time).then_some(data_sheet.dead_zone_v);
    let fit = identify(&rec, known).map_err(|e| InputError::Board(e.to_string()))?;
    let fitted = fit
        .plant(
            guess,
            pwm_hz,
            &format!("{} samples at {} Hz", samples, 1.0 / rec.period),
        )
        .map_err(|e| InputError::Board(e.to_string()))?;
    Ok((
        Report {
            fit,
            data_sheet,
            truth: truth.map(|t| Model::of(t, pwm_hz)),
            samples,
            clock_hz: s.identity.clock_hz,
            ts: f.ts,
            runs: rec.segments.len(),
            plant_file: a.out.clone(),
            mismatches: None,
        },
        fitted,
    ))
}

/// One parameter of a model, for the table.
type Getter = fn(&Model) -> f64;

/// The table the command prints.
pub fn table(r: &Report) -> String {
    let m = &r.fit.model;
    let mut s = format!(
        "identified from {} samples in {} runs (filter {:.0} Hz; the voltage {} the angle): the model explains {:.1} % of the speed's variation, simulated alone {:.1} %\n\n\
         parameter                                    identified   data sheet{}\n",
        r.samples,
        r.runs,
        r.fit.filter_hz,
        if r.fit.voltage_lead == 0 { "paired with" } else { "a sample ahead of" },
        r.fit.equation_fit_percent,
        r.fit.simulation_fit_percent,
        if r.truth.is_some() { "   the virtual board's motor" } else { "" }
    );
    let rows: [(&str, Getter); 4] = [
        ("K, speed per volt (rad/s/V)", |m| m.gain),
        ("τ, mechanical time constant (ms)", |m| m.tau * 1e3),
        ("u_c, Coulomb friction (V)", |m| m.coulomb_v),
        ("u_dz, the dead time's loss (V)", |m| m.dead_zone_v),
    ];
    for (name, get) in rows {
        s.push_str(&format!(
            "{name:<44} {:>10.4}   {:>10.4}",
            get(m),
            get(&r.data_sheet)
        ));
        if let Some(t) = &r.truth {
            s.push_str(&format!(
                "   {:>10.4} ({:+.1} %)",
                get(t),
                100.0 * (get(m) / get(t) - 1.0)
            ));
        }
        s.push('\n');
    }
    if !r.fit.dead_zone_fitted {
        s.push_str("(u_dz is the plant file's dead time, not fitted: --fit-dead-time fits it)\n");
    }
    s.push_str(&format!("wrote {}\n", r.plant_file.display()));
    if let Some(mm) = r.mismatches {
        s.push_str(&format!(
            "fabric against model: {mm} mismatches (every output on every clock)\n"
        ));
    }
    s.push('\n');
    s
}
