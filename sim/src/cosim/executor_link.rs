//! The host's [`Link`] to the lockstep core through the board's own command executor: the
//! model's [`Executor`] and [`FrameRx`] are clocked beside the core, every clock, and drive its
//! command and configuration inputs as they do on a board, so the host code a stream plays
//! (`snapgen_host::online::play`: PING, stop limits, POWER, then the driver's uploads, counts
//! and SWAP_ATs) reaches the Verilated core through the executor's checks and rules, not
//! through a re-implementation of them.
//!
//! What is left out is the UART: a command's bytes take their wire time at the stream's baud
//! rate (idle clocks, the executor still clocked), the last of it spent entering the frame
//! receiver one byte a clock; its reply is read from the model's live values on the clock the executor queues it
//! ([`Live::reply`], the reply transmitter's own encoding) and decoded by the host's codec,
//! then its wire time passes too. No byte is lost or corrupted here, so the retry policy is
//! not exercised (the virtual board's link does that, `crate::host_link`).
//!
//! Timing is the board's: the executor's edge on clock `c` sees the core's outputs before
//! that clock and its new outputs are the core's inputs of clock `c` — the core takes them
//! on the edge after, as the device's core takes the executor's registered outputs.

use snapgen_host::link::{command_name, Link, LinkError};
use snapgen_host::protocol::{Command, Frame, Reply, Status};
use snapgen_model::device::Design;
use snapgen_model::io::executor::{Executor, ExecutorInputs, ReplyDesc, ReplyKind};
use snapgen_model::io::frame_rx::{FrameRx, FrameRxInputs};
use snapgen_model::io::reply_tx::{status, Live, StatusInputs};
use snapgen_model::io::servo::ServoOutputs;
use snapgen_model::timing::Dividers;
use snapgen_model::{CoreInputs, CoreModel, CoreOutputs, Format};
use snapgen_spec::StateReply;

use super::lockstep::Lockstep;
use super::Mismatch;

/// Clocks the executor has to queue a reply once a frame is in (it answers on the clock
/// after the frame; more is a fault of the link).
const REPLY_CLOCKS: u32 = 64;

/// The board around the core: frame receiver and executor, and the bytes on their way in.
struct Board {
    exec: Executor,
    rx: FrameRx,
    /// Bytes arriving, one a clock.
    incoming: std::collections::VecDeque<u8>,
    /// The executor's reply pulse, kept until read.
    reply: Option<ReplyDesc>,
    /// A telemetry pulse was seen.
    telemetry: bool,
    /// A reset is applied on the next clock.
    reset: bool,
    /// The encoder count the reference loads on POWER 1.
    encoder: u32,
}

impl Board {
    /// One clock of the board from the core's outputs before it: the core's inputs of the
    /// clock.
    fn clock(&mut self, core: &CoreOutputs) -> CoreInputs {
        let reset = std::mem::take(&mut self.reset);
        let byte = if reset {
            None
        } else {
            self.incoming.pop_front()
        };
        let exec_in = ExecutorInputs {
            reset,
            rx: self.rx.outputs(),
            core: core.status(),
            ..Default::default()
        };
        self.rx.clock(&FrameRxInputs {
            reset,
            data: byte.unwrap_or(0),
            valid: byte.is_some(),
            line_error: false,
            timeout: u32::MAX,
        });
        let out = self.exec.clock(&exec_in);
        if out.reply.is_some() {
            self.reply = out.reply;
        }
        self.telemetry |= out.telemetry;
        let mut i = CoreInputs {
            tick_div: out.config.tick_divider,
            stop_jerk: out.config.stop_jerk,
            stop_accel: out.config.stop_accel,
            load_position: self.encoder,
            ..Default::default()
        };
        i.set_command(&out.command);
        i
    }
}

