//! The Zynq build, in which the board's own ARM is the host (`snapgen build --host ps`, issue 23
//! item 3): the AXI4-Lite station (`snapgen_axi.v`) packaged for Vivado's IP catalogue, a block
//! design with the PS7, an AXI interconnect from its M_AXI_GP0 and a reset from its FCLK_RESET0_N
//! and the board's reset button, the constraints of the station's pins, a device-tree overlay
//! node for Linux's UIO driver, the register map's C header and JSON, a Makefile and a README of
//! the steps on the board.
//!
//! Everything is derived: the pins from the spec's board pins and the board file, the bus
//! interfaces and the external ports from the AXI top's port table, the register list of the
//! IP from the spec's register map, the clock from the board file's `[ps]` table. Vivado is not
//! on the machines snapgen is tested on, so none of the TCL has run in Vivado: the tests run
//! each script under a stand-in that records Vivado's commands and check what they name
//! against the design (cli/tests/zynq.rs), compile the overlay with `dtc` and lint the Verilog.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use snapgen_model::device::Design;
use snapgen_model::timing::Timing;
use snapgen_spec::axi::{Access, REGISTERS, SPAN};
use snapgen_spec::ports::{board_pins, Dir, PinUse, AXI_TOP};

use crate::board_spec::{Board, Pin, ProcessingSystem};
use crate::fpga::{xdc_pin, BuildPlan, Runner};

/// M_AXI_GP0's address window on the Zynq-7000 (UG585, "System Addresses").
pub const GP0_WINDOW: std::ops::RangeInclusive<u64> = 0x4000_0000..=0x7FFF_F000;
/// The address range given to the slave, and mapped by the UIO driver: one 4 KiB page. The
/// slave decodes `snapgen_spec::axi::ADDR_BITS` (8) address bits, so the page holds the
/// 256-byte map 16 times over (an offset past [`SPAN`] within each 256 bytes answers SLVERR;
/// offset 0x100 + k is offset k). The host's UIO link refuses offsets past the map.
pub const UIO_SPAN: u64 = 4096;
/// The shared peripheral interrupt of IRQ_F2P[0], which the station's `irq` drives (UG585,
/// Table 7-4: IRQ_F2P[7:0] are IDs 61 to 68). A device tree numbers SPIs from 32.
pub const IRQ_F2P0_ID: u32 = 61;
/// The IP's identity in Vivado's catalogue: vendor, library, name, version.
pub const IP_VLNV: [&str; 4] = ["snapgen.dev", "snapgen", "snapgen_axi", "1.0"];
/// The IP's instance in the block design.
pub const CELL: &str = "snapgen_0";
/// FCLK_CLK0 in the Zynq-7000 clock controller's numbering (the `clkc` binding: fclk0 is 15).
pub const FCLK0_CLKC: u32 = 15;
/// The overlay node's name, which the UIO driver reports as the device's name.
pub const UIO_NAME: &str = "snapgen";
/// The block design's name.
pub const BD_NAME: &str = "snapgen_ps";
/// The AXI top's bus interface (the `s_axi_` ports).
pub const BUSIF: &str = "s_axi";

/// The two dividers (1 to 63 each) that make `fclk_hz` exactly from the IO PLL's `io_pll_hz`,
/// if any (UG585, FPGA0_CLK_CTRL: DIVISOR0 and DIVISOR1 are 6 bits).
pub fn fclk_dividers(io_pll_hz: u64, fclk_hz: u64) -> Option<(u64, u64)> {
    if fclk_hz == 0 || io_pll_hz < fclk_hz || io_pll_hz % fclk_hz != 0 {
        return None;
    }
    let n = io_pll_hz / fclk_hz;
    (1..=63u64).find_map(|d0| (n % d0 == 0 && n / d0 <= 63).then_some((d0, n / d0)))
}

/// A pin of the block design's wrapper: the AXI top's port it carries (its name is the
/// wrapper's port's, and the constraints') and the board file's pin.
struct External<'a> {
    port: &'static str,
    dir: Dir,
    pin: &'a Pin,
}

/// The station's pins the PS build brings out: every board pin wired to a port the AXI top
/// has (the UART pins are the UART top's), named as the AXI top names them.
fn externals(b: &Board) -> Vec<External<'_>> {
    board_pins(1)
        .into_iter()
        .filter_map(|bp| {
            let PinUse::Io(io) = bp.wired else {
                return None;
            };
            let port = AXI_TOP.port(io)?;
            // Board::check: every board pin has its [[pins]] entry.
            let pin = b.pins.iter().find(|p| p.port == bp.port)?;
            Some(External {
                port: port.name,
                dir: port.dir,
                pin,
            })
        })
        .collect()
}

