//! Board builds and the synthesis check (Yosys and Verilator are installed by the test
//! command; Vivado is not available here, so the build is written, linted and synthesised by
//! Yosys, not run).

use std::path::PathBuf;
use std::process::Command;

mod common;
use common::{assert_ok, lint_clean, snapgen};

fn tmp(name: &str) -> PathBuf {
    common::tmp("fpga", name)
}

/// Stand-ins for the 7-series MMCM and global clock buffer, for the lint only (Verilator does
/// not know the primitives): the ports the board top connects, one file each.
const XC7_STAND_INS: [(&str, &str); 2] = [
    (
        "MMCME2_BASE",
        "module MMCME2_BASE #(parameter BANDWIDTH = \"\", STARTUP_WAIT = \"\",
  real CLKIN1_PERIOD = 0.0, CLKFBOUT_MULT_F = 0.0, CLKFBOUT_PHASE = 0.0,
  CLKOUT0_DIVIDE_F = 0.0, CLKOUT0_DUTY_CYCLE = 0.0, CLKOUT0_PHASE = 0.0, REF_JITTER1 = 0.0,
  integer DIVCLK_DIVIDE = 1) (
  input wire CLKIN1, CLKFBIN, PWRDWN, RST,
  output wire CLKFBOUT, CLKOUT0, LOCKED);
  assign CLKFBOUT = CLKIN1;
  assign CLKOUT0 = CLKIN1;
  assign LOCKED = 1'b1;
endmodule
",
    ),
    (
        "BUFG",
        "module BUFG (input wire I, output wire O);
  assign O = I;
endmodule
",
    ),
];

/// Writes the stand-ins into `dir/stand-ins/`; their paths, relative to `dir`.
fn write_xc7_stand_ins(dir: &std::path::Path) -> Vec<String> {
    std::fs::create_dir_all(dir.join("stand-ins")).unwrap();
    XC7_STAND_INS
        .iter()
        .map(|(name, body)| {
            let path = format!("stand-ins/{name}.v");
            std::fs::write(
                dir.join(&path),
                format!(
                    "// A stand-in for a 7-series primitive, for the lint only.\n`default_nettype none\n\
                     /* verilator lint_off UNUSEDPARAM */ // only the ports are linted\n\
                     /* verilator lint_off UNUSEDSIGNAL */ // only the ports are linted\n{body}\
                     /* verilator lint_on UNUSEDSIGNAL */\n/* verilator lint_on UNUSEDPARAM */\n\
                     `default_nettype wire\n"
                ),
            )
            .unwrap();
            path
        })
        .collect()
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
    assert_ok(&out);
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
        "if {$wns < 0 || $whs < 0}",
        "write_bitstream",
    ] {
        assert!(tcl.contains(step), "build.tcl lacks {step}");
    }
    // The bitstream is written only after the slack check.
    assert!(tcl.find("$whs < 0") < tcl.find("write_bitstream"), "{tcl}");
    // The fabric runs at 100 MHz, made by an MMCM from the 125 MHz oscillator (the XDC
    // constrains the oscillator; Vivado derives the MMCM's clock), held in reset until it locks.
    let top = read("snapgen_zybo_z7_10.v");
    for want in [
        "MMCME2_BASE #(",
        ".CLKIN1_PERIOD(8.000)",
        ".DIVCLK_DIVIDE(1)",
        ".CLKFBOUT_MULT_F(8.0)",
        ".CLKOUT0_DIVIDE_F(10.0)",
        "BUFG clock_buffer",
        ".clock(clk)",
        "btn_reset | !pll_locked",
        "Clock 100 MHz",
    ] {
        assert!(top.contains(want), "board top lacks {want}");
    }
    assert!(tcl.contains("set part xc7z010clg400-1"));
    assert!(read("Makefile").contains("VIVADO ?= vivado"));
    assert!(read("snapgen_io.v").contains("module snapgen_io("));
}

