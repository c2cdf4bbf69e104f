//! `snapgen experiment seed001`: seed 001's experiment on the closed loop — the S-curve of
//! Table 1, the trapezoid at 32 rad/s, an order-4 profile of the same duration, and Table 3's
//! return — each on a motor at rest, with the controller in the fabric (at `--loop-hz`), then
//! at the seed's 5 ms host-loop rate (with and without the feed-forward the seed's controller
//! did not have). Prints each profile's figures beside the paper's, writes the error and the
//! control signal against time as SVG (the seed's Figures 10, 12 and 15), and with `--json`
//! one object.
//!
//! The loop runs on the Verilated I/O top with the device model in lockstep (`fabric`: every
//! output compared on every clock; `mismatches` counts the clocks that differ), on the device
//! model alone (`model`), or on the fast model-only loop (`fast`, `snapgen_plant::fast`).
//!
//! With `--mismatch`, the gains come from the plant file and the loop runs plants that differ
//! from it ([`mismatch`]).

mod mismatch;

use std::path::{Path, PathBuf};

use anyhow::Context;
use serde::Serialize;

use snapgen_host::protocol::{AxisState, ErrorId};
use snapgen_model::device::Design;
use snapgen_model::io::servo::{ServoConfig, E_FRAC};
use snapgen_model::timing::Timing;
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plant::fast::{FabricTiming, FastLoop, LoopSample};
use snapgen_plant::gains::{derive, Gains, LoopDesign, LoopTiming};
use snapgen_plant::metrics::{figures, MoveFigures, MoveSpan};
use snapgen_plant::seed001::{profiles, PaperFigures, Profile, SETTLE_BAND};
use snapgen_plant::{Physical, PlantParams};
use snapgen_sim::closed_loop::{AxisSetup, ClosedLoop};

use crate::args::{MotorArgs, ServoArgs};
use crate::error::{InputError, Mismatched};

/// Which experiment.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Which {
    /// Seed 001, sections 3 and 4.
    Seed001,
}

/// Seed 001's experiment on the closed loop.
#[derive(clap::Args)]
pub struct Args {
    /// Which experiment.
    #[arg(value_enum)]
    which: Which,
    /// Where the loop runs: the Verilated I/O top with the device model in lockstep, the
    /// device model, or the fast model-only loop.
    #[arg(long, value_enum, default_value = "fabric")]
    board: Board,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
    /// Directory for the SVG plots.
    #[arg(long, default_value = "out/seed001")]
    out: PathBuf,
    /// Only the S-curve and the trapezoid, watched 0.5 s after their end.
    #[arg(long)]
    short: bool,
    /// Leave out the 5 ms host-loop runs.
    #[arg(long)]
    no_host_loop: bool,
    /// The 5 ms host loops' transport delay (ms): each duty reaches the PWM this much later
    /// than the fabric's controller's (the seed's Raspberry Pi: the count over the UART, the
    /// control computed, the command back). `--board fast` only: the fabric's controller has
    /// none.
    #[arg(long, default_value_t = 0.0)]
    transport_delay_ms: f64,
    /// The fabric clock (Hz).
    #[arg(long, default_value_t = EXPERIMENT_CLOCK_HZ)]
    clock_hz: f64,
    /// Tick period Ts (s).
    #[arg(long, default_value_t = DEFAULT_FORMAT.ts)]
    ts: f64,
    /// The plant's integration step (µs).
    #[arg(long, default_value_t = 1.0)]
    step_us: f64,
    /// Robustness to a wrong model: the gains are derived from the plant file (`--motor`), the
    /// S-curve and the trapezoid run on the fabric-rate loop with plants that differ from it,
    /// each case factors `r=1.4,j=0.7,friction=2` (resistance, inertia, Coulomb and viscous
    /// friction; a factor left out is 1), after the nominal plant. Without a case: the standard sweep (nominal, R +40 %,
    /// J ±30 %, friction ×2 and the two corners). Writes no plots.
    #[arg(long, num_args = 0.., value_name = "CASE")]
    mismatch: Option<Vec<String>>,
    #[command(flatten)]
    motor: MotorArgs,
    #[command(flatten)]
    servo: ServoArgs,
}

