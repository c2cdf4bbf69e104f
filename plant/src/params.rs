//! The plant as data: a motor (in its data sheet's units), its load, the amplifier and the
//! encoder, read from TOML (`plant/motors/*.toml`, docs/PLANT.md) and checked field by field;
//! [`Physical`] is the same in SI units, as the simulation uses it.

use std::f64::consts::PI;
use std::path::Path;

use serde::{Deserialize, Serialize};

/// A current-mode drive's current-loop bandwidth when the file gives none (Hz): an assumption,
/// typical of analog brush servo drives (the 12A8's is not published here).
pub const DEFAULT_CURRENT_LOOP_HZ: f64 = 2500.0;
/// A current-mode drive's command filter when the file gives none (Hz): an assumption.
pub const DEFAULT_COMMAND_FILTER_HZ: f64 = 5000.0;

/// The default plant: maxon RE 40 (148877) with seed 001's load, amplifier and encoder.
pub const DEFAULT_PLANT: &str = include_str!("../motors/re40-148877.toml");

/// The motor, in its data sheet's units.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Motor {
    /// What it is.
    pub name: String,
    /// Where its values come from.
    pub source: String,
    /// Nominal voltage (V).
    pub nominal_voltage_v: f64,
    /// Terminal resistance (Ω).
    pub terminal_resistance_ohm: f64,
    /// Terminal inductance (mH).
    pub terminal_inductance_mh: f64,
    /// Torque constant (mN·m/A).
    pub torque_constant_mnm_per_a: f64,
    /// Speed constant (rpm/V): the back-EMF constant is its inverse.
    pub speed_constant_rpm_per_v: f64,
    /// Rotor inertia (g·cm²).
    pub rotor_inertia_gcm2: f64,
    /// No-load speed at the nominal voltage (rpm).
    pub no_load_speed_rpm: f64,
    /// No-load current (mA): taken as Coulomb friction (torque constant × no-load current).
    pub no_load_current_ma: f64,
    /// Viscous friction (N·m·s/rad), in addition.
    pub viscous_friction_nm_s_per_rad: f64,
}

/// The load on the shaft.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Load {
    /// What it is.
    pub description: String,
    /// Its inertia about the shaft (kg·m²).
    pub inertia_kg_m2: f64,
}

/// How the amplifier drives the motor.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum AmplifierKind {
    /// An H-bridge switched by the fabric's PWM and direction: the supply (or 0 V) across the
    /// motor, with dead time and a cycle-by-cycle current limit.
    #[default]
    Voltage,
    /// A servo drive in current (torque) mode, as seed 001's AMC 12A8 is usually run: the
    /// fabric's PWM and direction are its command (their average, through the drive's input
    /// filter), full scale `current_limit_a`; its own current loop sets the motor's current
    /// within its bandwidth and the supply.
    Current,
}

/// The amplifier: PWM and direction in, the motor's voltage (or current) out.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Amplifier {
    /// What it is.
    pub description: String,
    /// `voltage` (the default: an H-bridge) or `current` (a drive in torque mode).
    #[serde(default)]
    pub kind: AmplifierKind,
    /// A current-mode drive's current-loop bandwidth (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_loop_hz: Option<f64>,
    /// A current-mode drive's command input filter (Hz): it averages the PWM.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command_filter_hz: Option<f64>,
    /// Supply voltage (V).
    pub supply_v: f64,
    /// Dead time after each switching edge (ns).
    pub dead_time_ns: f64,
    /// Current limit (A): beyond it the bridge stops driving (cycle by cycle); a current-mode
    /// drive's full-scale current.
    pub current_limit_a: f64,
}

/// The quadrature encoder.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Encoder {
    /// Lines (pulses) per revolution: 4 counts each with ×4 decoding.
    pub lines: u32,
    /// An index pulse once per revolution.
    pub index: bool,
}

/// A whole plant file.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PlantParams {
    /// The motor.
    pub motor: Motor,
    /// Its load.
    pub load: Load,
    /// The amplifier.
    pub amplifier: Amplifier,
    /// The encoder.
    pub encoder: Encoder,
}

