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
    let dir = std::env::temp_dir().join(format!("snapgen-lint-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(core_name), &core).unwrap();
    std::fs::write(dir.join(io_name), &io).unwrap();
    let out = std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", "snapgen_io"])
        .arg(dir.join(core_name))
        .arg(dir.join(io_name))
        .output()
        .expect("verilator is installed by the test command");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !text.contains("%Warning"), "{text}");
}