/// The reset button's [[pins]] entry.
fn reset_button(b: &Board) -> Option<&Pin> {
    let name = board_pins(1)
        .into_iter()
        .find(|p| p.wired == PinUse::ResetButton)?
        .port;
    b.pins.iter().find(|p| p.port == name)
}

/// The build of `b`'s processing-system design for `timing` (its clock FCLK_CLK0) and the
/// (checked, hashed) `design`.
pub fn build_plan(
    b: &Board,
    ps: &ProcessingSystem,
    timing: &Timing,
    design: &Design,
) -> anyhow::Result<BuildPlan> {
    let Some((d0, d1)) = fclk_dividers(ps.io_pll_hz, timing.clock_hz) else {
        return Err(crate::error::InputError::Board(format!(
            "{}: the fabric clock of {} Hz: the PS makes FCLK_CLK0 as its IO PLL's {} Hz divided by two dividers of 1 to 63; give such a clock (--clock-hz), e.g. the board file's {} Hz",
            b.name, timing.clock_hz, ps.io_pll_hz, ps.fclk_hz
        ))
        .into());
    };
    let Some(button) = reset_button(b) else {
        anyhow::bail!("{}: no reset button among its pins", b.name);
    };
    let ext = externals(b);
    let top = format!("{}_ps", b.top_name());
    let mut files = BTreeMap::new();
    let mut sources = Vec::new();
    for (name, text) in snapgen_hdl::axi_top::axi_sources(design) {
        sources.push(name);
        files.insert(name.to_string(), text);
    }
    files.insert("snapgen_axi.h".into(), snapgen_spec::emit::axi::c_header());
    files.insert(
        "snapgen_axi.json".into(),
        serde_json::to_string_pretty(&snapgen_spec::emit::axi::json())? + "\n",
    );
    files.insert("package_ip.tcl".into(), package_ip_tcl(b, &sources));
    files.insert(
        "block_design.tcl".into(),
        block_design_tcl(b, ps, timing, (d0, d1), &ext, button),
    );
    files.insert("build.tcl".into(), build_tcl(b, &top));
    files.insert(format!("{top}.xdc"), xdc(b, &ext, button));
    files.insert(format!("{UIO_NAME}.dtso"), overlay(ps, timing, &top));
    files.insert(format!("{top}.bif"), bif(&top));
    files.insert("Makefile".into(), makefile(b, &top, &sources));
    files.insert(
        "README.md".into(),
        readme(b, ps, timing, &top, &ext, button),
    );
    Ok(BuildPlan {
        files,
        runner: Runner::Vivado,
    })
}

const NEVER_RUN: &str = "\
# Vivado is not on the machines snapgen is tested on: this script has never run in Vivado.
# snapgen's tests run it under a stand-in that records Vivado's commands and check the names
# it uses against the design (cli/tests/zynq.rs).";