/// Runs the subcommand: exit 1 if the fabric and the model disagree.
pub fn run(a: Args) -> anyhow::Result<()> {
    let Which::Seed001 = a.which;
    let plant = a.motor.load()?;
    let t = a.servo.timing(a.clock_hz, a.ts)?;
    if !(a.step_us.is_finite() && a.step_us > 0.0) {
        return Err(InputError::Board(format!(
            "--step-us {}: give a positive step in µs",
            a.step_us
        ))
        .into());
    }
    if !(a.transport_delay_ms.is_finite() && (0.0..=1000.0).contains(&a.transport_delay_ms)) {
        return Err(InputError::Board(format!(
            "--transport-delay-ms {}: give 0 to 1000 ms",
            a.transport_delay_ms
        ))
        .into());
    }
    if a.transport_delay_ms > 0.0 && a.board != Board::Fast {
        return Err(InputError::Board(
            "--transport-delay-ms models a host's loop: it runs on --board fast only (the fabric's controller, and its model, have no transport delay)".into(),
        )
        .into());
    }
    let o = Options {
        transport_delay_s: a.transport_delay_ms * 1e-3,
        board: a.board,
        plant,
        clock_hz: a.clock_hz,
        ts: a.ts,
        pwm_hz: a.clock_hz / f64::from(t.pwm_period),
        loop_hz: 1.0 / (f64::from(t.servo_period) * a.ts),
        design: a.servo.design(),
        host_loop: !a.no_host_loop,
        short: a.short,
        step_s: a.step_us * 1e-6,
        out: Some(a.out),
    };
    if let Some(cases) = &a.mismatch {
        if o.transport_delay_s > 0.0 {
            return Err(InputError::Board(
                "--mismatch runs the fabric-rate loop only: --transport-delay-ms (the 5 ms host loops') does not apply".into(),
            )
            .into());
        }
        return mismatch::run(&o, cases, a.json);
    }
    let r = play(&o)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", table(&r));
    }
    if r.mismatches.is_some_and(|m| m > 0) {
        return Err(anyhow::Error::new(Mismatched));
    }
    Ok(())
}

/// Where the loop runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Board {
    /// The Verilated I/O top, the device model in lockstep.
    Fabric,
    /// The device model alone.
    Model,
    /// The fast model-only loop.
    Fast,
}

impl Board {
    /// What it is, for a table's heading.
    pub fn describe(self) -> &'static str {
        match self {
            Board::Fabric => "the Verilated I/O top (the device model in lockstep)",
            Board::Model => "the device model",
            Board::Fast => "the fast model-only loop",
        }
    }
}

/// The experiment's settings.
#[derive(Clone, Debug)]
pub struct Options {
    /// Where the loop runs.
    pub board: Board,
    /// The plant.
    pub plant: PlantParams,
    /// Fabric clock (Hz).
    pub clock_hz: f64,
    /// Tick (s).
    pub ts: f64,
    /// PWM frequency (Hz).
    pub pwm_hz: f64,
    /// The fabric loop's rate (Hz).
    pub loop_hz: f64,
    /// Bandwidth and damping.
    pub design: LoopDesign,
    /// Also the seed's 5 ms host-loop rate.
    pub host_loop: bool,
    /// The host loops' transport delay (s; `fast` only).
    pub transport_delay_s: f64,
    /// Only the S-curve and the trapezoid, with a shorter watch after each.
    pub short: bool,
    /// The plant's integration step (s).
    pub step_s: f64,
    /// Where the SVG plots go (none: no plots).
    pub out: Option<PathBuf>,
}

/// One profile's outcome on one loop.
#[derive(Clone, Debug, Serialize)]
pub struct ProfileResult {
    /// `scurve`, `trapezoid`, `order4`, `return`.
    pub name: &'static str,
    /// The figures.
    #[serde(flatten)]
    pub figures: MoveFigures,
    /// The paper's.
    pub paper: PaperFigures,
    /// The board's registers at the end are the plan's, bit for bit (the reference landed
    /// exactly).
    pub landed_exactly: bool,
    /// The samples (not in the JSON).
    #[serde(skip)]
    pub samples: Vec<LoopSample>,
}

