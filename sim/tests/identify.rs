//! Identification through the fabric (issue 24, item 1): the host's excitation
//! (`snapgen_host::identify`) on the Verilated I/O top with the device model in lockstep,
//! around a simulated motor unlike the plant file; the record is the board's own TELEMETRY
//! frames over its UART, the fit `snapgen_plant::identify`'s.

use snapgen_host::identify::{record, to_record, Excitation};
use snapgen_host::protocol::ErrorId;
use snapgen_host::session::HostError;
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_model::{Format, DEFAULT_FORMAT};
use snapgen_plant::gains::{derive, LoopDesign, LoopTiming};
use snapgen_plant::identify::{excitation, identify, Bounds, Model};
use snapgen_plant::{Physical, PlantParams};
use snapgen_sim::closed_loop::{AxisSetup, ClosedLoop};

/// A small design: 2 MHz, 250 000 baud, Ts = 50 µs; PWM 20 kHz (100 clocks); the excitation's
/// loop at 250 Hz (80 ticks), one TELEMETRY frame (1.4 ms on the wire) a sample.
const PWM: u16 = 100;
const PERIOD: u16 = 80;

fn design() -> Design {
    let t = Timing {
        clock_hz: 2_000_000,
        baud: 250_000,
        ts: 50e-6,
    };
    snapgen_hdl::verilog::io_design(&Design::from_timing(&DEFAULT_FORMAT, &t).unwrap())
}

/// The excitation for the data sheet's plant, with the following-error limit `limit_rad`.
fn excitation_for(f: &Format, guess: &Physical, limit_rad: f64) -> Excitation {
    let g = derive(
        guess,
        &LoopDesign {
            bandwidth_hz: 5.0,
            following_limit_rad: limit_rad,
            ..Default::default()
        },
        &LoopTiming {
            ts: f.ts,
            servo_period: PERIOD,
            pwm_period: PWM,
        },
    )
    .unwrap();
    let bounds = Bounds {
        travel: 8.0,
        speed: 40.0,
        accel: 2000.0,
    };
    Excitation {
        pwm_period: PWM,
        servo: g.config,
        stop: AxisSetup::stop_limits(f).unwrap(),
        moves: excitation(f, &bounds)
            .unwrap()
            .into_iter()
            .map(|p| p.program)
            .collect(),
        settle_s: 0.1,
    }
}

#[test]
fn the_fabric_identifies_a_motor_unlike_the_file() {
    let d = design();
    let guess = PlantParams::default_plant().physical();
    let truth = Physical {
        j: guess.j * 1.8,
        tc: guess.tc * 1.5,
        b: 2e-5,
        ..guess
    };
    let f = Format {
        ts: d.ts(),
        position_lsb: guess.rad_per_count(),
        ..DEFAULT_FORMAT
    };
    let mut l = ClosedLoop::new(&d, &truth, 1e-6, true, u64::MAX).unwrap();
    l.run(200);
    let e = excitation_for(&f, &guess, 0.5);
    let frames = {
        let mut s = l.host().unwrap();
        record(&mut s, &e).unwrap()
    };
    assert_eq!(l.mismatches(), 0, "{:?}", l.first_mismatch());
    let pwm_hz = 2e6 / f64::from(PWM);
    let rec = to_record(&frames, &e, &guess, f.ts, 2_000_000);
    let samples: usize = rec.segments.iter().map(|s| s.angle.len()).sum();
    // A frame for every sample of every move came (but the one a move may start between).
    let expected: u64 = e
        .moves
        .iter()
        .map(|p| p.total_ticks() / u64::from(PERIOD))
        .sum();
    assert!(samples as u64 + 8 >= expected, "{samples} of {expected}");
    let want = Model::of(&truth, pwm_hz);
    let fit = identify(&rec, Some(Model::of(&guess, pwm_hz).dead_zone_v)).unwrap();
    let m = fit.model;
    let rel = |a: f64, b: f64| (a / b - 1.0).abs();
    let msg = format!("{fit:?}\nwant {want:?}");
    assert!(rel(m.gain, want.gain) < 0.05, "{msg}");
    assert!(rel(m.tau, want.tau) < 0.10, "{msg}");
    assert!(rel(m.coulomb_v, want.coulomb_v) < 0.25, "{msg}");
    assert!(fit.simulation_fit_percent > 80.0, "{msg}");
    // The plant file written from it holds the inertia the fit measured.
    let file = fit
        .plant(&PlantParams::default_plant(), pwm_hz, "test")
        .unwrap();
    assert!(
        rel(file.physical().j, truth.j) < 0.12,
        "{}",
        file.physical().j
    );
}

/// The excitation is bounded: a motor that cannot follow (the following-error limit below
/// what the loop needs) trips the board, which switches the amplifier off, and the recording
/// ends with the board's error instead of a fit.
#[test]
fn a_following_error_ends_the_excitation() {
    let d = design();
    let guess = PlantParams::default_plant().physical();
    let f = Format {
        ts: d.ts(),
        position_lsb: guess.rad_per_count(),
        ..DEFAULT_FORMAT
    };
    let mut l = ClosedLoop::new(&d, &guess, 1e-6, true, u64::MAX).unwrap();
    l.run(200);
    let r = {
        let mut s = l.host().unwrap();
        record(&mut s, &excitation_for(&f, &guess, 0.002))
    };
    match r {
        Err(HostError::Stopped { error, .. }) => assert_eq!(error, ErrorId::FollowingError),
        r => panic!("{r:?}"),
    }
    assert_eq!(l.mismatches(), 0, "{:?}", l.first_mismatch());
}
