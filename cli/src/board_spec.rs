//! Board descriptions: a board is data (device, clock, pins), read from TOML and checked
//! before anything is generated from it. The schema is documented in docs/BOARDS.md; the
//! built-in boards live in `cli/boards/`, and `--board-file FILE` reads a user's own.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;
use snapgen_spec::ports::{board_pins, Dir};

/// The ports of the board top (`snapgen build`) with their directions and what they are for,
/// from the spec's board pins (one axis): every board file maps each of them to a package pin
/// (the clock in its `[clock]` table), and nothing else.
pub fn top_ports() -> Vec<(String, Direction, &'static str)> {
    board_pins(1)
        .into_iter()
        .map(|p| {
            let dir = match p.dir {
                Dir::In => Direction::In,
                Dir::Out => Direction::Out,
            };
            (p.port, dir, p.doc)
        })
        .collect()
}

/// Yosys `synth_xilinx` families Vivado can also build (7 series and UltraScale).
pub const FAMILIES: [&str; 3] = ["xc7", "xcu", "xcup"];

/// The Lattice ECP5 family: built here with the open toolchain (Yosys `synth_ecp5`,
/// nextpnr-ecp5, ecppack; [`crate::ecp5`]).
pub const ECP5: &str = "ecp5";

/// How a board's bitstream is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Toolchain {
    /// Vivado (AMD/Xilinx), not available here: the build is written, `--run` runs it.
    Vivado,
    /// The open ECP5 flow, run by `snapgen build`.
    OpenEcp5,
}

/// A pin's pull resistor inside the FPGA.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Pull {
    /// Pull-up.
    Up,
    /// Pull-down.
    Down,
    /// None.
    None,
}

/// A pin's direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Into the FPGA.
    In,
    /// Out of the FPGA.
    Out,
}

impl Direction {
    /// As written in a board file.
    pub fn name(self) -> &'static str {
        match self {
            Direction::In => "in",
            Direction::Out => "out",
        }
    }
}

/// The device's resources (for the share printed by `snapgen synth`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceResources {
    /// LUTs.
    pub luts: u64,
    /// Flip-flops.
    pub ffs: u64,
    /// DSP48E1 slices (Xilinx boards).
    #[serde(default)]
    pub dsp48e1: Option<u64>,
    /// 36 kb block RAMs (Xilinx boards).
    #[serde(default)]
    pub bram36: Option<u64>,
}

/// The board clock.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClockPin {
    /// Top-level port.
    pub port: String,
    /// Package pin.
    pub pin: String,
    /// I/O standard.
    pub iostandard: String,
    /// The oscillator's frequency (Hz).
    pub frequency_hz: u64,
    /// The fabric clock the FPGA makes from the oscillator (Hz): the ECP5's PLL or a 7-series
    /// MMCM. Without it the fabric runs at the oscillator's frequency.
    #[serde(default)]
    pub pll_hz: Option<u64>,
}

/// A named pin.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// Top-level port (`led[0]` for a bit of a bus).
    pub port: String,
    /// Package pin.
    pub pin: String,
    /// I/O standard.
    pub iostandard: String,
    /// `in` or `out`.
    pub direction: Direction,
    /// The FPGA's pull resistor on it (default: the device's default).
    #[serde(default)]
    pub pull: Option<Pull>,
    /// What it is for.
    pub comment: String,
}

/// A pin the board top drives to a constant level, for the board's own sake (e.g. the
/// ULX3S's ESP32 GPIO0, held high so that the module does not reset the board).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tie {
    /// Top-level port (a Verilog name).
    pub port: String,
    /// Package pin.
    pub pin: String,
    /// I/O standard.
    pub iostandard: String,
    /// The level driven: 0 or 1.
    pub level: u8,
    /// Why.
    pub comment: String,
}

