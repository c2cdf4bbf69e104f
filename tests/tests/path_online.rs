//! The axis group online (issue 22): random chains of lines and arcs, each joined to the one
//! before it tangentially (to the grid's rounding, as a CAM program's are), entering the
//! buffer while the path moves (seed 002's path extension) or all at once, under feed
//! overrides at random times. Played by `snapgen_host::path` (the path length through the
//! PLCopen host axis, the interpolator's rules onto the axes) and held, from the axes'
//! positions alone (`snapgen_verify::path`), against the path as programmed and each axis's
//! limits on every tick; the path length never turns back, every element ends Done, the
//! path ends on its end point's cell.

use proptest::prelude::*;
use snapgen_host::axis::Outcome;
use snapgen_host::gcode::Block;
use snapgen_host::path::{
    play_events, verify, verify_stop, Group, PathAction, PathEvent, STOP_PAST_MAX,
};
use snapgen_model::{Format, DEFAULT_FORMAT, FRAC_BITS};
use snapgen_plan::path::speed::Limits;
use snapgen_plan::path::Element;

/// mm: 1 µm LSB, Ts = 100 µs.
const F: Format = Format {
    ts: 1e-4,
    position_lsb: 1e-3,
    ..DEFAULT_FORMAT
};

/// One element drawn: a line of `length` mm, or an arc of `radius` mm turning `sweep` rad
/// (counter-clockwise when `ccw`).
#[derive(Clone, Copy, Debug)]
enum Draw {
    Line { length: f64 },
    Arc { radius: f64, sweep: f64, ccw: bool },
}

fn draw() -> impl Strategy<Value = Draw> {
    prop_oneof![
        (0.2f64..40.0).prop_map(|length| Draw::Line { length }),
        (0.5f64..40.0, 0.05f64..3.0, any::<bool>())
            .prop_map(|(radius, sweep, ccw)| { Draw::Arc { radius, sweep, ccw } }),
    ]
}

/// The elements from the origin heading along +X, each tangent to the one before it on the
/// grid (µm), and the end point.
fn chain(draws: &[Draw], feed: f64) -> Vec<Block> {
    let mut p = [0i64, 0];
    let mut u = [1.0f64, 0.0];
    let um = |mm: f64| (mm * 1e3).round() as i64;
    let mut out = Vec::new();
    for (k, d) in draws.iter().enumerate() {
        let element = match *d {
            Draw::Line { length } => {
                let to = [p[0] + um(u[0] * length), p[1] + um(u[1] * length)];
                let (dx, dy) = ((to[0] - p[0]) as f64, (to[1] - p[1]) as f64);
                let n = dx.hypot(dy);
                u = [dx / n, dy / n];
                p = to;
                Element::Line { to: to.to_vec() }
            }
            Draw::Arc { radius, sweep, ccw } => {
                let side = if ccw { 1.0 } else { -1.0 };
                let centre = [
                    p[0] + um(-u[1] * radius * side),
                    p[1] + um(u[0] * radius * side),
                ];
                let (rx, ry) = ((p[0] - centre[0]) as f64, (p[1] - centre[1]) as f64);
                let (s, c) = (side * sweep).sin_cos();
                let end = [
                    centre[0] + (rx * c - ry * s).round() as i64,
                    centre[1] + (rx * s + ry * c).round() as i64,
                ];
                let (ex, ey) = ((end[0] - centre[0]) as f64, (end[1] - centre[1]) as f64);
                let n = ex.hypot(ey);
                u = [-ey / n * side, ex / n * side];
                p = end;
                Element::Arc {
                    plane: [0, 1],
                    centre,
                    ccw,
                    to: end.to_vec(),
                }
            }
        };
        out.push(Block {
            line: k + 1,
            element,
            feed: Some(feed),
        });
    }
    out
}

