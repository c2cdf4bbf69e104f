//! The AXI4-Lite top (issue 23): the station ([`crate::station`], `snapgen_io_station` in
//! `snapgen_io.v`) behind an AXI4-Lite slave whose register map is the spec's
//! ([`snapgen_spec::axi`]); the reference, clock for clock, is
//! `snapgen_model::io::axi::AxiDevice`. Its ports are the spec's `with_axi_top_ports!`.
//!
//! The Verilog (`hdl/verilog/axi.v`, `snapgen_axi.v`) is a template whose register decode,
//! read multiplexer, snapshot registers and station instance are written from the register
//! map and the station's port list. For rust-hdl's simulator the block runs the model; the
//! Verilog is what is checked: Verilator co-simulation against the model on every clock under
//! random AXI traffic (`snapgen_sim::axi_cosim`).

use rust_hdl::prelude::*;
use snapgen_model::device::Design;
use snapgen_model::io::axi::AxiDevice;
use snapgen_model::ports::{AxiInputs, AxiOutputs};
use snapgen_spec::axi::{
    offset, Access, ADDR_BITS, COMMAND_FIELDS, IRQ_DONE, IRQ_FAULT, IRQ_REPLY, IRQ_SWAP, REGISTERS,
    REPLY_FIELDS, REPLY_VALID, RESP_OKAY, RESP_SLVERR, STATUS_DONE_BIT, STATUS_STATE_LSB,
    STATUS_SWAP_PENDING_BIT,
};
use snapgen_spec::ports::{Dir, Port, AXI_TOP, STATION};
use snapgen_spec::AxisState;

use crate::block_with_ports;
use crate::emit::{Note, Waiver};
use crate::path_steppers::{instance, wire};
use crate::sim_bits::model_ports;
use crate::template::{fill, Holes};

/// The block's template.
const TEMPLATE: &str = include_str!("../verilog/axi.v");

/// Module prefix of the AXI4-Lite top (`snapgen_axi.v`).
pub const AXI_PREFIX: &str = "snapgen_axi";

/// The station's module (in `snapgen_io.v`).
const STATION_MODULE: &str = "snapgen_io_station";

// The template's IRQ_STATUS is {REPLY, latched causes}: the causes' bits as the spec's.
const _: () = assert!(IRQ_DONE == 1 && IRQ_FAULT == 2 && IRQ_SWAP == 4 && IRQ_REPLY == 8);
// The template's REPLY read is {23'd0, 1'b1, byte} and a COMMAND write takes bits 7:0: the
// fields as the spec's.
const _: () = assert!(
    REPLY_FIELDS[0].lsb == 0
        && REPLY_FIELDS[0].bits == 8
        && REPLY_VALID == 1 << 8
        && COMMAND_FIELDS[0].lsb == 0
        && COMMAND_FIELDS[0].bits == 8
);

/// Lint waivers of the AXI top: the address bits and byte lanes the slave does not decode.
pub const WAIVERS: [Waiver; 4] = [
    unused(
        "s_axi_awaddr",
        "word access: the low two address bits are ignored",
    ),
    unused(
        "s_axi_araddr",
        "word access: the low two address bits are ignored",
    ),
    unused("s_axi_wdata", "every writable field lies in byte lane 0"),
    unused(
        "s_axi_wstrb",
        "every writable field lies in byte lane 0: only its strobe is used",
    ),
];

const fn unused(signal: &'static str, reason: &'static str) -> Waiver {
    Waiver {
        module: "",
        signal,
        note: Note::LintOff("UNUSEDSIGNAL"),
        reason,
    }
}

snapgen_spec::with_axi_top_ports!(block_with_ports! {
    /// The AXI4-Lite top for a design.
    pub struct AxiTop(design: Design) {
        _sim: AxiDevice = AxiDevice::powered_up(&design, 0),
    }
});

impl AxiTop {
    /// The AXI top of `design` (its station's dividers and identity).
    pub fn new(design: Design) -> Self {
        AxiTop::build(design)
    }
}

snapgen_spec::with_axi_top_ports!(model_ports! { AxiTop, AxiInputs, AxiOutputs, |_| axi_body(); });

/// The Verilog name of register `name`'s first word index.
fn word_param(name: &str) -> String {
    format!("WORD_{name}")
}

/// Word-index bits.
const WORD_BITS: u32 = ADDR_BITS - 2;

/// The snapshot register of the station's port `port`.
fn snap_reg(port: &str) -> String {
    format!("snap_{port}_q")
}

/// What the station's port `p` is connected to: its outputs to wires `station_*` (the
/// top's output ports are `reg`s driven from them), its pins' inputs to the top's.
fn station_net(p: &Port) -> String {
    match (p.dir, p.name) {
        (Dir::In, "link_valid") => "link_valid_q".into(),
        (Dir::In, "link_data") => "link_data_q".into(),
        (Dir::In, "link_error") => "1'b0".into(),
        (Dir::In, name) => name.into(),
        (Dir::Out, name) => format!("station_{name}"),
    }
}