/// Every file snapgen generates — the core, the I/O top and a board build, here for another
/// clock, baud rate and Ts than the defaults — goes into one project: read together, Verilator
/// lints each top clean under -Wall with no configuration file, Yosys synthesises each top, the
/// module names are unique and free of '$', and every waiver in them gives its reason.
#[test]
fn every_generated_file_reads_together() {
    let dir = tmp("together");
    let timing = ["--clock-hz", "100e6", "--baud", "921600", "--ts", "2e-5"];
    let mut args = vec!["verilog", "--out", dir.to_str().unwrap()];
    args.extend_from_slice(&timing);
    let out = snapgen(&args);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    assert!(
        text.contains("109 clocks per bit") && text.contains("2000 clocks"),
        "{text}"
    );
    let mut args = vec!["build", "--out", dir.to_str().unwrap()];
    args.extend_from_slice(&timing);
    let out = snapgen(&args);
    assert_ok(&out);
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["snapgen_core.v", "snapgen_io.v", "snapgen_zybo_z7_10.v"],
        "files written"
    );
    let io = std::fs::read_to_string(dir.join("snapgen_io.v")).unwrap();
    assert!(
        io.contains("(109 clocks per bit)") && io.contains("tick divider 1999 after reset"),
        "header"
    );
    let mut modules = Vec::new();
    for f in &files {
        let v = std::fs::read_to_string(dir.join(f)).unwrap();
        let plain = v.replace("$signed", "").replace("$unsigned", "");
        assert!(!plain.contains('$'), "{f}: a name with '$'");
        assert!(v.contains("`default_nettype none"), "{f}");
        for line in v.lines().filter(|l| l.contains("lint_off")) {
            assert!(
                line.contains("*/ //"),
                "{f}: a waiver without its reason: {line}"
            );
        }
        modules.extend(
            v.lines()
                .filter_map(|l| l.trim_start().strip_prefix("module "))
                .map(|m| m.split(['(', ' ']).next().unwrap().to_string()),
        );
    }
    let n = modules.len();
    modules.sort();
    modules.dedup();
    assert_eq!(modules.len(), n, "a module name is defined twice");
    // The board top makes the 100 MHz from the Zybo's 125 MHz with an MMCM: Verilator reads
    // stand-ins for the primitives (Yosys knows them). Each top lints clean on its own; the
    // board top, which holds the other two, and the motion core alone are synthesised and
    // checked for latches by `snapgen synth` (its test below).
    let stand_ins = write_xc7_stand_ins(&dir);
    for top in ["snapgen_zybo_z7_10", "snapgen_io", "snapgen_core"] {
        let mut lint_files = files.clone();
        if top == "snapgen_zybo_z7_10" {
            lint_files.extend(stand_ins.iter().cloned());
        }
        lint_clean(&dir, top, &lint_files);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A board of one's own: a copy of the Zybo file with another name and clock builds; a
/// broken one is refused with exit 2 and the field to change.
#[test]
fn a_board_file_of_ones_own() {
    let dir = tmp("own-board");
    std::fs::create_dir_all(&dir).unwrap();
    let zybo = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/boards/zybo-z7-10.toml"
    ))
    .unwrap();
    let mine = zybo
        .replace("name = \"zybo-z7-10\"", "name = \"my-board\"")
        .replace("frequency_hz = 125000000", "frequency_hz = 100000000");
    let file = dir.join("my-board.toml");
    std::fs::write(&file, &mine).unwrap();
    let out_dir = dir.join("build");
    let out = snapgen(&[
        "build",
        "--board-file",
        file.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let xdc = std::fs::read_to_string(out_dir.join("snapgen_my_board.xdc")).unwrap();
    assert!(xdc.contains("-period 10.000"), "{xdc}");
    assert!(out_dir.join("snapgen_my_board.v").exists());
    // A pin used twice.
    std::fs::write(&file, mine.replace("pin = \"W15\"", "pin = \"V15\"")).unwrap();
    let out = snapgen(&[
        "build",
        "--board-file",
        file.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("my-board.toml") && err.contains("already used by pwm"),
        "{err}"
    );
    // A Ts the board's clock cannot count.
    let out = snapgen(&[
        "build",
        "--ts",
        "1.0001e-5",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("not a whole number"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
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
    assert!(
        err.contains("known boards are zybo-z7-10") && err.contains("--board-file"),
        "{err}"
    );
}

/// The CI budget: the motion core alone within 1 000 LUT, 1 500 FF and a 5 ns logic-only path.
#[test]
fn synth_keeps_the_motion_core_within_budget() {
    let out = snapgen(&["synth", "--board", "zybo-z7-10"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    assert!(text.contains("motion core within budget"), "{text}");
    assert!(text.contains("| motion core alone"), "{text}");
    assert!(text.contains("| stop unit"), "{text}");
    assert!(text.contains("| board top"), "{text}");
    assert!(text.contains("| path interpolator for 4 axes"), "{text}");
    assert!(text.contains("| path sequencer for 4 axes"), "{text}");
    assert!(text.contains("| path steppers for 4 axes"), "{text}");
    assert!(text.contains("| path core for 4 axes"), "{text}");
    assert!(text.contains("| step/dir generator of one axis"), "{text}");
}

/// The ULX3S's open-toolchain build, written without running it: the constraints carry the
/// board's pins, pulls and oscillator; the board top makes the fabric clock with the ECP5's
/// PLL and lints clean with the rest (an EHXPLLL stand-in for Verilator, which does not know
/// the primitive); the Makefile holds the steps `snapgen build` runs. Place and route and the
/// bitstream themselves run in the test command (scripts/route.sh), which fails when routed
/// timing does not close.
#[test]
fn build_writes_an_open_ecp5_build() {
    let dir = tmp("ulx3s");
    let out = snapgen(&[
        "build",
        "--board",
        "ulx3s",
        "--files-only",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    let lpf = read("snapgen_ulx3s.lpf");
    assert!(lpf.contains("FREQUENCY PORT \"sysclk\" 25 MHZ;"), "{lpf}");
    // ULX3S facts (emard/ulx3s ulx3s_v20.lpf): the oscillator, the FT231X's lines, FIRE1,
    // the LEDs and header J1.
    for (port, site) in [
        ("sysclk", "G2"),
        ("uart_txd", "L4"),
        ("uart_rxd", "M1"),
        ("btn_reset", "R1"),
        ("led[0]", "B2"),
        ("led[3]", "D2"),
        ("pwm", "B11"),
        ("enc_i", "A7"),
        ("wifi_gpio0", "L2"),
    ] {
        let line = format!("LOCATE COMP \"{port}\" SITE \"{site}\";");
        assert!(lpf.contains(&line), "missing {line}");
    }
    assert!(lpf.contains("IOBUF PORT \"estop\" IO_TYPE=LVCMOS33 PULLMODE=UP;"));
    assert!(lpf.contains("IOBUF PORT \"btn_reset\" IO_TYPE=LVCMOS33 PULLMODE=DOWN;"));
    let top = read("snapgen_ulx3s.v");
    for want in [
        ".CLKI_DIV(1)",
        ".CLKFB_DIV(4)",
        ".CLKOP_DIV(6)",
        ".clock(clk)",
        "btn_reset | !pll_locked",
        "assign wifi_gpio0 = 1'b1;",
        "Clock 100 MHz",
    ] {
        assert!(top.contains(want), "board top lacks {want}");
    }
    let make = read("Makefile");
    for want in [
        "synth_ecp5 -top snapgen_ulx3s",
        "$(NEXTPNR) --85k --package CABGA381 --speed 6",
        "--lpf snapgen_ulx3s.lpf",
        "$(ECPPACK) --compress snapgen_ulx3s.config snapgen_ulx3s.bit",
    ] {
        assert!(make.contains(want), "Makefile lacks {want}");
    }
    std::fs::write(
        dir.join("EHXPLLL.v"),
        "// A stand-in for the ECP5 PLL primitive, for the lint only.\n\
         `default_nettype none\n\
         /* verilator lint_off UNUSEDPARAM */ // only the ports are linted\n\
         /* verilator lint_off UNUSEDSIGNAL */ // only the ports are linted\n\
         module EHXPLLL #(parameter PLLRST_ENA = \"\", INTFB_WAKE = \"\", STDBY_ENABLE = \"\",\n\
           DPHASE_SOURCE = \"\", OUTDIVIDER_MUXA = \"\", CLKOP_ENABLE = \"\", FEEDBK_PATH = \"\",\n\
           integer CLKI_DIV = 1, CLKFB_DIV = 1, CLKOP_DIV = 1, CLKOP_CPHASE = 0, CLKOP_FPHASE = 0) (\n\
           input wire CLKI, CLKFB, RST, STDBY, PHASESEL0, PHASESEL1, PHASEDIR, PHASESTEP,\n\
           input wire PHASELOADREG, PLLWAKESYNC, ENCLKOP,\n\
           output wire CLKOP, LOCK);\n\
           assign CLKOP = CLKI;\n\
           assign LOCK = 1'b1;\n\
         endmodule\n\
         /* verilator lint_on UNUSEDSIGNAL */\n\
         /* verilator lint_on UNUSEDPARAM */\n\
         `default_nettype wire\n",
    )
    .unwrap();
    let files: Vec<String> = [
        "EHXPLLL.v",
        "snapgen_core.v",
        "snapgen_io.v",
        "snapgen_ulx3s.v",
    ]
    .map(String::from)
    .to_vec();
    lint_clean(&dir, "snapgen_ulx3s", &files);
    // A fabric clock the PLL cannot make exactly is refused (exit 2) with the nearest ones.
    let out = snapgen(&[
        "build",
        "--board",
        "ulx3s",
        "--files-only",
        "--clock-hz",
        "77000000",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no ECP5 PLL setting makes exactly 77000000 Hz"),
        "{err}"
    );
    // Flags of the other toolchain, and synth's Xilinx report, are refused (exit 2).
    let out_dir = dir.to_str().unwrap();
    for (args, want) in [
        (
            vec!["build", "--board", "ulx3s", "--run", "--out", out_dir],
            "drop --run",
        ),
        (
            vec!["build", "--files-only", "--out", out_dir],
            "drop --files-only",
        ),
        (vec!["synth", "--board", "ulx3s"], "is an ECP5 board"),
    ] {
        let out = snapgen(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
