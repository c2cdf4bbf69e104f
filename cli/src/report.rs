//! Plan reports: one JSON object (`--json`) or a human-readable summary.
//!
//! Physical values are in user units and seconds; raw values are the integers the fabric holds.
//! Snap values in `segments` exceed 2^53: read the JSON with a reader that keeps big integers
//! (Python's `json` does).

use ethnum::I256;
use serde::Serialize;
use snapgen_model::{Quantity, Segment, FRAC_BITS};
use snapgen_plan::{planner::DurationValues, Plan};

/// Peak magnitudes over every tick of the move: the program integrated independently of the
/// planner (snapgen-verify: exact, closed form per segment, per-tick extremes).
#[derive(Serialize)]
pub struct PeakReport {
    /// max |v| (units/s).
    pub v: f64,
    /// max |a| (units/s²).
    pub a: f64,
    /// max |j| (units/s³).
    pub j: f64,
    /// max |d| (units/s⁴).
    pub d: f64,
}

/// State at the end of the move, from the same independent integration.
#[derive(Serialize)]
pub struct FinalReport {
    /// Output position reached (whole output LSBs × LSB, units, from the start): what the
    /// fabric's position port shows. The sub-LSB remainder is `final_residual_lsb`.
    pub x: f64,
    /// Velocity (units/s).
    pub v: f64,
    /// Acceleration (units/s²).
    pub a: f64,
    /// Jerk (units/s³).
    pub j: f64,
}

/// Phase times in ticks; only the order's phases are present.
#[derive(Serialize, Default)]
pub struct PhaseReport {
    /// t_d (order 4).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d: Option<u64>,
    /// t_j (orders 4, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub j: Option<u64>,
    /// t_a.
    pub a: u64,
    /// t_v (cruise).
    pub v: u64,
}

/// The format the plan is for.
#[derive(Serialize)]
pub struct FormatReport {
    /// Tick period (s).
    pub ts: f64,
    /// Output position LSB (units).
    pub position_lsb: f64,
    /// Fractional bits below the output LSB.
    pub frac_bits: u32,
    /// Register widths x, v, a, j, d.
    pub widths: [u32; 5],
}

/// The `--json` object of `snapgen plan`.
#[derive(Serialize)]
pub struct PlanReport {
    /// 4, 3 or 2.
    pub order: u8,
    /// "order4", "order3", "order2" or "duration".
    pub method: &'static str,
    /// Tick period (s).
    pub ts: f64,
    /// Ticks the program lasts.
    pub ticks_total: u64,
    /// Seconds the program lasts.
    pub duration_s: f64,
    /// Phase times in ticks: order 4 {d,j,a,v}; order 3 {j,a,v}; order 2 {a,v}.
    pub phase_ticks: PhaseReport,
    /// Cruise ticks added so the integer trace respects the limits.
    pub cruise_extension_ticks: u64,
    /// The program.
    pub segments: Vec<Segment>,
    /// Integer amplitude of the program (snap, jerk or acceleration raw, signed).
    pub amplitude_raw: i128,
    /// Amplitude after the continuous planner's last recomputation (physical, signed).
    pub continuous_amplitude: f64,
    /// Peaks over every tick (independent integration of the program).
    pub peak: PeakReport,
    /// Final state (independent integration of the program).
    pub r#final: FinalReport,
    /// Requested distance (units).
    pub distance: f64,
    /// Target: the distance rounded to whole output LSBs (units).
    pub target: f64,
    /// Target in output LSBs.
    pub target_lsb: i128,
    /// Final output position minus the requested distance (units); ≤ half an LSB.
    pub final_position_error: f64,
    /// Final output position minus the target, in output LSBs (0 for every plan).
    pub final_error_lsb: i128,
    /// Position register minus the target cell's centre, as a fraction of an output LSB.
    pub final_residual_lsb: f64,
    /// Physical size of one output LSB (units).
    pub position_lsb: f64,
    /// The fixed-point format.
    pub format: FormatReport,
    /// Seed 001: ω_d (units/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity: Option<f64>,
    /// Seed 001: α_d (units/s²).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration: Option<f64>,
    /// Seed 001: J_d (units/s³).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jerk: Option<f64>,
    /// Seed 001: T_acc (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub t_acc: Option<f64>,
    /// Seed 001: T_jerk (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub t_jerk: Option<f64>,
}

