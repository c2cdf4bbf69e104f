//! Every block's generated Verilog is lint-clean under `verilator --lint-only -Wall`, with the
//! project's waiver file (needs Verilator; the README's test command installs it).

use rust_hdl::prelude::*;
use snapgen_hdl::verilog::direct_clocks;

fn lint<U: Block>(name: &str, mut uut: U) {
    uut.connect_all();
    let v = direct_clocks(&generate_verilog(&uut));
    let dir = std::env::temp_dir().join(format!("snapgen-lint-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = if name == "io_top" {
        "io_top.v"
    } else {
        "top.v"
    };
    std::fs::write(dir.join(file), v).unwrap();
    let out = std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", "top"])
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/verilator.vlt"))
        .arg(dir.join(file))
        .output()
        .expect("verilator is installed by the test command");
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && !text.contains("%Warning"),
        "{name}:\n{text}"
    );
}

#[test]
fn every_block_lints_clean() {
    lint("motion_core", snapgen_hdl::core::MotionCore::default());
    lint(
        "quadrature",
        snapgen_hdl::quadrature::QuadratureDecoder::<32>::default(),
    );
    lint("pwm", snapgen_hdl::pwm::PwmGenerator::default());
    lint("uart_rx", snapgen_hdl::uart_rx::UartRx::default());
    lint("uart_tx", snapgen_hdl::uart_tx::UartTx::default());
    lint("byte_fifo", snapgen_hdl::byte_fifo::ByteFifo::default());
    lint("frame_rx", snapgen_hdl::frame_rx::FrameRx::default());
    lint("executor", snapgen_hdl::executor::Executor::default());
    lint("reply_tx", snapgen_hdl::reply_tx::ReplyTx::default());
    lint("io_top", snapgen_hdl::io_top::IoTop::default());
}
