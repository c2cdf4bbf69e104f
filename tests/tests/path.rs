//! Several axes along one path (issue 22, first part): a path of a line, a helical half turn
//! and a line (tangent in space), planned on its length alone by the rest-to-rest planner, played tick by tick on
//! the chain and mapped onto the axes by the interpolator's integer rules
//! (`snapgen_model::path::interp`); then held, from the axes' positions alone, against the path
//! as programmed (`snapgen_verify::path`: lines within 1 LSB on every axis, the arc within 2,
//! ending exactly on the end point) and against each axis's limits.
//!
//! The limits each axis sees are the path's plus what its geometry adds: on the arc the
//! centripetal acceleration `v²/R`, and where the line meets the arc that acceleration's step
//! within one tick, a jerk of `v²/(R·Ts)`. The bounds below are that physics, computed from
//! the path's limits and the radius, not from the interpolator. Keeping them within an axis's
//! own limits is the motion planner's job (the speed an element allows), not built yet.

use snapgen_model::chain::Trace;
use snapgen_model::{Format, Quantity, DEFAULT_FORMAT, FRAC_BITS};
use snapgen_plan::path::{prepare, Element, Prepared};
use snapgen_plan::{plan, Method, MoveRequest};
use snapgen_verify::path::limits::{check, AxisLimits};
use snapgen_verify::path::{follow, Arc, Bounds, Direction, Element as Checked, Line};

/// mm: 1 nm LSB, Ts = 100 µs.
const F: Format = Format {
    ts: 1e-4,
    ..DEFAULT_FORMAT
};
const MM: i64 = 1_000_000;
const V: f64 = 20.0;
const A: f64 = 500.0;
const J: f64 = 100_000.0;
const R: f64 = 20.0;

/// A slot in XY climbing in z at one slope, 1 in 10, all along (so that the helix meets the
/// lines tangentially in space: a flat line met by a climbing helix is a corner,
/// `a_corner_in_space_is_caught`): a line 30 mm along x, a helical half turn of radius
/// 20 mm, a line 30 mm back.
fn points() -> [Vec<i64>; 4] {
    let climb = |mm: f64| (mm * 0.1 * MM as f64).round() as i64;
    let arc = std::f64::consts::PI * R;
    [
        vec![0, 0, 0],
        vec![30 * MM, 0, climb(30.0)],
        vec![30 * MM, 40 * MM, climb(30.0 + arc)],
        vec![0, 40 * MM, climb(60.0 + arc)],
    ]
}

fn grid(p: &[i64]) -> Vec<i128> {
    p.iter().map(|&x| i128::from(x)).collect()
}

/// The raw positions of every axis on every tick, from rest to rest.
fn played() -> Vec<Vec<i128>> {
    played_through(points())
}

/// The same along other points.
fn played_through([start, a, b, c]: [Vec<i64>; 4]) -> Vec<Vec<i128>> {
    let prepared = prepare(
        &start,
        &[
            Element::Line { to: a },
            Element::Arc {
                plane: [0, 1],
                centre: [30 * MM, 20 * MM],
                ccw: true,
                to: b,
            },
            Element::Line { to: c },
        ],
    )
    .unwrap();
    play(&prepared, V, A, J).0
}

/// `prepared` planned from rest to rest on its length with these path limits, played on the
/// chain and mapped onto the axes: every axis's raw position on every tick, and the ticks.
fn play(prepared: &Prepared, v: f64, a: f64, j: f64) -> (Vec<Vec<i128>>, u64) {
    let p = plan(
        &MoveRequest {
            distance: prepared.length_physical(F.position_lsb),
            method: Method::Order3 {
                vmax: v,
                amax: a,
                jmax: j,
            },
        },
        &F,
    )
    .unwrap();
    // The path fitted onto the chain's exact displacement (the planner's quantized move of
    // the path's length: within an LSB of it).
    let moved = p.final_state.x - p.start.x;
    assert!((moved - prepared.length()).abs() < 1 << FRAC_BITS);
    let path = prepared.fit(moved);
    let raw = Trace::new(&p.program, p.start, F.widths)
        .map(|t| path.at(t.state.x - p.start.x).unwrap())
        .collect();
    (raw, p.ticks_total())
}