/// The template filled.
fn axi_body() -> String {
    let mut params = vec![
        format!("localparam [1:0] RESP_OKAY = 2'd{RESP_OKAY};"),
        format!("localparam [1:0] RESP_SLVERR = 2'd{RESP_SLVERR};"),
        "// Each register's first word (byte offset / 4).".to_string(),
    ];
    let mut writable = Vec::new();
    let mut readable = Vec::new();
    let mut snap_regs = Vec::new();
    let mut snap_reset = Vec::new();
    let mut snap_latch = Vec::new();
    for (k, r) in REGISTERS.iter().enumerate() {
        let first = offset(k) / 4;
        params.push(format!(
            "localparam [{}:0] {} = {WORD_BITS}'d{first}; // {:#04x}, {} word{}",
            WORD_BITS - 1,
            word_param(r.name),
            offset(k),
            r.words,
            if r.words == 1 { "" } else { "s" }
        ));
        if r.access.writable() {
            writable.push(format!("{}: write_ok = 1'b1;", word_param(r.name)));
        }
        if let Some(snap) = r.snap {
            let port = STATION
                .port(snap.port)
                .expect("a snapshot's port is the station's");
            let width = 32 * r.words;
            let name = snap_reg(snap.port);
            snap_regs.push(format!("reg [{}:0] {name} = {width}'d0;", width - 1));
            snap_reset.push(format!("{name} <= {width}'d0;"));
            let src = format!("station_{}", port.name);
            let pad = width - port.bits;
            snap_latch.push(if pad == 0 {
                format!("{name} <= {src};")
            } else if snap.signed {
                format!(
                    "{name} <= {{{{{pad}{{{src}[{}]}}}}, {src}}};",
                    port.bits - 1
                )
            } else {
                format!("{name} <= {{{pad}'d0, {src}}};")
            });
            for w in 0..r.words {
                let item = if w == 0 {
                    word_param(r.name)
                } else {
                    format!("{} + {WORD_BITS}'d{w}", word_param(r.name))
                };
                readable.push(format!(
                    "{item}: read_data = {name}[{}:{}];",
                    32 * w + 31,
                    32 * w
                ));
            }
            continue;
        }
        let read = match (r.access, r.name) {
            (Access::WriteOnly, _) => "read_resp = RESP_SLVERR;".to_string(),
            (Access::ReadTakes, "REPLY") => {
                "read_data = station_reply_ready ? {23'd0, 1'b1, station_reply_data} : 32'd0;"
                    .to_string()
            }
            (_, "IRQ_STATUS") => "read_data = {28'd0, irq_status};".to_string(),
            (_, "IRQ_ENABLE") => "read_data = {28'd0, irq_enable_q};".to_string(),
            (_, _) => format!("read_data = 32'h{:08x};", r.reset),
        };
        readable.push(format!("{}: {read}", word_param(r.name)));
    }
    let wires: Vec<String> = STATION
        .ports
        .iter()
        .filter(|p| p.dir == Dir::Out)
        .map(|p| wire(&station_net(p), p.bits))
        .collect();
    // The station's outputs that are the top's own (its pins and status).
    let pins: Vec<String> = STATION
        .ports
        .iter()
        .filter(|p| p.dir == Dir::Out && AXI_TOP.port(p.name).is_some())
        .map(|p| format!("{} = {};", p.name, station_net(p)))
        .collect();
    let station = instance(STATION_MODULE, "station", STATION.ports, station_net);
    let holes = Holes::new()
        .block("localparams", params.join("\n"))
        .block("wires", wires.join("\n"))
        .block("station", station)
        .block("snapshot_regs", snap_regs.join("\n"))
        .block("snapshot_reset", snap_reset.join("\n"))
        .block("snapshot_latch", snap_latch.join("\n"))
        .block("pins", pins.join("\n"))
        .block("writable", writable.join("\n"))
        .block("readable", readable.join("\n"))
        .value("WORD_MSB", WORD_BITS - 1)
        .value("WORD_BITS", WORD_BITS)
        .value("ADDR_MSB", ADDR_BITS - 1)
        .value("DONE_BIT", STATUS_DONE_BIT)
        .value("SWAP_PENDING_BIT", STATUS_SWAP_PENDING_BIT)
        .value("STATE_LSB", STATUS_STATE_LSB)
        .value("STATE_MSB", STATUS_STATE_LSB + 7)
        .value("ERROR_STOP", format!("8'd{}", AxisState::ErrorStop as u8));
    fill("axi.v", TEMPLATE, &holes).expect("the AXI top's template is filled")
}

/// The AXI4-Lite top's Verilog for `design`: `snapgen_axi.v`, top module `snapgen_axi`, which
/// instantiates the station of `snapgen_io.v` (read the design's three files:
/// [`axi_sources`]).
pub fn axi_top_verilog(design: &Design) -> String {
    let header = [
        "snapgen AXI4-Lite top: the station (snapgen_io_station, in snapgen_io.v) behind an AXI4-Lite slave.".to_string(),
        format!(
            "Register map version {}: docs/AXI.md, snapgen_axi.h, snapgen_axi.json (snapgen spec --emit).",
            snapgen_spec::axi::MAP_VERSION
        ),
        "Reference: snapgen_model::io::axi, clock for clock.".to_string(),
        format!(
            "Built for: {} Hz clock, tick divider {} after reset (the station's; its UART divisor is unused here).",
            design.clock_hz, design.dividers.tick_div
        ),
    ];
    let mut uut = AxiTop::new(*design);
    uut.connect_all();
    crate::emit::emit(&generate_verilog(&uut), AXI_PREFIX, &header, &WAIVERS)
        .expect("the AXI top's names and waivers are checked by its tests")
}

/// Every source file of the AXI4-Lite design for `design`: the I/O design's two (the motion
/// core, and the station with the UART top) and `snapgen_axi.v`.
pub fn axi_sources(design: &Design) -> [(&'static str, String); 3] {
    let [core, io] = crate::verilog::io_sources(design);
    [core, io, ("snapgen_axi.v", axi_top_verilog(design))]
}

/// The AXI4-Lite design's sources as one text.
pub fn axi_sources_text(design: &Design) -> String {
    axi_sources(design).map(|(_, v)| v).concat()
}