/// The core a board's executor drives, in lockstep with its model: the motion core
/// ([`Lockstep`]) or a design around it (the path core's, `crate::path_board::PathCoreBoard`).
pub trait CoreSide {
    /// A lockstep's first difference.
    type Mismatch: std::fmt::Display;
    /// `n` clocks, each with the core's inputs that `source` gives from the core model's
    /// outputs before it, compared.
    fn run(
        &mut self,
        n: u64,
        source: &mut dyn FnMut(&CoreOutputs) -> CoreInputs,
    ) -> Result<(), Self::Mismatch>;
    /// The core's model.
    fn core(&self) -> &CoreModel;
    /// Clocks run.
    fn clocks(&self) -> u64;
}

impl CoreSide for Lockstep {
    type Mismatch = Mismatch;

    fn run(
        &mut self,
        n: u64,
        source: &mut dyn FnMut(&CoreOutputs) -> CoreInputs,
    ) -> Result<(), Mismatch> {
        Lockstep::run(self, n, source)
    }

    fn core(&self) -> &CoreModel {
        &self.side.model
    }

    fn clocks(&self) -> u64 {
        self.clock
    }
}

/// A link to the lockstep core through the board's executor (module documentation).
pub struct ExecutorLink<'l, S: CoreSide = Lockstep> {
    ls: &'l mut S,
    board: Board,
    design: Design,
    /// The format commands are encoded with (set after PING).
    format: Format,
    seq: u8,
    /// Seconds one byte takes on the wire: 10 bits at the baud rate, or one clock when that
    /// is shorter (the board's receiver takes a byte a clock; a stream's slow clocks meet a
    /// fast baud rate).
    byte_time: f64,
    /// Wire time not yet passed on the core (clocks, a fraction of one).
    owed: f64,
    /// The first mismatch: every request fails after it.
    mismatch: Option<S::Mismatch>,
    telemetry: std::collections::VecDeque<Status>,
}

impl<'l, S: CoreSide> ExecutorLink<'l, S> {
    /// A link at `baud` to a board whose core is `ls`, ticking every `tick_div + 1` clocks of
    /// `ts` each and planning in `format`: the executor reset (its configuration at the
    /// design's defaults, the axis Disabled), the encoder reading the cell the core stands
    /// in (POWER 1 loads the reference where it is).
    pub fn new(ls: &'l mut S, format: &Format, tick_div: u32, baud: f64) -> Self {
        let clock_hz = (f64::from(tick_div) + 1.0) / format.ts;
        let design = Design {
            format: *format,
            dividers: Dividers {
                // The UART is not modelled: its wire time is `byte_time`.
                uart_divisor: 0,
                tick_div,
                frame_timeout: u32::MAX,
                heartbeat_bit: 0,
                clocks_per_ms: (clock_hz / 1000.0).round().max(1.0) as u32,
            },
            clock_hz: clock_hz.round() as u32,
            baud: baud as u32,
            design_hash: 0,
            input_polarity: 0,
        };
        let encoder = (ls.core().chain().x >> snapgen_model::FRAC_BITS) as u32;
        let d = design.dividers;
        ExecutorLink {
            ls,
            board: Board {
                exec: Executor::new(d.tick_div, d.clocks_per_ms, 0),
                rx: FrameRx::new(),
                incoming: Default::default(),
                reply: None,
                telemetry: false,
                reset: true,
                encoder,
            },
            design,
            format: *format,
            seq: 0,
            byte_time: (10.0 / baud).max(1.0 / f64::from(design.clock_hz)),
            owed: 0.0,
            mismatch: None,
            telemetry: std::collections::VecDeque::new(),
        }
    }

    /// The lockstep (for what the stream does after the link).
    pub fn lockstep(&mut self) -> &mut S {
        self.ls
    }

    /// The executor's outputs now.
    pub fn executor_outputs(&self) -> snapgen_model::io::executor::ExecutorOutputs {
        self.board.exec.outputs()
    }

    /// The first mismatch the link met, taken.
    pub fn take_mismatch(&mut self) -> Option<S::Mismatch> {
        self.mismatch.take()
    }

