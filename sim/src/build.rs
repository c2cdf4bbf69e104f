//! Builds the Verilated core into a shared library, through the Verilator CLI:
//!
//! ```text
//! verilator --cc --exe --build -O3 -Wall --x-assign fast --x-initial fast --noassert
//!           --top-module top top.v harness.cpp
//!           -CFLAGS "-fPIC -march=native -fno-semantic-interposition -DSNAPGEN_TRACE=0|1"
//!           -MAKEFLAGS "OPT_FAST=-O3 OPT_SLOW=-O1 OPT_GLOBAL=-O3"   (Opt::Speed; -O0 for
//!                                                                 Opt::BuildTime)
//!           -LDFLAGS "-shared -Wl,-Bsymbolic" -o libsnapgen_core.so
//! ```
//!
//! The C++ optimisation level must go through `OPT_FAST`/`OPT_GLOBAL`: Verilator's makefile
//! appends its default `-Os` after `-CFLAGS`, so an `-O3` there is silently overridden (measured:
//! 80 ns per clock at `-Os`, 38 ns at `-O3`). `-fno-semantic-interposition` and `-Bsymbolic` let
//! the compiler inline and call Verilator's runtime helpers directly instead of through the PLT
//! of the shared library. `-march=native` builds for this CPU, so the CPU's identity (its
//! `/proc/cpuinfo` model and flags) is part of the cache key: a cache directory shared with
//! another machine never hands it a library its CPU cannot run.
//!
//! Builds are cached in `$SNAPGEN_CACHE_DIR` (default `$XDG_CACHE_HOME/snapgen` or
//! `~/.cache/snapgen`) under a hash of the Verilog (its lint waivers and scheduling hints are
//! written into it, see `snapgen_hdl::verilog`), the harness, the Verilator
//! version, these flags, the CPU and the trace flag: an unchanged design never rebuilds.
//! `-Wall` makes every lint warning that the Verilog does not waive fatal, so a build is also a
//! lint check.
//! `$SNAPGEN_VERILATOR` overrides the `verilator` binary.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::SimError;

/// The harness source of every build (the motion core's and the I/O top's).
pub const HARNESS_CPP: &str = include_str!("../harness/harness.cpp");

/// C++ flags of every build (see the module documentation).
const CFLAGS: &str = "-fPIC -march=native -fno-semantic-interposition";
/// Link flags: a shared library whose internal calls bind locally.
const LDFLAGS: &str = "-shared -Wl,-Bsymbolic";

/// What a build is optimised for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opt {
    /// The simulation's speed (`-O3`): every library that runs long streams.
    Speed,
    /// The build's time (`-O0`): a library that runs a short stream once, such as a
    /// deliberately altered design in a test that the co-simulation must find. Half the
    /// build (measured: 7.8 s against 3.8 s for the interpolator, 12.7 s against 6.9 s for
    /// the path core).
    BuildTime,
}

impl Opt {
    /// Verilator's makefile variables: the optimisation levels it would otherwise set to
    /// `-Os`.
    fn makeflags(self) -> &'static str {
        match self {
            Opt::Speed => "OPT_FAST=-O3 OPT_SLOW=-O1 OPT_GLOBAL=-O3",
            Opt::BuildTime => "OPT_FAST=-O0 OPT_SLOW=-O0 OPT_GLOBAL=-O0",
        }
    }
}

/// The Verilator binary to use.
pub fn verilator_bin() -> String {
    std::env::var("SNAPGEN_VERILATOR").unwrap_or_else(|_| "verilator".into())
}

fn missing_verilator() -> SimError {
    SimError::ToolMissing {
        tool: "verilator",
        hint:
            "install it (Debian/Ubuntu: apt-get install verilator) or point SNAPGEN_VERILATOR at it",
    }
}