/// `package_ip.tcl`: the AXI top and the two files it instantiates packaged as an IP of
/// Vivado's catalogue in `./ip`, with its bus interfaces (AXI4-Lite slave, clock, active-high
/// reset, level interrupt) and its register map from the spec.
fn package_ip_tcl(b: &Board, sources: &[&str]) -> String {
    let [vendor, library, name, version] = IP_VLNV;
    let mut regs = String::new();
    for (k, r) in REGISTERS.iter().enumerate() {
        let access = match r.access {
            Access::ReadOnly | Access::ReadTakes => "read-only",
            Access::WriteOnly => "write-only",
            Access::ReadWrite | Access::WriteOneToClear => "read-write",
        };
        for w in 0..r.words {
            let reg = if r.words > 1 {
                format!("{}_{w}", r.name)
            } else {
                r.name.to_string()
            };
            let _ = writeln!(
                regs,
                "snapgen_register $block {reg} 0x{:02X} {access} {} {{{}}}",
                snapgen_spec::axi::offset(k) + 4 * w,
                r.reset,
                r.doc.replace(['{', '}', '[', ']', '$', '\\', '"'], "")
            );
        }
    }
    format!(
        "\
# snapgen: packages the AXI4-Lite station as an IP of Vivado's catalogue in ./ip
# ({vendor}:{library}:{name}:{version}), for the {desc}.
# Run: vivado -mode batch -source package_ip.tcl (build.tcl runs it first).
# Generated by `snapgen build --host ps`; do not edit: regenerate it.
{NEVER_RUN}

set part {part}
set here [file dirname [file normalize [info script]]]
create_project -force snapgen_ip [file join $here ip_project] -part $part
add_files -norecurse [list {files}]
set_property top {name} [current_fileset]
update_compile_order -fileset sources_1
ipx::package_project -root_dir [file join $here ip] -vendor {vendor} -library {library} -taxonomy /UserIP -import_files -set_current true
set core [ipx::current_core]
set_property name {name} $core
set_property version {version} $core
set_property display_name {{snapgen AXI4-Lite motion station}} $core
set_property description {{snapgen's station (executor, motion core, controller, encoder, PWM, switches) behind an AXI4-Lite slave; register map docs/AXI.md}} $core

# Bus interfaces, each inferred explicitly (what Vivado guessed from the port names is dropped,
# so that the names below are the interfaces' names), then checked.
ipx::remove_all_bus_interface $core
foreach map [ipx::get_memory_maps -of_objects $core] {{
    ipx::remove_memory_map [get_property name $map] $core
}}
proc snapgen_interface {{core name ports abstraction}} {{
    ipx::infer_bus_interface $ports $abstraction $core
    set busif [ipx::get_bus_interfaces $name -of_objects $core]
    if {{[llength $busif] != 1}} {{
        error \"snapgen: the IP has no bus interface $name after inferring it from $ports\"
    }}
    return $busif
}}
proc snapgen_parameter {{busif name value}} {{
    set p [ipx::get_bus_parameters $name -of_objects $busif]
    if {{[llength $p] == 0}} {{
        set p [ipx::add_bus_parameter $name $busif]
    }}
    set_property value $value $p
}}
set axi [snapgen_interface $core {BUSIF} {{{axi_ports}}} xilinx.com:interface:aximm_rtl:1.0]
snapgen_interface $core {clock} {clock} xilinx.com:signal:clock_rtl:1.0
set rst [snapgen_interface $core reset reset xilinx.com:signal:reset_rtl:1.0]
snapgen_parameter $rst POLARITY ACTIVE_HIGH
set irq [snapgen_interface $core irq irq xilinx.com:signal:interrupt_rtl:1.0]
snapgen_parameter $irq SENSITIVITY LEVEL_HIGH
ipx::associate_bus_interfaces -busif {BUSIF} -clock {clock} $core
ipx::associate_bus_interfaces -clock {clock} -reset reset $core

# The register map (snapgen_spec::axi, docs/AXI.md) in the IP's memory map: {span} bytes of a
# {uio}-byte block.
set map [ipx::add_memory_map {BUSIF} $core]
set_property slave_memory_map_ref {BUSIF} $axi
set block [ipx::add_address_block reg0 $map]
set_property range {uio} $block
set_property width 32 $block
proc snapgen_register {{block name offset access reset doc}} {{
    set r [ipx::add_register $name $block]
    set_property address_offset $offset $r
    set_property size 32 $r
    set_property access $access $r
    set_property description $doc $r
    set_property reset_value $reset $r
    set_property reset_value_format long $r
}}
{regs}
ipx::create_xgui_files $core
ipx::update_checksums $core
ipx::check_integrity $core
ipx::save_core $core
close_project
puts \"snapgen: packaged {vendor}:{library}:{name}:{version} in [file join $here ip]\"
",
        desc = b.description,
        part = b.part,
        files = sources
            .iter()
            .map(|f| format!("[file join $here {f}]"))
            .collect::<Vec<_>>()
            .join(" "),
        axi_ports = AXI_TOP
            .section("axi")
            .filter(|p| p.name.starts_with(&format!("{BUSIF}_")))
            .map(|p| p.name)
            .collect::<Vec<_>>()
            .join(" "),
        clock = AXI_TOP.clock,
        span = SPAN,
        uio = UIO_SPAN,
    )
}

/// `block_design.tcl`: the block design (PS7 on the board preset, FCLK_CLK0 checked exact,
/// the interconnect, the reset, the station, its pins and interrupt) and its wrapper.
fn block_design_tcl(
    b: &Board,
    ps: &ProcessingSystem,
    timing: &Timing,
    (d0, d1): (u64, u64),
    ext: &[External],
    button: &Pin,
) -> String {
    let [vendor, library, name, version] = IP_VLNV;
    let mhz = timing.clock_hz as f64 / 1e6;
    let mut pins = String::new();
    for e in ext {
        let _ = writeln!(
            pins,
            "create_bd_port -dir {} {p}\nconnect_bd_net [get_bd_ports {p}] [get_bd_pins {CELL}/{p}]",
            if e.dir == Dir::In { "I" } else { "O" },
            p = e.port
        );
    }
    for t in &b.ties {
        let _ = writeln!(
            pins,
            "create_bd_cell -type ip -vlnv xilinx.com:ip:xlconstant:1.1 tie_{p}\nset_property -dict [list CONFIG.CONST_WIDTH {{1}} CONFIG.CONST_VAL {{{l}}}] [get_bd_cells tie_{p}]\ncreate_bd_port -dir O {p}\nconnect_bd_net [get_bd_ports {p}] [get_bd_pins tie_{p}/dout]",
            p = t.port,
            l = t.level
        );
    }
    let reset_port = AXI_TOP.section("reset").next().map_or("reset", |p| p.name);
    format!(
        "\
# snapgen: the block design {BD_NAME} for the {desc}: the PS7 (the board preset's DDR and MIO),
# FCLK_CLK0 at {mhz} MHz as the fabric clock, M_AXI_GP0 through an AXI interconnect to the
# station ({vendor}:{library}:{name}:{version}, package_ip.tcl) at 0x{base:08X} ({uio} bytes),
# its irq on IRQ_F2P[0] (interrupt ID {irq_id}), its reset from FCLK_RESET0_N and the board's
# reset button ({button}), its pins to the board's.
# Run after package_ip.tcl, in a project for part {part} (build.tcl does both).
# Generated by `snapgen build --host ps`; do not edit: regenerate it.
{NEVER_RUN}

set here [file dirname [file normalize [info script]]]
set board_part {board_part}
if {{[llength [get_board_parts -quiet $board_part]] == 0}} {{
    # Another version of the same board's files (the preset is the board's, not the version's).
    set other [lindex [get_board_parts -quiet -latest_file_version {board_family}:*] 0]
    if {{$other eq \"\"}} {{
        error \"snapgen: Vivado does not know the board part $board_part: install the board vendor's board files (Digilent: github.com/Digilent/vivado-boards) and run again\"
    }}
    puts \"snapgen: board part $board_part not installed; using $other\"
    set board_part $other
}}
set_property board_part $board_part [current_project]
set_property ip_repo_paths [list [file join $here ip]] [current_project]
update_ip_catalog
create_bd_design {BD_NAME}

# The processing system on the board's preset; M_AXI_GP0, FCLK_CLK0 and the fabric interrupt.
create_bd_cell -type ip -vlnv xilinx.com:ip:processing_system7:5.5 ps7
apply_bd_automation -rule xilinx.com:bd_rule:processing_system7 -config {{make_external \"FIXED_IO, DDR\" apply_board_preset \"1\" Master \"Disable\" Slave \"Disable\"}} [get_bd_cells ps7]
set_property -dict [list CONFIG.PCW_USE_M_AXI_GP0 {{1}} CONFIG.PCW_EN_CLK0_PORT {{1}} CONFIG.PCW_EN_RST0_PORT {{1}} CONFIG.PCW_FPGA0_PERIPHERAL_FREQMHZ {{{mhz}}} CONFIG.PCW_USE_FABRIC_INTERRUPT {{1}} CONFIG.PCW_IRQ_F2P_INTR {{1}}] [get_bd_cells ps7]
# The design's tick period counts clocks of exactly {mhz} MHz (the IO PLL's {pll} MHz / {d0} /
# {d1}): anything else would run every move at another speed than the host planned.
set actual [get_property CONFIG.PCW_ACT_FPGA0_PERIPHERAL_FREQMHZ [get_bd_cells ps7]]
if {{abs($actual - {mhz}) > 1e-6 * {mhz}}} {{
    error \"snapgen: the PS makes FCLK_CLK0 at $actual MHz, not {mhz} MHz: the board preset's IO PLL is not {pll} MHz; give the board file's \\[ps\\] io_pll_hz and a clock it divides into exactly\"
}}

# The station.
create_bd_cell -type ip -vlnv {vendor}:{library}:{name}:{version} {CELL}
# Reset: FCLK_RESET0_N, and the board's button (active high), synchronised to FCLK_CLK0.
create_bd_cell -type ip -vlnv xilinx.com:ip:proc_sys_reset:5.0 rst_fclk0
set_property -dict [list CONFIG.C_AUX_RESET_HIGH {{1}}] [get_bd_cells rst_fclk0]
create_bd_port -dir I -type rst {btn}
set_property CONFIG.POLARITY ACTIVE_HIGH [get_bd_ports {btn}]
connect_bd_net [get_bd_ports {btn}] [get_bd_pins rst_fclk0/aux_reset_in]
connect_bd_net [get_bd_pins ps7/FCLK_RESET0_N] [get_bd_pins rst_fclk0/ext_reset_in]
# M_AXI_GP0 (AXI3) to the AXI4-Lite slave through an interconnect (protocol conversion).
create_bd_cell -type ip -vlnv xilinx.com:ip:axi_interconnect:2.1 axi_gp0
set_property -dict [list CONFIG.NUM_SI {{1}} CONFIG.NUM_MI {{1}}] [get_bd_cells axi_gp0]
connect_bd_intf_net [get_bd_intf_pins ps7/M_AXI_GP0] [get_bd_intf_pins axi_gp0/S00_AXI]
connect_bd_intf_net [get_bd_intf_pins axi_gp0/M00_AXI] [get_bd_intf_pins {CELL}/{BUSIF}]
connect_bd_net [get_bd_pins ps7/FCLK_CLK0] [get_bd_pins ps7/M_AXI_GP0_ACLK] [get_bd_pins rst_fclk0/slowest_sync_clk] [get_bd_pins axi_gp0/ACLK] [get_bd_pins axi_gp0/S00_ACLK] [get_bd_pins axi_gp0/M00_ACLK] [get_bd_pins {CELL}/{clock}]
connect_bd_net [get_bd_pins rst_fclk0/interconnect_aresetn] [get_bd_pins axi_gp0/ARESETN]
connect_bd_net [get_bd_pins rst_fclk0/peripheral_aresetn] [get_bd_pins axi_gp0/S00_ARESETN] [get_bd_pins axi_gp0/M00_ARESETN]
connect_bd_net [get_bd_pins rst_fclk0/peripheral_reset] [get_bd_pins {CELL}/{reset_port}]
connect_bd_net [get_bd_pins {CELL}/irq] [get_bd_pins ps7/IRQ_F2P]

# The station's pins, named as the AXI top names them ({top_xdc}).
{pins}
# The address: 0x{base:08X}, one {uio}-byte page (the UIO driver maps whole pages).
assign_bd_address -offset 0x{base:08X} -range {uio} -target_address_space [get_bd_addr_spaces ps7/Data] [get_bd_addr_segs {CELL}/{BUSIF}/*]

validate_bd_design
save_bd_design
set wrapper [make_wrapper -files [get_files {BD_NAME}.bd] -top]
add_files -norecurse $wrapper
set_property top {BD_NAME}_wrapper [current_fileset]
update_compile_order -fileset sources_1
",
        desc = b.description,
        part = b.part,
        board_part = ps.board_part,
        board_family = ps.board_part.rsplit_once(':').map_or(ps.board_part.as_str(), |(f, _)| f),
        base = ps.axi_base,
        uio = UIO_SPAN,
        irq_id = IRQ_F2P0_ID,
        button = button.comment,
        btn = button.port,
        pll = ps.io_pll_hz as f64 / 1e6,
        clock = AXI_TOP.clock,
        top_xdc = format_args!("{}_ps.xdc", b.top_name()),
    )
}

/// `build.tcl`: the IP, the block design, synthesis, place and route, the timing check, the
/// bitstream and the hardware platform (`.xsa`).
fn build_tcl(b: &Board, top: &str) -> String {
    format!(
        "\
# snapgen: the Vivado build for the {desc} with its ARM as the host. Run:
#   vivado -mode batch -source build.tcl       (or `make`)
# Writes {top}.bit, {top}.xsa (for PetaLinux / Vitis), utilization.rpt and timing.rpt;
# fails when routed timing does not close.
# Generated by `snapgen build --host ps`; do not edit: regenerate it.
{NEVER_RUN}

set here [file dirname [file normalize [info script]]]
set part {part}
source [file join $here package_ip.tcl]
create_project -force {top} [file join $here vivado] -part $part
source [file join $here block_design.tcl]
add_files -fileset constrs_1 -norecurse [file join $here {top}.xdc]
generate_target all [get_files {BD_NAME}.bd]
launch_runs synth_1 -jobs 2
wait_on_run synth_1
if {{[get_property PROGRESS [get_runs synth_1]] != \"100%\"}} {{
    error \"snapgen: synthesis failed (vivado/{top}.runs/synth_1/runme.log)\"
}}
launch_runs impl_1 -to_step write_bitstream -jobs 2
wait_on_run impl_1
if {{[get_property PROGRESS [get_runs impl_1]] != \"100%\"}} {{
    error \"snapgen: implementation failed (vivado/{top}.runs/impl_1/runme.log)\"
}}
open_run impl_1
report_utilization -file [file join $here utilization.rpt]
report_timing_summary -file [file join $here timing.rpt]
{check}# The run's bitstream becomes {top}.bit only when timing closes.
file copy -force [file join [get_property DIRECTORY [get_runs impl_1]] {BD_NAME}_wrapper.bit] [file join $here {top}.bit]
write_hw_platform -fixed -include_bit -force -file [file join $here {top}.xsa]
puts \"snapgen: wrote {top}.bit and {top}.xsa; routed timing closes (setup slack $wns ns, hold slack $whs ns)\"
",
        desc = b.description,
        part = b.part,
        check = crate::fpga::vivado_timing_check(
            "timing.rpt",
            "lower the clock (the board file's \\[ps\\] fclk_hz, or --clock-hz)"
        ),
    )
}

/// The wrapper's constraints: the station's pins and the reset button (FCLK_CLK0 is
/// constrained by the PS7's own constraints).
fn xdc(b: &Board, ext: &[External], button: &Pin) -> String {
    let mut s = format!(
        "## snapgen constraints for the {} ({}) with its ARM as the host: the station's pins, named\n\
         ## as the AXI top names them (the clock is the PS's FCLK_CLK0, constrained by the PS7).\n\
         ## Generated by `snapgen build --host ps`.\n\n",
        b.description, b.part
    );
    s.push_str(&xdc_pin(
        &button.port,
        button,
        &format!("{} (in)", button.comment),
    ));
    for e in ext {
        s.push_str(&xdc_pin(
            e.port,
            e.pin,
            &format!(
                "{}: {} ({})",
                e.pin.port,
                e.pin.comment,
                e.pin.direction.name()
            ),
        ));
    }
    for t in &b.ties {
        let _ = writeln!(
            s,
            "set_property -dict {{ PACKAGE_PIN {} IOSTANDARD {} }} [get_ports {{ {} }}] ;# {} (held at {})",
            t.pin, t.iostandard, t.port, t.comment, t.level
        );
    }
    s
}

/// The device-tree overlay: the bitstream for the FPGA manager, and the station as a
/// `generic-uio` device with its page and its interrupt.
fn overlay(ps: &ProcessingSystem, timing: &Timing, top: &str) -> String {
    format!(
        "\
// snapgen device-tree overlay: loads {top}.bit.bin through the FPGA manager and declares the
// station at 0x{base:08x} ({uio} bytes, interrupt IRQ_F2P[0] = ID {irq_id}) as a UIO device named
// \"{UIO_NAME}\" (/sys/class/uio/uioN/name). Linux's uio_pdrv_genirq binds it when the kernel
// runs with uio_pdrv_genirq.of_id=generic-uio. Build: dtc -@ -I dts -O dtb -o {UIO_NAME}.dtbo {UIO_NAME}.dtso
// Targets the labels of the Zynq-7000 device tree (fpga_full, amba, intc, clkc): the board's
// base device tree must be compiled with symbols (dtc -@).
// Generated by `snapgen build --host ps`; do not edit: regenerate it.
/dts-v1/;
/plugin/;

/ {{
\tfragment@0 {{
\t\ttarget = <&fpga_full>;
\t\t__overlay__ {{
\t\t\tfirmware-name = \"{top}.bit.bin\";
\t\t}};
\t}};

\tfragment@1 {{
\t\ttarget = <&amba>;
\t\t__overlay__ {{
\t\t\t#address-cells = <1>;
\t\t\t#size-cells = <1>;

\t\t\t/* FCLK_CLK0, the station's clock: kept running and at its rate (Xilinx's fclk driver;
\t\t\t * without it a kernel turns the unused clock off at the end of boot). */
\t\t\t{UIO_NAME}_fclk0: {UIO_NAME}-fclk0 {{
\t\t\t\tcompatible = \"xlnx,fclk\";
\t\t\t\t#clock-cells = <0>;
\t\t\t\tclocks = <&clkc {FCLK0_CLKC}>;
\t\t\t\tclock-output-names = \"{UIO_NAME}_fclk0\";
\t\t\t\tassigned-clocks = <&clkc {FCLK0_CLKC}>;
\t\t\t\tassigned-clock-rates = <{hz}>;
\t\t\t}};

\t\t\t{UIO_NAME}@{base:x} {{
\t\t\t\tcompatible = \"snapgen,axi-station\", \"generic-uio\";
\t\t\t\treg = <0x{base:x} 0x{uio:x}>;
\t\t\t\tclocks = <&clkc {FCLK0_CLKC}>;
\t\t\t\tassigned-clocks = <&clkc {FCLK0_CLKC}>;
\t\t\t\tassigned-clock-rates = <{hz}>;
\t\t\t\tinterrupt-parent = <&intc>;
\t\t\t\t/* SPI {spi} (ID {irq_id}), level, active high */
\t\t\t\tinterrupts = <0 {spi} 4>;
\t\t\t}};
\t\t}};
\t}};
}};
",
        base = ps.axi_base,
        uio = UIO_SPAN,
        irq_id = IRQ_F2P0_ID,
        spi = IRQ_F2P0_ID - 32,
        hz = timing.clock_hz,
    )
}

