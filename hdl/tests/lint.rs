//! Every block's generated Verilog, finished as `snapgen verilog` finishes a design (module
//! prefix, waivers written beside their declarations), is lint-clean under
//! `verilator --lint-only -Wall` on its own, with no configuration file (needs Verilator; the
//! README's test command installs it).

use rust_hdl::prelude::*;
use snapgen_hdl::emit::{block_verilog, Waiver};
use snapgen_hdl::verilog::{SEQUENCER_HINTS, SWAP_TIMER_WAIVER};

fn lint<U: Block>(name: &str, uut: U, extra: &[Waiver]) {
    let top = format!("snapgen_{name}");
    let mut waivers = SEQUENCER_HINTS.to_vec();
    waivers.extend_from_slice(extra);
    let v = block_verilog(uut, &top, &waivers).unwrap_or_else(|e| panic!("{name}: {e}"));
    let dir = std::env::temp_dir().join(format!("snapgen-lint-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{top}.v"));
    std::fs::write(&file, v).unwrap();
    let out = std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", &top])
        .arg(&file)
        .output()
        .expect("verilator is installed by the test command");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && !text.contains("%Warning"),
        "{name}:\n{text}"
    );
}

#[test]
fn every_block_lints_clean() {
    lint(
        "motion_core",
        snapgen_hdl::core::MotionCore::default(),
        &[SWAP_TIMER_WAIVER],
    );
    lint(
        "swap_timer",
        snapgen_hdl::swap_timer::SwapTimer::default(),
        &[SWAP_TIMER_WAIVER],
    );
    lint(
        "quadrature",
        snapgen_hdl::quadrature::QuadratureDecoder::<32>::default(),
        &[],
    );
    lint("pwm", snapgen_hdl::pwm::PwmGenerator::default(), &[]);
    lint("servo", snapgen_hdl::servo::Servo::default(), &[]);
    lint("uart_rx", snapgen_hdl::uart_rx::UartRx::default(), &[]);
    lint("uart_tx", snapgen_hdl::uart_tx::UartTx::default(), &[]);
    lint(
        "byte_fifo",
        snapgen_hdl::byte_fifo::ByteFifo::default(),
        &[],
    );
    lint("frame_rx", snapgen_hdl::frame_rx::FrameRx::default(), &[]);
    lint("executor", snapgen_hdl::executor::Executor::default(), &[]);
    lint(
        "reply_queue",
        snapgen_hdl::reply_queue::ReplyQueue::default(),
        &[],
    );
    lint("reply_tx", snapgen_hdl::reply_tx::ReplyTx::default(), &[]);
    lint(
        "status_block",
        snapgen_hdl::status_block::StatusBlock::default(),
        &[],
    );
    lint(
        "flags_word",
        snapgen_hdl::status_block::FlagsWord::default(),
        &[],
    );
    lint(
        "input_filter",
        snapgen_hdl::input_filter::InputFilter::new(false),
        &[],
    );
    lint(
        "station",
        snapgen_hdl::station::Station::default(),
        &snapgen_hdl::verilog::station_waivers(),
    );
    lint(
        "io_top",
        snapgen_hdl::io_top::IoTop::default(),
        &snapgen_hdl::verilog::io_top_waivers(),
    );
    lint(
        "step_dir",
        snapgen_hdl::step_dir::StepDirGenerator::default(),
        &[],
    );
    // The interpolator at every number of axes.
    for axes in 1..=8 {
        lint(
            "interpolator",
            snapgen_hdl::interpolator::Interpolator::new(axes),
            &[],
        );
    }
}

/// The files `snapgen verilog` writes: `snapgen_io.v` instantiates `snapgen_core` (no module
/// of the core is written twice), no register is a module of its own, and the two files lint
/// clean together.
#[test]
fn the_io_design_is_its_two_files_with_one_core() {
    let design = snapgen_hdl::verilog::io_design(&snapgen_hdl::defaults::default_design());
    let [(core_name, core), (io_name, io)] = snapgen_hdl::verilog::io_sources(&design);
    assert_eq!((core_name, io_name), ("snapgen_core.v", "snapgen_io.v"));
    assert!(
        io.contains("snapgen_core core("),
        "the I/O top instantiates the core"
    );
    assert!(
        !io.contains("module snapgen_io_core"),
        "no copy of the core"
    );
    for text in [&core, &io] {
        assert!(!text.contains("(d,q,clock)"), "a register module survived");
    }
    lint_files("io", &[(core_name, core), (io_name, io)], "snapgen_io");
}

/// The AXI4-Lite design's three files (`snapgen_axi.v` instantiates the station of
/// `snapgen_io.v`) lint clean together.
#[test]
fn the_axi_design_is_the_io_files_and_its_own() {
    let design = snapgen_hdl::verilog::io_design(&snapgen_hdl::defaults::default_design());
    let files = snapgen_hdl::axi_top::axi_sources(&design);
    assert_eq!(files[2].0, "snapgen_axi.v");
    assert!(files[2].1.contains("snapgen_io_station station("));
    assert!(!files[2].1.contains("module snapgen_axi_station"));
    lint_files("axi", &files, "snapgen_axi");
    // Yosys reads it as plain Verilog and elaborates it without a latch or a driver conflict.
    let dir = std::env::temp_dir().join(format!("snapgen-yosys-axi-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut read = String::new();
    for (name, text) in &files {
        std::fs::write(dir.join(name), text).unwrap();
        read.push_str(&format!("read_verilog {}; ", dir.join(name).display()));
    }
    let out = std::process::Command::new("yosys")
        .args(["-q", "-p"])
        .arg(format!(
            "{read}hierarchy -check -top snapgen_axi; proc; check -assert"
        ))
        .output()
        .expect("yosys is installed by the test command");
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        out.status.success(),
        "yosys: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `files` written to a directory and linted together with `top` as the top module.
fn lint_files(what: &str, files: &[(&str, String)], top: &str) {
    let dir = std::env::temp_dir().join(format!("snapgen-lint-{what}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let out = std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", top])
        .args(files.iter().map(|(name, _)| dir.join(name)))
        .output()
        .expect("verilator is installed by the test command");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && !text.contains("%Warning"),
        "{what}: {text}"
    );
}
