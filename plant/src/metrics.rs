//! The figures of a closed-loop move, from its samples: the error at the end of the reference
//! move, the peak and RMS error, the peak velocity, the peak control effort and the time to
//! settle — the encoder's error (what the controller sees) and the true shaft's beside it
//! (what the machine does: the encoder hides up to half a count).

use serde::Serialize;

use crate::fast::LoopSample;

/// A move's figures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MoveFigures {
    /// Reference − encoder when the reference reaches its end, `T` (rad, signed).
    pub error_at_t_rad: f64,
    /// The largest |reference − encoder| from the move's start to the end of the window (rad).
    pub peak_error_rad: f64,
    /// The RMS of reference − encoder over the same span (rad).
    pub rms_error_rad: f64,
    /// Reference − the shaft's true angle at `T` (rad, signed).
    pub shaft_error_at_t_rad: f64,
    /// The largest |reference − the shaft's true angle| over the span (rad).
    pub shaft_peak_error_rad: f64,
    /// The largest |shaft speed| over the same span (rad/s).
    pub peak_velocity: f64,
    /// The largest |commanded voltage| (duty / PWM period × supply) over the same span (V).
    pub peak_effort: f64,
    /// Seconds after `T` until |error| stays within the band to the window's end (0: within
    /// it at `T`); `None` if it never does within the window.
    pub settle_s: Option<f64>,
}

/// The span of one move in a run of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveSpan {
    /// The move starts (s).
    pub start: f64,
    /// The reference reaches its end: `T` (s).
    pub end: f64,
    /// The window ends (s): the settling time counts up to here.
    pub window_end: f64,
}

/// The figures of the move `span` in `samples`, with the settling band `band` (rad) and `volts_per_duty`
/// (the supply over the PWM period). `None` without samples in the span.
pub fn figures(
    samples: &[LoopSample],
    span: &MoveSpan,
    band: f64,
    volts_per_duty: f64,
) -> Option<MoveFigures> {
    let inside: Vec<&LoopSample> = samples
        .iter()
        .filter(|s| s.t >= span.start && s.t <= span.window_end)
        .collect();
    let at_t = inside
        .iter()
        .min_by(|a, b| (a.t - span.end).abs().total_cmp(&(b.t - span.end).abs()))?;
    let max = |f: &dyn Fn(&LoopSample) -> f64| inside.iter().map(|s| f(s)).fold(0.0, f64::max);
    let last_out = inside
        .iter()
        .filter(|s| s.t >= span.end && s.error().abs() > band)
        .map(|s| s.t)
        .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))));
    let last_t = inside.last().map_or(span.end, |s| s.t);
    let settle_s = match last_out {
        None => Some(0.0),
        Some(t) if t >= last_t => None,
        // Settled on the sample after the last one outside the band.
        Some(t) => inside.iter().find(|s| s.t > t).map(|s| s.t - span.end),
    };
    let rms = (inside.iter().map(|s| s.error().powi(2)).sum::<f64>() / inside.len() as f64).sqrt();
    Some(MoveFigures {
        error_at_t_rad: at_t.error(),
        peak_error_rad: max(&|s| s.error().abs()),
        rms_error_rad: rms,
        shaft_error_at_t_rad: at_t.shaft_error(),
        shaft_peak_error_rad: max(&|s| s.shaft_error().abs()),
        peak_velocity: max(&|s| s.omega.abs()),
        peak_effort: max(&|s| f64::from(s.duty).abs() * volts_per_duty),
        settle_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_made_up_run() {
        // Error 0.1 rad falling by 0.01 per 0.1 s from t = 1 s; the move ends at 1 s.
        let samples: Vec<LoopSample> = (0..30)
            .map(|k| {
                let t = 0.1 * f64::from(k);
                let e = if t < 1.0 {
                    0.05
                } else {
                    (0.1 - (t - 1.0) * 0.1).max(0.0)
                };
                LoopSample {
                    t,
                    reference: e,
                    encoder: 0.0,
                    theta: 0.002,
                    omega: if k == 3 { -7.0 } else { 1.0 },
                    duty: if k == 5 { -200 } else { 10 },
                    ..Default::default()
                }
            })
            .collect();
        let span = MoveSpan {
            start: 0.0,
            end: 1.0,
            window_end: 2.9,
        };
        let f = figures(&samples, &span, 0.009, 0.1).unwrap();
        assert!((f.error_at_t_rad - 0.1).abs() < 1e-12);
        assert!((f.peak_error_rad - 0.1).abs() < 1e-12);
        assert_eq!((f.peak_velocity, f.peak_effort), (7.0, 20.0));
        // RMS by hand: ten samples of 0.05, then 0.1, 0.09, …, 0.01 and nine of 0, over the 29
        // samples in the window (the 30th, at 0.1 × 29 = 2.9000000000000004 s, is past its end).
        let squares =
            10.0 * 0.05f64.powi(2) + (1..=10).map(|m| (0.01 * m as f64).powi(2)).sum::<f64>();
        assert!(
            (f.rms_error_rad - (squares / 29.0).sqrt()).abs() < 1e-12,
            "{f:?}"
        );
        // The shaft stands 0.002 rad ahead of the encoder's reading.
        assert!((f.shaft_error_at_t_rad - 0.098).abs() < 1e-12);
        assert!((f.shaft_peak_error_rad - 0.098).abs() < 1e-12);
        // Out of the band while 0.1 − 0.1(t − 1) > 0.009: t = 1.9 is the last sample out
        // (0.01), so it settles at the next, 2.0 s: 1.0 s after T.
        assert!((f.settle_s.unwrap() - 1.0).abs() < 1e-9, "{f:?}");
        // A band nothing reaches: not settled.
        let never = figures(
            &samples,
            &MoveSpan {
                window_end: 1.5,
                ..span
            },
            0.009,
            0.1,
        )
        .unwrap();
        assert_eq!(never.settle_s, None);
    }
}
