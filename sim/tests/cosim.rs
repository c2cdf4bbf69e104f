//! Co-simulation of the generated core against the model (needs Verilator; the README's test
//! command installs it).

use snapgen_sim::build::build;
use snapgen_sim::cosim::{run, CosimConfig, Fault, Register};
use snapgen_sim::moves::OrderMix;
use snapgen_sim::SimError;

/// The compared register called `name`.
fn reg(name: &str) -> Register {
    Register::named(name).unwrap_or_else(|| panic!("no register {name}"))
}

fn verilog() -> String {
    snapgen_hdl::verilog::motion_core_verilog()
}

fn quiet(moves: usize, seed: u64) -> CosimConfig {
    CosimConfig::new(moves, seed)
}

/// PLCopen event streams only (no controlled stops, no single replans).
fn streams_only(moves: usize, seed: u64) -> CosimConfig {
    let mut c = quiet(moves, seed);
    c.stream_share = 1.0;
    c.stop_share = 0.0;
    c.replan_share = 0.0;
    c
}

/// The scale CI asks for: at least 1 000 random moves and 10^7 ticks, every output compared
/// on every clock, no mismatch.
#[test]
fn thousand_random_moves_match_bit_for_bit() {
    // Stops that begin outside their limits are rare in this stream (0–4 in 240–260 stops,
    // depending on where the stops fall): seed 9 has some (seed 7 had one before the stop
    // unit's landing clocks lengthened its preparation, none after).
    let mut c = quiet(1000, 9);
    // The PLCopen streams have a test of their own.
    c.stream_share = 0.0;
    let r = run(&verilog(), &c).unwrap();
    assert_eq!(r.mismatch, None);
    assert_eq!(r.planner_disagreements, 0);
    assert_eq!(r.moves, 1000);
    assert!(r.ticks >= 10_000_000, "only {} ticks", r.ticks);
    assert!(r.aborted > 0, "no move was aborted midway");
    // Controlled stops at random clocks of random moves: every one at rest at its end, some
    // begun outside their limits, some aborted on the way.
    eprintln!(
        "{} stops, {} began over their limits, {} aborted on the way, {} ran too long",
        r.stopped, r.stops_over, r.stops_aborted, r.stops_timed_out
    );
    assert!(
        r.stops_timed_out * 10 < r.stopped,
        "most stops must run to their end"
    );
    assert!(r.stopped >= 100, "only {} controlled stops", r.stopped);
    assert!(r.stops_over > 0, "no stop began outside its limits");
    assert!(r.stops_aborted > 0, "no stop was aborted");
    assert_eq!(r.stops_not_at_rest, 0);
}

/// Online replanning on the fabric, at the scale the issue asks of CI: at least 10 000 program
/// swaps at random ticks (mid-jerk, mid-acceleration, at cruise, from rest), each planned from
/// the state the model predicts for its tick, over at least 10^7 ticks; late swaps that must
/// change nothing and stops that cancel an armed swap among them. Every output compared on
/// every clock, and every chain ends exactly where its last plan said.
#[test]
fn ten_thousand_random_replans_match_bit_for_bit() {
    let mut c = quiet(2600, 11);
    c.replan_share = 1.0;
    c.stop_share = 0.0;
    c.stream_share = 0.0;
    let r = run(&verilog(), &c).unwrap();
    eprintln!(
        "{} replans, {} ticks, refused {:?}, {} too long, {} late, {} cancelled by a stop",
        r.replans, r.ticks, r.replans_refused, r.replans_too_long, r.late_swaps, r.swaps_cancelled
    );
    assert_eq!(r.mismatch, None);
    assert_eq!(r.planner_disagreements, 0);
    assert_eq!(r.swap_faults(), 0);
    assert!(r.replans >= 10_000, "only {} replans", r.replans);
    assert!(r.ticks >= 10_000_000, "only {} ticks", r.ticks);
    assert!(r.late_swaps >= 100 && r.swaps_cancelled >= 50);
    assert_eq!(r.stops_not_at_rest, 0);
}