/// One loop (a rate, with or without feed-forward) over the profiles.
#[derive(Clone, Debug, Serialize)]
pub struct LoopResult {
    /// What it is.
    pub name: String,
    /// Sample rate (Hz).
    pub loop_hz: f64,
    /// Feed-forward on.
    pub feed_forward: bool,
    /// The gains.
    pub gains: GainsReport,
    /// The profiles.
    pub profiles: Vec<ProfileResult>,
}

/// The gains as the JSON gives them.
#[derive(Clone, Debug, Serialize)]
pub struct GainsReport {
    /// Bandwidth used (Hz).
    pub bandwidth_hz: f64,
    /// In volts and radians: `kp` V/rad, `ki` V/(rad·s), `kd` V·s/rad, `kv` V·s/rad, `ka`
    /// V·s²/rad.
    pub volts: [f64; 5],
    /// CONFIGURE's integers: KP, KI, KD, KV, KA, INTEGRAL_LIMIT, OUTPUT_LIMIT, FOLLOWING_LIMIT.
    pub registers: [i64; 8],
}

impl GainsReport {
    fn of(g: &Gains) -> Self {
        let c = &g.config;
        GainsReport {
            bandwidth_hz: g.bandwidth_hz,
            volts: [g.volts.kp, g.volts.ki, g.volts.kd, g.volts.kv, g.volts.ka],
            registers: [
                c.kp,
                c.ki,
                c.kd,
                c.kv,
                c.ka,
                c.integral_limit,
                i64::from(c.output_limit),
                i64::from(c.following_limit),
            ],
        }
    }
}

/// The whole experiment.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// `seed001`.
    pub experiment: &'static str,
    /// Where it ran.
    pub board: Board,
    /// The motor.
    pub motor: String,
    /// Fabric clock (Hz), tick (s), PWM (Hz).
    pub clock_hz: f64,
    /// Tick.
    pub ts: f64,
    /// PWM frequency.
    pub pwm_hz: f64,
    /// The fabric loop's profiles (`fabric`'s figures).
    pub profiles: Vec<ProfileResult>,
    /// Every loop: the fabric loop first, then the 5 ms host-loop ones.
    pub loops: Vec<LoopResult>,
    /// Clocks the fabric's outputs differed from the model's (`fabric` only; null otherwise).
    pub mismatches: Option<u64>,
    /// Clocks simulated.
    pub clocks: u64,
    /// Wall time (s).
    pub seconds: f64,
}

/// The format of a board whose output LSB is one count of `p`'s encoder.
fn format(p: &Physical, ts: f64) -> Format {
    Format {
        ts,
        position_lsb: p.rad_per_count(),
        ..DEFAULT_FORMAT
    }
}

/// The design, the format and the PWM period of an experiment's options.
struct Setup {
    design: Design,
    format: Format,
    pwm_period: u16,
}

impl Setup {
    fn of(o: &Options) -> anyhow::Result<Self> {
        let timing = Timing {
            clock_hz: o.clock_hz as u64,
            baud: snapgen_model::timing::DEFAULT_BAUD,
            ts: o.ts,
        };
        let design = snapgen_hdl::verilog::io_design(
            &Design::from_timing(&DEFAULT_FORMAT, &timing).context("the experiment's timing")?,
        );
        let format = format(&o.plant.physical(), design.ts());
        let pwm_period = (o.clock_hz / o.pwm_hz).round();
        if !(1.0..=32767.0).contains(&pwm_period) {
            anyhow::bail!(
                "--pwm-hz {}: {} clocks per PWM period at {} Hz; give a rate with 1 to 32 767",
                o.pwm_hz,
                pwm_period,
                o.clock_hz
            );
        }
        Ok(Setup {
            design,
            format,
            pwm_period: pwm_period as u16,
        })
    }
}

/// SERVO_PERIOD for a loop at `hz`: whole ticks of `f`.
fn servo_ticks(f: &Format, hz: f64) -> u16 {
    ((1.0 / hz) / f.ts).round().clamp(1.0, 65535.0) as u16
}

