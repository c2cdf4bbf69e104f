//! The co-simulation's random host on the AXI side: command frames of every kind (good, bad,
//! damaged) written byte by byte to COMMAND, moves planned and uploaded, started or swapped
//! in, replies read back from REPLY and decoded, snapshots taken and read, the interrupt's
//! registers enabled, read and cleared, reads and writes anywhere in (and past) the map, the
//! emergency stop and the limit switches pressed; the motor's encoder follows the reference
//! ([`Peer`], whose UART stays idle).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_host::protocol::{code, Command, Decoded, Decoder, Param, Reply};
use snapgen_model::device::Design;
use snapgen_model::io::axi::AxiDevice;
use snapgen_model::peer::Peer;
use snapgen_model::ports::{AxiInputs, AxiOutputs};
use snapgen_model::Format;
use snapgen_plan::plan_from;
use snapgen_spec::axi::{offset_of, IRQ_ALL, REPLY_VALID, RESP_OKAY, SPAN};

use super::master::{AxiMaster, Done};
use super::AxiCosimReport;
use crate::io_cosim::stream::{random_command, random_move, stop_limits};
use crate::moves::log_uniform;

/// The host.
pub(super) struct Host {
    rng: StdRng,
    design: Design,
    pub(super) master: AxiMaster,
    peer: Peer,
    decoder: Decoder,
    seq: u8,
    /// Clocks before the next action.
    wait: u64,
    /// Clocks since the start.
    now: u64,
    /// When the switches go back to rest.
    release: Option<u64>,
    pub(super) report: AxiCosimReport,
}

impl Host {
    pub(super) fn new(seed: u64, design: Design) -> Self {
        let mut rng = StdRng::seed_from_u64(seed);
        let mut master = AxiMaster::new();
        master.ready_odds = rng.gen_range(0.2..=1.0);
        master.max_wait = rng.gen_range(0..=4);
        let mut peer = Peer::new(design.dividers.uart_divisor);
        peer.follow = true;
        peer.reset_clocks = 6;
        peer.wiring = design.input_polarity;
        Host {
            rng,
            design,
            master,
            peer,
            decoder: Decoder::new(),
            seq: 0,
            wait: 10,
            now: 0,
            release: None,
            report: AxiCosimReport::default(),
        }
    }

