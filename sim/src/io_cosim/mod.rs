//! Lockstep co-simulation of the Verilated I/O top against the device model
//! (`snapgen_model::device::Device`), clock by clock: both get the same pins on every clock and
//! every output — `uart_tx`, PWM, direction, amplifier enable, the LEDs and every field of the
//! status block — is compared after every rising edge.
//!
//! The pins come from a host, an encoder and switches ([`snapgen_model::peer::Peer`]) driven
//! by a random command stream: commands of every kind with good and bad arguments, back to
//! back and in bursts past the reply queue, retries with the same and with another payload,
//! bit errors, frames cut short, over-long lengths, noise, line breaks, real moves uploaded and
//! started, stops and halts at random ticks (mid-jerk, mid-acceleration), limit switches,
//! the emergency stop, watchdog expiry, telemetry at short periods and configuration changes.
//! The peer reacts to the model's outputs (which must equal the fabric's on every clock), so
//! the stream is computed a batch ahead and the fabric then runs the batch.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use snapgen_host::protocol::{code, ErrorId, Reason};
use snapgen_model::device::{Design, Device};
use snapgen_model::peer::Peer;
use snapgen_model::timing::Dividers;
use snapgen_model::DEFAULT_FORMAT;

use crate::build::build_io;
use crate::fabric::VcdWindow;
use crate::io::{encode_inputs, encode_outputs, FabricIo, IoSignal, IN_WORDS, OUT_WORDS};
use crate::SimError;

pub(crate) mod stream;

use stream::Stream;

/// Clocks per batch: the stream and the model run a batch ahead, then the fabric runs it.
const BATCH: usize = 1 << 10;

/// The design the co-simulation uses: a 1 MHz clock, 8 clocks per UART bit (125 000 baud), a
/// tick every 16 clocks, a 2 ms frame timeout — small numbers, so that a million clocks hold
/// hundreds of frames, moves and stops. (The stop unit decides a stopping tick in more clocks
/// than 16, so stopping ticks wait for it here, which is exercised too.)
pub fn cosim_design() -> Design {
    let d = Design {
        format: DEFAULT_FORMAT,
        dividers: Dividers {
            uart_divisor: 8,
            tick_div: 15,
            frame_timeout: 2000,
            heartbeat_bit: 10,
            clocks_per_ms: 1000,
        },
        clock_hz: 1_000_000,
        baud: 125_000,
        design_hash: 0,
        // Limit+ and the emergency stop normally closed: the reset value is exercised.
        input_polarity: 5,
    };
    snapgen_hdl::verilog::io_design(&d)
}

/// A deliberate error in the captured fabric outputs, to prove the comparison fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IoFault {
    /// Clock at which to flip.
    pub clock: u64,
    /// Signal to flip.
    pub signal: IoSignal,
    /// Bit (modulo its width).
    pub bit: u32,
}

/// The first difference between fabric and model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IoMismatch {
    /// Session that found it.
    pub session: usize,
    /// Clock (rising edges since power-up, from 0).
    pub clock: u64,
    /// Signal that differs.
    pub signal: IoSignal,
    /// Model's value.
    pub expected: u128,
    /// Fabric's value.
    pub actual: u128,
}

impl std::fmt::Display for IoMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "first I/O mismatch in session {} at clock {}: {} expected {:#x} got {:#x}",
            self.session,
            self.clock,
            self.signal.name(),
            self.expected,
            self.actual
        )
    }
}

/// Settings of an I/O co-simulation.
#[derive(Clone, Debug)]
pub struct IoCosimConfig {
    /// Clocks per session.
    pub clocks: u64,
    /// Seed of session 0 (the others derive theirs from it).
    pub seed: u64,
    /// Sessions (each its own I/O top, model and stream), run on one thread per core.
    pub sessions: usize,
    /// A deliberate fault (tests); it goes to session 0.
    pub fault: Option<IoFault>,
    /// Where to write the waves around a mismatch.
    pub mismatch_vcd: PathBuf,
}

impl IoCosimConfig {
    /// `clocks` clocks in each of `sessions` sessions from `seed`.
    pub fn new(clocks: u64, seed: u64, sessions: usize) -> Self {
        IoCosimConfig {
            clocks,
            seed,
            sessions: sessions.max(1),
            fault: None,
            mismatch_vcd: PathBuf::from("io-mismatch.vcd"),
        }
    }

