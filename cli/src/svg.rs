//! SVG plots (`snapgen plot`, `online --svg`, the experiment's figures): position, velocity,
//! acceleration, jerk and snap against time.
//!
//! Long moves are drawn from per-bucket minima and maxima of the integer trace, so one-tick
//! snap impulses stay visible however many ticks share a pixel.

use std::path::Path;

use plotters::prelude::*;
use snapgen_model::{ChainState, Format, Program, Quantity as Physical, Trace};
use snapgen_plan::Plan;
use snapgen_plant::fast::LoopSample;

/// Number of time buckets drawn.
const BUCKETS: u64 = 1000;

/// One bucket: time and (min, max) of x, v, a, j, d.
struct Bucket {
    t: f64,
    lo: [f64; 5],
    hi: [f64; 5],
}

fn buckets(program: &Program, start: ChainState, f: &Format) -> Vec<Bucket> {
    let x0 = f.position_physical(start.x);
    let per = (program.total_ticks() / BUCKETS).max(1);
    let mut out: Vec<Bucket> = Vec::new();
    for t in Trace::new(program, start, f.widths) {
        let s = t.state;
        let vals = [
            f.position_physical(s.x) - x0,
            f.to_physical(Physical::Velocity, s.v),
            f.to_physical(Physical::Acceleration, s.a),
            f.to_physical(Physical::Jerk, s.j),
            f.to_physical(Physical::Snap, t.d),
        ];
        let k = t.tick / per;
        match out.last_mut() {
            Some(b) if (b.t / f.ts) as u64 / per == k => {
                for (i, v) in vals.iter().enumerate() {
                    b.lo[i] = b.lo[i].min(*v);
                    b.hi[i] = b.hi[i].max(*v);
                }
            }
            _ => out.push(Bucket {
                t: (k * per) as f64 * f.ts,
                lo: vals,
                hi: vals,
            }),
        }
    }
    out
}

/// Errors while drawing.
pub type PlotError = Box<dyn std::error::Error + Send + Sync>;

/// Draws the five panels into `path`.
pub fn write_svg(plan: &Plan, title: &str, path: &Path) -> Result<(), PlotError> {
    write_program_svg(&plan.program, plan.start, &plan.format, title, &[], path)
}

/// A panel of values in `y` against time from 0 to `t_end` (s), its caption and mesh drawn.
fn time_panel<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: &str,
    t_end: f64,
    y: (f64, f64),
) -> Result<
    ChartContext<
        'a,
        SVGBackend<'b>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    PlotError,
> {
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(90)
        .caption(caption, ("sans-serif", 16))
        .build_cartesian_2d(0.0..t_end, y.0..y.1)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_label_formatter(&|y| format!("{y:.3e}"))
        .draw()?;
    Ok(chart)
}