#[test]
fn a_helical_slot_stays_on_its_path_and_ends_on_its_point() {
    let raw = played();
    let on_grid: Vec<Vec<i128>> = raw
        .iter()
        .map(|p| p.iter().map(|x| x >> FRAC_BITS).collect())
        .collect();
    let [start, a, b, c] = points();
    let path = [
        Checked::Line(Line {
            from: grid(&start),
            to: grid(&a),
        }),
        Checked::Arc(Arc {
            plane: [0, 1],
            centre: [30 * i128::from(MM), 20 * i128::from(MM)],
            direction: Direction::CounterClockwise,
            from: grid(&a),
            to: grid(&b),
        }),
        Checked::Line(Line {
            from: grid(&b),
            to: grid(&c),
        }),
    ];
    let followed = follow(&path, &on_grid, Bounds { line: 1, arc: 2 })
        .unwrap()
        .unwrap_or_else(|d| panic!("{d:?}"));
    assert!(followed.entered.iter().all(Option::is_some));
    // The check is not blind: one axis of one tick on the arc two LSBs out fails it.
    let mut bad = on_grid.clone();
    let k = followed.entered[1].unwrap() + 100;
    bad[k][2] += 3;
    assert!(follow(&path, &bad, Bounds { line: 1, arc: 2 })
        .unwrap()
        .is_err());
}

/// The axis limits of the slot: the path's plus what its arc adds (module documentation).
fn slot_limits() -> (AxisLimits, i128) {
    let s = |q| F.scale(q);
    let slack = 1.0 + 1e-6;
    let limits = AxisLimits {
        velocity: (V * s(Quantity::Velocity) * slack) as i128,
        acceleration: ((A + V * V / R) * s(Quantity::Acceleration) * slack) as i128,
        jerk: ((J + V * V / (R * F.ts) + V.powi(3) / (R * R) + 3.0 * V * A / R)
            * s(Quantity::Jerk)
            * slack) as i128,
    };
    (limits, (V * s(Quantity::Velocity) * slack) as i128)
}

#[test]
fn each_axis_moves_within_the_path_limits_and_what_the_arc_adds() {
    let raw = played();
    let s = |q| F.scale(q);
    let slack = 1.0 + 1e-6;
    let (limits, speed) = slot_limits();
    let peaks = check(&raw, &[limits; 3], Some(speed)).unwrap_or_else(|e| panic!("{e:?}"));
    // The term the arc adds is there, where the line meets it: y stands still along the
    // first line, then takes the centripetal acceleration within a tick or two, a jerk of the
    // order of v²/(R·Ts) (in the plane the speed is v/√1.01).
    let y: Vec<f64> = raw.iter().map(|p| p[1] as f64).collect();
    let meets = y.iter().position(|&q| q != y[0]).expect("y moves");
    let jerk_y = (meets.saturating_sub(3)..meets + 3)
        .map(|k| (y[k + 3] - 3.0 * y[k + 2] + 3.0 * y[k + 1] - y[k]).abs())
        .fold(0.0, f64::max)
        / s(Quantity::Jerk);
    let jump = V * V / 1.01 / (R * F.ts);
    assert!(
        jerk_y > 0.25 * jump && jerk_y <= jump * slack,
        "{jerk_y} against {jump}"
    );
    let jerk = |i: usize| peaks.axes[i][2].as_f64() / s(Quantity::Jerk);
    // z climbs at a constant share of the path speed (1 in √101): within the path's.
    assert!(jerk(2) <= J / 101f64.sqrt() * 1.001, "{}", jerk(2));
}

/// A flat line met by a climbing helix is a corner in space: z's velocity steps within a
/// tick, and the per-axis check finds it there, far beyond the bound.
#[test]
fn a_corner_in_space_is_caught() {
    let [start, a, b, c] = points();
    let flat_a = vec![a[0], a[1], 0];
    let raw = played_through([start, flat_a, b, c]);
    let (limits, speed) = slot_limits();
    let e = check(&raw, &[limits; 3], Some(speed)).unwrap_err();
    // Where the line meets the helix: the first tick y moves.
    let meets = raw.iter().position(|p| p[1] != raw[0][1]).unwrap();
    assert!(e.tick.abs_diff(meets) <= 3, "{e:?} at {meets}");
    assert!(e.value > e.limit * 2, "{e:?}");
}

mod elements {
    //! Any single element, any axis limits: planned on its length with the limits the element
    //! allows (`snapgen_plan::path::speed`), every axis stays within its own limits on every
    //! tick (from the positions' differences, exactly) and on the element.

    use super::*;
    use proptest::prelude::*;
    use snapgen_plan::path::speed::{element_limits, Limits};

    fn axis() -> impl Strategy<Value = Limits> {
        (5.0f64..100.0, 50.0f64..2000.0, 1e3f64..1e6).prop_map(|(v, a, j)| Limits {
            velocity: v,
            acceleration: a,
            jerk: j,
        })
    }