fn axis() -> impl Strategy<Value = Limits> {
    (100.0f64..300.0, 1000.0f64..10_000.0, 1e5f64..5e6).prop_map(|(v, a, j)| Limits {
        velocity: v,
        acceleration: a,
        jerk: j,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn a_tangent_chain_entering_online_under_overrides_stays_on_its_path_within_every_limit(
        draws in prop::collection::vec(draw(), 2..7),
        feed in 20.0f64..200.0,
        axes in prop::array::uniform2(axis()),
        online in any::<bool>(),
        entering in prop::collection::vec(0.2f64..0.95, 6),
        overrides in prop::collection::vec(
            (0.0f64..1500.0, prop_oneof![Just(0.0), 0.0f64..2.0]),
            0..4,
        ),
        order in prop::collection::vec(any::<bool>(), 12),
    ) {
        let blocks = chain(&draws, feed);
        let mut timed: Vec<PathEvent> = overrides
            .iter()
            .map(|&(at_ms, k)| PathEvent { at_ms, at_length: None, action: PathAction::Override(k) })
            .collect();
        timed.sort_by(|a, b| a.at_ms.total_cmp(&b.at_ms));
        let enter = |at_length, k| PathEvent { at_ms: 0.0, at_length, action: PathAction::Enter(k) };
        let entries = if online {
            // Element k enters when the path is `entering[k]` of the way along element k-1.
            let mut done = 0.0;
            let mut list = vec![enter(None, 0)];
            for k in 1..draws.len() {
                let before = match draws[k - 1] {
                    Draw::Line { length } => length,
                    Draw::Arc { radius, sweep, .. } => radius * sweep,
                };
                list.push(enter(Some(done + entering[k - 1] * before), k));
                done += before;
            }
            list
        } else {
            vec![enter(None, blocks.len() - 1)]
        };
        // The entries and the overrides interleaved as `order` draws (each list in its own
        // order; events are taken in order, so an override may wait for an entry or not).
        let (mut e, mut o) = (entries.into_iter().peekable(), timed.into_iter().peekable());
        let mut events = vec![e.next().unwrap()];
        for &pick in order.iter().chain(std::iter::repeat(&true)) {
            match (pick, e.peek().is_some(), o.peek().is_some()) {
                (_, false, false) => break,
                (true, true, _) | (false, true, false) => events.push(e.next().unwrap()),
                _ => events.push(o.next().unwrap()),
            }
        }
        // A stop on the path (override 0) goes on 300 ms later (an entry waiting for a length
        // would otherwise wait for ever: events are taken in order).
        let mut i = 0;
        while i < events.len() {
            if let PathEvent { at_ms, action: PathAction::Override(k), .. } = events[i] {
                if k == 0.0 {
                    let resume = PathAction::Override(1.0);
                    events.insert(i + 1, PathEvent { at_ms: at_ms + 300.0, at_length: None, action: resume });
                }
            }
            i += 1;
        }
        events.push(PathEvent { at_ms: 2000.0, at_length: None, action: PathAction::Override(1.0) });
        let run = play_events(&blocks, &axes, None, &F, &events).unwrap();
        prop_assert_eq!(run.blocks.len(), blocks.len());
        prop_assert!(run.blocks.iter().all(|b| b.outcome == Outcome::Done), "{:?}", run.blocks);
        let c = verify(&run, &blocks, &axes, &F);
        prop_assert_eq!(&c.deviation, &None);
        prop_assert_eq!(&c.exceeded, &None);
        prop_assert!(run.lengths.windows(2).all(|w| w[1] >= w[0]), "the path turned back");
        let end = run.end_cells();
        let want: Vec<i128> = blocks.last().unwrap().element.to().iter().map(|&x| x.into()).collect();
        prop_assert_eq!(end, want);
    }
}

/// The direction (rad) the last of `blocks` ends in (from the origin).
fn heading_at_end(blocks: &[Block]) -> f64 {
    let from = match blocks.len() {
        0 | 1 => vec![0, 0],
        n => blocks[n - 2].element.to().to_vec(),
    };
    match &blocks.last().unwrap().element {
        Element::Line { to } => ((to[1] - from[1]) as f64).atan2((to[0] - from[0]) as f64),
        Element::Arc {
            centre, ccw, to, ..
        } => {
            let radial = ((to[1] - centre[1]) as f64).atan2((to[0] - centre[0]) as f64);
            radial + if *ccw { 1.0 } else { -1.0 } * std::f64::consts::FRAC_PI_2
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// On a board (its controlled stop set from the path, every move within it:
    /// `Group::for_board_stop`), a stop taken at random ticks of a random tangent chain with a
    /// corner after it stays on the path within every axis's limits and comes to rest before
    /// the corner or the path's end (a hair past at most, every axis inside the cell there).
    #[test]
    fn a_board_stop_at_any_tick_of_a_chain_with_a_corner_stays_on_the_path(
        draws in prop::collection::vec(draw(), 1..5),
        feed in 20.0f64..200.0,
        axes in prop::array::uniform2(axis()),
        corner in 0.3f64..2.8,
        back in 0.5f64..20.0,
        at in prop::collection::vec(0.0f64..1.0, 12),
    ) {
        let mut blocks = chain(&draws, feed);
        // A line turning `corner` rad off the chain's heading at its end: a corner.
        let end = blocks.last().unwrap().element.to().to_vec();
        let heading = heading_at_end(&blocks) + corner;
        let (s, c) = heading.sin_cos();
        let to = vec![end[0] + (c * back * 1e3).round() as i64, end[1] + (s * back * 1e3).round() as i64];
        blocks.push(Block { line: blocks.len() + 1, element: Element::Line { to }, feed: Some(feed) });
        let mut g = Group::new(&blocks, &axes, None, &F).unwrap().for_board_stop();
        g.play(&[PathEvent { at_ms: 0.0, at_length: None, action: PathAction::Enter(blocks.len() - 1) }]);
        let stop = g.stop_limits();
        let ticks = g.lengths().len() as f64;
        for f in at {
            let t = (f * ticks) as u64;
            let past = verify_stop(&g, &blocks, &axes, stop, t);
            prop_assert!(past.is_ok(), "stop after tick {}: {:?}", t, past);
            let past = past.unwrap();
            prop_assert!(past <= STOP_PAST_MAX);
        }
    }
}

/// The check is not blind: on a chain's trace, each axis's largest first, second and third
/// differences, computed here from the raw positions (an implementation of their own), are
/// what the check measures: axes 3 % below them fail it, axes at them pass.
#[test]
fn the_check_sees_a_chain_played_for_faster_axes() {
    let draws = [
        Draw::Line { length: 20.0 },
        Draw::Arc {
            radius: 10.0,
            sweep: 1.5,
            ccw: true,
        },
        Draw::Line { length: 20.0 },
    ];
    let blocks = chain(&draws, 150.0);
    let axes = [Limits {
        velocity: 200.0,
        acceleration: 5000.0,
        jerk: 1e6,
    }; 2];
    let events = [PathEvent {
        at_ms: 0.0,
        at_length: None,
        action: PathAction::Enter(2),
    }];
    let run = play_events(&blocks, &axes, None, &F, &events).unwrap();
    let c = verify(&run, &blocks, &axes, &F);
    assert_eq!((c.deviation, c.exceeded), (None, None));
    assert!(run.blocks[1].entry > 0.0 && run.blocks[2].entry > 0.0);
    // |Δ¹|, |Δ²|, |Δ³| of each axis in output LSBs (f64), then in mm/s, mm/s², mm/s³.
    let unit = 2f64.powi(FRAC_BITS as i32);
    let mut peaks = [[0.0f64; 3]; 2];
    for (i, peak) in peaks.iter_mut().enumerate() {
        let x: Vec<f64> = run.trace.iter().map(|p| p[i] as f64 / unit).collect();
        let mut d = x;
        for (order, p) in peak.iter_mut().enumerate() {
            d = d.windows(2).map(|w| w[1] - w[0]).collect();
            let most = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            *p = most * F.position_lsb / F.ts.powi(order as i32 + 1);
        }
    }
    let at = |scale: f64, q: usize| {
        let mut l = axes;
        for (a, p) in l.iter_mut().zip(&peaks) {
            match q {
                0 => a.velocity = p[0] * scale,
                1 => a.acceleration = p[1] * scale,
                _ => a.jerk = p[2] * scale,
            }
        }
        verify(&run, &blocks, &l, &F).exceeded
    };
    for q in 0..3 {
        assert!(at(0.97, q).is_some(), "quantity {q}");
        assert_eq!(at(1.001, q), None, "quantity {q}");
    }
}