/// A plan's program integrated from its start register by snapgen-verify (exact, closed form
/// per segment, per-tick extremes), independently of the planner.
pub fn integrate_plan(p: &Plan) -> snapgen_verify::Integration {
    let s = p.start;
    snapgen_verify::integrate(
        snapgen_verify::State::new(s.x, s.v, s.a, s.j),
        p.program
            .segments
            .iter()
            .map(|g| (u64::from(g.ticks), g.snap)),
    )
}

impl PlanReport {
    /// Builds the report of a plan. Its `peak`, `final` and `final_*` fields come from
    /// integrating the program from the plan's start register with snapgen-verify, not from
    /// the planner's own numbers.
    pub fn new(p: &Plan) -> Self {
        let f = &p.format;
        let s = p.start;
        let run = integrate_plan(p);
        let physical = |q: Quantity, raw: I256| raw.as_f64() / f.scale(q);
        let peak = |q: Quantity, k: usize| physical(q, run.range(k).max_abs());
        // Output cells: x >> FRAC_BITS (what the fabric's position port shows).
        let start_cell = I256::from(s.x) >> FRAC_BITS;
        let end_cell = run.end.x >> FRAC_BITS;
        let moved_lsb = (end_cell - start_cell).as_i128();
        let target_centre =
            ((start_cell + I256::from(p.target_lsb)) << FRAC_BITS) + (I256::ONE << (FRAC_BITS - 1));
        let dv: Option<DurationValues> = p.duration_values;
        let order = p.order();
        let phase_ticks = PhaseReport {
            d: (order == 4).then_some(p.phases.d),
            j: (order >= 3).then_some(p.phases.j),
            a: p.phases.a,
            v: p.phases.v,
        };
        PlanReport {
            order,
            method: match p.request.method {
                snapgen_plan::Method::Order4 { .. } => "order4",
                snapgen_plan::Method::Order3 { .. } => "order3",
                snapgen_plan::Method::Order2 { .. } => "order2",
                snapgen_plan::Method::Duration { .. } => "duration",
            },
            ts: f.ts,
            ticks_total: p.ticks_total(),
            duration_s: p.duration_s(),
            phase_ticks,
            cruise_extension_ticks: p.cruise_extension,
            segments: p.program.segments.clone(),
            amplitude_raw: p.amplitude_raw,
            continuous_amplitude: p.continuous_amplitude,
            peak: PeakReport {
                v: peak(Quantity::Velocity, 1),
                a: peak(Quantity::Acceleration, 2),
                j: peak(Quantity::Jerk, 3),
                d: peak(Quantity::Snap, 4),
            },
            r#final: FinalReport {
                x: moved_lsb as f64 * f.position_lsb,
                v: physical(Quantity::Velocity, run.end.v),
                a: physical(Quantity::Acceleration, run.end.a),
                j: physical(Quantity::Jerk, run.end.j),
            },
            distance: p.request.distance,
            target: p.target_physical(),
            target_lsb: p.target_lsb,
            final_position_error: moved_lsb as f64 * f.position_lsb - p.request.distance,
            final_error_lsb: moved_lsb - p.target_lsb,
            final_residual_lsb: (run.end.x - target_centre).as_f64() / (1u128 << FRAC_BITS) as f64,
            position_lsb: f.position_lsb,
            format: FormatReport {
                ts: f.ts,
                position_lsb: f.position_lsb,
                frac_bits: FRAC_BITS,
                widths: f.widths.as_array(),
            },
            velocity: dv.map(|d| d.velocity),
            acceleration: dv.map(|d| d.acceleration),
            jerk: dv.map(|d| d.jerk),
            t_acc: dv.map(|d| d.t_acc),
            t_jerk: dv.map(|d| d.t_jerk),
        }
    }

    /// The human-readable summary.
    pub fn human(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} move of {} units (target {} = {} LSB of {:e} units), Ts = {} s",
            self.method, self.distance, self.target, self.target_lsb, self.position_lsb, self.ts
        );
        if let (Some(v), Some(a), Some(j), Some(ta), Some(tj)) = (
            self.velocity,
            self.acceleration,
            self.jerk,
            self.t_acc,
            self.t_jerk,
        ) {
            let _ = writeln!(
                s,
                "  seed 001: velocity {v:.4} units/s, acceleration {a:.4} units/s^2, jerk {j:.4} units/s^3, T_acc {ta:.4} s, T_jerk {tj:.4} s"
            );
        }
        let ph = &self.phase_ticks;
        let phases: Vec<String> = [
            ("d", ph.d),
            ("j", ph.j),
            ("a", Some(ph.a)),
            ("v", Some(ph.v)),
        ]
        .iter()
        .filter_map(|(k, v)| v.map(|v| format!("t_{k} = {v}")))
        .collect();
        let _ = writeln!(
            s,
            "  phases (ticks): {}{}",
            phases.join(", "),
            if self.cruise_extension_ticks > 0 {
                format!(
                    " (cruise lengthened by {} ticks to keep the integer trace within limits)",
                    self.cruise_extension_ticks
                )
            } else {
                String::new()
            }
        );
        let _ = writeln!(
            s,
            "  duration: {} ticks = {:.6} s in {} segments",
            self.ticks_total,
            self.duration_s,
            self.segments.len()
        );
        let _ = writeln!(
            s,
            "  peaks (every tick, integrated independently): |v| {:.6} units/s, |a| {:.6} units/s^2, |j| {:.6} units/s^3, |d| {:.6} units/s^4",
            self.peak.v, self.peak.a, self.peak.j, self.peak.d
        );
        let _ = writeln!(
            s,
            "  final: x {} units, v {}, a {}, j {}; output error {} LSB, residual {:.3e} LSB, vs request {:.3e} units",
            self.r#final.x,
            self.r#final.v,
            self.r#final.a,
            self.r#final.j,
            self.final_error_lsb,
            self.final_residual_lsb,
            self.final_position_error
        );
        let _ = writeln!(s, "  program (ticks x raw snap):");
        for (i, seg) in self.segments.iter().enumerate() {
            let _ = writeln!(s, "    {i:>3}: {:>10} x {}", seg.ticks, seg.snap);
        }
        s
    }
}

