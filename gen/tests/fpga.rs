//! Board builds and the synthesis check (Yosys and Verilator are installed by the test
//! command; Vivado is not available here, so the build is written, linted and synthesised by
//! Yosys, not run).

use std::process::Command;

fn snapgen(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(args)
        .output()
        .unwrap()
}

fn tmp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("snapgen-fpga-{}-{name}", std::process::id()))
}

#[test]
fn build_writes_a_complete_vivado_build() {
    let dir = tmp("build");
    let out = snapgen(&[
        "build",
        "--board",
        "zybo-z7-10",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    let xdc = read("snapgen_zybo_z7_10.xdc");
    assert!(
        xdc.contains("create_clock -add -name sys_clk_pin -period 8.000"),
        "{xdc}"
    );
    // The Zybo Z7-10 facts: clock, BTN0, the LEDs, the Pmod pins used.
    for (pin, port) in [
        ("K17", "sysclk"),
        ("K18", "btn_reset"),
        ("M14", "led[0]"),
        ("M15", "led[1]"),
        ("G14", "led[2]"),
        ("D18", "led[3]"),
        ("W16", "uart_txd"),
        ("J15", "uart_rxd"),
        ("T14", "enc_a"),
        ("T15", "enc_b"),
        ("P14", "enc_i"),
        ("V15", "pwm"),
        ("W15", "dir"),
    ] {
        let line = format!("PACKAGE_PIN {pin} IOSTANDARD LVCMOS33 }} [get_ports {{ {port} }}]");
        assert!(xdc.contains(&line), "missing {line}");
    }
    let tcl = read("build.tcl");
    for step in [
        "read_verilog",
        "read_xdc",
        "synth_design -top $top -part $part",
        "opt_design",
        "place_design",
        "route_design",
        "report_utilization",
        "report_timing_summary",
        "write_bitstream",
    ] {
        assert!(tcl.contains(step), "build.tcl lacks {step}");
    }
    assert!(tcl.contains("set part xc7z010clg400-1"));
    assert!(read("Makefile").contains("VIVADO ?= vivado"));
    // The board top and the I/O top together are lint-clean under -Wall (with the waivers).
    std::fs::write(dir.join("verilator.vlt"), snapgen_sim_waivers()).unwrap();
    let lint = Command::new("verilator")
        .current_dir(&dir)
        .args([
            "--lint-only",
            "-Wall",
            "--top-module",
            "snapgen_zybo_z7_10",
            "verilator.vlt",
            "io_top.v",
            "snapgen_zybo_z7_10.v",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&lint.stderr);
    assert!(
        lint.status.success() && !text.contains("%Warning"),
        "{text}"
    );
}

fn snapgen_sim_waivers() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../hdl/verilator.vlt")).unwrap()
}

#[test]
fn running_without_vivado_says_how_to_get_it() {
    let dir = tmp("run");
    let out = Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(["build", "--out", dir.to_str().unwrap(), "--run"])
        .env("VIVADO", "/nonexistent/vivado")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("Vivado") && err.contains("set VIVADO"),
        "{err}"
    );
}

#[test]
fn unknown_board_is_a_usage_error() {
    let out = snapgen(&[
        "build",
        "--board",
        "arty",
        "--out",
        tmp("x").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("known boards are zybo-z7-10"), "{err}");
}

/// The CI budget: the motion core alone within 1 000 LUT, 1 500 FF and a 5 ns logic-only path.
#[test]
fn synth_keeps_the_motion_core_within_budget() {
    let out = snapgen(&["synth", "--board", "zybo-z7-10"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("motion core within budget"), "{text}");
    assert!(text.contains("| motion core alone"), "{text}");
    assert!(text.contains("| board top"), "{text}");
}