/// PLCopen event streams on the fabric, at the scale the issue asks of CI: random scripts of
/// MC_MoveAbsolute (every buffer mode, blends among them), MC_MoveVelocity, MC_Halt and
/// override changes at random ticks (mid-jerk, mid-acceleration, at cruise), every change
/// planned by the host axis from the exact state at its swap tick and its swap led by the host's
/// own driver over the core's ports with a UART's wire time: at least 10 000 replans (swaps
/// other than the uploads of the rest of a long change) over at least 10^7 ticks. Every output
/// compared on every clock, every state the driver reads equal to its prediction, every
/// stream ending at rest where its timeline says.
#[test]
fn ten_thousand_plcopen_replans_match_bit_for_bit() {
    let c = streams_only(3000, 17);
    let r = run(&verilog(), &c).unwrap();
    let errors: usize = r.stream_errors.values().sum();
    eprintln!(
        "{} streams, {} commands ({} in Error: {:?}), {} swaps ({} extensions), {} ticks; failed runs {:?}",
        r.streams,
        r.stream_commands,
        errors,
        r.stream_errors,
        r.stream_swaps,
        r.stream_extensions,
        r.ticks,
        r.streams_failed
    );
    assert_eq!(r.mismatch, None);
    assert_eq!(r.streams_diverged, 0, "{:?}", r.divergences);
    assert_eq!(r.planner_disagreements, 0);
    assert_eq!(r.swap_faults(), 0);
    assert!(r.streams_failed.is_empty(), "{:?}", r.streams_failed);
    assert_eq!(r.streams_stopped, 0, "a stream did not end at rest");
    let replans = r.stream_swaps - r.stream_extensions;
    assert!(replans >= 10_000, "only {replans} replans");
    assert!(r.ticks >= 10_000_000, "only {} ticks", r.ticks);
    // A command is refused rarely (a blend the previous move can no longer reach is buffered
    // instead, not refused): a link too slow for a long change, a start far beyond new limits.
    assert!(
        errors * 500 <= r.stream_commands,
        "{errors} commands in Error"
    );
}

/// Two stream sets where a change came while the upload of a short head was under way, so it
/// waited for that head's swap and then had to upload the rest of the head's change at once.
/// Both once ended a stream in "LATE again and again", from two faults: the rest was carried
/// from too early a tick (more segments, so a longer lead than needed), and the wait for the
/// swap counted from the tick the board answered, not from its reply's arrival. Seed 7 fails
/// with either fault put back; every stream now keeps the board going.
#[test]
fn a_change_during_a_short_heads_upload_keeps_the_board_going() {
    for seed in [5, 7] {
        let c = streams_only(2000, seed);
        let r = run(&verilog(), &c).unwrap();
        assert_eq!(r.mismatch, None);
        assert_eq!(r.streams_diverged, 0, "{:?}", r.divergences);
        assert!(
            r.streams_failed.is_empty(),
            "seed {seed}: {:?}",
            r.streams_failed
        );
        assert_eq!(
            r.streams_stopped, 0,
            "seed {seed}: a stream did not end at rest"
        );
    }
}

/// The swap comparison can fail: a fabric whose swap comes one tick early (its timer flags
/// the last old tick one tick too soon) is caught; the same comparison written another way
/// (both sides less one) is not a difference and agrees.
#[test]
fn a_swap_one_tick_early_is_caught() {
    let good = verilog();
    let compare = "next_is_last_d = ticks_next == last_reg_q;";
    assert_eq!(
        good.matches(compare).count(),
        1,
        "the swap timer's comparison moved: update this test"
    );
    let mut c = quiet(30, 4);
    c.replan_share = 1.0;
    c.stop_share = 0.0;
    c.session_count = 1;
    let same = good.replace(
        compare,
        "next_is_last_d = (ticks_next - 32'd1) == (last_reg_q - 32'd1);",
    );
    let r = run(&same, &c).unwrap();
    assert_eq!(r.mismatch, None, "an equivalent comparison must agree");
    assert!(r.replans > 10, "{} replans", r.replans);
    let early = good.replace(
        compare,
        "next_is_last_d = ticks_next == (last_reg_q - 32'd1);",
    );
    let r = run(&early, &c).unwrap();
    let m = r.mismatch.expect("a swap one tick early must be caught");
    eprintln!("{m}");
    // And by the PLCopen streams.
    c.replan_share = 0.0;
    c.stream_share = 1.0;
    let r = run(&early, &c).unwrap();
    let m = r
        .mismatch
        .expect("a swap one tick early must be caught by the streams");
    eprintln!("{m}");
}

#[test]
fn every_order_alone_matches() {
    for (mix, seed) in [
        (OrderMix::Two, 21),
        (OrderMix::Three, 22),
        (OrderMix::Four, 23),
    ] {
        let mut c = quiet(60, seed);
        c.mix = mix;
        let r = run(&verilog(), &c).unwrap();
        assert_eq!(r.mismatch, None, "{mix:?}");
        assert_eq!(r.planner_disagreements, 0, "{mix:?}");
        assert_eq!(r.moves, 60);
    }
}

