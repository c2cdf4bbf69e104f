//! Built-in scripts for `snapgen online --scenario` (units: mm and s; docs/ONLINE.md).
//!
//! * `seed002`: seed 002's demonstration (Red 2000, Figures 5–7): a 400 mm move whose set speed
//!   is changed several times, a 100 mm tangent move entering the buffer at 300 mm,
//!   acceleration 4000 mm/s², deceleration 3000 mm/s², jerk 5000, 50 000 or 500 000 mm/s³
//!   (`--jerk`, default 50 000). The paper gives the lengths and limits but not the set speeds
//!   or when they change (they are only drawn): this script's set speeds are ours — 100 mm/s,
//!   then 200, 50 and 150 mm/s, and 80 mm/s on the tangent move — given as feed overrides of
//!   200 mm/s moves, and the tangent move blends in at the previous move's set speed
//!   (BlendingPrevious).
//! * `seed000-fig3`: the two MC_MoveAbsolute cases of seed 000's Figure 3 (the standard's
//!   timing diagram): (a) the second block starts after the first has stopped, (b) it starts
//!   while the first still moves (Aborting); both end on the same position. The figure has no
//!   numbers; ours are the standard's example scaled down (positions 6 and 10 mm, velocities
//!   150 and 100 mm/s), case (a) followed by a return to 0 and case (b).

use snapgen_host::axis::{BufferMode, MotionCommand};
use snapgen_host::driver::{Action, Event};

use snapgen_host::online::Script;

/// A built-in scenario.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Scenario {
    /// Seed 002's Figures 5–7.
    Seed002,
    /// Seed 000's Figure 3.
    #[value(name = "seed000-fig3")]
    Seed000Fig3,
}

fn at(ms: f64, c: MotionCommand) -> Event {
    Event {
        at_ms: ms,
        at_position: None,
        action: Action::Command(c),
    }
}