/// Runs it.
pub fn play(o: &Options) -> anyhow::Result<Report> {
    let started = std::time::Instant::now();
    let p = o.plant.physical();
    let Setup {
        design,
        format: f,
        pwm_period,
    } = Setup::of(o)?;
    let ticks = |hz: f64| servo_ticks(&f, hz);
    let mut loops = vec![("fabric", ticks(o.loop_hz), o.design.feed_forward, 0.0)];
    if o.host_loop {
        let d = o.transport_delay_s;
        loops.push(("host 5 ms", ticks(200.0), o.design.feed_forward, d));
        loops.push(("host 5 ms, feedback only", ticks(200.0), false, d));
    }
    let window = if o.short { 0.5 } else { 1.2 };
    let mut all = profiles(&f, 0.05, window)?;
    if o.short {
        all.retain(|p| matches!(p.name, "scurve" | "trapezoid"));
    }
    let (mut mismatches, mut clocks) = (0u64, 0u64);
    let mut gains = Vec::new();
    for &(_, period, ff, _) in &loops {
        gains.push(derive(
            &p,
            &LoopDesign {
                feed_forward: ff,
                ..o.design
            },
            &LoopTiming {
                ts: f.ts,
                servo_period: period,
                pwm_period,
            },
        )?);
    }
    // Every (loop, profile) run is independent.
    let jobs: Vec<(usize, usize)> = (0..loops.len())
        .flat_map(|l| (0..all.len()).map(move |k| (l, k)))
        .collect();
    let done = in_parallel(&jobs, |&(l, k)| {
        let setup = LoopSetup {
            servo: gains[l].config,
            pwm_period,
            delay_s: loops[l].3,
        };
        run_profile(o, &design, &f, &p, &setup, &all[k])
            .with_context(|| format!("{} on the {} loop", all[k].name, loops[l].0))
    });
    let mut per_loop: Vec<Vec<ProfileResult>> = vec![Vec::new(); loops.len()];
    for (&(l, _), r) in jobs.iter().zip(done) {
        let r = r?;
        mismatches += r.mismatches;
        clocks += r.clocks;
        per_loop[l].push(r.result);
    }
    let mut results = Vec::new();
    for ((name, period, ff, delay), (gains, out)) in
        loops.into_iter().zip(gains.iter().zip(per_loop))
    {
        results.push(LoopResult {
            name: format!(
                "{name} ({:.0} Hz{}{})",
                1.0 / (f64::from(period) * f.ts),
                if ff { ", feed-forward" } else { "" },
                if delay > 0.0 {
                    format!(", {:.1} ms delay", delay * 1e3)
                } else {
                    String::new()
                }
            ),
            loop_hz: 1.0 / (f64::from(period) * f.ts),
            feed_forward: ff,
            gains: GainsReport::of(gains),
            profiles: out,
        });
    }
    let report = Report {
        experiment: "seed001",
        board: o.board,
        motor: o.plant.motor.name.clone(),
        clock_hz: o.clock_hz,
        ts: f.ts,
        pwm_hz: o.clock_hz / f64::from(pwm_period),
        profiles: results[0].profiles.clone(),
        loops: results,
        mismatches: (o.board == Board::Fabric).then_some(mismatches),
        clocks,
        seconds: started.elapsed().as_secs_f64(),
    };
    if let Some(dir) = &o.out {
        write_plots(&report, dir, p.vs / f64::from(pwm_period))?;
    }
    Ok(report)
}

/// `f` of every job, as many at once as there are cores; the results in the jobs' order.
fn in_parallel<J: Sync, R: Send>(jobs: &[J], f: impl Fn(&J) -> R + Sync) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(jobs.len());
    let done = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(job) = jobs.get(i) else { break };
                let r = f(job);
                done.lock().expect("no worker panics").push((i, r));
            });
        }
    });
    let mut done = done.into_inner().expect("no worker panics");
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}

/// One profile's run on one loop.
struct Run {
    result: ProfileResult,
    /// Clocks the fabric differed from the model.
    mismatches: u64,
    /// Clocks simulated.
    clocks: u64,
    /// The following error passed its limit: the amplifier went off (FOLLOWING_ERROR).
    tripped: bool,
    /// The largest following error at a sample (rad): the board's own record (`fabric`,
    /// `model`), the samples' (`fast`).
    following_peak_rad: f64,
}

