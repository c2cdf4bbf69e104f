//! A board's build plan and the Yosys synthesis check of a board ([`crate::board_spec`]).
//!
//! * [`BuildPlan`] is data too: every file of the build (board top Verilog, the I/O top and
//!   the toolchain's files) and how it runs; it can be written without running anything. A
//!   Xilinx board's is a Vivado non-project build (XDC, TCL, Makefile; running needs Vivado,
//!   `$VIVADO` or `vivado` on the PATH); an ECP5 board's is the open flow of [`crate::ecp5`]
//!   (LPF, Makefile), run here.
//! * [`synth`] runs Yosys `synth_xilinx -family xc7` on the full top and on the motion core alone,
//!   reads the cell counts, and estimates the logic-only critical path with Yosys `sta` (the
//!   Xilinx cell library with its specify blocks; routing delay is not included).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};
use snapgen_model::device::Design;
use snapgen_model::timing::Timing;

use snapgen_spec::ports::{board_pins, Dir, PinUse, BOARD_CLOCK, BOARD_RESET, IO_TOP};

use crate::board_spec::{Board, Pin, Toolchain};

/// The board top: clock, power-on and button reset synchronised to the clock, the I/O top. Its
/// ports and their wiring are the spec's board pins (`snapgen_spec::ports::board_pins`): a pin
/// named `name[k]` is bit `k` of the vector port `name`; the I/O top's debug outputs are left
/// unconnected inside.
///
/// With a clock generator (`pll`: the ECP5's PLL or a 7-series MMCM, which makes the fabric's
/// `timing.clock_hz` from the board's oscillator) the fabric runs on its output and stays in
/// reset until it has locked.
pub fn board_top_verilog(b: &Board, timing: &Timing, pll: Option<ClockGen>) -> String {
    let pins = board_pins(1);
    // The ports, in order, a vector once (its bits' docs together).
    let mut ports: Vec<(String, Dir, usize, Vec<String>)> = Vec::new();
    for p in &pins {
        let (base, bit) = match p.port.split_once('[') {
            Some((base, rest)) => (base, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (p.port.as_str(), None),
        };
        let doc = match (p.wired, &pll) {
            (PinUse::Clock, None) => format!("{} MHz", timing.clock_hz as f64 / 1e6),
            (PinUse::Clock, Some(gen)) => format!(
                "{} MHz oscillator (the {} makes the {} MHz fabric clock)",
                b.clock.frequency_hz as f64 / 1e6,
                gen.name(),
                timing.clock_hz as f64 / 1e6
            ),
            _ => p.doc.trim_end_matches('.').to_string(),
        };
        match ports.iter_mut().find(|(n, ..)| n == base) {
            Some(port) => {
                port.2 = port.2.max(bit.map_or(1, |k| k + 1));
                port.3.push(doc);
            }
            None => ports.push((base.to_string(), p.dir, bit.map_or(1, |k| k + 1), vec![doc])),
        }
    }
    for t in &b.ties {
        ports.push((t.port.clone(), Dir::Out, 1, vec![t.comment.clone()]));
    }
    let ties: String = b
        .ties
        .iter()
        .map(|t| format!("    assign {} = 1'b{};\n", t.port, t.level))
        .collect();
    let decls: Vec<String> = ports
        .iter()
        .enumerate()
        .map(|(k, (name, dir, width, docs))| {
            let range = if *width > 1 {
                format!("[{}:0]", width - 1)
            } else {
                String::new()
            };
            let comma = if k + 1 < ports.len() { "," } else { "" };
            format!(
                "    {:<6} wire {:<5} {}{:<w$}// {}",
                dir.verilog(),
                range,
                name,
                comma,
                docs.join("; "),
                w = 16 - name.len().min(15)
            )
        })
        .collect();
    let (fin, fout) = (b.clock.frequency_hz, timing.clock_hz);
    let (clock, clock_gen, unlocked) = match &pll {
        Some(ClockGen::Ecp5(s)) => (
            "clk",
            crate::ecp5::pll::pll_verilog(BOARD_CLOCK, fin, fout, s) + "\n",
            " | !pll_locked",
        ),
        Some(ClockGen::Xc7(s)) => (
            "clk",
            crate::xc7::mmcm::mmcm_verilog(BOARD_CLOCK, fin, fout, s) + "\n",
            " | !pll_locked",
        ),
        None => (BOARD_CLOCK, String::new(), ""),
    };
    let mut conns = vec![
        format!(".{}({clock})", IO_TOP.clock),
        ".reset(reset)".to_string(),
    ];
    for p in &pins {
        if let PinUse::Io(io) = p.wired {
            conns.push(format!(".{io}({})", p.port));
        }
    }
    let mut unused = String::new();
    for d in IO_TOP.section("debug") {
        unused.push_str(&format!(
            "    /* verilator lint_off UNUSEDSIGNAL */ // {}\n    wire [{}:0] {}_unused;\n    /* verilator lint_on UNUSEDSIGNAL */\n",
            d.doc.trim_end_matches('.'),
            d.bits - 1,
            d.name
        ));
        conns.push(format!(".{0}({0}_unused)", d.name));
    }
    format!(
        "\
// snapgen board top for the {desc}.
// The clock, a reset synchroniser (power-on and the reset button), and the snapgen I/O top
// (snapgen_io.v). Clock {mhz} MHz, UART {baud} baud, Ts {ts} s after reset.
// Generated by `snapgen build`; do not edit: regenerate it.
`default_nettype none
module {top} (
{decls}
);
{clock_gen}{ties_block}    // Reset: held for 16 clocks after configuration, and while the button is pressed{lock_doc}
    // (synchronised through two flip-flops).
    reg [1:0] btn_sync = 2'b00;
    reg [4:0] por_count = 5'd0;
    reg reset = 1'b1;
    always @(posedge {clock}) begin
        btn_sync <= {{btn_sync[0], {button}{unlocked}}};
        if (por_count != 5'd16) por_count <= por_count + 5'd1;
        reset <= btn_sync[1] | (por_count != 5'd16);
    end

{unused}
    snapgen_io io (
        {conns}
    );
endmodule
`default_nettype wire
",
        desc = b.description,
        top = b.top_name(),
        mhz = timing.clock_hz as f64 / 1e6,
        baud = timing.baud,
        ts = timing.ts,
        decls = decls.join("\n"),
        lock_doc = match &pll {
            Some(gen) => format!("\n    // or the {} has not locked", gen.name()),
            None => String::new(),
        },
        button = BOARD_RESET,
        ties_block = if ties.is_empty() {
            String::new()
        } else {
            format!("    // Pins held at a level for the board's sake (its board file's [[ties]]).\n{ties}\n")
        },
        conns = conns.join(",\n        "),
    )
}

/// The constraints: pins, I/O standards, the oscillator's clock (Vivado derives an MMCM's
/// output clock from it).
pub fn xdc(b: &Board) -> String {
    let period_ns = 1e9 / b.clock.frequency_hz as f64;
    let mut s = format!(
        "## snapgen constraints for the {} ({}). Generated by `snapgen build`.\n\n\
         set_property -dict {{ PACKAGE_PIN {} IOSTANDARD {} }} [get_ports {{ {} }}]\n\
         create_clock -add -name sys_clk_pin -period {:.3} -waveform {{0 {:.3}}} [get_ports {{ {} }}]\n\n",
        b.description,
        b.part,
        b.clock.pin,
        b.clock.iostandard,
        b.clock.port,
        period_ns,
        period_ns / 2.0,
        b.clock.port
    );
    for p in &b.pins {
        s.push_str(&xdc_pin(
            &p.port,
            p,
            &format!("{} ({})", p.comment, p.direction.name()),
        ));
    }
    for t in &b.ties {
        s.push_str(&format!(
            "set_property -dict {{ PACKAGE_PIN {} IOSTANDARD {} }} [get_ports {{ {} }}] ;# {} (held at {})\n",
            t.pin, t.iostandard, t.port, t.comment, t.level
        ));
    }
    s
}

/// One constraint line: a port on its package pin with its I/O standard and pull.
pub fn xdc_pin(port: &str, pin: &Pin, what: &str) -> String {
    let mut s = format!(
        "set_property -dict {{ PACKAGE_PIN {} IOSTANDARD {} }} [get_ports {{ {port} }}] ;# {what}\n",
        pin.pin, pin.iostandard
    );
    let pull = match pin.pull {
        Some(crate::board_spec::Pull::Up) => "PULLUP",
        Some(crate::board_spec::Pull::Down) => "PULLDOWN",
        Some(crate::board_spec::Pull::None) => "NONE",
        None => return s,
    };
    let _ = writeln!(s, "set_property PULLTYPE {pull} [get_ports {{ {port} }}]");
    s
}

/// A board build, as data.
#[derive(Clone, Debug)]
pub struct BuildPlan {
    /// File name → contents.
    pub files: BTreeMap<String, String>,
    /// How it runs.
    pub runner: Runner,
}

/// How a build runs in its output directory.
#[derive(Clone, Debug)]
pub enum Runner {
    /// `make`, which runs Vivado (not available here).
    Vivado,
    /// The open ECP5 flow's steps, run here; the fabric clock in Hz, which routed timing must
    /// close at.
    Ecp5 {
        /// The steps (also written as the Makefile).
        steps: Vec<crate::ecp5::Step>,
        /// The fabric clock.
        clock_hz: u64,
    },
}

/// The two clocks nearest `fout_hz` among those a clock generator can make ("nearest: A Hz,
/// B Hz"), or that it can make none: the hint of a refused fabric clock (the ECP5's PLL and the
/// 7-series MMCM).
pub fn nearest_clocks(mut reachable: Vec<u64>, fout_hz: u64) -> String {
    reachable.sort_by_key(|f| (f.abs_diff(fout_hz), *f));
    reachable.dedup();
    if reachable.is_empty() {
        return "it can make no clock from this oscillator".to_string();
    }
    let near: Vec<String> = reachable
        .iter()
        .take(2)
        .map(|f| format!("{f} Hz"))
        .collect();
    format!("nearest: {}", near.join(", "))
}

/// The board top's generator of the fabric clock, when the fabric does not run on the
/// oscillator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClockGen {
    /// The ECP5's PLL (EHXPLLL).
    Ecp5(crate::ecp5::PllSetting),
    /// A 7-series MMCM (MMCME2_BASE).
    Xc7(crate::xc7::MmcmSetting),
}