fn feed(ms: f64, k: f64) -> Event {
    Event {
        at_ms: ms,
        at_position: None,
        action: Action::Override { r#override: k },
    }
}

fn mv(position: f64, velocity: f64, jerk: f64, buffer_mode: BufferMode) -> MotionCommand {
    MotionCommand::MoveAbsolute {
        position,
        velocity,
        acceleration: 4000.0,
        deceleration: 3000.0,
        jerk,
        buffer_mode,
        path: None,
    }
}

impl Scenario {
    /// Its script.
    pub fn script(self, jerk: Option<f64>) -> anyhow::Result<Script> {
        let s = match self {
            Scenario::Seed002 => {
                let j = jerk.unwrap_or(50_000.0);
                anyhow::ensure!(
                    j.is_finite() && j > 0.0,
                    "--jerk {j}: give a jerk > 0 (the seed uses 5000, 50000 and 500000 mm/s³)"
                );
                Script {
                    order: 3,
                    stop_deceleration: None,
                    stop_jerk: None,
                    events: vec![
                        feed(0.0, 0.5),
                        at(0.0, mv(400.0, 200.0, j, BufferMode::Aborting)),
                        feed(800.0, 1.0),
                        feed(1300.0, 0.25),
                        feed(2000.0, 0.75),
                        Event {
                            at_ms: 2000.0,
                            at_position: Some(300.0),
                            action: Action::Command(mv(
                                500.0,
                                200.0,
                                j,
                                BufferMode::BlendingPrevious,
                            )),
                        },
                        feed(3000.0, 0.4),
                    ],
                }
            }
            Scenario::Seed000Fig3 => {
                let j = jerk.unwrap_or(500_000.0);
                Script {
                    order: 3,
                    stop_deceleration: None,
                    stop_jerk: None,
                    events: vec![
                        // (a) the second block after the first has stopped.
                        at(0.0, mv(6.0, 150.0, j, BufferMode::Aborting)),
                        at(150.0, mv(10.0, 100.0, j, BufferMode::Aborting)),
                        // Back to the start.
                        at(300.0, mv(0.0, 150.0, j, BufferMode::Aborting)),
                        // (b) the second block while the first still moves.
                        at(450.0, mv(6.0, 150.0, j, BufferMode::Aborting)),
                        at(480.0, mv(10.0, 100.0, j, BufferMode::Aborting)),
                    ],
                }
            }
        };
        s.check()?;
        Ok(s)
    }

    /// A title for the summary and the plot.
    pub fn title(self, jerk: Option<f64>) -> String {
        match self {
            Scenario::Seed002 => format!(
                "seed 002 (Figures 5–7): 400 mm, set speed changes, a 100 mm tangent move at 300 mm, jerk {} mm/s³",
                jerk.unwrap_or(50_000.0)
            ),
            Scenario::Seed000Fig3 => {
                "seed 000 Figure 3: MC_MoveAbsolute after a stop (a) and while moving (b)".into()
            }
        }
    }
}

/// The output cell of a position in mm (the scenarios' unit) in `f`.
pub fn cell_mm(mm: f64, f: &snapgen_model::Format) -> i128 {
    snapgen_host::axis::cell_of(mm, f)
}

/// Seed 002's demonstration as a Cartesian path (`snapgen path --scenario seed002`): the
/// single-axis script ([`Scenario::Seed002`]: its moves' lengths, set speed, limits, events
/// and times) on a line along X and a counter-clockwise arc of radius 200 mm tangent to it,
/// the arc entering the buffer where the script's second move does. The arc's curvature
/// begins at full speed at the junction: the planner passes it at the speed that jump allows
/// the Y axis (`snapgen_plan::path::junction`).
pub mod seed002_path {
    use snapgen_host::axis::MotionCommand;
    use snapgen_host::driver::Action;
    use snapgen_host::gcode::Block;
    use snapgen_host::path::{PathAction, PathEvent, PathLimits};
    use snapgen_plan::path::speed::Limits;
    use snapgen_plan::path::Element;

    use super::Scenario;

    /// The arc's radius (mm).
    pub const RADIUS: f64 = 200.0;
    /// The machine's axes (ours: the seed has one coordinate): velocity, acceleration and
    /// jerk of X, Y and Z.
    pub const AXES: Limits = Limits {
        velocity: 250.0,
        acceleration: 5000.0,
        jerk: 2e6,
    };

    /// The path from the script at `jerk`: its blocks on a grid of `lsb` mm, the path's own
    /// limits (the moves' acceleration, deceleration and jerk), the events.
    pub fn path(jerk: f64, lsb: f64) -> anyhow::Result<(Vec<Block>, PathLimits, Vec<PathEvent>)> {
        let script = Scenario::Seed002.script(Some(jerk))?;
        let (mut ends, mut feed, mut own) = (Vec::new(), 0.0, None);
        let mut events = Vec::new();
        for e in &script.events {
            let action = match e.action {
                Action::Override { r#override } => PathAction::Override(r#override),
                Action::Command(MotionCommand::MoveAbsolute {
                    position,
                    velocity,
                    acceleration,
                    deceleration,
                    jerk,
                    ..
                }) => {
                    ends.push(position);
                    feed = velocity;
                    own = Some(PathLimits {
                        acceleration,
                        deceleration,
                        jerk,
                    });
                    PathAction::Enter(ends.len() - 1)
                }
                _ => anyhow::bail!("the seed 002 script has a command a path does not take"),
            };
            events.push(PathEvent {
                at_ms: e.at_ms,
                at_length: e.at_position,
                action,
            });
        }
        let (&[line, end], Some(own)) = (&ends[..], own) else {
            anyhow::bail!("the seed 002 script has not two moves");
        };
        let at = |mm: f64| (mm / lsb).round() as i64;
        let phi = (end - line) / RADIUS;
        let to = vec![
            at(line + RADIUS * phi.sin()),
            at(RADIUS - RADIUS * phi.cos()),
            0,
        ];
        let block = |line, element| Block {
            line,
            element,
            feed: Some(feed),
        };
        let blocks = vec![
            block(
                1,
                Element::Line {
                    to: vec![at(line), 0, 0],
                },
            ),
            block(
                2,
                Element::Arc {
                    plane: [0, 1],
                    centre: [at(line), at(RADIUS)],
                    ccw: true,
                    to,
                },
            ),
        ];
        Ok((blocks, own, events))
    }
}
