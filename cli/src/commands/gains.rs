//! `snapgen gains`: the controller's gains for a motor (pole placement at a bandwidth and
//! damping on the plant's model, docs/PLANT.md), in volts and radians, in PWM clocks and
//! counts, and the integers CONFIGURE writes.

use snapgen_plant::gains::{derive, Gains, LoopTiming};
use snapgen_plant::PlantParams;
use snapgen_spec::Param;

use crate::args::{MotorArgs, ServoArgs};
use crate::error::InputError;

/// The controller's gains for a motor.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    motor: MotorArgs,
    #[command(flatten)]
    servo: ServoArgs,
    /// The fabric clock (Hz).
    #[arg(long, default_value_t = super::experiment::EXPERIMENT_CLOCK_HZ)]
    clock_hz: f64,
    /// Tick period Ts (s).
    #[arg(long, default_value_t = snapgen_model::DEFAULT_FORMAT.ts)]
    ts: f64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let plant = a.motor.load()?;
    let t = a.servo.timing(a.clock_hz, a.ts)?;
    let g = derive(&plant.physical(), &a.servo.design(), &t)
        .map_err(|e| InputError::Board(e.to_string()))?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&gains_json(&plant, &t, &g))?
        );
    } else {
        print!("{}", gains_text(&plant, &t, &g));
    }
    Ok(())
}

/// `snapgen gains --json`.
pub fn gains_json(plant: &PlantParams, t: &LoopTiming, g: &Gains) -> serde_json::Value {
    let p = plant.physical();
    serde_json::json!({
        "motor": plant.motor.name,
        "plant": { "k_rad_per_s_per_v": g.plant_k, "tau_s": g.plant_tau, "counts_per_rev": p.counts_per_rev, "supply_v": p.vs },
        "timing": { "ts": t.ts, "servo_period_ticks": t.servo_period, "sample_s": t.sample_s(), "pwm_period_clocks": t.pwm_period },
        "bandwidth_hz": g.bandwidth_hz,
        "volts": { "kp": g.volts.kp, "ki": g.volts.ki, "kd": g.volts.kd, "kv": g.volts.kv, "ka": g.volts.ka },
        "duty": { "kp": g.physical.kp, "ki": g.physical.ki, "kd": g.physical.kd, "kv": g.physical.kv, "ka": g.physical.ka },
        "configure": configure(g, t),
    })
}

/// What CONFIGURE writes, by the spec's parameter names: the controller's group and the PWM
/// period.
fn configure(g: &Gains, t: &LoopTiming) -> serde_json::Map<String, serde_json::Value> {
    let mut m: serde_json::Map<String, serde_json::Value> = g
        .config
        .writes()
        .into_iter()
        .map(|(p, v)| (p.name().to_string(), serde_json::Value::from(v as i64)))
        .collect();
    m.insert(
        Param::PwmPeriod.name().to_string(),
        serde_json::Value::from(t.pwm_period),
    );
    m
}

/// `snapgen gains`.
pub fn gains_text(plant: &PlantParams, t: &LoopTiming, g: &Gains) -> String {
    let p = plant.physical();
    let c = &g.config;
    let drive = match p.drive {
        snapgen_plant::params::Drive::Voltage => format!(
            "H-bridge: K = {:.4} rad/s per V, τ = {:.4} s",
            g.plant_k, g.plant_tau
        ),
        snapgen_plant::params::Drive::Current { loop_rad_s, .. } => format!(
            "current-mode drive ({:.0} A full scale = {} V of command, its loop {:.0} Hz): J/Kc = {:.4e} V per rad/s²",
            p.i_limit,
            p.vs,
            loop_rad_s / (2.0 * std::f64::consts::PI),
            snapgen_plant::gains::plant_terms(&p).0
        ),
    };
    format!(
        "motor: {}\n\
         plant: {} (J {:.4e} kg·m², R {} Ω, Kt {} N·m/A), {} counts/rev, supply {} V\n\
         loop: sample {} ticks of {} s ({:.0} Hz), PWM period {} clocks; bandwidth {:.2} Hz\n\
         \n\
         gain  volts and radians          PWM clocks, counts, samples, ticks   CONFIGURE\n\
         KP    {:>12.5e} V/rad          {:>12.5e} per count                   {}\n\
         KI    {:>12.5e} V/(rad·s)      {:>12.5e} per count·sample            {}\n\
         KD    {:>12.5e} V·s/rad        {:>12.5e} per count/sample            {}\n\
         KV    {:>12.5e} V·s/rad        {:>12.5e} per count/tick              {}\n\
         KA    {:>12.5e} V·s²/rad       {:>12.5e} per count/tick²             {}\n\
         INTEGRAL_LIMIT {}  OUTPUT_LIMIT {}  FOLLOWING_LIMIT {} counts  D_FILTER {}  SERVO_PERIOD {}  PWM_PERIOD {}\n",
        plant.motor.name,
        drive,
        p.j,
        p.r,
        p.kt,
        p.counts_per_rev,
        p.vs,
        t.servo_period,
        t.ts,
        1.0 / t.sample_s(),
        t.pwm_period,
        g.bandwidth_hz,
        g.volts.kp,
        g.physical.kp,
        c.kp,
        g.volts.ki,
        g.physical.ki,
        c.ki,
        g.volts.kd,
        g.physical.kd,
        c.kd,
        g.volts.kv,
        g.physical.kv,
        c.kv,
        g.volts.ka,
        g.physical.ka,
        c.ka,
        c.integral_limit,
        c.output_limit,
        c.following_limit,
        c.d_filter,
        c.servo_period,
        t.pwm_period,
    )
}