    fn session_seed(&self, s: usize) -> u64 {
        if s == 0 {
            self.seed
        } else {
            self.seed ^ (s as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        }
    }
}

/// What the streams did (counted from what the host received and the status it saw), so a
/// test can check that every path was exercised.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IoCosimReport {
    /// Clocks compared.
    pub clocks: u64,
    /// Frames the host sent whole and well-formed.
    pub frames_sent: u64,
    /// Frames sent with a bit error, cut short, with an over-long length, or noise bursts.
    pub damaged_sent: u64,
    /// Replies and telemetry frames the host received, by code (ACK, NAK, …).
    pub replies: Vec<(u8, u64)>,
    /// NAKs by reason byte.
    pub naks: Vec<(u8, u64)>,
    /// NAKs of a command for a reason the refusal table (`protocol::REFUSALS`,
    /// docs/PROTOCOL.md) does not list for it: (command, reason).
    pub undocumented: Vec<(u8, u8)>,
    /// Moves uploaded and started (START acknowledged).
    pub moves_started: u64,
    /// Program swaps armed (SWAP_AT acknowledged).
    pub swaps_armed: u64,
    /// Clocks with a swap armed.
    pub swap_pending_clocks: u64,
    /// Armed swaps cancelled by a stop, a fault or the emergency stop (SWAP_PENDING fell with
    /// the axis stopping or in ErrorStop: the standby bank is emptied).
    pub swaps_cancelled: u64,
    /// SWAP_AT frames sent with their tick at the edge of the lateness check (1 tick below
    /// it, on it or above it), timed so that the time base ticks just before the check.
    pub swaps_aimed: u64,
    /// STOP and HALT commands acknowledged.
    pub stops_acked: u64,
    /// Clocks with a controlled stop running.
    pub stopping_clocks: u64,
    /// Entries into ErrorStop, by error identifier byte.
    pub errors: Vec<(u8, u64)>,
    /// Clocks with the reply-overflow flag set.
    pub overflow_clocks: u64,
    /// Seconds of wall time.
    pub seconds: f64,
    /// The first mismatch.
    pub mismatch: Option<IoMismatch>,
    /// Waves written around it.
    pub vcd: Option<PathBuf>,
}

impl IoCosimReport {
    pub(crate) fn bump(list: &mut Vec<(u8, u64)>, key: u8) {
        match list.iter_mut().find(|(k, _)| *k == key) {
            Some((_, n)) => *n += 1,
            None => {
                list.push((key, 1));
                list.sort_unstable();
            }
        }
    }

    /// How many of `key` in `list`.
    pub fn count(list: &[(u8, u64)], key: u8) -> u64 {
        list.iter().find(|(k, _)| *k == key).map_or(0, |(_, n)| *n)
    }

    fn merge(&mut self, o: &IoCosimReport) {
        self.clocks += o.clocks;
        self.frames_sent += o.frames_sent;
        self.damaged_sent += o.damaged_sent;
        self.moves_started += o.moves_started;
        self.swaps_armed += o.swaps_armed;
        self.swap_pending_clocks += o.swap_pending_clocks;
        self.swaps_cancelled += o.swaps_cancelled;
        self.swaps_aimed += o.swaps_aimed;
        self.stops_acked += o.stops_acked;
        self.stopping_clocks += o.stopping_clocks;
        self.overflow_clocks += o.overflow_clocks;
        for (dst, src) in [
            (&mut self.replies, &o.replies),
            (&mut self.naks, &o.naks),
            (&mut self.errors, &o.errors),
        ] {
            for &(k, n) in src {
                for _ in 0..n {
                    Self::bump(dst, k);
                }
            }
        }
        for p in &o.undocumented {
            if !self.undocumented.contains(p) {
                self.undocumented.push(*p);
            }
        }
    }

    /// Clocks per second of wall time.
    pub fn clocks_per_second(&self) -> f64 {
        self.clocks as f64 / self.seconds.max(1e-9)
    }
}

/// One session: the stream, the model and (unless `None`) the fabric in lockstep.
fn session(
    design: &Design,
    seed: u64,
    clocks: u64,
    mut fabric: Option<FabricIo>,
    fault: Option<IoFault>,
    index: usize,
) -> IoCosimReport {
    let mut dev = Device::new(design);
    let mut peer = Peer::new(design.dividers.uart_divisor);
    peer.wiring = design.input_polarity;
    let mut stream = Stream::new(seed, *design);
    let mut ins: Vec<[u32; IN_WORDS]> = Vec::with_capacity(BATCH);
    let mut want: Vec<[u32; OUT_WORDS]> = Vec::with_capacity(BATCH);
    let mut got: Vec<u32> = Vec::new();
    let start = Instant::now();
    let mut clock = 0u64;
    while clock < clocks {
        let n = (clocks - clock).min(BATCH as u64) as usize;
        ins.clear();
        want.clear();
        for _ in 0..n {
            let i = stream.inputs(&mut peer, &dev);
            ins.push(encode_inputs(&i));
            let o = dev.clock(&i);
            stream.observe(&mut peer, &o);
            want.push(encode_outputs(&o));
        }
        if let Some(fab) = fabric.as_mut() {
            fab.run(&ins, &mut got);
            for (k, w) in want.iter().enumerate() {
                let words = &mut got[k * OUT_WORDS..(k + 1) * OUT_WORDS];
                let at = clock + k as u64;
                if let Some(fl) = fault.filter(|fl| fl.clock == at) {
                    fl.signal.flip(words, fl.bit);
                }
                if words != w {
                    let signal = IoSignal::all()
                        .find(|s| s.value(words) != s.value(w))
                        .expect("every output bit belongs to a signal (tested)");
                    stream.report.clocks = at;
                    stream.report.seconds = start.elapsed().as_secs_f64();
                    stream.report.mismatch = Some(IoMismatch {
                        session: index,
                        clock: at,
                        signal,
                        expected: signal.value(w),
                        actual: signal.value(words),
                    });
                    return stream.report;
                }
            }
        }
        clock += n as u64;
    }
    stream.report.clocks = clock;
    stream.report.seconds = start.elapsed().as_secs_f64();
    stream.report
}