/// A board.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    /// Short name: lower-case letters, digits and `-` (module `snapgen_<name>`).
    pub name: String,
    /// Human description.
    pub description: String,
    /// The vendor's part name (Vivado's part for a Xilinx board).
    pub part: String,
    /// Yosys `synth_xilinx` family (`xc7`, `xcu`, `xcup`) or `ecp5`.
    pub family: String,
    /// Device.
    pub device: String,
    /// Package.
    pub package: String,
    /// Speed grade.
    pub speed_grade: String,
    /// Resources.
    pub resources: DeviceResources,
    /// Clock.
    pub clock: ClockPin,
    /// The limit and emergency-stop inputs' polarity after reset (INPUT_POLARITY: bit 0
    /// inverts limit_pos, bit 1 limit_neg, bit 2 estop; set a bit for a normally-closed
    /// contact). Built into the bitstream; default 0.
    #[serde(default)]
    pub input_polarity: u8,
    /// Pins.
    pub pins: Vec<Pin>,
    /// Pins driven to a constant level (optional).
    #[serde(default)]
    pub ties: Vec<Tie>,
    /// The processing system of a Zynq board (optional): what `snapgen build --host ps` needs.
    #[serde(default)]
    pub ps: Option<ProcessingSystem>,
}

/// A Zynq-7000 board's processing system, for the build in which its ARM is the host over
/// AXI4-Lite (`snapgen build --host ps`, [`crate::zynq`]).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessingSystem {
    /// Vivado's board part (the board vendor's board files, which hold the PS7's DDR and MIO
    /// preset), e.g. `digilentinc.com:zybo-z7-10:part0:1.0`.
    pub board_part: String,
    /// The PS's IO PLL frequency under that preset (Hz): FCLK_CLK0 is it divided by two
    /// dividers of 1 to 63.
    pub io_pll_hz: u64,
    /// The fabric clock, FCLK_CLK0 (Hz): an exact division of `io_pll_hz`.
    pub fclk_hz: u64,
    /// The snapgen slave's base address on M_AXI_GP0 (0x4000_0000 to 0x7FFF_F000, 4 KiB
    /// aligned).
    pub axi_base: u64,
}