/// A plant file that cannot be used, with what to change.
#[derive(Debug, thiserror::Error)]
pub enum PlantError {
    /// The file cannot be read.
    #[error("cannot read the plant file {path}: {source}")]
    Read {
        /// Path.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML of the schema.
    #[error("plant file {origin}: {message} (the schema is in docs/PLANT.md)")]
    Schema {
        /// File.
        origin: String,
        /// What TOML said.
        message: String,
    },
    /// A value the simulation cannot use.
    #[error("plant file {origin}: {field} = {value}: {fix}")]
    Invalid {
        /// File.
        origin: String,
        /// Field.
        field: &'static str,
        /// Its value.
        value: String,
        /// What to change.
        fix: &'static str,
    },
}

/// How the motor is driven, in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The H-bridge.
    Voltage,
    /// A current-mode drive.
    Current {
        /// Its current loop's bandwidth (rad/s).
        loop_rad_s: f64,
        /// Its command filter's corner (rad/s).
        filter_rad_s: f64,
        /// Its PI current loop's gains, tuned once to the plant file's winding: `L·ω_c` (V/A)
        /// and `R·ω_c` (V/(A·s)). A winding that differs later (hot: `snapgen_plant::mismatch`)
        /// keeps the drive's tuning.
        kp: f64,
        /// The integral gain.
        ki: f64,
    },
}

/// The plant in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Physical {
    /// The amplifier's kind.
    pub drive: Drive,
    /// Armature resistance (Ω).
    pub r: f64,
    /// Armature inductance (H).
    pub l: f64,
    /// Torque constant (N·m/A).
    pub kt: f64,
    /// Back-EMF constant (V·s/rad).
    pub ke: f64,
    /// Total inertia: rotor and load (kg·m²).
    pub j: f64,
    /// Viscous friction (N·m·s/rad).
    pub b: f64,
    /// Coulomb friction (N·m).
    pub tc: f64,
    /// Supply (V).
    pub vs: f64,
    /// Dead time (s).
    pub dead_time: f64,
    /// Current limit (A).
    pub i_limit: f64,
    /// Encoder counts per revolution (×4).
    pub counts_per_rev: u32,
    /// Index pulse.
    pub index: bool,
}

impl Physical {
    /// Radians per encoder count.
    pub fn rad_per_count(&self) -> f64 {
        2.0 * PI / f64::from(self.counts_per_rev)
    }

    /// The motor's mechanical time constant with its load, `J·R / (R·b + Kt·Ke)` (s).
    pub fn mechanical_time_constant(&self) -> f64 {
        self.j * self.r / (self.r * self.b + self.kt * self.ke)
    }

    /// The steady-state speed per volt, `Kt / (R·b + Kt·Ke)` (rad/s per V).
    pub fn speed_per_volt(&self) -> f64 {
        self.kt / (self.r * self.b + self.kt * self.ke)
    }
}

impl PlantParams {
    /// The default plant ([`DEFAULT_PLANT`]).
    pub fn default_plant() -> Self {
        Self::parse(DEFAULT_PLANT, "plant/motors/re40-148877.toml")
            .expect("the default plant file is valid (tested)")
    }

