//! Co-simulation of the Verilated I/O top against the device model, clock by clock, under
//! random command streams (needs Verilator; the README's test command installs it).

use snapgen_host::protocol::{code, ErrorId, Reason};
use snapgen_sim::io::IoSignal;
use snapgen_sim::io_cosim::{cosim_design, describe, run, IoCosimConfig, IoCosimReport, IoFault};

/// The scale CI asks for: two sessions of 4 million clocks each (8·10⁶ clocks), every
/// output compared on every clock, no mismatch — and every path of the command interface
/// exercised on the way.
#[test]
fn random_command_streams_match_bit_for_bit() {
    // (Seed 17: a stream that reaches every path asserted below; seed 14, used before the
    // stream aimed SWAP_AT frames at the lateness edge, no longer reaches a following error.)
    let r = run(&cosim_design(), &IoCosimConfig::new(4_000_000, 17, 2)).unwrap();
    eprintln!("{}", describe(&r));
    assert_eq!(r.mismatch, None);
    assert!(r.clocks >= 8_000_000, "only {} clocks", r.clocks);
    let replies = |c| IoCosimReport::count(&r.replies, c);
    for (c, name) in [
        (code::ACK, "ACK"),
        (code::NAK, "NAK"),
        (code::STATUS, "STATUS"),
        (code::STATE, "STATE"),
        (code::IDENTITY, "IDENTITY"),
        (code::CONFIG, "CONFIG"),
        (code::TELEMETRY, "TELEMETRY"),
    ] {
        assert!(replies(c) > 0, "no {name} was sent");
    }
    for reason in [
        Reason::BadCrc,
        Reason::BadLength,
        Reason::UnknownCommand,
        Reason::Framing,
        Reason::NotEnabled,
        Reason::AxisError,
        Reason::Busy,
        Reason::BadArgument,
        Reason::NoProgram,
        Reason::Stopping,
        Reason::NotConfigured,
        Reason::Limit,
        Reason::NotDisabled,
        Reason::Late,
        Reason::SwapPending,
    ] {
        assert!(
            IoCosimReport::count(&r.naks, reason as u8) > 0,
            "no NAK {}",
            reason.name()
        );
    }
    // Every refusal is one the refusal table lists for its command.
    assert!(
        r.undocumented.is_empty(),
        "refusals not in the table: {:?}",
        r.undocumented
    );
    for e in [
        ErrorId::EmergencyStop,
        ErrorId::LimitPositive,
        ErrorId::LimitNegative,
        ErrorId::Watchdog,
        ErrorId::ProgramEnd,
        ErrorId::FollowingError,
    ] {
        assert!(
            IoCosimReport::count(&r.errors, e as u8) > 0,
            "never in ErrorStop for {}",
            e.name()
        );
    }
    assert!(r.moves_started >= 10, "{} moves", r.moves_started);
    assert!(r.swaps_armed >= 10, "{} swaps armed", r.swaps_armed);
    // (A cancelled swap empties the standby bank, a clock after the stop.)
    assert!(r.swaps_cancelled > 0, "no armed swap was cancelled");
    // (SWAP_AT's lateness check at its edge, with the time base ticking just before it.)
    assert!(
        r.swaps_aimed > 0,
        "no SWAP_AT was sent at the lateness edge"
    );
    assert!(r.stops_acked >= 10, "{} stops", r.stops_acked);
    assert!(r.stopping_clocks > 10_000);
    assert!(r.overflow_clocks > 0, "the reply queue never overflowed");
    assert!(r.damaged_sent > 20);
}

/// The comparison can fail: a flipped bit of a pin or of a status field is reported at its
/// clock, with its name, and the waves around it are written.
#[test]
fn a_flipped_output_bit_is_reported_with_waves() {
    let dir = std::env::temp_dir().join(format!("snapgen-io-fault-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (clock, signal, bit) in [
        (1_000u64, "uart_tx", 0u32),
        (20_000, "amplifier", 0),
        (30_000, "status.flags", 5),
        (40_000, "status.encoder", 31),
        (45_000, "led_heartbeat", 0),
    ] {
        let mut cfg = IoCosimConfig::new(50_000, 3, 1);
        cfg.fault = Some(IoFault {
            clock,
            signal: signal.parse::<IoSignal>().unwrap(),
            bit,
        });
        cfg.mismatch_vcd = dir.join(format!("{signal}.vcd"));
        let r = run(&cosim_design(), &cfg).unwrap();
        let m = r.mismatch.expect("the flipped bit must be reported");
        assert_eq!((m.clock, m.signal.name()), (clock, signal.to_string()));
        assert_ne!(m.expected, m.actual);
        let vcd = std::fs::read_to_string(r.vcd.unwrap()).unwrap();
        assert!(vcd.contains("$enddefinitions"), "a VCD file");
        // The window's clocks before the mismatch (2 000 at most) are recorded, two edges each.
        let edges = snapgen_sim::vcd::clock_changes(&vcd) as u64;
        assert!(
            edges >= 2 * clock.min(2000),
            "{edges} clock edges in the waves"
        );
    }
    // A fault past the session's end is an error, not a clean report.
    let mut cfg = IoCosimConfig::new(1_000, 3, 1);
    cfg.fault = Some(IoFault {
        clock: 5_000,
        signal: "pwm".parse().unwrap(),
        bit: 0,
    });
    assert!(run(&cosim_design(), &cfg).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}
