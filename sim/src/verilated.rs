//! The one loader of every Verilated design: a shared library built by [`crate::build`] from
//! `sim/harness/harness.cpp` and the design's generated layout, loaded, its ABI word checked
//! (the design's tag and its input and output word counts), and one instance driven through
//! the harness's C API. [`crate::fabric::Fabric`] (the motion core) and
//! [`crate::io::FabricIo`] (the I/O top) are this with their port layouts.

use std::ffi::{c_char, c_void, CString};
use std::path::{Path, PathBuf};

use libloading::Library;

use crate::SimError;

type NewFn = unsafe extern "C" fn(*const c_char, u64, u64) -> *mut c_void;
type FreeFn = unsafe extern "C" fn(*mut c_void);
type SetFn = unsafe extern "C" fn(*mut c_void, *const u32);
type RunFn = unsafe extern "C" fn(*mut c_void, u64, *mut u32);
type RunEachFn = unsafe extern "C" fn(*mut c_void, u64, *const u32, *mut u32);
type AbiFn = unsafe extern "C" fn() -> u32;

/// Where to write waves, and which clocks.
#[derive(Clone, Debug)]
pub struct VcdWindow {
    /// The VCD file.
    pub path: PathBuf,
    /// First clock dumped.
    pub from: u64,
    /// Last clock dumped.
    pub to: u64,
}

/// The ABI word of a design: its tag, and its input and output word counts (what the
/// generated layout header defines as `SNAPGEN_ABI`).
pub const fn abi(tag: u32, in_words: usize, out_words: usize) -> u32 {
    (tag << 16) | ((in_words as u32) << 8) | out_words as u32
}

/// One instance of a Verilated design.
pub struct Verilated {
    handle: *mut c_void,
    free: FreeFn,
    set: SetFn,
    run: RunFn,
    run_each: RunEachFn,
    in_words: usize,
    out_words: usize,
    // Declared last: dropped after the instance is freed.
    _lib: Library,
}

// The instance is only ever used from the thread that owns it.
unsafe impl Send for Verilated {}

impl Verilated {
    /// Loads `library` and creates one instance of its design, whose ABI word must be
    /// [`abi`]`(tag, in_words, out_words)`; with `vcd`, the library must be a trace build.
    pub fn open(
        library: &Path,
        vcd: Option<&VcdWindow>,
        tag: u32,
        in_words: usize,
        out_words: usize,
    ) -> Result<Self, SimError> {
        let err = |reason: String| SimError::Load {
            path: library.to_path_buf(),
            reason,
        };
        // SAFETY: the library is one that `build` made from our own harness; its symbols have
        // the types declared above, and its layout is the caller's (checked through the ABI
        // word before anything else is called).
        unsafe {
            let lib = Library::new(library).map_err(|e| err(e.to_string()))?;
            let got: AbiFn = *lib
                .get::<AbiFn>(b"snapgen_sim_abi\0")
                .map_err(|e| err(e.to_string()))?;
            let want = abi(tag, in_words, out_words);
            if got() != want {
                return Err(err(format!("harness ABI {:#x}, expected {want:#x}", got())));
            }
            let new: NewFn = *lib
                .get(b"snapgen_sim_new\0")
                .map_err(|e| err(e.to_string()))?;
            let free: FreeFn = *lib
                .get(b"snapgen_sim_free\0")
                .map_err(|e| err(e.to_string()))?;
            let set: SetFn = *lib
                .get(b"snapgen_sim_set\0")
                .map_err(|e| err(e.to_string()))?;
            let run: RunFn = *lib
                .get(b"snapgen_sim_run\0")
                .map_err(|e| err(e.to_string()))?;
            let run_each: RunEachFn = *lib
                .get(b"snapgen_sim_run_each\0")
                .map_err(|e| err(e.to_string()))?;
            let (path, from, to) = match vcd {
                Some(w) => (
                    CString::new(w.path.to_string_lossy().as_bytes())
                        .map_err(|_| err("VCD path contains a NUL byte".into()))?,
                    w.from,
                    w.to,
                ),
                None => (CString::default(), 0, 0),
            };
            let handle = new(path.as_ptr(), from, to);
            Ok(Verilated {
                handle,
                free,
                set,
                run,
                run_each,
                in_words,
                out_words,
                _lib: lib,
            })
        }
    }

    /// Applies inputs (`in_words` words), held until the next call.
    pub fn set(&mut self, words: &[u32]) {
        assert_eq!(words.len(), self.in_words, "a clock's input words");
        // SAFETY: `handle` is a live instance; `words` has the design's input words.
        unsafe { (self.set)(self.handle, words.as_ptr()) }
    }

    /// Runs `n` clocks with the inputs held; `out` receives `n` clocks of output words.
    pub fn run(&mut self, n: usize, out: &mut Vec<u32>) {
        out.resize(n * self.out_words, 0);
        // SAFETY: `out` holds room for n clocks of the design's output words.
        unsafe { (self.run)(self.handle, n as u64, out.as_mut_ptr()) }
    }

    /// Runs one clock per `in_words` words of `ins`; `out` receives each clock's outputs.
    pub fn run_each(&mut self, ins: &[u32], out: &mut Vec<u32>) {
        assert_eq!(ins.len() % self.in_words, 0, "whole clocks of inputs");
        let n = ins.len() / self.in_words;
        out.resize(n * self.out_words, 0);
        // SAFETY: `ins` holds n clocks of input words, `out` room for n clocks of outputs.
        unsafe { (self.run_each)(self.handle, n as u64, ins.as_ptr(), out.as_mut_ptr()) }
    }
}

impl Drop for Verilated {
    fn drop(&mut self) {
        // SAFETY: `handle` came from `snapgen_sim_new` and is freed once.
        unsafe { (self.free)(self.handle) }
    }
}
