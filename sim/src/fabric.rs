//! The Verilated core, loaded from the shared library that [`crate::build`] makes.

use std::ffi::{c_char, c_void, CString};
use std::path::{Path, PathBuf};

use libloading::Library;
use snapgen_model::{CoreInputs, CoreOutputs};

use crate::layout::{harness_header, pack, Port, PortValue, Slot};
use crate::SimError;

/// The core's port tables, encoders and decoders, from the spec's port list: one slot per
/// port in list order (the harness's word order), one `put` per port with a constant slot
/// (straight-line code), one field of [`CoreInputs`]/[`CoreOutputs`] per port.
macro_rules! core_layout {
    (
        clock: $cdoc:literal;
        inputs { $( $isec:ident { $( $i:ident : $ik:ident [$ib:expr] $it:ty, $idoc:literal; )* } )* }
        outputs { $( $osec:ident { $( $o:ident : $ok:ident [$ob:expr] $ot:ty, $odoc:literal; )* } )* }
    ) => {
        /// The core's inputs, in the harness's word order (the wrapper registers each of them).
        pub const CORE_INPUTS: [Port; [$($(stringify!($i)),*),*].len()] =
            [$($( Port { name: stringify!($i), bits: $ib }, )*)*];

        /// The core's outputs, in [`crate::cosim::Register`] order.
        pub const CORE_OUTPUTS: [Port; [$($(stringify!($o)),*),*].len()] =
            [$($( Port { name: stringify!($o), bits: $ob }, )*)*];

        /// Each output's raw bits in [`CoreOutputs`], by register.
        pub(crate) const OUTPUT_BITS: [fn(&CoreOutputs) -> u128; CORE_OUTPUTS.len()] =
            [$($( |o: &CoreOutputs| PortValue::to_word(o.$o), )*)*];

        /// The inputs in the harness's word layout.
        #[inline(always)]
        pub fn encode_inputs(i: &CoreInputs) -> [u32; IN_WORDS] {
            let mut w = [0u32; IN_WORDS];
            let mut k = 0;
            $($( IN_SLOTS[k].put(&mut w, PortValue::to_word(i.$i)); k += 1; )*)*
            debug_assert_eq!(k, IN_SLOTS.len());
            w
        }

        /// Encodes outputs in the harness's word layout (the inverse of [`decode`]): what the
        /// co-simulation compares the fabric's words with, on every clock.
        #[inline(always)]
        pub fn encode(o: &CoreOutputs) -> [u32; OUT_WORDS] {
            let mut w = [0u32; OUT_WORDS];
            let mut k = 0;
            $($( OUT_SLOTS[k].put(&mut w, PortValue::to_word(o.$o)); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            w
        }

        /// Decodes one clock's output words.
        pub fn decode(w: &[u32]) -> CoreOutputs {
            let mut k = 0;
            $($( let $o = PortValue::from_word(OUT_SLOTS[k].get(w), $ob); k += 1; )*)*
            debug_assert_eq!(k, OUT_SLOTS.len());
            CoreOutputs { $($( $o, )*)* }
        }
    };
}

snapgen_spec::with_motion_core_ports!(core_layout! {});

const IN_LAYOUT: ([Slot; CORE_INPUTS.len()], usize) = pack(&CORE_INPUTS);
const OUT_LAYOUT: ([Slot; CORE_OUTPUTS.len()], usize) = pack(&CORE_OUTPUTS);
/// Where each input is in the input words.
pub const IN_SLOTS: [Slot; CORE_INPUTS.len()] = IN_LAYOUT.0;
/// Where each output is in a clock's output words.
pub const OUT_SLOTS: [Slot; CORE_OUTPUTS.len()] = OUT_LAYOUT.0;
/// Input words per `set` call.
pub const IN_WORDS: usize = IN_LAYOUT.1;
/// Output words per clock.
pub const OUT_WORDS: usize = OUT_LAYOUT.1;

/// The core harness's generated header (`snapgen_layout.h`).
pub fn core_layout_header() -> String {
    harness_header(&CORE_INPUTS, &CORE_OUTPUTS)
}

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
        let words = encode_inputs(i);
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