    /// `n` clocks of board and core, compared.
    fn clocks(&mut self, n: u64) {
        if n == 0 || self.mismatch.is_some() {
            return;
        }
        let board = &mut self.board;
        if let Err(m) = self.ls.run(n, &mut |o| board.clock(o)) {
            self.mismatch = Some(m);
        }
        if std::mem::take(&mut self.board.telemetry) {
            if self.telemetry.len() == snapgen_host::link::TELEMETRY_KEPT {
                self.telemetry.pop_front();
            }
            let status = self.live().status;
            self.telemetry.push_back(status);
        }
    }

    /// Lets `seconds` pass on the board.
    fn pass(&mut self, seconds: f64) {
        self.owed += seconds * f64::from(self.design.clock_hz);
        let whole = self.owed.floor();
        self.owed -= whole;
        self.clocks(whole as u64);
    }

    /// The values a reply is read from, now.
    fn live(&self) -> Live {
        let exec = self.board.exec.outputs();
        let core = self.ls.core().outputs();
        Live {
            status: status(&StatusInputs {
                exec: &exec,
                core: &core,
                v_bits: self.design.format.widths.v,
                encoder: i64::from(self.board.encoder as i32),
                encoder_error: false,
                limit_pos: false,
                limit_neg: false,
                estop: false,
                servo: &ServoOutputs::default(),
            }),
            state: StateReply {
                ticks: core.ticks,
                x: core.x,
                v: core.v,
                a: core.a,
                j: core.j,
            },
            config: exec.config,
            identity: self.design.identity(),
        }
    }

    fn failed(&self) -> Result<(), LinkError> {
        match &self.mismatch {
            Some(m) => Err(LinkError::Io(format!(
                "the fabric and the model differ: {m}"
            ))),
            None => Ok(()),
        }
    }
}

impl<S: CoreSide> Link for ExecutorLink<'_, S> {
    fn ask(&mut self, c: &Command) -> Result<Reply, LinkError> {
        self.failed()?;
        self.seq = self.seq.wrapping_add(1).max(1);
        let bytes = c.to_frame(self.seq, &self.format).to_bytes();
        // The frame's wire time, its bytes entering the receiver one a clock at its end (the
        // receiver takes no more than one a clock: `byte_time` is at least a clock).
        let n = bytes.len() as u64;
        self.pass(n as f64 * self.byte_time - n as f64 / f64::from(self.design.clock_hz));
        self.board.reply = None;
        self.board.incoming.extend(bytes);
        self.clocks(n);
        let mut waited = 0;
        while self.board.reply.is_none() && waited < REPLY_CLOCKS {
            self.clocks(1);
            self.failed()?;
            waited += 1;
        }
        self.failed()?;
        let Some(desc) = self.board.reply.take() else {
            return Err(LinkError::Timeout {
                command: command_name(c),
                tries: 1,
                timeout_ms: 0,
            });
        };
        let (code, payload) = self.live().reply(&desc);
        let frame = Frame {
            cmd: code,
            seq: desc.seq,
            payload,
        };
        let reply_bytes = frame.to_bytes().len();
        let reply = Reply::from_frame(&frame)
            .ok_or_else(|| LinkError::Io(format!("undecodable reply {frame:?}")))?;
        if desc.seq != self.seq || matches!(desc.kind, ReplyKind::Telemetry) {
            return Err(LinkError::Io(format!(
                "{} answered with sequence {} (sent {})",
                command_name(c),
                desc.seq,
                self.seq
            )));
        }
        self.pass(reply_bytes as f64 * self.byte_time);
        self.failed()?;
        Ok(reply)
    }

    fn set_format(&mut self, format: &Format) {
        self.format = *format;
    }

    fn take_telemetry(&mut self) -> Option<Status> {
        let last = self.telemetry.pop_back();
        self.telemetry.clear();
        last
    }

    fn drain_telemetry(&mut self) -> Vec<Status> {
        self.telemetry.drain(..).collect()
    }

    fn now(&self) -> f64 {
        (self.ls.clocks() as f64 + self.owed) / f64::from(self.design.clock_hz)
    }

    fn wait(&mut self, seconds: f64) {
        self.pass(seconds);
    }

    fn byte_time(&self) -> f64 {
        self.byte_time
    }
}