/// One loop's controller: its registers, the PWM period and a host's transport delay (s).
struct LoopSetup {
    servo: ServoConfig,
    pwm_period: u16,
    delay_s: f64,
}

/// One profile on one loop.
fn run_profile(
    o: &Options,
    design: &Design,
    f: &Format,
    p: &Physical,
    setup: &LoopSetup,
    prof: &Profile,
) -> anyhow::Result<Run> {
    let (servo, pwm_period) = (&setup.servo, setup.pwm_period);
    let volts_per_duty = p.vs / f64::from(pwm_period);
    let last_end = prof.span.window_end;
    let record_every = (f64::from(design.clock_hz) * 1e-4).round().max(1.0) as u64;
    let (samples, starts, landed, mismatches, clocks, tripped, peak) = match o.board {
        Board::Fast => {
            let timing = FabricTiming {
                clock_hz: f64::from(design.clock_hz),
                clocks_per_tick: u64::from(design.dividers.tick_div) + 1,
                pwm_period,
            };
            let mut l =
                FastLoop::new(p, f, timing, *servo, o.step_s)?.with_transport_delay(setup.delay_s);
            let mut samples = Vec::new();
            let mut starts = Vec::new();
            for (t, plan) in &prof.moves {
                l.run_until(*t, |s| samples.push(*s));
                starts.push(l.play(&plan.program));
            }
            l.run_until(last_end, |s| samples.push(*s));
            let want = prof.moves.last().map(|(_, p)| p.final_state);
            let landed = want == Some(l.chain());
            let clocks = (last_end * f64::from(design.clock_hz)) as u64;
            let peak = samples.iter().map(|s| s.error().abs()).fold(0.0, f64::max);
            let tripped = l.tripped().is_some();
            (samples, starts, landed, 0, clocks, tripped, peak)
        }
        Board::Fabric | Board::Model => {
            let mut l =
                ClosedLoop::new(design, p, o.step_s, o.board == Board::Fabric, record_every)?;
            l.run(1000);
            let stop = AxisSetup::stop_limits(f).map_err(InputError::Host)?;
            l.setup(&AxisSetup {
                pwm_period,
                servo: *servo,
                stop,
            })
            .map_err(crate::error::loop_failure)?;
            let origin = l.time();
            for (t, plan) in &prof.moves {
                l.run_until(origin + t);
                l.start(&plan.program).map_err(crate::error::loop_failure)?;
            }
            let starts = l.starts();
            // The watch after the last move, from its real start.
            let last_start = starts.last().copied().unwrap_or(origin);
            let last_plan = &prof.moves.last().expect("a profile has moves").1;
            l.run_until(
                last_start + last_plan.ticks_total() as f64 * f.ts + (last_end - prof.span.end),
            );
            let mut host = l.host().map_err(crate::error::failure)?;
            let s = host.state()?;
            let st = host.status()?;
            drop(host);
            let landed = s.x == last_plan.final_state.x && (s.v, s.a, s.j) == (0, 0, 0);
            let tripped =
                st.state == AxisState::ErrorStop as u8 && st.error == ErrorId::FollowingError as u8;
            let peak = f64::from(st.following_peak) / f64::from(1u32 << E_FRAC) * p.rad_per_count();
            let samples = l.take_samples();
            (
                samples,
                starts,
                landed,
                l.mismatches(),
                l.clocks(),
                tripped,
                peak,
            )
        }
    };
    // The reported move's span, from when it really started.
    let k = prof.moves.len() - 1;
    let start = starts.get(k).copied().unwrap_or(prof.span.start);
    let shift = start - prof.moves[k].0;
    let span = MoveSpan {
        start,
        end: prof.span.end + shift,
        window_end: prof.span.window_end + shift,
    };
    let figs = figures(&samples, &span, SETTLE_BAND, volts_per_duty)
        .context("no samples in the move's span")?;
    Ok(Run {
        result: ProfileResult {
            name: prof.name,
            figures: figs,
            paper: prof.paper,
            landed_exactly: landed,
            samples,
        },
        mismatches,
        clocks,
        tripped,
        following_peak_rad: peak,
    })
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".to_string(), |x| format!("{x:.digits$}"))
}