    fn send(&mut self, c: Command) {
        self.seq = self.seq.wrapping_add(1).max(1);
        let bytes = c.to_frame(self.seq, &self.design.format).to_bytes();
        self.bytes(&bytes);
        self.report.frames_sent += 1;
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            // The unused lanes carry noise; lane 0 is strobed (now and then not: the byte is
            // not taken, and the frame is damaged).
            let noise = self.rng.gen::<u32>() & !0xFF;
            let lane0 = u8::from(!self.rng.gen_bool(0.002));
            let strb = lane0 | (self.rng.gen_range(0..16) & !1);
            self.master
                .write(offset_of("COMMAND"), noise | u32::from(b), strb);
        }
    }

    /// A move from where the model stands, uploaded, then started or swapped in.
    fn upload_move(&mut self, dev: &AxiDevice) {
        let f = Format::with_ts(1e-3);
        let req = random_move(&mut self.rng);
        let chain = dev.station().core().chain();
        let Ok(plan) = plan_from(&req, &f, chain) else {
            return;
        };
        if plan.ticks_total() > 3000 || plan.program.segments.is_empty() {
            return;
        }
        for (k, s) in plan.program.segments.iter().enumerate() {
            self.send(Command::LoadSegment {
                index: k as u8,
                segment: *s,
            });
        }
        let count = plan.program.segments.len() as u8;
        self.send(Command::Commit { count });
        if self.rng.gen_bool(0.3) {
            // At a tick around when the upload will be in: what is queued, at about 12 clocks
            // a write, times 0.3 to 3 (the early ones are refused: LATE).
            let per_tick = u64::from(dev.station().executor_outputs().config.tick_divider) + 1;
            let queued = self.master.writes_pending() as f64 + 20.0;
            let lead = (queued * 12.0 * self.rng.gen_range(0.3..3.0)) as u64 / per_tick.max(1);
            let tick = dev.station().core().outputs().ticks + lead;
            self.send(Command::SwapAt { tick });
        } else {
            self.send(Command::Start);
        }
        self.report.moves_sent += 1;
    }

    /// The next action.
    fn act(&mut self, dev: &AxiDevice) {
        let r = &mut self.rng;
        match r.gen_range(0..100) {
            0..=29 => {
                let ticks = dev.station().core().outputs().ticks;
                let c = random_command(r, &self.design.format, ticks);
                self.send(c);
            }
            30..=44 => {
                let (jerk, accel) = stop_limits(r);
                self.send(Command::Configure {
                    param: Param::StopJerk,
                    value: jerk,
                });
                self.send(Command::Configure {
                    param: Param::StopAccel,
                    value: accel,
                });
                self.send(Command::Power { on: true });
                self.upload_move(dev);
            }
            45..=54 => {
                self.master.write(offset_of("SNAPSHOT"), 0, 0);
                let words = (offset_of("J") + 16 - offset_of("STATUS")) / 4;
                for k in 0..words {
                    self.master.read(offset_of("STATUS") + 4 * k);
                }
                self.report.snapshots += 1;
            }
            55..=64 => {
                let enable = self.rng.gen_range(0..=IRQ_ALL);
                self.master
                    .write(offset_of("IRQ_ENABLE"), enable, self.rng.gen_range(0..16));
                self.master.read(offset_of("IRQ_STATUS"));
                let clear = self.rng.gen::<u32>();
                self.master
                    .write(offset_of("IRQ_STATUS"), clear, self.rng.gen_range(0..16));
                self.master.read(offset_of("IRQ_ENABLE"));
            }
            65..=76 => {
                // Anywhere, in the map and past it, any lanes.
                let addr = self.rng.gen_range(0..=255u32);
                if self.rng.gen_bool(0.7) {
                    self.master.read(addr);
                } else if addr / 4 != offset_of("COMMAND") / 4 {
                    let (data, strb) = (self.rng.gen(), self.rng.gen_range(0..16));
                    self.master.write(addr, data, strb);
                }
            }
            77..=84 => {
                // A damaged frame: a byte changed, or noise.
                let c = random_command(&mut self.rng, &self.design.format, 0);
                let mut bytes = c.to_frame(1, &self.design.format).to_bytes();
                let k = self.rng.gen_range(0..bytes.len());
                bytes[k] ^= 1 << self.rng.gen_range(0..8);
                if self.rng.gen_bool(0.3) {
                    bytes.truncate(k);
                }
                self.bytes(&bytes);
            }
            85..=88 => {
                match self.rng.gen_range(0..3) {
                    0 => self.peer.emergency_stop = true,
                    1 => self.peer.limit_positive = true,
                    _ => self.peer.limit_negative = true,
                }
                self.release = Some(self.now + self.rng.gen_range(5..300));
            }
            89..=91 => self.send(Command::Reset),
            // The reset pin, with transactions in flight: the slave forgets them.
            92 => self.peer.reset_clocks = self.rng.gen_range(1..4),
            _ => {
                let value = [15, 7, 40][self.rng.gen_range(0..3)];
                self.send(Command::Configure {
                    param: Param::TickDivider,
                    value,
                });
            }
        }
        self.wait = log_uniform(&mut self.rng, 1.0, 3000.0) as u64;
    }

    /// The inputs for the next clock; `o` the outputs as they stand.
    pub(super) fn inputs(&mut self, dev: &AxiDevice) -> AxiInputs {
        self.now += 1;
        if self.release.is_some_and(|t| t <= self.now) {
            self.release = None;
            self.peer.emergency_stop = false;
            self.peer.limit_positive = false;
            self.peer.limit_negative = false;
        }
        let pins = self.peer.inputs();
        if pins.reset {
            // A reset ends every transaction, queued or in flight, and any frame half read.
            self.master.abort();
            self.decoder = Decoder::new();
            self.report.resets += 1;
        }
        if !pins.reset {
            if self.now < 20 {
                // First a short tick, so that moves take few clocks.
            } else if self.now == 20 {
                self.send(Command::Configure {
                    param: Param::TickDivider,
                    value: 15,
                });
            } else if self.wait > 0 {
                self.wait -= 1;
            } else if self.master.writes_pending() < 4 {
                self.act(dev);
            }
            // Replies are read back whenever the read channel is free.
            if self.master.reads_pending() == 0 && self.rng.gen_bool(0.5) {
                self.master.read(offset_of("REPLY"));
            }
        }
        let mut i = crate::axi::with_pins(&pins, AxiInputs::default());
        if !pins.reset {
            self.master.drive(&mut self.rng, &mut i);
        }
        i
    }

    /// After the edge: `i` the inputs, `before` and `after` the outputs around it.
    pub(super) fn observe(&mut self, i: &AxiInputs, before: &AxiOutputs, after: &AxiOutputs) {
        self.master.after_edge(i, before);
        self.peer.observe_status(&after.status);
        while let Some(d) = self.master.done.pop_front() {
            match d {
                Done::Write { resp, .. } => {
                    self.report.writes += 1;
                    self.report.slave_errors += u64::from(resp != RESP_OKAY);
                }
                Done::Read { addr, data, resp } => {
                    self.report.reads += 1;
                    self.report.slave_errors += u64::from(resp != RESP_OKAY);
                    let a = u32::from(addr) & !3;
                    if a >= SPAN && resp == RESP_OKAY {
                        self.report
                            .violation
                            .get_or_insert(format!("a read past the map ({a:#x}) answered OKAY"));
                    }
                    if a == offset_of("IRQ_STATUS") {
                        self.report.irq_seen |= data;
                    }
                    if a == offset_of("REPLY") && data & REPLY_VALID != 0 {
                        self.reply_byte(data as u8);
                    }
                }
            }
        }
        if after.irq {
            self.report.irq_clocks += 1;
        }
        let error_stop = snapgen_spec::AxisState::ErrorStop as u8;
        if after.status.state == error_stop && before.status.state != error_stop {
            crate::io_cosim::IoCosimReport::bump(&mut self.report.errors, after.status.error);
        }
    }

    fn reply_byte(&mut self, b: u8) {
        self.report.reply_bytes += 1;
        if let Some(Decoded::Frame(f)) = self.decoder.push(b) {
            self.report.replies += 1;
            if let Some(Reply::Nak { reason, .. }) = Reply::from_frame(&f) {
                crate::io_cosim::IoCosimReport::bump(&mut self.report.naks, reason as u8);
            }
            if let Some(Reply::Ack { cmd }) = Reply::from_frame(&f) {
                if cmd == code::START {
                    self.report.starts_acked += 1;
                }
                if cmd == code::SWAP_AT {
                    self.report.swaps_armed += 1;
                }
            }
        }
    }
}
