//! The Verilated core, loaded from the shared library that [`crate::build`] makes.

use std::ffi::{c_char, c_void, CString};
use std::path::{Path, PathBuf};

use libloading::Library;
use snapgen_model::chain::wrap;
use snapgen_model::{CoreInputs, CoreOutputs, Format};

use crate::SimError;

/// Input words per `set` call (must match the harness).
pub const IN_WORDS: usize = 15;
/// Output words per clock (must match the harness).
pub const OUT_WORDS: usize = 19;

type NewFn = unsafe extern "C" fn(*const c_char, u64, u64) -> *mut c_void;
type FreeFn = unsafe extern "C" fn(*mut c_void);
type SetFn = unsafe extern "C" fn(*mut c_void, *const u32);
type RunFn = unsafe extern "C" fn(*mut c_void, u64, *mut u32);
type AbiFn = unsafe extern "C" fn() -> u32;

/// One instance of the Verilated core.
pub struct Fabric {
    handle: *mut c_void,
    free: FreeFn,
    set: SetFn,
    run: RunFn,
    // Declared last: dropped after the instance is freed.
    _lib: Library,
}

// The instance is only ever used from the thread that owns the `Fabric`.
unsafe impl Send for Fabric {}

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

impl Fabric {
    /// Loads `library` and creates one core; with `vcd`, the library must be a trace build.
    pub fn open(library: &Path, vcd: Option<&VcdWindow>) -> Result<Self, SimError> {
        let load_err = |reason: String| SimError::Load {
            path: library.to_path_buf(),
            reason,
        };
        // SAFETY: the library is one that `build` made from our own harness; its symbols have
        // the types declared above (checked through `snapgen_core_abi`).
        unsafe {
            let lib = Library::new(library).map_err(|e| load_err(e.to_string()))?;
            let abi: AbiFn = *lib
                .get::<AbiFn>(b"snapgen_core_abi\0")
                .map_err(|e| load_err(e.to_string()))?;
            let want = ((IN_WORDS as u32) << 8) | OUT_WORDS as u32;
            if abi() != want {
                return Err(load_err(format!(
                    "harness ABI {:#x}, expected {want:#x}",
                    abi()
                )));
            }
            let new: NewFn = *lib
                .get::<NewFn>(b"snapgen_core_new\0")
                .map_err(|e| load_err(e.to_string()))?;
            let free: FreeFn = *lib
                .get::<FreeFn>(b"snapgen_core_free\0")
                .map_err(|e| load_err(e.to_string()))?;
            let set: SetFn = *lib
                .get::<SetFn>(b"snapgen_core_set\0")
                .map_err(|e| load_err(e.to_string()))?;
            let run: RunFn = *lib
                .get::<RunFn>(b"snapgen_core_run\0")
                .map_err(|e| load_err(e.to_string()))?;
            let (path, from, to) = match vcd {
                Some(w) => (
                    CString::new(w.path.to_string_lossy().as_bytes())
                        .map_err(|_| load_err("VCD path contains a NUL byte".into()))?,
                    w.from,
                    w.to,
                ),
                None => (CString::default(), 0, 0),
            };
            let handle = new(path.as_ptr(), from, to);
            Ok(Fabric {
                handle,
                free,
                set,
                run,
                _lib: lib,
            })
        }
    }

    /// Applies inputs (held until the next call).
    pub fn set(&mut self, i: &CoreInputs) {
        let snap = i.write_snap as u128;
        let words: [u32; IN_WORDS] = [
            u32::from(i.reset),
            i.tick_div,
            u32::from(i.start),
            u32::from(i.stop),
            u32::from(i.write_enable),
            u32::from(i.write_address),
            i.write_ticks,
            snap as u32,
            (snap >> 32) as u32,
            (snap >> 64) as u32,
            (snap >> 96) as u32,
            u32::from(i.count_enable),
            u32::from(i.count_value),
            u32::from(i.cruise_value),
            u32::from(i.soft_stop),
        ];
        // SAFETY: `handle` is a live instance; `words` has IN_WORDS words.
        unsafe { (self.set)(self.handle, words.as_ptr()) }
    }

    /// Runs `n` clocks; `out` receives `n * OUT_WORDS` words.
    pub fn run(&mut self, n: usize, out: &mut Vec<u32>) {
        out.resize(n * OUT_WORDS, 0);
        // SAFETY: `out` holds room for n clocks of OUT_WORDS words.
        unsafe { (self.run)(self.handle, n as u64, out.as_mut_ptr()) }
    }
}

impl Drop for Fabric {
    fn drop(&mut self) {
        // SAFETY: `handle` came from `snapgen_core_new` and is freed once.
        unsafe { (self.free)(self.handle) }
    }
}

/// Encodes outputs in the harness's word layout (the inverse of [`decode`]). The co-simulation
/// compares the fabric's words against the model without building this array (its
/// `differs`, tested against this function).
#[inline]
pub fn encode(o: &CoreOutputs, f: &Format) -> [u32; OUT_WORDS] {
    let mut w = [0u32; OUT_WORDS];
    let mut wide = |k: usize, v: i128, bits: u32| {
        let u = (v as u128) & (u128::MAX >> (128 - bits));
        w[k] = u as u32;
        w[k + 1] = (u >> 32) as u32;
        w[k + 2] = (u >> 64) as u32;
        w[k + 3] = (u >> 96) as u32;
    };
    wide(0, o.x, f.widths.x);
    wide(4, o.v, f.widths.v);
    wide(8, o.a, f.widths.a);
    wide(12, o.j, f.widths.j);
    w[16] = o.position;
    w[17] = u32::from(o.segment)
        | u32::from(o.busy) << 8
        | u32::from(o.done) << 9
        | u32::from(o.aborted) << 10
        | u32::from(o.tick) << 11
        | u32::from(o.active_bank) << 12
        | u32::from(o.standby_count) << 16;
    w[18] = o.tick_count;
    w
}

/// Decodes one clock's output words.
#[inline]
pub fn decode(w: &[u32], f: &Format) -> CoreOutputs {
    let wide = |k: usize, bits: u32| {
        let u = u128::from(w[k])
            | (u128::from(w[k + 1]) << 32)
            | (u128::from(w[k + 2]) << 64)
            | (u128::from(w[k + 3]) << 96);
        wrap(u as i128, bits)
    };
    let flags = w[17];
    CoreOutputs {
        x: wide(0, f.widths.x),
        v: wide(4, f.widths.v),
        a: wide(8, f.widths.a),
        j: wide(12, f.widths.j),
        position: w[16],
        segment: (flags & 0xff) as u8,
        busy: flags >> 8 & 1 == 1,
        done: flags >> 9 & 1 == 1,
        aborted: flags >> 10 & 1 == 1,
        tick: flags >> 11 & 1 == 1,
        active_bank: flags >> 12 & 1 == 1,
        standby_count: (flags >> 16 & 0x3f) as u8,
        tick_count: w[18],
    }
}