    /// A plant file's contents; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, PlantError> {
        let p: PlantParams = toml::from_str(text).map_err(|e| PlantError::Schema {
            origin: origin.to_string(),
            message: e.message().to_string()
                + &e.span()
                    .map(|s| format!(" (line {})", text[..s.start].lines().count().max(1)))
                    .unwrap_or_default(),
        })?;
        p.physical_checked(origin)?;
        Ok(p)
    }

    /// The plant file's text (TOML, the schema [`PlantParams::parse`] reads), headed by
    /// `comment` (each line prefixed with `# `).
    pub fn to_toml(&self, comment: &str) -> String {
        let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
        head + &toml::to_string(self).expect("a plant is plain data")
    }

    /// A plant file.
    pub fn from_file(path: &Path) -> Result<Self, PlantError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlantError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The plant in SI units (the values are checked when the file is read).
    pub fn physical(&self) -> Physical {
        let m = &self.motor;
        let kt = m.torque_constant_mnm_per_a * 1e-3;
        let a = &self.amplifier;
        let hz = |v: Option<f64>, default: f64| 2.0 * PI * v.unwrap_or(default);
        Physical {
            drive: match a.kind {
                AmplifierKind::Voltage => Drive::Voltage,
                AmplifierKind::Current => {
                    let loop_rad_s = hz(a.current_loop_hz, DEFAULT_CURRENT_LOOP_HZ);
                    Drive::Current {
                        loop_rad_s,
                        filter_rad_s: hz(a.command_filter_hz, DEFAULT_COMMAND_FILTER_HZ),
                        kp: m.terminal_inductance_mh * 1e-3 * loop_rad_s,
                        ki: m.terminal_resistance_ohm * loop_rad_s,
                    }
                }
            },
            r: m.terminal_resistance_ohm,
            l: m.terminal_inductance_mh * 1e-3,
            kt,
            ke: 60.0 / (2.0 * PI * m.speed_constant_rpm_per_v),
            j: m.rotor_inertia_gcm2 * 1e-7 + self.load.inertia_kg_m2,
            b: m.viscous_friction_nm_s_per_rad,
            tc: kt * m.no_load_current_ma * 1e-3,
            vs: self.amplifier.supply_v,
            dead_time: self.amplifier.dead_time_ns * 1e-9,
            i_limit: self.amplifier.current_limit_a,
            counts_per_rev: 4 * self.encoder.lines,
            index: self.encoder.index,
        }
    }

    fn physical_checked(&self, origin: &str) -> Result<Physical, PlantError> {
        let bad = |field: &'static str, value: f64, fix: &'static str| PlantError::Invalid {
            origin: origin.to_string(),
            field,
            value: value.to_string(),
            fix,
        };
        let m = &self.motor;
        let positive = [
            ("motor.nominal_voltage_v", m.nominal_voltage_v),
            ("motor.terminal_resistance_ohm", m.terminal_resistance_ohm),
            ("motor.terminal_inductance_mh", m.terminal_inductance_mh),
            (
                "motor.torque_constant_mnm_per_a",
                m.torque_constant_mnm_per_a,
            ),
            ("motor.speed_constant_rpm_per_v", m.speed_constant_rpm_per_v),
            ("motor.rotor_inertia_gcm2", m.rotor_inertia_gcm2),
            ("motor.no_load_speed_rpm", m.no_load_speed_rpm),
            ("amplifier.supply_v", self.amplifier.supply_v),
            ("amplifier.current_limit_a", self.amplifier.current_limit_a),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(
                    field,
                    v,
                    "give a positive number, as the data sheet lists it",
                ));
            }
        }
        let non_negative = [
            ("motor.no_load_current_ma", m.no_load_current_ma),
            (
                "motor.viscous_friction_nm_s_per_rad",
                m.viscous_friction_nm_s_per_rad,
            ),
            ("load.inertia_kg_m2", self.load.inertia_kg_m2),
            ("amplifier.dead_time_ns", self.amplifier.dead_time_ns),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(field, v, "give a number ≥ 0"));
            }
        }
        for (field, v) in [
            ("amplifier.current_loop_hz", self.amplifier.current_loop_hz),
            (
                "amplifier.command_filter_hz",
                self.amplifier.command_filter_hz,
            ),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(field, v, "give a positive frequency in Hz"));
                }
                if self.amplifier.kind != AmplifierKind::Current {
                    return Err(bad(
                        field,
                        v,
                        "only a current-mode drive has it: set amplifier.kind = \"current\" or remove it",
                    ));
                }
            }
        }
        if self.amplifier.dead_time_ns > 10_000.0 {
            return Err(bad(
                "amplifier.dead_time_ns",
                self.amplifier.dead_time_ns,
                "a dead time is nanoseconds to a few microseconds: check the unit",
            ));
        }
        if !(1..=1 << 20).contains(&self.encoder.lines) {
            return Err(bad(
                "encoder.lines",
                f64::from(self.encoder.lines),
                "give the encoder's lines per revolution (1 to 2^20)",
            ));
        }
        // The data sheet's own consistency: the no-load speed follows from the voltage, the
        // resistance, the no-load current and the speed constant (within 5 %).
        let p = self.physical();
        let rpm =
            (m.nominal_voltage_v - p.r * m.no_load_current_ma * 1e-3) / p.ke * 60.0 / (2.0 * PI);
        if (rpm / m.no_load_speed_rpm - 1.0).abs() > 0.05 {
            return Err(bad(
                "motor.no_load_speed_rpm",
                m.no_load_speed_rpm,
                "it disagrees by more than 5 % with (nominal voltage − resistance × no-load current) × speed constant: check the speed constant and the units",
            ));
        }
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_plant_is_the_data_sheets() {
        let p = PlantParams::default_plant().physical();
        // Kt and Ke agree (SI: the same constant) within the data sheet's rounding.
        assert!((p.kt / p.ke - 1.0).abs() < 0.01, "{} {}", p.kt, p.ke);
        assert_eq!(p.counts_per_rev, 8000);
        // Loaded mechanical time constant ≈ 39 ms; the motor alone: the data sheet's 4.28 ms.
        let alone = Physical { j: 137e-7, ..p };
        assert!((alone.mechanical_time_constant() * 1e3 - 4.28).abs() < 0.05);
        assert!((p.mechanical_time_constant() * 1e3 - 39.5).abs() < 0.5);
    }

    /// Every file in plant/motors/ is a valid plant; the 24 V winding's back-EMF constant is
    /// half the 48 V winding's (the data sheets' 317 and 158 rpm/V).
    #[test]
    fn every_shipped_plant_file_reads() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/motors");
        let mut n = 0;
        for e in std::fs::read_dir(dir).unwrap() {
            let path = e.unwrap().path();
            if path.extension().is_some_and(|x| x == "toml") {
                PlantParams::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
                n += 1;
            }
        }
        assert!(n >= 3, "{n}");
        let low = PlantParams::from_file(&std::path::Path::new(dir).join("re40-148867-24v.toml"))
            .unwrap()
            .physical();
        let ratio = PlantParams::default_plant().physical().ke / low.ke;
        assert!((ratio - 2.0).abs() < 0.01, "{ratio}");
    }

    #[test]
    fn a_plant_file_written_reads_back() {
        let p = PlantParams::default_plant();
        let text = p.to_toml("identified\nby a test");
        assert!(text.starts_with("# identified\n# by a test\n"));
        assert_eq!(PlantParams::parse(&text, "written").unwrap(), p);
    }

    #[test]
    fn mistakes_are_named_with_what_to_change() {
        let bad = DEFAULT_PLANT.replace(
            "terminal_resistance_ohm = 1.13",
            "terminal_resistance_ohm = -1",
        );
        let e = PlantParams::parse(&bad, "x.toml").unwrap_err().to_string();
        assert!(
            e.contains("motor.terminal_resistance_ohm = -1: give a positive number"),
            "{e}"
        );
        let bad = DEFAULT_PLANT.replace(
            "speed_constant_rpm_per_v = 158.0",
            "speed_constant_rpm_per_v = 15.8",
        );
        let e = PlantParams::parse(&bad, "x.toml").unwrap_err().to_string();
        assert!(e.contains("no_load_speed_rpm"), "{e}");
        let bad = DEFAULT_PLANT.replace("lines = 2000", "lines = 2000\ncolour = 1");
        let e = PlantParams::parse(&bad, "x.toml").unwrap_err().to_string();
        assert!(
            e.contains("unknown field") && e.contains("docs/PLANT.md"),
            "{e}"
        );
    }
}