impl ClockGen {
    /// What the board top's comments call it.
    pub fn name(&self) -> &'static str {
        match self {
            ClockGen::Ecp5(_) => "PLL",
            ClockGen::Xc7(_) => "MMCM",
        }
    }

    /// The generator that makes `fabric_hz` from `b`'s oscillator: none when they are equal;
    /// refused, with the nearest clocks it can make, when it cannot make it exactly. The one
    /// rule for a board file's `pll_hz` and for `--clock-hz`.
    pub fn solve(b: &Board, fabric_hz: u64) -> Result<Option<ClockGen>, String> {
        let osc = b.clock.frequency_hz;
        if fabric_hz == osc {
            return Ok(None);
        }
        match b.toolchain() {
            Toolchain::OpenEcp5 => crate::ecp5::solve_pll(osc, fabric_hz)
                .map(|s| Some(ClockGen::Ecp5(s)))
                .map_err(|e| e.to_string()),
            Toolchain::Vivado if b.family != crate::board_spec::FAMILIES[0] => Err(format!(
                "snapgen generates the clock's MMCM for 7-series boards (family \"{}\") only: run the fabric at the oscillator's {osc} Hz (no pll_hz, or --clock-hz {osc}), or feed the board the clock you want",
                crate::board_spec::FAMILIES[0]
            )),
            Toolchain::Vivado => crate::xc7::solve_mmcm(osc, fabric_hz)
                .map(|s| Some(ClockGen::Xc7(s)))
                .map_err(|e| e.to_string()),
        }
    }

    /// [`ClockGen::solve`] for a build, its refusal an input error naming the board.
    pub fn for_board(
        b: &Board,
        fabric_hz: u64,
    ) -> Result<Option<ClockGen>, crate::error::InputError> {
        Self::solve(b, fabric_hz).map_err(|e| {
            crate::error::InputError::Board(format!(
                "{}: the fabric clock of {fabric_hz} Hz: {e}",
                b.name
            ))
        })
    }
}