/// Runs the I/O co-simulation of `design` (its I/O top's Verilog generated here): its
/// sessions on one worker thread per core; on a mismatch, the session is run again with a
/// trace build and the waves around it are written.
pub fn run(design: &Design, cfg: &IoCosimConfig) -> Result<IoCosimReport, SimError> {
    let verilog = snapgen_hdl::verilog::io_sources_text(design);
    let built = build_io(&verilog, false)?;
    let mut queue: VecDeque<(usize, FabricIo)> = VecDeque::new();
    for s in 0..cfg.sessions {
        queue.push_back((s, FabricIo::open(&built.library, None)?));
    }
    let queue = Mutex::new(queue);
    let outcomes: Mutex<Vec<Option<IoCosimReport>>> = Mutex::new(vec![None; cfg.sessions]);
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(cfg.sessions);
    let wall = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let next = queue.lock().unwrap_or_else(|e| e.into_inner()).pop_front();
                let Some((s, fab)) = next else { break };
                let fault = if s == 0 { cfg.fault } else { None };
                let r = session(design, cfg.session_seed(s), cfg.clocks, Some(fab), fault, s);
                outcomes.lock().unwrap_or_else(|e| e.into_inner())[s] = Some(r);
            });
        }
    });
    let mut report = IoCosimReport::default();
    let outcomes = outcomes.into_inner().unwrap_or_else(|e| e.into_inner());
    for r in outcomes.iter().flatten() {
        report.merge(r);
        if report.mismatch.is_none() {
            report.mismatch = r.mismatch.clone();
        }
    }
    report.seconds = wall.elapsed().as_secs_f64();
    if let (Some(fault), Some(r0)) = (cfg.fault, outcomes.first().and_then(|o| o.as_ref())) {
        if r0.mismatch.is_none() {
            return Err(SimError::FaultNotReached {
                clock: fault.clock,
                clocks: r0.clocks,
            });
        }
    }
    if let Some(m) = report.mismatch.clone() {
        let traced = build_io(&verilog, true)?;
        let w = VcdWindow {
            path: cfg.mismatch_vcd.clone(),
            from: m.clock.saturating_sub(2000),
            to: m.clock + 16,
        };
        let fab = FabricIo::open(&traced.library, Some(&w))?;
        let fault = if m.session == 0 { cfg.fault } else { None };
        let _ = session(
            design,
            cfg.session_seed(m.session),
            m.clock + 1,
            Some(fab),
            fault,
            m.session,
        );
        report.vcd = Some(cfg.mismatch_vcd.clone());
    }
    Ok(report)
}

/// The same sessions on the model alone (the reference for the speed ratio).
pub fn run_model_only(design: &Design, cfg: &IoCosimConfig) -> IoCosimReport {
    let mut report = IoCosimReport::default();
    let wall = Instant::now();
    for s in 0..cfg.sessions {
        let r = session(design, cfg.session_seed(s), cfg.clocks, None, None, s);
        report.merge(&r);
    }
    report.seconds = wall.elapsed().as_secs_f64();
    report
}

/// Names of the NAK reasons and error identifiers a report counts (for printing).
pub fn describe(r: &IoCosimReport) -> String {
    let naks: Vec<String> = r
        .naks
        .iter()
        .map(|&(k, n)| {
            format!(
                "{} {n}",
                Reason::from_byte(k).map_or("?".into(), |x| x.name().to_string())
            )
        })
        .collect();
    let errors: Vec<String> = r
        .errors
        .iter()
        .map(|&(k, n)| {
            format!(
                "{} {n}",
                ErrorId::from_byte(k).map_or("?".into(), |x| x.name().to_string())
            )
        })
        .collect();
    let count = |c: u8| IoCosimReport::count(&r.replies, c);
    format!(
        "{} clocks; sent {} frames and {} damaged ones; received {} ACK, {} NAK ({}), {} STATUS, {} STATE, {} IDENTITY, {} CONFIG, {} TELEMETRY; {} moves started, {} swaps armed ({} clocks armed, {} cancelled, {} sent at the lateness edge), {} stops acknowledged, {} clocks stopping; ErrorStop entries: {}; {} clocks with the reply overflow flag",
        r.clocks,
        r.frames_sent,
        r.damaged_sent,
        count(code::ACK),
        count(code::NAK),
        naks.join(", "),
        count(code::STATUS),
        count(code::STATE),
        count(code::IDENTITY),
        count(code::CONFIG),
        count(code::TELEMETRY),
        r.moves_started,
        r.swaps_armed,
        r.swap_pending_clocks,
        r.swaps_cancelled,
        r.swaps_aimed,
        r.stops_acked,
        r.stopping_clocks,
        if errors.is_empty() { "none".into() } else { errors.join(", ") },
        r.overflow_clocks,
    )
}