    /// Raw per-axis limits of `axes` in `F`.
    fn raw_limits(axes: &[Limits]) -> Vec<AxisLimits> {
        let s = |q| F.scale(q);
        axes.iter()
            .map(|a| AxisLimits {
                velocity: (a.velocity * s(Quantity::Velocity)) as i128,
                acceleration: (a.acceleration * s(Quantity::Acceleration)) as i128,
                jerk: (a.jerk * s(Quantity::Jerk)) as i128,
            })
            .collect()
    }

    /// The check is not blind: a small arc planned with the axes' own limits, as if it were a
    /// line (no centripetal share), goes past an axis's acceleration; with the limits the
    /// element allows it does not.
    #[test]
    fn a_small_arc_at_the_axes_own_limits_is_caught() {
        let axes = [Limits {
            velocity: 100.0,
            acceleration: 1000.0,
            jerk: 100_000.0,
        }; 2];
        let arc = Element::Arc {
            plane: [0, 1],
            centre: [0, MM / 2],
            ccw: true,
            to: vec![0, MM],
        };
        let prepared = prepare(&[0, 0], &[arc]).unwrap();
        let run = |l: Limits| {
            let (raw, _) = play(&prepared, l.velocity, l.acceleration, l.jerk);
            check(&raw, &raw_limits(&axes), None)
        };
        assert!(run(axes[0]).is_err());
        let g = prepared.geometries()[0].scaled(F.position_lsb);
        assert!(run(element_limits(&g, &axes, 1e9).unwrap()).is_ok());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn every_axis_within_its_limits(
            axes in prop::array::uniform3(axis()),
            to in prop::array::uniform3(-20 * MM..20 * MM),
            radius in (MM / 2)..(20 * MM),
            start_angle in 0.0f64..std::f64::consts::TAU,
            kind in 0usize..3,
            ccw in any::<bool>(),
            feed in 1.0f64..200.0,
        ) {
            let start = vec![0i64, 0, 0];
            let element = match kind {
                0 => Element::Line { to: to.to_vec() },
                _ => {
                    // An arc from the start around a centre `radius` away, to the point of
                    // the circle at the angle of `to`; a helix (kind 2) climbs to `to`'s z.
                    let centre = [
                        -(radius as f64 * start_angle.cos()).round() as i64,
                        -(radius as f64 * start_angle.sin()).round() as i64,
                    ];
                    let r = ((centre[0] as f64).powi(2) + (centre[1] as f64).powi(2)).sqrt();
                    let end_angle = (to[1] as f64).atan2(to[0] as f64);
                    let end = |c: i64, f: f64| c + (r * f).round() as i64;
                    Element::Arc {
                        plane: [0, 1],
                        centre,
                        ccw,
                        to: vec![
                            end(centre[0], end_angle.cos()),
                            end(centre[1], end_angle.sin()),
                            if kind == 2 { to[2] } else { 0 },
                        ],
                    }
                }
            };
            let prepared = match prepare(&start, std::slice::from_ref(&element)) {
                Ok(p) => p,
                // An end point more than 1 LSB off the circle (the rounding of a small one):
                // refused with an error, which is the rule.
                Err(snapgen_plan::path::PathError::Radius { .. }) => return Ok(()),
                Err(e) => return Err(TestCaseError::fail(format!("{element:?}: {e}"))),
            };
            prop_assume!(prepared.length() > 1 << FRAC_BITS);
            let g = prepared.geometries()[0].scaled(F.position_lsb);
            let l = element_limits(&g, &axes, feed).unwrap();
            let (raw, ticks) = play(&prepared, l.velocity, l.acceleration, l.jerk);
            prop_assume!(ticks < 200_000);
            if let Err(e) = check(&raw, &raw_limits(&axes), None) {
                return Err(TestCaseError::fail(format!("{element:?} {l:?}: {e:?}")));
            }
            let on_grid: Vec<Vec<i128>> = raw
                .iter()
                .map(|p| p.iter().map(|x| x >> FRAC_BITS).collect())
                .collect();
            let checked = match &element {
                Element::Line { to } => Checked::Line(Line { from: grid(&start), to: grid(to) }),
                Element::Arc { plane, centre, ccw, to } => Checked::Arc(Arc {
                    plane: *plane,
                    centre: [i128::from(centre[0]), i128::from(centre[1])],
                    direction: if *ccw { Direction::CounterClockwise } else { Direction::Clockwise },
                    from: grid(&start),
                    to: grid(to),
                }),
            };
            let f = follow(&[checked], &on_grid, Bounds { line: 1, arc: 2 }).unwrap();
            prop_assert!(f.is_ok(), "{element:?}: {f:?}");
        }
    }
}