/// A board description that cannot be used, with what to change.
#[derive(Debug, thiserror::Error)]
pub enum BoardError {
    /// No built-in board of that name.
    #[error("unknown board {name:?}: known boards are {known}, or describe yours in a file and pass --board-file FILE (docs/BOARDS.md)")]
    Unknown {
        /// Asked for.
        name: String,
        /// Built-in names.
        known: String,
    },
    /// The file cannot be read.
    #[error("cannot read the board file {path}: {source}")]
    Read {
        /// Path.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML of the schema (missing or unknown key, wrong type).
    #[error("board file {origin}: {message} (the schema is in docs/BOARDS.md)")]
    Schema {
        /// File or board name.
        origin: String,
        /// What TOML/serde said.
        message: String,
    },
    /// A value the build cannot use.
    #[error("board file {origin}: {field} = {value:?}: {fix}")]
    Invalid {
        /// File or board name.
        origin: String,
        /// The field.
        field: String,
        /// Its value.
        value: String,
        /// What to change.
        fix: String,
    },
}

const BUILTIN: &[(&str, &str)] = &[
    ("zybo-z7-10", include_str!("../boards/zybo-z7-10.toml")),
    ("ulx3s", include_str!("../boards/ulx3s.toml")),
];

/// A built-in board by name.
pub fn builtin(name: &str) -> Result<Board, BoardError> {
    let Some((_, text)) = BUILTIN.iter().find(|(n, _)| *n == name) else {
        let known: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
        return Err(BoardError::Unknown {
            name: name.to_string(),
            known: known.join(", "),
        });
    };
    Board::parse(text, name)
}

/// A board from a user's file.
pub fn from_file(path: &Path) -> Result<Board, BoardError> {
    let text = std::fs::read_to_string(path).map_err(|source| BoardError::Read {
        path: path.display().to_string(),
        source,
    })?;
    Board::parse(&text, &path.display().to_string())
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

impl Board {
    /// Parses and checks a board description; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Board, BoardError> {
        let b: Board = toml::from_str(text).map_err(|e| BoardError::Schema {
            origin: origin.to_string(),
            message: e.message().to_string()
                + &e.span()
                    .map(|s| {
                        let line = text[..s.start].lines().count().max(1);
                        format!(" (line {line})")
                    })
                    .unwrap_or_default(),
        })?;
        b.check(origin)?;
        Ok(b)
    }

    /// The Verilog name of the board top.
    pub fn top_name(&self) -> String {
        format!("snapgen_{}", self.name.replace('-', "_"))
    }

    /// How its bitstream is built.
    pub fn toolchain(&self) -> Toolchain {
        if self.family == ECP5 {
            Toolchain::OpenEcp5
        } else {
            Toolchain::Vivado
        }
    }

    /// The fabric's clock (Hz): the PLL's output, else the oscillator's.
    pub fn fabric_clock_hz(&self) -> u64 {
        self.clock.pll_hz.unwrap_or(self.clock.frequency_hz)
    }

    fn check(&self, origin: &str) -> Result<(), BoardError> {
        let bad = |field: &str, value: &dyn std::fmt::Display, fix: &str| BoardError::Invalid {
            origin: origin.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            fix: fix.to_string(),
        };
        if self.name.is_empty()
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            || !self.name.starts_with(|c: char| c.is_ascii_lowercase())
        {
            return Err(bad(
                "name",
                &self.name,
                "use lower-case letters, digits and '-', starting with a letter (it names the top module and files)",
            ));
        }
        for (field, value) in [
            ("part", &self.part),
            ("device", &self.device),
            ("package", &self.package),
            ("speed_grade", &self.speed_grade),
        ] {
            if value.trim().is_empty() {
                return Err(bad(
                    field,
                    value,
                    "give the device's value (see the vendor's part list)",
                ));
            }
        }
        if !FAMILIES.contains(&self.family.as_str()) && self.family != ECP5 {
            return Err(bad(
                "family",
                &self.family,
                &format!(
                    "use one of {} (Yosys synth_xilinx families that Vivado builds) or {ECP5} (built here with Yosys, nextpnr-ecp5 and ecppack)",
                    FAMILIES.join(", ")
                ),
            ));
        }
        match self.toolchain() {
            Toolchain::OpenEcp5 => {
                if crate::ecp5::nextpnr_device(&self.device).is_none() {
                    return Err(bad(
                        "device",
                        &self.device,
                        &format!(
                            "give an ECP5 device nextpnr-ecp5 knows: {}",
                            crate::ecp5::devices()
                        ),
                    ));
                }
                if !["6", "7", "8"].contains(&self.speed_grade.as_str()) {
                    return Err(bad(
                        "speed_grade",
                        &self.speed_grade,
                        "give the ECP5's speed grade: \"6\", \"7\" or \"8\" (the digit after the device in the part name)",
                    ));
                }
            }
            Toolchain::Vivado => {
                if self.resources.dsp48e1.is_none() || self.resources.bram36.is_none() {
                    return Err(bad(
                        "resources",
                        &"dsp48e1 or bram36 missing",
                        "give the device's DSP48E1 and 36 kb block RAM counts (snapgen synth prints the share of each)",
                    ));
                }
            }
        }
        if self.input_polarity > 7 {
            return Err(bad(
                "input_polarity",
                &self.input_polarity,
                "give 0..=7: bit 0 inverts limit_pos, bit 1 limit_neg, bit 2 estop",
            ));
        }
        let r = &self.resources;
        if r.luts == 0 || r.ffs == 0 {
            return Err(bad(
                "resources",
                &format!("{} LUT, {} FF", r.luts, r.ffs),
                "give the device's LUT and flip-flop counts (> 0)",
            ));
        }
        let c = &self.clock;
        if c.port != "sysclk" {
            return Err(bad(
                "clock.port",
                &c.port,
                "the board top's clock port is \"sysclk\"",
            ));
        }
        if !(1_000_000..=1_000_000_000).contains(&c.frequency_hz) {
            return Err(bad(
                "clock.frequency_hz",
                &c.frequency_hz,
                "give the oscillator's frequency in Hz, 1e6 to 1e9",
            ));
        }
        if let Some(pll) = c.pll_hz {
            let made = crate::fpga::ClockGen::solve(self, pll);
            if let Err(e) = made {
                return Err(bad("clock.pll_hz", &pll, &e));
            }
        }
        if let Some(ps) = &self.ps {
            self.check_ps(ps, &bad)?;
        }
        let mut pins: BTreeMap<&str, &str> = BTreeMap::new();
        let mut ports: BTreeMap<&str, Direction> = BTreeMap::new();
        let claim = |pin: &str, iostandard: &str, field: &str| {
            if pin.trim().is_empty() || pin.contains(char::is_whitespace) {
                return Err(bad(
                    &format!("{field}.pin"),
                    &pin,
                    "give the package pin (e.g. K17)",
                ));
            }
            if iostandard.trim().is_empty() {
                return Err(bad(
                    &format!("{field}.iostandard"),
                    &iostandard,
                    "give the bank's I/O standard (e.g. LVCMOS33)",
                ));
            }
            Ok::<(), BoardError>(())
        };
        claim(&c.pin, &c.iostandard, "clock")?;
        pins.insert(&c.pin, &c.port);
        ports.insert(&c.port, Direction::In);
        for p in &self.pins {
            let field = format!("pins[{}]", p.port);
            claim(&p.pin, &p.iostandard, &field)?;
            let base = p.port.split('[').next().unwrap_or("");
            if !is_identifier(base) {
                return Err(bad(
                    &field,
                    &p.port,
                    "a port is a Verilog name, or name[bit]",
                ));
            }
            if let Some(other) = pins.insert(&p.pin, &p.port) {
                return Err(bad(
                    &format!("{field}.pin"),
                    &p.pin,
                    &format!("pin {} is already used by {other}: each pin once", p.pin),
                ));
            }
            if ports.insert(&p.port, p.direction).is_some() {
                return Err(bad(&field, &p.port, "each port once"));
            }
        }
        for t in &self.ties {
            let field = format!("ties[{}]", t.port);
            claim(&t.pin, &t.iostandard, &field)?;
            if !is_identifier(&t.port) {
                return Err(bad(&field, &t.port, "a tied port is a Verilog name"));
            }
            if t.level > 1 {
                return Err(bad(&format!("{field}.level"), &t.level, "give 0 or 1"));
            }
            if let Some(other) = pins.insert(&t.pin, &t.port) {
                return Err(bad(
                    &format!("{field}.pin"),
                    &t.pin,
                    &format!("pin {} is already used by {other}: each pin once", t.pin),
                ));
            }
            if ports.contains_key(t.port.as_str())
                || top_ports().iter().any(|(p, _, _)| p == &t.port)
                || self.ties.iter().filter(|u| u.port == t.port).count() > 1
            {
                return Err(bad(
                    &field,
                    &t.port,
                    "each port once, and not a port of the board top's",
                ));
            }
        }
        let top = top_ports();
        for (port, dir, what) in &top {
            let (port, dir) = (port.as_str(), *dir);
            match ports.get(port) {
                None => {
                    return Err(bad(
                        "pins",
                        &format!("no {port}"),
                        &format!(
                            "add a [[pins]] entry for port {port:?} ({what}, direction \"{}\")",
                            dir.name()
                        ),
                    ))
                }
                Some(d) if *d != dir => {
                    return Err(bad(
                        &format!("pins[{port}].direction"),
                        &d.name(),
                        &format!(
                            "{port} is an {} of the board top",
                            if dir == Direction::In {
                                "input"
                            } else {
                                "output"
                            }
                        ),
                    ))
                }
                Some(_) => {}
            }
        }
        if let Some(extra) = ports.keys().find(|p| !top.iter().any(|(t, _, _)| t == *p)) {
            let known: Vec<&str> = top.iter().map(|(t, _, _)| t.as_str()).collect();
            return Err(bad(
                &format!("pins[{extra}]"),
                extra,
                &format!("the board top has no such port: use {}", known.join(", ")),
            ));
        }
        Ok(())
    }

    fn check_ps(
        &self,
        ps: &ProcessingSystem,
        bad: &dyn Fn(&str, &dyn std::fmt::Display, &str) -> BoardError,
    ) -> Result<(), BoardError> {
        if self.family != "xc7" || !self.device.starts_with("xc7z") {
            return Err(bad(
                "ps",
                &self.device,
                "a [ps] table is for Zynq-7000 boards (family \"xc7\", device xc7z...): remove it",
            ));
        }
        if ps.board_part.split(':').count() != 4 {
            return Err(bad(
                "ps.board_part",
                &ps.board_part,
                "give Vivado's board part, vendor:board:part0:version (e.g. digilentinc.com:zybo-z7-10:part0:1.0)",
            ));
        }
        if crate::zynq::fclk_dividers(ps.io_pll_hz, ps.fclk_hz).is_none() {
            return Err(bad(
                "ps.fclk_hz",
                &ps.fclk_hz,
                &format!(
                    "the PS makes FCLK_CLK0 as io_pll_hz ({}) divided by two dividers of 1 to 63: give such a frequency (e.g. {})",
                    ps.io_pll_hz,
                    ps.io_pll_hz / 10
                ),
            ));
        }
        if !crate::zynq::GP0_WINDOW.contains(&ps.axi_base)
            || ps.axi_base % crate::zynq::UIO_SPAN != 0
        {
            return Err(bad(
                "ps.axi_base",
                &format!("{:#x}", ps.axi_base),
                "give a 4 KiB aligned address in M_AXI_GP0's window, 0x40000000 to 0x7ffff000 (e.g. 0x43c00000)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fclk_is_made_by_two_dividers() {
        assert_eq!(
            crate::zynq::fclk_dividers(1_000_000_000, 100_000_000),
            Some((1, 10))
        );
        assert_eq!(
            crate::zynq::fclk_dividers(1_000_000_000, 125_000_000),
            Some((1, 8))
        );
        // 4000 > 63 x 63: no pair of 6-bit dividers.
        assert_eq!(crate::zynq::fclk_dividers(1_000_000_000, 250_000), None);
        // 64 = 2 x 32 (one divider alone cannot make 64).
        assert_eq!(
            crate::zynq::fclk_dividers(1_000_000_000, 15_625_000),
            Some((2, 32))
        );
        assert_eq!(crate::zynq::fclk_dividers(1_000_000_000, 123_000_000), None);
        assert_eq!(crate::zynq::fclk_dividers(1_000_000_000, 0), None);
    }

    #[test]
    fn the_builtin_board_is_valid() {
        let b = builtin("zybo-z7-10").unwrap();
        assert_eq!(b.top_name(), "snapgen_zybo_z7_10");
        assert_eq!(b.clock.frequency_hz, 125_000_000);
    }

    fn zybo_with(edit: impl Fn(&str) -> String) -> Result<Board, BoardError> {
        Board::parse(&edit(BUILTIN[0].1), "test.toml")
    }

    #[test]
    fn mistakes_are_named_with_what_to_change() {
        type Edit<'a> = &'a dyn Fn(&str) -> String;
        let cases: [(Edit, &str); 12] = [
            (
                &|t| t.replace("name = \"zybo-z7-10\"", "name = \"Zybo Z7\""),
                "name = \"Zybo Z7\"",
            ),
            (
                &|t| t.replace("family = \"xc7\"", "family = \"ice40\""),
                "use one of xc7",
            ),
            (
                &|t| t.replace("frequency_hz = 125000000", "frequency_hz = 0"),
                "clock.frequency_hz",
            ),
            (
                &|t| t.replace("pin = \"W15\"", "pin = \"V15\""),
                "already used by pwm",
            ),
            (
                &|t| t.replace("port = \"enc_i\"", "port = \"enc_z\""),
                "add a [[pins]] entry for port \"enc_i\"",
            ),
            (
                &|t| t.replacen("direction = \"out\"", "direction = \"in\"", 1),
                "led[0] is an output",
            ),
            (
                &|t| {
                    t.replace(
                        "speed_grade = \"-1\"",
                        "speed_grade = \"-1\"\ncolour = \"red\"",
                    )
                },
                "unknown field `colour`",
            ),
            (
                &|t| t.replace("[resources]\n", "[resources]\nluts_x = 1\n"),
                "unknown field `luts_x`",
            ),
            (
                &|t| t.replace("fclk_hz = 100000000", "fclk_hz = 123000000"),
                "ps.fclk_hz = \"123000000\": the PS makes FCLK_CLK0",
            ),
            (
                &|t| t.replace("axi_base = 0x43C00000", "axi_base = 0x43C00100"),
                "ps.axi_base = \"0x43c00100\": give a 4 KiB aligned address",
            ),
            (
                &|t| t.replace("axi_base = 0x43C00000", "axi_base = 0x80000000"),
                "M_AXI_GP0's window",
            ),
            (&|t| t.replace(":part0:1.2", ""), "ps.board_part"),
        ];
        for (edit, want) in cases {
            let e = zybo_with(edit).unwrap_err().to_string();
            assert!(e.contains(want), "{want:?} not in: {e}");
            assert!(e.contains("test.toml"), "{e}");
        }
    }

    #[test]
    fn ecp5_boards_and_clock_generators_are_checked_too() {
        let b = builtin("ulx3s").unwrap();
        assert_eq!(b.toolchain(), Toolchain::OpenEcp5);
        assert_eq!(
            (b.clock.frequency_hz, b.fabric_clock_hz()),
            (25_000_000, 100_000_000)
        );
        let ulx3s = BUILTIN[1].1;
        let ps = &BUILTIN[0].1[BUILTIN[0].1.find("\n[ps]").unwrap()..];
        let cases: [(String, &str); 8] = [
            (ulx3s.replace("level = 1", "level = 2"), "give 0 or 1"),
            (
                format!("{ulx3s}{ps}"),
                "a [ps] table is for Zynq-7000 boards",
            ),
            (
                ulx3s.replace("port = \"wifi_gpio0\"", "port = \"pwm\""),
                "not a port of the board top",
            ),
            (
                ulx3s.replace("device = \"LFE5U-85F\"", "device = \"LFE5U-100F\""),
                "give an ECP5 device nextpnr-ecp5 knows",
            ),
            (
                ulx3s.replace("speed_grade = \"6\"", "speed_grade = \"-6\""),
                "give the ECP5's speed grade",
            ),
            (
                ulx3s.replace("pll_hz = 100000000", "pll_hz = 77777777"),
                "no ECP5 PLL setting makes exactly 77777777 Hz",
            ),
            (
                BUILTIN[0]
                    .1
                    .replace("pll_hz = 100000000", "pll_hz = 99999999"),
                "no 7-series MMCM setting makes exactly 99999999 Hz",
            ),
            (
                BUILTIN[0].1.replace("family = \"xc7\"", "family = \"xcu\""),
                "for 7-series boards (family \"xc7\") only",
            ),
        ];
        for (text, want) in cases {
            let e = Board::parse(&text, "test.toml").unwrap_err().to_string();
            assert!(e.contains(want), "{want:?} not in: {e}");
        }
    }

    #[test]
    fn an_unknown_builtin_points_to_board_files() {
        let e = builtin("arty").unwrap_err().to_string();
        assert!(
            e.contains("known boards are zybo-z7-10") && e.contains("--board-file"),
            "{e}"
        );
    }
}