/// Draws the five panels of `program` played from `start` into `path`, with a vertical line
/// at each of `events` (s from the start).
pub fn write_program_svg(
    program: &Program,
    start: ChainState,
    format: &Format,
    title: &str,
    events: &[f64],
    path: &Path,
) -> Result<(), PlotError> {
    let data = buckets(program, start, format);
    let t_end = (program.total_ticks() as f64 * format.ts).max(format.ts);
    let root = SVGBackend::new(path, (1000, 1200)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(40);
    head.titled(title, ("sans-serif", 20))?;
    let panels = body.split_evenly((5, 1));
    let names = [
        ("position", "units"),
        ("velocity", "units/s"),
        ("acceleration", "units/s^2"),
        ("jerk", "units/s^3"),
        ("snap", "units/s^4"),
    ];
    let colors = [&BLUE, &RED, &GREEN, &MAGENTA, &BLACK];
    for (i, area) in panels.iter().enumerate() {
        let lo = data.iter().map(|b| b.lo[i]).fold(f64::INFINITY, f64::min);
        let hi = data
            .iter()
            .map(|b| b.hi[i])
            .fold(f64::NEG_INFINITY, f64::max);
        let pad = ((hi - lo) * 0.05).max(1e-12);
        let caption = format!("{} ({})", names[i].0, names[i].1);
        let mut chart = time_panel(area, &caption, t_end, (lo - pad, hi + pad))?;
        // The envelope: lower and upper edge of every bucket.
        let color = colors[i];
        chart.draw_series(LineSeries::new(data.iter().map(|b| (b.t, b.hi[i])), color))?;
        chart.draw_series(LineSeries::new(data.iter().map(|b| (b.t, b.lo[i])), color))?;
        for &t in events {
            chart.draw_series(LineSeries::new(
                [(t, lo - pad), (t, hi + pad)],
                BLACK.mix(0.4),
            ))?;
        }
    }
    root.present()?;
    Ok(())
}

/// What a panel shows of a sample.
type Quantity<'a> = dyn Fn(&LoopSample) -> f64 + 'a;

/// A closed loop's runs: the position error (rad) and the control signal (V: duty × `volts_per_duty`)
/// against time, one line per run (the seed's Figures 10, 12 and 15).
pub fn write_loop_svg(
    title: &str,
    runs: &[(String, &[LoopSample])],
    volts_per_duty: f64,
    path: &Path,
) -> Result<(), PlotError> {
    let root = SVGBackend::new(path, (1000, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(40);
    head.titled(title, ("sans-serif", 20))?;
    let panels = body.split_evenly((2, 1));
    let t_end = runs
        .iter()
        .flat_map(|(_, s)| s.last().map(|x| x.t))
        .fold(0.0, f64::max)
        .max(1e-3);
    let colors = [&BLUE, &RED, &GREEN, &MAGENTA];
    let quantities: [(&str, &Quantity<'_>); 2] = [
        ("position error, reference − encoder (rad)", &|s| {
            s.error()
        }),
        ("control signal (V)", &|s| {
            f64::from(s.duty) * volts_per_duty
        }),
    ];
    for (area, (caption, value)) in panels.iter().zip(quantities) {
        let (lo, hi) = runs
            .iter()
            .flat_map(|(_, s)| s.iter().map(value))
            .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let pad = ((hi - lo) * 0.05).max(1e-6);
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .caption(caption, ("sans-serif", 16))
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_label_formatter(&|y| format!("{y:.3}"))
            .draw()?;
        for (k, (name, samples)) in runs.iter().enumerate() {
            let color = colors[k % colors.len()];
            chart
                .draw_series(LineSeries::new(
                    samples.iter().map(|s| (s.t, value(s))),
                    color,
                ))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

/// A path played on several axes (`snapgen path --svg`): the path in the XY plane, then each
/// axis's velocity, acceleration and jerk against time, from the differences of its raw
/// positions (per-bucket minima and maxima, so one-tick spikes stay visible).
pub fn write_path_svg(
    trace: &[Vec<i128>],
    distance: &[f64],
    format: &Format,
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    let half = 1i128 << (snapgen_model::FRAC_BITS - 1);
    let unit = format.position_lsb / 2f64.powi(snapgen_model::FRAC_BITS as i32);
    let mm = |x: i128| (x - half) as f64 * unit;
    let axes = trace.first().map_or(0, Vec::len);
    // Per axis and tick: velocity, acceleration, jerk (units/s^k) from the raw differences.
    let scale = [
        format.scale(Physical::Velocity),
        format.scale(Physical::Acceleration),
        format.scale(Physical::Jerk),
    ];
    let n = trace.len() as u64;
    let per = (n / BUCKETS).max(1);
    // [quantity][axis] -> buckets of (t, lo, hi)
    let mut series: Vec<Vec<Vec<(f64, f64, f64)>>> = vec![vec![Vec::new(); axes]; 3];
    for i in 0..axes {
        let (mut v0, mut a0, mut x0) = (0i128, 0i128, trace[0][i]);
        for (k, p) in trace.iter().enumerate() {
            let v = p[i] - x0;
            let a = v - v0;
            let j = a - a0;
            (x0, v0, a0) = (p[i], v, a);
            let t = k as f64 * format.ts;
            for (q, raw) in [v, a, j].into_iter().enumerate() {
                let y = raw as f64 / scale[q];
                let s = &mut series[q][i];
                match s.last_mut() {
                    Some(b) if (b.0 / format.ts) as u64 / per == k as u64 / per => {
                        b.1 = b.1.min(y);
                        b.2 = b.2.max(y);
                    }
                    _ => s.push((t, y, y)),
                }
            }
        }
    }
    let root = SVGBackend::new(path, (1000, 1720)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(40);
    head.titled(title, ("sans-serif", 20))?;
    let (top, rest) = body.split_vertically(500);
    let (rest, bottom) = rest.split_vertically(900);
    // The path in the XY plane, and in the ZX and YZ planes when Z moves.
    let step = (trace.len() / 20_000).max(1);
    let coordinate = |p: &Vec<i128>, i: usize| mm(p.get(i).copied().unwrap_or(half));
    let z_moves = axes > 2 && trace.iter().any(|p| p[2] != trace[0][2]);
    let planes: &[(usize, usize, &str)] = if z_moves {
        &[(0, 1, "XY"), (0, 2, "XZ"), (1, 2, "YZ")]
    } else {
        &[(0, 1, "XY")]
    };
    let names_of = ["X", "Y", "Z"];
    for (&(h, v, name), area) in planes
        .iter()
        .zip(top.split_evenly((1, planes.len())).iter())
    {
        let points: Vec<(f64, f64)> = trace
            .iter()
            .step_by(step)
            .chain(trace.last())
            .map(|p| (coordinate(p, h), coordinate(p, v)))
            .collect();
        let span = |f: fn(&(f64, f64)) -> f64| {
            points
                .iter()
                .map(f)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                    (l.min(x), h.max(x))
                })
        };
        let (x_lo, x_hi) = span(|p| p.0);
        let (y_lo, y_hi) = span(|p| p.1);
        let pad = ((x_hi - x_lo).max(y_hi - y_lo) * 0.05).max(1e-9);
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .caption(format!("path, {name} plane (mm)"), ("sans-serif", 16))
            .build_cartesian_2d((x_lo - pad)..(x_hi + pad), (y_lo - pad)..(y_hi + pad))?;
        chart
            .configure_mesh()
            .x_desc(names_of[h])
            .y_desc(names_of[v])
            .draw()?;
        chart.draw_series(LineSeries::new(points, &BLUE))?;
    }
    let t_end = (n.max(2) - 1) as f64 * format.ts;
    let names = ["velocity (mm/s)", "acceleration (mm/s^2)", "jerk (mm/s^3)"];
    let colors = [&RED, &GREEN, &BLUE];
    for (q, area) in rest.split_evenly((3, 1)).iter().enumerate() {
        let all = series[q].iter().flatten();
        let lo = all.clone().map(|b| b.1).fold(f64::INFINITY, f64::min);
        let hi = all.map(|b| b.2).fold(f64::NEG_INFINITY, f64::max);
        let pad = ((hi - lo) * 0.05).max(1e-12);
        let caption = format!("{} — X red, Y green, Z blue", names[q]);
        let mut chart = time_panel(area, &caption, t_end, (lo - pad, hi + pad))?;
        for (i, s) in series[q].iter().enumerate() {
            let color = colors[i % colors.len()];
            chart.draw_series(LineSeries::new(s.iter().map(|b| (b.0, b.2)), color))?;
            chart.draw_series(LineSeries::new(s.iter().map(|b| (b.0, b.1)), color))?;
        }
    }
    // The distance from the programmed path, per bucket of ticks its largest.
    let mut far: Vec<(f64, f64)> = Vec::new();
    for (k, &d) in distance.iter().enumerate() {
        let t = k as f64 * format.ts;
        match far.last_mut() {
            Some(b) if (b.0 / format.ts) as u64 / per == k as u64 / per => b.1 = b.1.max(d),
            _ => far.push((t, d)),
        }
    }
    let top_d = far.iter().map(|b| b.1).fold(0.0f64, f64::max).max(1e-6) * 1.1;
    let caption = format!(
        "distance from the programmed path (LSB; largest {:.3e}; the check allows 1 on a line's axes, 2 from an arc)",
        distance.iter().copied().fold(0.0f64, f64::max)
    );
    let mut chart = time_panel(&bottom, &caption, t_end, (0.0, top_d))?;
    chart.draw_series(LineSeries::new(far, &BLACK))?;
    root.present()?;
    Ok(())
}