/// The build of `b` for `timing` and its (checked, hashed) `design`: a Vivado non-project
/// build for a Xilinx board, the open flow for an ECP5 board; with the FPGA's PLL or MMCM when
/// the fabric clock is not the oscillator's (refused when it cannot make it exactly).
pub fn build_plan(b: &Board, timing: &Timing, design: &Design) -> anyhow::Result<BuildPlan> {
    let pll = ClockGen::for_board(b, timing.clock_hz)?;
    // What every build holds: the motion core, the I/O top and the board top.
    let top = b.top_name();
    let mut files = BTreeMap::new();
    let mut sources = Vec::new();
    for (name, text) in snapgen_hdl::verilog::io_sources(design) {
        sources.push(name.to_string());
        files.insert(name.into(), text);
    }
    files.insert(format!("{top}.v"), board_top_verilog(b, timing, pll));
    let runner = match b.toolchain() {
        Toolchain::Vivado => {
            vivado_files(b, &mut files);
            Runner::Vivado
        }
        Toolchain::OpenEcp5 => {
            files.insert(format!("{top}.lpf"), crate::ecp5::lpf(b));
            let steps = crate::ecp5::steps(b, &sources);
            files.insert("Makefile".into(), crate::ecp5::makefile(b, &steps));
            Runner::Ecp5 {
                steps,
                clock_hz: timing.clock_hz,
            }
        }
    };
    Ok(BuildPlan { files, runner })
}