/// bootgen's image description: the bitstream as the `.bit.bin` the FPGA manager loads.
fn bif(top: &str) -> String {
    format!(
        "/* snapgen: bootgen -image {top}.bif -arch zynq -process_bitstream bin (writes {top}.bit.bin) */\nall:\n{{\n\t{top}.bit\n}}\n"
    )
}

fn makefile(b: &Board, top: &str, sources: &[&str]) -> String {
    format!(
        "\
# snapgen build for the {desc} with its ARM as the host (README.md).
#   make            the bitstream and hardware platform (Vivado), {top}.bit.bin (bootgen, with
#                   Vivado) and the overlay {UIO_NAME}.dtbo (dtc)
#   make overlay    the overlay only
# VIVADO and BOOTGEN point to the tools (default: on the PATH).
VIVADO ?= vivado
BOOTGEN ?= bootgen
DTC ?= dtc

all: {top}.bit.bin {UIO_NAME}.dtbo

{top}.bit: {sources} {top}.xdc package_ip.tcl block_design.tcl build.tcl
\t@command -v $(VIVADO) >/dev/null 2>&1 || {{ echo \"Vivado not found: install Vivado (AMD/Xilinx) or run make VIVADO=/path/to/vivado\" >&2; exit 1; }}
\t$(VIVADO) -mode batch -nojournal -nolog -source build.tcl

{top}.bit.bin: {top}.bit {top}.bif
\t$(BOOTGEN) -image {top}.bif -arch zynq -process_bitstream bin -w on

{UIO_NAME}.dtbo: {UIO_NAME}.dtso
\t$(DTC) -@ -I dts -O dtb -o $@ $<

overlay: {UIO_NAME}.dtbo

clean:
\trm -rf {top}.bit {top}.bit.bin {top}.xsa {UIO_NAME}.dtbo utilization.rpt timing.rpt vivado ip ip_project .Xil

.PHONY: all overlay clean
",
        desc = b.description,
        sources = sources.join(" "),
    )
}

fn readme(
    b: &Board,
    ps: &ProcessingSystem,
    timing: &Timing,
    top: &str,
    ext: &[External],
    button: &Pin,
) -> String {
    let pins: String = ext
        .iter()
        .map(|e| {
            format!(
                "| `{}` | {} | {} | {} |\n",
                e.port,
                e.pin.pin,
                e.pin.direction.name(),
                e.pin.comment
            )
        })
        .collect();
    format!(
        "\
# snapgen on the {desc}, its ARM as the host

Generated by `snapgen build --board {board} --host ps`. The station (command executor, motion
core, position controller, encoder, PWM, switches) sits behind an AXI4-Lite slave on the PS's
M_AXI_GP0 at `0x{base:08X}` (one {uio}-byte page; the register map is docs/AXI.md, also
`snapgen_axi.h` and `snapgen_axi.json` here). The slave decodes 8 address bits: the page holds
the 256-byte map 16 times over, so a driver of your own must stay within the first 256 bytes
(offset 0x100 + k reaches register k; `snapgen` refuses offsets past the map). Its interrupt is IRQ_F2P[0] (ID {irq_id}); its clock
FCLK_CLK0 at {mhz} MHz, from which it makes its tick of {ts} s.

**What has run and what has not.** Vivado, bootgen and a Zynq board are not on the machines
snapgen is tested on. The Verilog here is linted by Verilator and synthesised by Yosys, and
co-simulated against the model every clock under random AXI traffic; the overlay compiles with
`dtc`; the TCL scripts run under a stand-in that records Vivado's commands, and the names they
use (cells, pins, ports, the IP's interfaces) are checked against the design. None of the TCL
has run in Vivado, no bitstream for this board has been built, and the host has never run on a
Zynq: expect to fix small things on the first run, and please report them.

## 1. Build the bitstream (Vivado)

Needs Vivado (the scripts are written for 2020.2 or later; never run) with the board vendor's board files (`{board_part}`;
Digilent's are at github.com/Digilent/vivado-boards).

```sh
make                # runs build.tcl: package_ip.tcl, block_design.tcl, synthesis, place and
                    # route, bitstream, {top}.xsa; then bootgen and dtc
```

The build fails when routed timing does not close at {mhz} MHz (`timing.rpt`). To build with
another clock: `snapgen build --board {board} --host ps --clock-hz HZ` (FCLK_CLK0 is the IO
PLL's {pll} MHz divided by two dividers of 1 to 63; the tick period follows the clock).

To use the IP in a project of your own: `vivado -mode batch -source package_ip.tcl` puts it in
`./ip` (`{vlnv}`); add that folder to the project's IP repositories.

## 2. Linux on the board

A Zynq-7000 Linux with the FPGA manager, device-tree overlays through configfs
(`CONFIG_OF_CONFIGFS`: Xilinx's kernel, PetaLinux from `{top}.xsa`, or a PYNQ image; mainline
Linux has no configfs overlays) and `uio_pdrv_genirq`; its base device tree compiled with
symbols (`dtc -@`), which the overlay's labels need. Start the kernel with
`uio_pdrv_genirq.of_id=generic-uio` on its command line, so that the UIO driver takes the
station's node. The overlay keeps FCLK_CLK0 running at {mhz} MHz through Xilinx's `xlnx,fclk`
driver; a kernel without it turns the clock off at the end of boot unless started with
`clk_ignore_unused`, and then runs it at whatever rate the boot loader set: check
`/sys/kernel/debug/clk/fclk0/clk_rate` before anything moves.

```sh
cp {top}.bit.bin /lib/firmware/
mkdir /sys/kernel/config/device-tree/overlays/{UIO_NAME}
cat {UIO_NAME}.dtbo > /sys/kernel/config/device-tree/overlays/{UIO_NAME}/dtbo
grep -l {UIO_NAME} /sys/class/uio/uio*/name   # which /dev/uioN is the station
```

(With Xilinx's `fpgautil`: `fpgautil -b {top}.bit.bin -o {UIO_NAME}.dtbo`.)

## 3. The host on the ARM

The Zybo's Cortex-A9 runs 32-bit ARM Linux. Cross-build the host on a PC:

```sh
rustup target add armv7-unknown-linux-gnueabihf
CARGO_TARGET_ARMV7_UNKNOWN_LINUX_GNUEABIHF_LINKER=arm-linux-gnueabihf-gcc \\
  cargo build --release --target armv7-unknown-linux-gnueabihf -p snapgen-cli
```

copy `target/armv7-unknown-linux-gnueabihf/release/snapgen` to the board and run, as root or
with access to the device:

```sh
snapgen send --uio /dev/uio0 --distance 1      # the same commands as over a serial port
snapgen online --uio /dev/uio0 ...              # (snapgen online --help)
snapgen path --uio /dev/uio0 ...                # (snapgen path --help)
```

The host checks the station's identity (`ID`, `VERSION`), reads the board's identity, plans
with the Ts and format read from its registers, and refuses a board of another protocol or
format before anything moves (as over a serial port).

## Pins

| Port | Package pin | Direction | Use |
|---|---|---|---|
| `{btn}` | {btn_pin} | in | {btn_use} |
{pins}
## Files

| File | What |
|---|---|
| `snapgen_core.v`, `snapgen_io.v`, `snapgen_axi.v` | the design (the IP's sources; top `snapgen_axi`) |
| `package_ip.tcl` | packages the IP in `./ip` |
| `block_design.tcl` | the block design `{BD_NAME}` and its wrapper |
| `build.tcl` | the whole build; fails when routed timing does not close |
| `{top}.xdc` | the pins |
| `{top}.bif` | bootgen's description of `{top}.bit.bin` |
| `{UIO_NAME}.dtso` | the device-tree overlay (bitstream and UIO node) |
| `snapgen_axi.h`, `snapgen_axi.json` | the register map for C and for tools |
| `Makefile` | `make`, `make overlay`, `make clean` |
",
        desc = b.description,
        board = b.name,
        base = ps.axi_base,
        uio = UIO_SPAN,
        irq_id = IRQ_F2P0_ID,
        mhz = timing.clock_hz as f64 / 1e6,
        ts = timing.ts,
        board_part = ps.board_part,
        pll = ps.io_pll_hz as f64 / 1e6,
        vlnv = IP_VLNV.join(":"),
        btn = button.port,
        btn_pin = button.pin,
        btn_use = button.comment,
    )
}
