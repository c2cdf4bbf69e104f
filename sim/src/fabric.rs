//! The Verilated core, loaded from the shared library that [`crate::build`] makes.

use std::ffi::{c_char, c_void, CString};
use std::path::{Path, PathBuf};

use libloading::Library;
use snapgen_hdl::{
    ADDR_BITS, A_BITS, D_BITS, INDEX_BITS, J_BITS, POSITION_BITS, TICK_BITS, V_BITS, X_BITS,
};
use snapgen_model::chain::wrap;
use snapgen_model::{CoreInputs, CoreOutputs, Format};

use crate::layout::{harness_header, pack, Port, Slot};
use crate::SimError;

/// The core's inputs, in the harness's word order (the wrapper registers each of them).
pub const CORE_INPUTS: [Port; 17] = [
    Port {
        name: "reset",
        bits: 1,
    },
    Port {
        name: "tick_div",
        bits: TICK_BITS as u32,
    },
    Port {
        name: "start",
        bits: 1,
    },
    Port {
        name: "abort_move",
        bits: 1,
    },
    Port {
        name: "stop",
        bits: 1,
    },
    Port {
        name: "load",
        bits: 1,
    },
    Port {
        name: "load_position",
        bits: POSITION_BITS as u32,
    },
    Port {
        name: "stop_jerk",
        bits: D_BITS as u32,
    },
    Port {
        name: "stop_accel",
        bits: D_BITS as u32,
    },
    Port {
        name: "write_enable",
        bits: 1,
    },
    Port {
        name: "write_address",
        bits: ADDR_BITS as u32,
    },
    Port {
        name: "write_ticks",
        bits: TICK_BITS as u32,
    },
    Port {
        name: "write_snap",
        bits: D_BITS as u32,
    },
    Port {
        name: "count_enable",
        bits: 1,
    },
    Port {
        name: "count_value",
        bits: INDEX_BITS as u32,
    },
    Port {
        name: "swap",
        bits: 1,
    },
    Port {
        name: "swap_last",
        bits: 32,
    },
];

/// The core's outputs, in [`crate::cosim::Register`] order.
pub const CORE_OUTPUTS: [Port; 20] = [
    Port {
        name: "x",
        bits: X_BITS as u32,
    },
    Port {
        name: "v",
        bits: V_BITS as u32,
    },
    Port {
        name: "a",
        bits: A_BITS as u32,
    },
    Port {
        name: "j",
        bits: J_BITS as u32,
    },
    Port {
        name: "position",
        bits: POSITION_BITS as u32,
    },
    Port {
        name: "segment",
        bits: INDEX_BITS as u32,
    },
    Port {
        name: "busy",
        bits: 1,
    },
    Port {
        name: "done",
        bits: 1,
    },
    Port {
        name: "aborted",
        bits: 1,
    },
    Port {
        name: "stopping",
        bits: 1,
    },
    Port {
        name: "stop_over",
        bits: 1,
    },
    Port {
        name: "tick",
        bits: 1,
    },
    Port {
        name: "heading_pos",
        bits: 1,
    },
    Port {
        name: "heading_neg",
        bits: 1,
    },
    Port {
        name: "at_rest",
        bits: 1,
    },
    Port {
        name: "active_bank",
        bits: 1,
    },
    Port {
        name: "standby_count",
        bits: INDEX_BITS as u32,
    },
    Port {
        name: "tick_count",
        bits: TICK_BITS as u32,
    },
    Port {
        name: "ticks",
        bits: 64,
    },
    Port {
        name: "swap_pending",
        bits: 1,
    },
];

const IN_LAYOUT: ([Slot; 17], usize) = pack(&CORE_INPUTS);
const OUT_LAYOUT: ([Slot; 20], usize) = pack(&CORE_OUTPUTS);
/// Where each input is in the input words.
pub const IN_SLOTS: [Slot; 17] = IN_LAYOUT.0;
/// Where each output is in a clock's output words.
pub const OUT_SLOTS: [Slot; 20] = OUT_LAYOUT.0;
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

/// The inputs in the harness's word layout.
pub fn encode_inputs(i: &CoreInputs) -> [u32; IN_WORDS] {
    let mut w = [0u32; IN_WORDS];
    let values: [u128; 17] = [
        u128::from(i.reset),
        u128::from(i.tick_div),
        u128::from(i.start),
        u128::from(i.abort),
        u128::from(i.stop),
        u128::from(i.load),
        u128::from(i.load_position),
        i.stop_limits.jerk as u128,
        i.stop_limits.accel as u128,
        u128::from(i.write_enable),
        u128::from(i.write_address),
        u128::from(i.write_ticks),
        i.write_snap as u128,
        u128::from(i.count_enable),
        u128::from(i.count_value),
        u128::from(i.swap),
        u128::from(i.swap_last),
    ];
    for (slot, v) in IN_SLOTS.iter().zip(values) {
        slot.put(&mut w, v);
    }
    w
}

/// Encodes outputs in the harness's word layout (the inverse of [`decode`]): what the
/// co-simulation compares the fabric's words with, on every clock.
///
/// One `put` per register, each with a constant register: every slot, shift and mask then
/// folds into straight-line code (a loop over the registers did not, and cost three times the
/// Verilated core's own clock). Every register is written (checked by a test).
#[inline(always)]
pub fn encode(o: &CoreOutputs, f: &Format) -> [u32; OUT_WORDS] {
    use crate::cosim::Register as R;
    let mut w = [0u32; OUT_WORDS];
    macro_rules! put {
        ($($r:expr),* $(,)?) => {
            $(OUT_SLOTS[$r as usize].put(&mut w, $r.bits_of(o, f));)*
            const _: () = assert!([$($r as usize),*].len() == R::ALL.len());
        };
    }
    put!(
        R::X,
        R::V,
        R::A,
        R::J,
        R::Position,
        R::Segment,
        R::Busy,
        R::Done,
        R::Aborted,
        R::Stopping,
        R::StopOver,
        R::Tick,
        R::HeadingPos,
        R::HeadingNeg,
        R::AtRest,
        R::ActiveBank,
        R::StandbyCount,
        R::TickCount,
        R::Ticks,
        R::SwapPending,
    );
    w
}

/// Decodes one clock's output words.
pub fn decode(w: &[u32], f: &Format) -> CoreOutputs {
    use crate::cosim::Register as R;
    let get = |r: R| OUT_SLOTS[r as usize].get(w);
    let wide = |r: R, bits: u32| wrap(get(r) as i128, bits);
    let flag = |r: R| get(r) == 1;
    CoreOutputs {
        x: wide(R::X, f.widths.x),
        v: wide(R::V, f.widths.v),
        a: wide(R::A, f.widths.a),
        j: wide(R::J, f.widths.j),
        position: get(R::Position) as u32,
        segment: get(R::Segment) as u8,
        busy: flag(R::Busy),
        done: flag(R::Done),
        aborted: flag(R::Aborted),
        stopping: flag(R::Stopping),
        stop_over: flag(R::StopOver),
        tick: flag(R::Tick),
        heading: i8::from(flag(R::HeadingPos)) - i8::from(flag(R::HeadingNeg)),
        at_rest: flag(R::AtRest),
        active_bank: flag(R::ActiveBank),
        standby_count: get(R::StandbyCount) as u8,
        tick_count: get(R::TickCount) as u32,
        ticks: get(R::Ticks) as u64,
        swap_pending: flag(R::SwapPending),
    }
}
