//! The host's UIO link (`snapgen_host::uio::RegisterTransport`) on the virtual AXI board
//! (`snapgen_sim::axi_board`): the same code that runs over a `/dev/uioN` mapping, up to the
//! register accesses, drives the AXI4-Lite top's model — or the Verilated design with the model
//! in lockstep — through the handshakes a processor's interconnect makes. Checked here: the
//! session, the PLCopen driver with feed overrides and its latency, the snapshot against
//! READ_STATE, and a station that is not one.

use snapgen_host::axis::{BufferMode, MotionCommand, Outcome};
use snapgen_host::driver::{Action, Event, RunOptions, RunReport};
use snapgen_host::link::{LinkError, Transport};
use snapgen_host::online::{play as play_script, PlayOptions};
use snapgen_host::session::Session;
use snapgen_host::uio::{RegisterTransport, Registers};
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::DEFAULT_FORMAT;
use snapgen_plan::online::OnlineOrder;
use snapgen_sim::axi_board::{axi_link, AxiBoard};

/// The default board's clock and Ts (125 MHz, 10 µs a tick).
fn real_design() -> Design {
    snapgen_hdl::verilog::io_design(
        &Design::from_timing(&DEFAULT_FORMAT, &Timing::default()).unwrap(),
    )
}

fn ev(ms: f64, action: Action) -> Event {
    Event {
        at_ms: ms,
        at_position: None,
        action,
    }
}

fn mv(position: f64, velocity: f64) -> Action {
    Action::Command(MotionCommand::MoveAbsolute {
        position,
        velocity,
        acceleration: 4000.0,
        deceleration: 3000.0,
        jerk: 500_000.0,
        buffer_mode: BufferMode::Aborting,
        path: None,
    })
}

fn play(board: AxiBoard, script: &[Event]) -> (RunReport, AxiBoard) {
    let lsb = board.design().format.position_lsb;
    let mut session = Session::open(axi_link(board).unwrap(), lsb).unwrap();
    let opts = PlayOptions {
        order: OnlineOrder::Three,
        stop_deceleration: Some(3000.0),
        stop_jerk: Some(500_000.0),
        run: RunOptions::memory_mapped(),
    };
    let (report, _, _) = play_script(&mut session, script, &opts).unwrap();
    let board = session.link.into_transport().into_registers();
    (report, board)
}

/// seed 002's set-speed changes over the memory map: every override acts within 100 µs of
/// its due tick (the target; 30–36 ms over a 115 200-baud UART), the move lands
/// exactly where it was sent, every state the driver read matched its prediction.
#[test]
fn overrides_act_within_100_us_over_axi() {
    let d = real_design();
    let script = [
        ev(0.0, mv(30.0, 200.0)),
        ev(20.0, Action::Override { r#override: 0.5 }),
        ev(40.0, Action::Override { r#override: 1.5 }),
        ev(60.0, Action::Override { r#override: 0.75 }),
    ];
    let (r, _) = play(AxiBoard::model(&d), &script);
    let outcomes: Vec<Outcome> = r.axis.commands.iter().map(|c| c.outcome.clone()).collect();
    assert_eq!(outcomes, [Outcome::Done]);
    assert!(r.refused_overrides.is_empty());
    let overrides: Vec<_> = r.swaps.iter().filter(|s| s.events[0] > 0).collect();
    assert_eq!(overrides.len(), 3, "one swap per override");
    for s in overrides {
        let us = s.latency_ticks as f64 * d.ts() * 1e6;
        eprintln!("override latency {us} µs ({} ticks)", s.latency_ticks);
        assert!(us < 100.0, "{us} µs");
    }
    assert_eq!((r.last.v, r.last.a, r.last.j), (0, 0, 0));
    assert_eq!(
        DEFAULT_FORMAT.output_lsb(r.last.x),
        (30.0 / DEFAULT_FORMAT.position_lsb).round() as i128
    );
    assert!(r.checks >= 5);
}

/// The Verilated AXI design with its model in lockstep under the same host: a move with an
/// override, no clock where they differ; the snapshot registers equal READ_STATE's at rest.
#[test]
fn the_fabric_runs_the_host_bit_for_bit() {
    let d = real_design();
    let script = [
        ev(0.0, mv(2.0, 100.0)),
        ev(5.0, Action::Override { r#override: 0.5 }),
    ];
    let board = AxiBoard::lockstep(&d).unwrap();
    let (r, board) = play(board, &script);
    assert_eq!(board.mismatches(), 0, "{:?}", board.first_mismatch());
    assert!(board.clocks() > 1_000_000);
    assert_eq!((r.last.v, r.last.a, r.last.j), (0, 0, 0));
    // The snapshot (no frame) against READ_STATE (a frame) at rest.
    let lsb = DEFAULT_FORMAT.position_lsb;
    let mut s = Session::open(axi_link(board).unwrap(), lsb).unwrap();
    let via_frame = s.state().unwrap();
    let (status, via_registers) = s.link.transport_mut().snapshot().unwrap();
    assert_eq!(
        (
            via_registers.x,
            via_registers.v,
            via_registers.a,
            via_registers.j
        ),
        (via_frame.x, via_frame.v, via_frame.a, via_frame.j)
    );
    assert!(via_registers.ticks >= via_frame.ticks);
    assert_eq!(
        i128::from(status.position),
        DEFAULT_FORMAT.output_lsb(via_frame.x)
    );
    assert_eq!(s.link.transport().registers().mismatches(), 0);
}

/// Registers that are not a station's: ID or VERSION wrong.
struct Fake(u32, u32);

impl Registers for Fake {
    fn read(&mut self, offset: u32) -> Result<u32, LinkError> {
        Ok(if offset == 0 { self.0 } else { self.1 })
    }
    fn write(&mut self, _: u32, _: u32) -> Result<(), LinkError> {
        Ok(())
    }
    fn wait_irq(&mut self, _: f64) -> Result<bool, LinkError> {
        Ok(false)
    }
    fn now(&self) -> f64 {
        0.0
    }
    fn sleep(&mut self, _: f64) {}
    fn access_time(&self) -> f64 {
        0.0
    }
}

#[test]
fn a_register_window_that_is_no_station_is_refused() {
    let id = snapgen_spec::axi::ID_MAGIC;
    let version = snapgen_spec::axi::REGISTERS[1].reset;
    let e = RegisterTransport::open(Fake(0xDEAD_BEEF, version))
        .err()
        .unwrap();
    assert!(e.to_string().contains("no snapgen station"), "{e}");
    let e = RegisterTransport::open(Fake(id, version + 1))
        .err()
        .unwrap();
    assert!(e.to_string().contains("register map is version"), "{e}");
    assert!(RegisterTransport::open(Fake(id, version)).is_ok());
    // Nothing waits: a read returns no byte after its wait.
    let mut t = RegisterTransport::open(Fake(id, version)).unwrap();
    let mut out = Vec::new();
    t.read(0.01, &mut out).unwrap();
    assert!(out.is_empty());
}