/// The comparison can fail: one flipped bit in the captured fabric stream is reported at its
/// clock, with its register and bits, and the waves around it are written.
#[test]
fn a_flipped_bit_is_reported_with_waves() {
    let dir = std::env::temp_dir().join(format!("snapgen-fault-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (clock, register, bit) in [
        (5_000u64, reg("x"), 3u32),
        (7_777, reg("j"), 101),
        (12_345, reg("busy"), 0),
        (9_000, reg("tick_count"), 31),
    ] {
        let mut c = quiet(40, 5);
        // The fault lands in session 0: two sessions give it 20 moves, long past these clocks.
        c.session_count = 2;
        c.fault = Some(Fault {
            clock,
            register,
            bit,
        });
        c.mismatch_vcd = dir.join(format!("{}.vcd", register.name()));
        let r = run(&verilog(), &c).unwrap();
        let m = r.mismatch.expect("the flipped bit must be reported");
        assert_eq!(m.clock, clock);
        assert_eq!(m.register, register);
        assert_eq!(m.expected ^ m.actual, 1u128 << bit);
        let vcd = std::fs::read_to_string(r.vcd.unwrap()).unwrap();
        assert!(
            vcd.contains("$var") && vcd.contains(" x "),
            "not a VCD with x"
        );
        // The window around the mismatch: dumps at times 2·clock ± a few.
        assert!(
            vcd.contains(&format!("#{}", 2 * clock + 1)),
            "mismatch clock not dumped"
        );
        assert!(
            !vcd.contains("\n#3\n"),
            "dumped from the start, not a window"
        );
        // Every clock of the window is recorded (two edges a clock), not only the first dump.
        let edges = snapgen_sim::vcd::clock_changes(&vcd);
        assert!(edges >= 2 * 64, "{edges} clock edges in the waves");
    }
}

/// A fault past the end of its session is an error, not a clean report.
#[test]
fn a_fault_never_reached_is_an_error() {
    let mut c = quiet(4, 5);
    c.fault = Some(Fault {
        clock: 1 << 40,
        register: reg("x"),
        bit: 0,
    });
    match run(&verilog(), &c) {
        Err(SimError::FaultNotReached { clock, clocks }) => {
            assert_eq!(clock, 1 << 40);
            assert!(clocks > 0 && clocks < clock);
        }
        other => panic!("expected FaultNotReached, got {other:?}"),
    }
}

#[test]
fn unchanged_verilog_is_not_rebuilt() {
    let v = verilog();
    build(&v, false).unwrap();
    assert!(build(&v, false).unwrap().cached);
}

/// The stop's release rule on the fabric: moves stopped in their deceleration with a stop jerk
/// of one LSB, where a release at STOP_JERK would reverse (the law's `E < 0`) but the next
/// velocity and acceleration do not (`V + Λ > 0`) — checked on the model's chain for every
/// tick the stop may be taken on — so the stop steps the acceleration to zero at once, then
/// brakes within its limits. Fabric and model agree on every clock, and each stop is reported
/// outside its limits and ends at rest.
#[test]
fn a_stop_that_releases_at_once_matches_on_the_fabric() {
    use snapgen_model::stop::{phase_clocks, StopLaw, StopLimits};
    use snapgen_model::{ChainState, Format};
    use snapgen_plan::{plan, Method, MoveRequest};
    use snapgen_sim::moves::MoveSpec;
    let f = Format::with_ts(1e-5);
    let prep = u64::from(phase_clocks().prep);
    let mut moves = Vec::new();
    for (k, distance) in [0.3, -0.5, 0.8].into_iter().enumerate() {
        let request = MoveRequest {
            distance,
            method: Method::Order3 {
                vmax: 1.0,
                amax: 50.0,
                jmax: 5e3,
            },
        };
        let p = plan(&request, &f).unwrap();
        let limits = StopLimits {
            jerk: 1,
            accel: 1 << 90,
        };
        // Requested so that it is taken 600–700 ticks before the end: in the deceleration at
        // its full value (the last jerk ramp takes 100 ticks).
        let total = p.ticks_total();
        let request_at = total - 650 - prep;
        for t in request_at + prep - 50..request_at + prep + 50 {
            let s = ChainState::at_rest(f.home_raw()).after_ticks(&p.program, t, &f.widths);
            let law = StopLaw::begin(s.v, s.a, s.j, limits);
            let (vv, lambda) = (s.v + s.a, s.a + s.j);
            assert!(
                law.over_limits() && (vv + lambda) * vv.signum() > 0,
                "move {k}, tick {t}: not a release state"
            );
            assert!(lambda.abs() > 1 << 40, "move {k}: decelerating");
        }
        moves.push(MoveSpec {
            stop_after: Some(request_at),
            stop_limits: limits,
            ..MoveSpec::plain(request, f.ts)
        });
    }
    let r = run(&verilog(), &CosimConfig::fixed(moves)).unwrap();
    assert_eq!(r.mismatch, None);
    assert_eq!((r.stopped, r.stops_over, r.stops_not_at_rest), (3, 3, 0));
}