/// The TCL that reads the routed design's worst setup and hold slack into `$wns` and `$whs`
/// and stops the build (no bitstream) when either is negative, naming the report and `fix`.
pub fn vivado_timing_check(report: &str, fix: &str) -> String {
    format!(
        "\
set wns [get_property SLACK [get_timing_paths -max_paths 1 -nworst 1 -setup]]
set whs [get_property SLACK [get_timing_paths -max_paths 1 -nworst 1 -hold]]
if {{$wns < 0 || $whs < 0}} {{
    error \"snapgen: routed timing does not close (setup slack $wns ns, hold slack $whs ns; {report}): {fix}\"
}}
"
    )
}

/// The Vivado non-project build's own files: the XDC, the TCL script and the Makefile.
fn vivado_files(b: &Board, files: &mut BTreeMap<String, String>) {
    let top = b.top_name();
    let tcl = format!(
        "\
# snapgen Vivado non-project build for the {desc}. Run: vivado -mode batch -source build.tcl
set part {part}
set top {top}
read_verilog [list snapgen_core.v snapgen_io.v {top}.v]
read_xdc {top}.xdc
synth_design -top $top -part $part
opt_design
place_design
route_design
report_utilization -file utilization.rpt
report_timing_summary -file timing.rpt
{check}write_bitstream -force $top.bit
puts \"snapgen: wrote $top.bit; routed timing closes (setup slack $wns ns, hold slack $whs ns)\"
",
        desc = b.description,
        part = b.part,
        top = top,
        check = vivado_timing_check(
            "timing.rpt",
            "lower the clock (the board file's clock.pll_hz, or --clock-hz)"
        ),
    );
    let makefile = format!(
        "\
# snapgen build for the {desc}: `make` runs Vivado in batch mode.
# VIVADO points to the vivado binary (default: vivado on the PATH).
VIVADO ?= vivado

{top}.bit: snapgen_core.v snapgen_io.v {top}.v {top}.xdc build.tcl
\t@command -v $(VIVADO) >/dev/null 2>&1 || {{ echo \"Vivado not found: install Vivado (AMD/Xilinx) or run make VIVADO=/path/to/vivado\" >&2; exit 1; }}
\t$(VIVADO) -mode batch -nojournal -nolog -source build.tcl

clean:
\trm -f {top}.bit utilization.rpt timing.rpt

.PHONY: clean
",
        desc = b.description,
        top = top,
    );
    files.insert(format!("{top}.xdc"), xdc(b));
    files.insert("build.tcl".into(), tcl);
    files.insert("Makefile".into(), makefile);
}

impl BuildPlan {
    /// Writes every file into `dir`.
    pub fn write(&self, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut out = Vec::new();
        for (name, text) in &self.files {
            let p = dir.join(name);
            std::fs::write(&p, text).with_context(|| format!("cannot write {}", p.display()))?;
            out.push(p);
        }
        Ok(out)
    }

    /// Runs the build in `dir` (its files written): Vivado through `make`, or the open ECP5
    /// flow, whose routed report it returns (the build fails when timing does not close).
    pub fn run(&self, dir: &Path) -> anyhow::Result<Option<crate::ecp5::Routed>> {
        match &self.runner {
            Runner::Vivado => {
                run_vivado(dir)?;
                Ok(None)
            }
            Runner::Ecp5 { steps, clock_hz } => crate::ecp5::run(steps, dir, *clock_hz).map(Some),
        }
    }
}

/// Runs `make` in `dir`, which runs Vivado.
fn run_vivado(dir: &Path) -> anyhow::Result<()> {
    let vivado = std::env::var("VIVADO").unwrap_or_else(|_| "vivado".into());
    if Command::new(&vivado).arg("-version").output().is_err() {
        bail!(
            "Vivado ({vivado}) was not found: install Vivado (AMD/Xilinx, not packaged for Debian) or set VIVADO to its path; the build files in {} can also be run elsewhere with `make`",
            dir.display()
        );
    }
    let status = Command::new("make")
        .env("VIVADO", &vivado)
        .current_dir(dir)
        .status()
        .context("cannot run make")?;
    if !status.success() {
        bail!("the Vivado build failed ({status})");
    }
    Ok(())
}

/// Budget of the motion core alone (sequencer + chain; its program memory and its stop unit
/// are reported apart). Issue 5 set 1000; issue 23's routed-timing work, which took the core
/// from 62.0 to 102.8 MHz routed, raised it to 1200: the core went from 957 to 1173 LUTs,
/// most of it the next program's first segment kept in registers and chosen after the
/// memory's read (docs/HDL.md).
pub const CORE_LUT_BUDGET: u64 = 1200;
/// Flip-flop budget of the motion core.
pub const CORE_FF_BUDGET: u64 = 1500;
/// Logic-only critical path budget of the motion core, in ns.
pub const CORE_PATH_BUDGET_NS: f64 = 5.0;

/// The whole report of `snapgen synth`.
#[derive(Clone, Debug)]
pub struct BoardSynth {
    /// Board.
    pub board: Board,
    /// Board top (I/O top and reset).
    pub full: crate::yosys::SynthReport,
    /// Motion core alone (with its stop unit, a block of its own in synthesis).
    pub core: crate::yosys::SynthReport,
    /// The path interpolator for [`INTERPOLATOR_AXES`] axes, on its own (issue 22: not yet
    /// part of the board's design).
    pub interpolator: crate::yosys::SynthReport,
    /// The path sequencer for [`INTERPOLATOR_AXES`] axes, on its own (issue 22: not yet part
    /// of the board's design).
    pub path_sequencer: crate::yosys::SynthReport,
    /// The path steppers for [`INTERPOLATOR_AXES`] axes (the sequencer, the interpolator and a
    /// step/dir generator per axis), on its own (issue 22: not yet in the board's design).
    pub path_steppers: crate::yosys::SynthReport,
    /// The path core for [`INTERPOLATOR_AXES`] axes (the motion core on the path length
    /// driving the path steppers; issue 22: not yet in the board's design).
    pub path_core: crate::yosys::SynthReport,
    /// The step/dir generator of one axis, on its own (issue 22: not yet in the design).
    pub step_dir: crate::yosys::SynthReport,
}

/// Axes of the path interpolator `snapgen synth` reports (issue 22's target: at least 4).
pub const INTERPOLATOR_AXES: u8 = 4;

/// The motion core's module, and its stop unit's (kept apart in synthesis).
const CORE_MODULE: &str = snapgen_hdl::verilog::CORE_PREFIX;
const STOP_UNIT_MODULE: &str = "snapgen_core_stop_unit";

impl BoardSynth {
    /// The motion core without its stop unit: what the budget applies to.
    pub fn core_block(&self) -> crate::yosys::ModuleReport {
        self.core
            .modules
            .get(CORE_MODULE)
            .cloned()
            .unwrap_or_default()
    }

    /// The stop unit.
    pub fn stop_unit(&self) -> crate::yosys::ModuleReport {
        self.core
            .modules
            .get(STOP_UNIT_MODULE)
            .cloned()
            .unwrap_or_default()
    }

    /// Budget violations of the motion core, and any design that synthesises with a latch
    /// (empty when within budget).
    pub fn violations(&self) -> Vec<String> {
        let mut v = Vec::new();
        let block = self.core_block();
        let r = &block.resources;
        if r.luts() > CORE_LUT_BUDGET {
            v.push(format!(
                "motion core uses {} LUTs, budget {CORE_LUT_BUDGET}",
                r.luts()
            ));
        }
        if r.ffs() > CORE_FF_BUDGET {
            v.push(format!(
                "motion core uses {} FFs, budget {CORE_FF_BUDGET}",
                r.ffs()
            ));
        }
        if block.path_ns > CORE_PATH_BUDGET_NS {
            v.push(format!(
                "motion core logic-only path is {:.2} ns, budget {CORE_PATH_BUDGET_NS} ns",
                block.path_ns
            ));
        }
        for (name, r) in [
            ("the board top", &self.full),
            ("the motion core", &self.core),
            ("the path interpolator", &self.interpolator),
            ("the path sequencer", &self.path_sequencer),
            ("the path steppers", &self.path_steppers),
            ("the path core", &self.path_core),
            ("the step/dir generator", &self.step_dir),
        ] {
            if r.resources.latches() > 0 {
                v.push(format!(
                    "{name} synthesises with {} latches (a combinational output not assigned on every path)",
                    r.resources.latches()
                ));
            }
        }
        v
    }

    /// The report as a Markdown table.
    pub fn table(&self) -> String {
        let d = &self.board.resources;
        let share = |n: u64, of: u64| format!("{n} ({:.1} %)", 100.0 * n as f64 / of as f64);
        let row = |name: &str, r: &crate::yosys::Resources, path_ns: f64| {
            format!(
                "| {name} | {} | {} | {} | {} | {} | {} | {:.2} |\n",
                share(r.luts(), d.luts),
                share(r.ffs(), d.ffs),
                r.carry4(),
                share(r.dsp(), d.dsp48e1.unwrap_or_default()),
                r.lutram(),
                share(r.bram36(), d.bram36.unwrap_or_default()),
                path_ns
            )
        };
        let (core, stop) = (self.core_block(), self.stop_unit());
        format!(
            "Yosys synth_xilinx -family {} for the {} ({}: {}, package {}, speed grade {}):\n\n\
             | design | LUT | FF | CARRY4 | DSP48E1 | LUT-RAM cells | BRAM36 | logic-only path (ns) |\n\
             |---|---|---|---|---|---|---|---|\n{}{}{}{}{}{}{}{}\n\
             Logic-only path: Yosys `sta` with the Xilinx cell library's specify blocks; routing is\n\
             not included. Motion core budget: ≤ {CORE_LUT_BUDGET} LUT, ≤ {CORE_FF_BUDGET} FF,\n\
             ≤ {CORE_PATH_BUDGET_NS} ns (its program memory is the LUT-RAM, reported apart; its\n\
             stop unit is a block of its own in synthesis, reported apart).\n",
            self.board.family,
            self.board.description,
            self.board.part,
            self.board.device,
            self.board.package,
            self.board.speed_grade,
            row(
                "board top (I/O top: UART command interface, motion core, position controller, encoder, PWM)",
                &self.full.resources,
                self.full.path_ns
            ),
            row(
                "motion core alone (sequencer, chain, program memory)",
                &core.resources,
                core.path_ns
            ),
            row(
                "stop unit (the motion core's controlled stop)",
                &stop.resources,
                stop.path_ns
            ),
            row(
                &format!(
                    "path interpolator for {INTERPOLATOR_AXES} axes, on its own (issue 22; not yet in the design)"
                ),
                &self.interpolator.resources,
                self.interpolator.path_ns
            ),
            row(
                &format!(
                    "path sequencer for {INTERPOLATOR_AXES} axes (ring of {} segments in block RAM), on its own (issue 22; not yet in the design)",
                    snapgen_spec::widths::PATH_SLOTS
                ),
                &self.path_sequencer.resources,
                self.path_sequencer.path_ns
            ),
            row(
                &format!(
                    "path steppers for {INTERPOLATOR_AXES} axes (sequencer, interpolator, a step/dir generator per axis), on its own (issue 22; not yet in the design)"
                ),
                &self.path_steppers.resources,
                self.path_steppers.path_ns
            ),
            row(
                &format!(
                    "path core for {INTERPOLATOR_AXES} axes (motion core on the path length driving the path steppers; no command interface), on its own (issue 22; not yet in the design)"
                ),
                &self.path_core.resources,
                self.path_core.path_ns
            ),
            row(
                "step/dir generator of one axis, on its own (issue 22; not yet in the design)",
                &self.step_dir.resources,
                self.step_dir.path_ns
            ),
        )
    }
}

/// Synthesises the board top and the motion core alone (in a temporary directory).
pub fn synth(b: &Board, timing: &Timing, design: &Design) -> anyhow::Result<BoardSynth> {
    if b.toolchain() == Toolchain::OpenEcp5 {
        return Err(crate::error::InputError::Board(format!(
            "snapgen synth reports Yosys synth_xilinx for Xilinx boards; the {} is an ECP5 board: `snapgen build` synthesises, places and routes it and prints its routed Fmax and resources",
            b.name
        ))
        .into());
    }
    let dir = std::env::temp_dir().join(format!("snapgen-synth-{}", std::process::id()));
    let plan = build_plan(b, timing, design)?;
    plan.write(&dir)?;
    let top = b.top_name();
    let core_file = dir.join("snapgen_core.v");
    // Each design's files and top module, written first; then one Yosys per design, all at
    // once (each is one process on one core; they share nothing).
    let write = |prefix: &str, files: Vec<(String, String)>| -> anyhow::Result<Vec<PathBuf>> {
        files
            .into_iter()
            .map(|(name, text)| {
                let file = dir.join(format!("{prefix}{name}"));
                std::fs::write(&file, text)
                    .with_context(|| format!("cannot write {}", file.display()))?;
                Ok(file)
            })
            .collect()
    };
    // A design of one file, named after its top module.
    let single = |top: &str, text: String| -> anyhow::Result<(Vec<PathBuf>, String)> {
        Ok((
            write("", vec![(format!("{top}.v"), text)])?,
            top.to_string(),
        ))
    };
    use snapgen_hdl::{interpolator as ip, path_core as pc, path_sequencer as ps};
    use snapgen_hdl::{path_steppers as st, step_dir as sd};
    let jobs: [(Vec<PathBuf>, String); 7] = [
        (
            vec![
                core_file.clone(),
                dir.join("snapgen_io.v"),
                dir.join(format!("{top}.v")),
            ],
            top.clone(),
        ),
        (
            vec![core_file],
            snapgen_hdl::verilog::CORE_PREFIX.to_string(),
        ),
        single(
            ip::INTERPOLATOR_PREFIX,
            ip::interpolator_verilog(INTERPOLATOR_AXES),
        )?,
        single(
            ps::PATH_SEQUENCER_PREFIX,
            ps::path_sequencer_verilog(INTERPOLATOR_AXES),
        )?,
        (
            write(
                "steppers_",
                st::path_steppers_sources(INTERPOLATOR_AXES).to_vec(),
            )?,
            st::PATH_STEPPERS_PREFIX.to_string(),
        ),
        (
            write("path_core_", pc::path_core_sources(INTERPOLATOR_AXES))?,
            pc::PATH_CORE_PREFIX.to_string(),
        ),
        single(sd::STEP_DIR_PREFIX, sd::step_dir_verilog())?,
    ];
    let family = &b.family;
    let [full, core, interpolator, path_sequencer, path_steppers, path_core, step_dir] =
        std::thread::scope(|s| {
            jobs.each_ref()
                .map(|(files, top)| s.spawn(move || crate::yosys::synth(files, top, family)))
                .map(|h| h.join().expect("a Yosys run's thread panicked"))
        });
    let (full, core, interpolator, path_sequencer, path_steppers, path_core, step_dir) = (
        full?,
        core?,
        interpolator?,
        path_sequencer?,
        path_steppers?,
        path_core?,
        step_dir?,
    );
    let _ = std::fs::remove_dir_all(&dir);
    Ok(BoardSynth {
        board: b.clone(),
        full,
        core,
        interpolator,
        path_sequencer,
        path_steppers,
        path_core,
        step_dir,
    })
}