/// The format as a Markdown table: widths, LSB and range of every register, and the limits on
/// moves.
pub fn format_table(f: &snapgen_model::Format) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Ts = {} s, output position LSB = {} units, {} fractional bits below it (internal LSB {:e} units)\n",
        f.ts,
        f.position_lsb,
        FRAC_BITS,
        f.internal_lsb()
    );
    let _ = writeln!(s, "| register | bits | LSB | largest magnitude |");
    let _ = writeln!(s, "|---|---|---|---|");
    for r in f.ranges() {
        let _ = writeln!(
            s,
            "| {} ({}) | {} | {:.3e} | {:.3e} |",
            r.quantity.name(),
            r.quantity.unit(),
            r.bits,
            r.lsb,
            r.max
        );
    }
    let _ = writeln!(
        s,
        "\nlongest move: ±{:.6} units from the centre of cell 0 (±{} output LSBs)",
        f.max_distance(),
        (f.max_distance() / f.position_lsb).round()
    );
    let _ = writeln!(
        s,
        "longest duration: {} ticks = {:.1} s ({}-bit tick counter)",
        (1u64 << f.tick_bits) - 1,
        f.max_duration_s(),
        f.tick_bits
    );
    let _ = writeln!(
        s,
        "exact endpoint: every move needs a position gain P < 2^{FRAC_BITS} (checked per plan; \
         e.g. an order-4 move whose snap phases last {:.2} s or more is refused)",
        // 8·td⁴ < 2^F  ⇒  td < (2^(F−3))^(1/4) ticks.
        2f64.powf((FRAC_BITS as f64 - 3.0) / 4.0) * f.ts
    );
    let _ = writeln!(
        s,
        "program memory: {} segments of {}-bit ticks and {}-bit snap",
        f.max_segments, f.tick_bits, f.widths.d
    );
    s
}