/// The table the command prints.
pub fn table(r: &Report) -> String {
    let mut s = format!(
        "seed 001's experiment on {}: {}, {} Hz clock, Ts {} s, PWM {:.0} Hz\n",
        r.board.describe(),
        r.motor,
        r.clock_hz,
        r.ts,
        r.pwm_hz
    );
    for l in &r.loops {
        s.push_str(&format!(
            "  {}: bandwidth {:.1} Hz; KP {} KI {} KD {} KV {} KA {}\n",
            l.name,
            l.gains.bandwidth_hz,
            l.gains.registers[0],
            l.gains.registers[1],
            l.gains.registers[2],
            l.gains.registers[3],
            l.gains.registers[4]
        ));
    }
    s.push_str(
        "\nprofile    loop                                   e(T) rad   peak e rad  peak ω rad/s  peak u V  settle s  landed\n",
    );
    let names: Vec<&str> = r.profiles.iter().map(|p| p.name).collect();
    for name in names {
        let paper = r.profiles.iter().find(|p| p.name == name).map(|p| p.paper);
        if let Some(pp) = paper {
            s.push_str(&format!(
                "{name:<10} {:<38} {:>8}   {:>9}   {:>11}   {:>7}   {:>7}\n",
                "paper (Raspberry Pi, 5 ms)",
                opt(pp.error_at_t_rad, 3),
                "—",
                opt(pp.peak_velocity, 1),
                opt(pp.peak_effort, 2),
                opt(pp.settle_s, 2)
            ));
        }
        for l in &r.loops {
            if let Some(p) = l.profiles.iter().find(|p| p.name == name) {
                let f = &p.figures;
                s.push_str(&format!(
                    "{:<10} {:<38} {:>8.4}   {:>9.4}   {:>11.2}   {:>7.2}   {:>7}   {}\n",
                    "",
                    l.name,
                    f.error_at_t_rad,
                    f.peak_error_rad,
                    f.peak_velocity,
                    f.peak_effort,
                    opt(f.settle_s, 3),
                    if p.landed_exactly { "exact" } else { "NO" }
                ));
            }
        }
    }
    s.push_str(&format!(
        "\ne(T): reference − encoder when the reference reaches its end (rad); peak e: the largest |e| from the move's start to the end of the watch; peak u: the largest commanded voltage; settle: from T until |e| stays ≤ {SETTLE_BAND} rad; landed: the board's registers end on the plan's, bit for bit.\n"
    ));
    if let Some(m) = r.mismatches {
        s.push_str(&format!(
            "{} clocks co-simulated, {m} mismatches (fabric against model, every output on every clock), {:.1} s\n",
            r.clocks, r.seconds
        ));
    } else {
        s.push_str(&format!(
            "{} clocks simulated, {:.1} s\n",
            r.clocks, r.seconds
        ));
    }
    s
}

/// The seed's figures: error and control signal against time, one SVG per profile.
fn write_plots(r: &Report, dir: &Path, volts_per_duty: f64) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for name in ["scurve", "trapezoid", "order4", "return"] {
        let series: Vec<(String, &[LoopSample])> = r
            .loops
            .iter()
            .filter_map(|l| {
                l.profiles
                    .iter()
                    .find(|p| p.name == name)
                    .map(|p| (l.name.clone(), p.samples.as_slice()))
            })
            .collect();
        if series.is_empty() {
            continue;
        }
        let file = match name {
            "trapezoid" => "fig10-trapezoid.svg",
            "scurve" => "fig12-scurve.svg",
            "return" => "fig15-return.svg",
            _ => "order4.svg",
        };
        let title = format!("seed 001, {name}: position error and control signal");
        crate::svg::write_loop_svg(&title, &series, volts_per_duty, &dir.join(file))
            .map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
        eprintln!("wrote {}", dir.join(file).display());
    }
    Ok(())
}

/// The default clock of the experiment's design (Hz).
pub const EXPERIMENT_CLOCK_HZ: f64 = 10e6;