/// `verilator --version`, or a typed error if it is not installed.
pub fn verilator_version() -> Result<String, SimError> {
    let out = Command::new(verilator_bin())
        .arg("--version")
        .output()
        .map_err(|_| missing_verilator())?;
    if !out.status.success() {
        return Err(missing_verilator());
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The cache root.
pub fn cache_root() -> PathBuf {
    if let Ok(d) = std::env::var("SNAPGEN_CACHE_DIR") {
        return PathBuf::from(d);
    }
    if let Ok(d) = std::env::var("XDG_CACHE_HOME") {
        return PathBuf::from(d).join("snapgen");
    }
    if let Ok(h) = std::env::var("HOME") {
        return PathBuf::from(h).join(".cache").join("snapgen");
    }
    std::env::temp_dir().join("snapgen")
}

/// What `-march=native` compiles for: the first `model name` and `flags` lines of
/// `/proc/cpuinfo` (empty where there is no such file).
fn host_cpu() -> String {
    let info = fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let first = |key: &str| {
        info.lines()
            .find(|l| l.split(':').next().is_some_and(|k| k.trim() == key))
            .unwrap_or("")
            .to_string()
    };
    format!("{}\n{}", first("model name"), first("flags"))
}

/// FNV-1a, 64 bit: a stable content hash for the cache key.
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for &b in *p {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h ^= 0xff;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn io<'p>(what: &'static str, path: &'p Path) -> impl FnOnce(std::io::Error) -> SimError + 'p {
    move |source| SimError::Io {
        what,
        path: path.to_path_buf(),
        source,
    }
}

/// A built co-simulation library.
#[derive(Clone, Debug)]
pub struct Built {
    /// The shared library.
    pub library: PathBuf,
    /// True if it was already in the cache.
    pub cached: bool,
}

/// Builds (or finds in the cache) the co-simulation library for the core `verilog` (wrapped by
/// [`crate::wrapper::cosim_top`]), with VCD tracing if `trace`.
pub fn build(core_verilog: &str, trace: bool) -> Result<Built, SimError> {
    let verilog = crate::wrapper::cosim_top(core_verilog);
    let layout = crate::fabric::core_layout_header();
    build_with(
        "core",
        "top",
        &verilog,
        HARNESS_CPP,
        &layout,
        trace,
        Opt::Speed,
    )
}

/// Builds (or finds in the cache) the library of the I/O top `io_verilog` (the virtual board
/// and the I/O co-simulation), with VCD tracing if `trace`.
pub fn build_io(io_verilog: &str, trace: bool) -> Result<Built, SimError> {
    build_with(
        "io",
        snapgen_hdl::verilog::IO_PREFIX,
        io_verilog,
        HARNESS_CPP,
        &crate::io::io_layout_header(),
        trace,
        Opt::Speed,
    )
}

/// Builds (or finds in the cache) the library of the AXI4-Lite design `verilog` (every source
/// of it: the generator's, or a deliberately altered copy; [`crate::axi`]), with VCD tracing
/// if `trace`.
pub fn build_axi(verilog: &str, trace: bool) -> Result<Built, SimError> {
    build_with(
        "axi",
        snapgen_hdl::axi_top::AXI_PREFIX,
        verilog,
        HARNESS_CPP,
        &crate::axi::axi_layout_header(),
        trace,
        Opt::Speed,
    )
}

/// Builds (or finds in the cache) the library of the path interpolator for `axes` axes
/// ([`crate::interp`]), with VCD tracing if `trace`.
pub fn build_interpolator(axes: u8, trace: bool) -> Result<Built, SimError> {
    build_interpolator_from(
        &snapgen_hdl::interpolator::interpolator_verilog(axes),
        trace,
        Opt::Speed,
    )
}

/// Builds the interpolator's library from the Verilog `verilog` (the generator's, or a
/// deliberately altered copy: the tests show that the co-simulation finds an altered line),
/// optimised for `opt`.
pub fn build_interpolator_from(verilog: &str, trace: bool, opt: Opt) -> Result<Built, SimError> {
    build_with(
        "interp",
        snapgen_hdl::interpolator::INTERPOLATOR_PREFIX,
        verilog,
        HARNESS_CPP,
        &crate::interp::interp_layout_header(),
        trace,
        opt,
    )
}

/// Builds (or finds in the cache) the library of the path sequencer for `axes` axes
/// ([`crate::path_seq`]), with VCD tracing if `trace`.
pub fn build_path_sequencer(axes: u8, trace: bool) -> Result<Built, SimError> {
    build_path_sequencer_from(
        &snapgen_hdl::path_sequencer::path_sequencer_verilog(axes),
        trace,
        Opt::Speed,
    )
}

/// Builds the path sequencer's library from the Verilog `verilog` (the generator's, or a
/// deliberately altered copy), optimised for `opt`.
pub fn build_path_sequencer_from(verilog: &str, trace: bool, opt: Opt) -> Result<Built, SimError> {
    build_with(
        "path-seq",
        snapgen_hdl::path_sequencer::PATH_SEQUENCER_PREFIX,
        verilog,
        HARNESS_CPP,
        &crate::path_seq::path_seq_layout_header(),
        trace,
        opt,
    )
}

/// Builds (or finds in the cache) the library of the path steppers for `axes` axes
/// ([`crate::path_steppers`]: the stage's file and the three blocks' it instantiates).
pub fn build_path_steppers(axes: u8, trace: bool) -> Result<Built, SimError> {
    build_path_steppers_from(
        &snapgen_hdl::path_steppers::path_steppers_sources_text(axes),
        trace,
        Opt::Speed,
    )
}

/// Builds the path steppers' library from the Verilog `verilog` (every source of the stage:
/// the generator's, or a deliberately altered copy), optimised for `opt`.
pub fn build_path_steppers_from(verilog: &str, trace: bool, opt: Opt) -> Result<Built, SimError> {
    build_with(
        "path-steppers",
        snapgen_hdl::path_steppers::PATH_STEPPERS_PREFIX,
        verilog,
        HARNESS_CPP,
        &crate::path_steppers::path_steppers_layout_header(),
        trace,
        opt,
    )
}

/// Builds (or finds in the cache) the library of the path core for `axes` axes
/// ([`crate::path_core`]: its file, the motion core's and the path steppers' four).
pub fn build_path_core(axes: u8, trace: bool) -> Result<Built, SimError> {
    build_path_core_from(
        &snapgen_hdl::path_core::path_core_sources_text(axes),
        trace,
        Opt::Speed,
    )
}

/// Builds the path core's library from the Verilog `verilog` (every source of it: the
/// generator's, or a deliberately altered copy), optimised for `opt`.
pub fn build_path_core_from(verilog: &str, trace: bool, opt: Opt) -> Result<Built, SimError> {
    build_with(
        "path-core",
        snapgen_hdl::path_core::PATH_CORE_PREFIX,
        verilog,
        HARNESS_CPP,
        &crate::path_core::path_core_layout_header(),
        trace,
        opt,
    )
}

/// Builds (or finds in the cache) the library of the step/dir generator ([`crate::step_dir`]),
/// with VCD tracing if `trace`.
pub fn build_step_dir(trace: bool) -> Result<Built, SimError> {
    build_with(
        "step-dir",
        snapgen_hdl::step_dir::STEP_DIR_PREFIX,
        &snapgen_hdl::step_dir::step_dir_verilog(),
        HARNESS_CPP,
        &crate::step_dir::step_dir_layout_header(),
        trace,
        Opt::Speed,
    )
}

/// Builds `verilog` (top module `top_module`, written to `TOP_MODULE.v`) with `harness` and its
/// generated word layout `layout` (`snapgen_layout.h`); the C++ class is `Vtop` whatever the
/// top module is called.
fn build_with(
    tag: &str,
    top_module: &str,
    verilog: &str,
    harness: &str,
    layout: &str,
    trace: bool,
    opt: Opt,
) -> Result<Built, SimError> {
    let version = verilator_version()?;
    let key = fnv1a(&[
        top_module.as_bytes(),
        verilog.as_bytes(),
        harness.as_bytes(),
        layout.as_bytes(),
        version.as_bytes(),
        CFLAGS.as_bytes(),
        host_cpu().as_bytes(),
        opt.makeflags().as_bytes(),
        LDFLAGS.as_bytes(),
        &[u8::from(trace)],
    ]);
    let root = cache_root();
    let dir = root.join(format!(
        "{tag}-{key:016x}{}",
        if trace { "-trace" } else { "" }
    ));
    let library = dir.join("libsnapgen_core.so");
    if library.exists() {
        return Ok(Built {
            library,
            cached: true,
        });
    }
    // Build in a private directory, then rename it into place: concurrent builds of the same
    // design (parallel tests) never see a half-written library.
    let tmp = root.join(format!(
        "build-{key:016x}-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    fs::create_dir_all(&tmp).map_err(io("cannot create", &tmp))?;
    let write = |name: &str, text: &str| {
        let p = tmp.join(name);
        fs::write(&p, text).map_err(io("cannot write", &p))
    };
    let file = format!("{top_module}.v");
    write(&file, verilog)?;
    write("harness.cpp", harness)?;
    write("snapgen_layout.h", layout)?;
    let log = tmp.join("build.log");
    let mut cmd = Command::new(verilator_bin());
    cmd.current_dir(&tmp)
        .args(["--cc", "--exe", "--build", "-j", "2", "-O3", "-Wall"])
        .args(["--x-assign", "fast", "--x-initial", "fast", "--noassert"])
        .args([
            "--top-module",
            top_module,
            "--prefix",
            "Vtop",
            "--Mdir",
            "obj",
        ])
        .args([
            "-CFLAGS",
            &format!("{CFLAGS} -DSNAPGEN_TRACE={}", u8::from(trace)),
        ])
        .args(["-MAKEFLAGS", opt.makeflags()])
        .args(["-LDFLAGS", LDFLAGS, "-o", "libsnapgen_core.so"]);
    if trace {
        cmd.arg("--trace");
    }
    cmd.args([file.as_str(), "harness.cpp"]);
    let out = cmd.output().map_err(|_| missing_verilator())?;
    let mut text = out.stdout.clone();
    text.extend_from_slice(&out.stderr);
    fs::write(&log, &text).map_err(io("cannot write", &log))?;
    if !out.status.success() {
        return Err(SimError::ToolFailed {
            tool: "verilator",
            code: out.status.code(),
            log,
        });
    }
    let built = tmp.join("obj").join("libsnapgen_core.so");
    fs::rename(&built, tmp.join("libsnapgen_core.so")).map_err(io("cannot move", &built))?;
    // Keep the sources and the log beside the library; drop the object files.
    let _ = fs::remove_dir_all(tmp.join("obj"));
    if fs::rename(&tmp, &dir).is_err() {
        // Another build of the same design won the race; use it.
        let _ = fs::remove_dir_all(&tmp);
        if !library.exists() {
            return Err(SimError::Io {
                what: "cannot install the build into",
                path: dir,
                source: std::io::Error::other("rename failed"),
            });
        }
    }
    Ok(Built {
        library,
        cached: false,
    })
}
