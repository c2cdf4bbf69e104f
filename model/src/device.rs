//! The device: what a board running the snapgen core does with the protocol
//! (docs/PROTOCOL.md). It decodes frames, executes commands on the clock-accurate core model,
//! answers every frame, counts bad ones, and streams telemetry. This is the reference the
//! fabric's command interface will be compared with, and what `snapgen board --pty` serves.
//!
//! Command effects, each one core clock: LOAD_SEGMENT writes the standby bank; COMMIT sets its
//! count (and cruise segment); START (idle, with a committed program) starts it; STOP cuts the
//! cruise short (controlled stop); ABORT stops at once; CONFIGURE sets
//! the tick divider or the telemetry period (PWM period and encoder filter are recorded for the
//! fabric's blocks). The encoder input follows the reference position exactly (an ideal motor,
//! one count per output LSB) until a motor model exists.

use crate::core::{CoreInputs, CoreModel};
use crate::format::{Format, FRAC_BITS};
use crate::program::Program;
use crate::protocol::{
    code, Command, Decoded, Decoder, Frame, Param, Reason, Reply, Status, PROTOCOL_VERSION,
};

/// Settings the host can change with CONFIGURE.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceConfig {
    /// Clocks per tick − 1.
    pub tick_div: u32,
    /// Telemetry period in ticks (0: off).
    pub telemetry_period: u32,
    /// PWM period in clocks.
    pub pwm_period: u32,
    /// Encoder glitch filter in clocks.
    pub encoder_filter: u32,
}

/// The device model.
#[derive(Clone, Debug)]
pub struct Device {
    format: Format,
    core: CoreModel,
    decoder: Decoder,
    config: DeviceConfig,
    bad_crc: u16,
    bad_frames: u16,
    errors: u8,
    last: Option<(u8, u8, Vec<u8>)>,
    ticks_to_telemetry: u32,
    out: Vec<u8>,
}

impl Device {
    /// A device after reset: at rest at the centre of cell 0, nothing loaded.
    pub fn new(format: &Format, config: DeviceConfig) -> Self {
        let mut core = CoreModel::new(format);
        core.clock(&CoreInputs {
            reset: true,
            ..Default::default()
        });
        Device {
            format: *format,
            core,
            decoder: Decoder::device(),
            config,
            bad_crc: 0,
            bad_frames: 0,
            errors: 0,
            last: None,
            ticks_to_telemetry: config.telemetry_period,
            out: Vec::new(),
        }
    }

    /// The core model.
    pub fn core(&self) -> &CoreModel {
        &self.core
    }

    /// The current settings.
    pub fn config(&self) -> DeviceConfig {
        self.config
    }

    /// Bytes waiting to be sent to the host.
    pub fn take_output(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.out)
    }

    /// The status block.
    pub fn status(&self) -> Status {
        let o = self.core.outputs();
        let v_shift = self.format.widths.v - 32;
        Status {
            state: u8::from(o.busy) | u8::from(o.done) << 1 | u8::from(o.aborted) << 2,
            errors: self.errors,
            tick_count: o.tick_count,
            position: o.position as i32,
            velocity: (o.v >> v_shift) as i32,
            encoder: (o.x >> FRAC_BITS) as i32,
            bad_crc: self.bad_crc,
            bad_frames: self.bad_frames,
        }
    }

    fn send(&mut self, reply: Reply, seq: u8) -> Vec<u8> {
        let bytes = reply.to_frame(seq).to_bytes();
        self.out.extend_from_slice(&bytes);
        bytes
    }

    fn clock(&mut self, i: CoreInputs) {
        self.core.clock(&CoreInputs {
            tick_div: self.config.tick_div,
            ..i
        });
    }

    /// True while part of a frame has arrived (for an inter-byte timeout).
    pub fn mid_frame(&self) -> bool {
        !self.decoder.is_idle()
    }

    /// An inter-byte timeout: a partial frame is dropped, counted and NAKed (FRAMING).
    pub fn timeout(&mut self) {
        if self.decoder.reset() {
            self.bad_frames = self.bad_frames.wrapping_add(1);
            self.send(
                Reply::Nak {
                    cmd: 0,
                    reason: Reason::Framing,
                },
                0,
            );
        }
    }

    /// A UART framing error: the error flag is raised and a partial frame is dropped, counted
    /// and NAKed (FRAMING).
    pub fn line_error(&mut self) {
        self.errors |= 2;
        if self.decoder.reset() {
            self.bad_frames = self.bad_frames.wrapping_add(1);
            self.send(
                Reply::Nak {
                    cmd: 0,
                    reason: Reason::Framing,
                },
                0,
            );
        }
    }

    /// Bytes from the host.
    pub fn receive(&mut self, bytes: &[u8]) {
        for &b in bytes {
            match self.decoder.push(b) {
                None => {}
                Some(Decoded::BadCrc) => {
                    self.bad_crc = self.bad_crc.wrapping_add(1);
                    self.send(
                        Reply::Nak {
                            cmd: 0,
                            reason: Reason::BadCrc,
                        },
                        0,
                    );
                }
                Some(Decoded::Frame(f)) => self.execute(&f),
            }
        }
    }

    fn execute(&mut self, f: &Frame) {
        // A retry of the last command with an effect: answer again, do not execute again.
        // (Reads and pings simply run again.)
        if let Some((cmd, seq, bytes)) = &self.last {
            if *cmd == f.cmd && *seq == f.seq {
                let bytes = bytes.clone();
                self.out.extend_from_slice(&bytes);
                return;
            }
        }
        let reply = match Command::from_frame(f, &self.format) {
            Err(r) => {
                if matches!(r.reason, Reason::BadLength | Reason::UnknownCommand) {
                    self.bad_frames = self.bad_frames.wrapping_add(1);
                }
                Reply::Nak {
                    cmd: f.cmd,
                    reason: r.reason,
                }
            }
            Ok(c) => self.command(c),
        };
        let bytes = self.send(reply, f.seq);
        if matches!(
            f.cmd,
            code::LOAD_SEGMENT
                | code::COMMIT
                | code::START
                | code::STOP
                | code::ABORT
                | code::CONFIGURE
        ) {
            self.last = Some((f.cmd, f.seq, bytes));
        }
    }

    fn command(&mut self, c: Command) -> Reply {
        let ack = Reply::Ack { cmd: c.code() };
        match c {
            Command::Ping => Reply::Version {
                protocol: PROTOCOL_VERSION,
                max_segments: self.format.max_segments as u8,
                snap_bytes: Program::snap_bytes(&self.format) as u8,
            },
            Command::LoadSegment { index, segment } => {
                self.clock(CoreInputs {
                    write_enable: true,
                    write_address: index,
                    write_ticks: segment.ticks,
                    write_snap: segment.snap,
                    ..Default::default()
                });
                ack
            }
            Command::Commit { count, cruise } => {
                self.clock(CoreInputs {
                    count_enable: true,
                    count_value: count,
                    cruise_value: cruise.unwrap_or(0xFF) & 0x3f,
                    ..Default::default()
                });
                ack
            }
            Command::Start => {
                if self.core.busy() {
                    Reply::Nak {
                        cmd: code::START,
                        reason: Reason::Busy,
                    }
                } else if self.core.standby_count() == 0 {
                    Reply::Nak {
                        cmd: code::START,
                        reason: Reason::NoProgram,
                    }
                } else {
                    self.clock(CoreInputs {
                        start: true,
                        ..Default::default()
                    });
                    ack
                }
            }
            Command::Stop => {
                self.clock(CoreInputs {
                    soft_stop: true,
                    ..Default::default()
                });
                ack
            }
            Command::Abort => {
                self.clock(CoreInputs {
                    stop: true,
                    ..Default::default()
                });
                ack
            }
            Command::ReadStatus => Reply::Status(self.status()),
            Command::ReadPosition => Reply::Position {
                x: self.core.chain().x,
            },
            Command::Configure { param, value } => {
                match param {
                    Param::TickDivider => self.config.tick_div = value,
                    Param::PwmPeriod => self.config.pwm_period = value,
                    Param::EncoderFilter => self.config.encoder_filter = value,
                    Param::TelemetryPeriod => {
                        self.config.telemetry_period = value;
                        self.ticks_to_telemetry = value;
                    }
                }
                ack
            }
        }
    }

    /// Runs `clocks` fabric clocks. While a move runs, a telemetry frame goes out every
    /// `telemetry_period` ticks, and one more when it ends; an idle device stays quiet.
    pub fn run(&mut self, clocks: u64) {
        for _ in 0..clocks {
            let before = self.core.outputs();
            self.clock(CoreInputs::default());
            if self.config.telemetry_period == 0 {
                continue;
            }
            if before.tick && before.busy {
                self.ticks_to_telemetry = self.ticks_to_telemetry.saturating_sub(1);
                if self.ticks_to_telemetry == 0 || !self.core.busy() {
                    self.ticks_to_telemetry = self.config.telemetry_period;
                    let s = self.status();
                    self.send(Reply::Telemetry(s), 0);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;
    use crate::planner::{plan, Method, MoveRequest};
    use crate::protocol::Decoded;

    fn replies(d: &mut Device) -> Vec<Reply> {
        let mut dec = Decoder::new();
        d.take_output()
            .into_iter()
            .filter_map(|b| match dec.push(b) {
                Some(Decoded::Frame(f)) => Reply::from_frame(&f),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn a_move_uploads_runs_and_lands_exactly() {
        let f = DEFAULT_FORMAT;
        let mut d = Device::new(&f, DeviceConfig::default());
        let p = plan(
            &MoveRequest {
                distance: -0.01,
                method: Method::Order3 {
                    vmax: 1.0,
                    amax: 10.0,
                    jmax: 1000.0,
                },
            },
            &f,
        )
        .unwrap();
        let mut seq = 0u8;
        let mut send = |d: &mut Device, c: Command| {
            seq += 1;
            d.receive(&c.to_frame(seq, &f).to_bytes());
            replies(d)
        };
        assert_eq!(
            send(&mut d, Command::Start),
            vec![Reply::Nak {
                cmd: code::START,
                reason: Reason::NoProgram
            }]
        );
        for (k, s) in p.program.segments.iter().enumerate() {
            let r = send(
                &mut d,
                Command::LoadSegment {
                    index: k as u8,
                    segment: *s,
                },
            );
            assert_eq!(
                r,
                vec![Reply::Ack {
                    cmd: code::LOAD_SEGMENT
                }]
            );
        }
        let n = p.program.segments.len() as u8;
        assert_eq!(
            send(
                &mut d,
                Command::Commit {
                    count: n,
                    cruise: None
                }
            ),
            vec![Reply::Ack { cmd: code::COMMIT }]
        );
        assert_eq!(
            send(&mut d, Command::Start),
            vec![Reply::Ack { cmd: code::START }]
        );
        // A retried START (same sequence number) is answered, not executed again.
        d.receive(&Command::Start.to_frame(seq, &f).to_bytes());
        assert_eq!(replies(&mut d), vec![Reply::Ack { cmd: code::START }]);
        d.run(p.ticks_total() + 5);
        assert_eq!(d.core().chain(), p.final_state);
        let st = d.status();
        assert_eq!(st.state & 3, 2, "done, not busy");
        assert_eq!(i64::from(st.position), -10_000);
    }

    #[test]
    fn bad_frames_are_counted_and_nakked_without_effect() {
        let f = DEFAULT_FORMAT;
        let mut d = Device::new(&f, DeviceConfig::default());
        let before = d.core().chain();
        let mut bytes = Command::Abort.to_frame(1, &f).to_bytes();
        bytes[3] ^= 0x10;
        d.receive(&bytes);
        d.receive(
            &Frame {
                cmd: 0x55,
                seq: 2,
                payload: vec![],
            }
            .to_bytes(),
        );
        d.receive(
            &Frame {
                cmd: code::START,
                seq: 3,
                payload: vec![9],
            }
            .to_bytes(),
        );
        assert_eq!(
            replies(&mut d),
            vec![
                Reply::Nak {
                    cmd: 0,
                    reason: Reason::BadCrc
                },
                Reply::Nak {
                    cmd: 0x55,
                    reason: Reason::UnknownCommand
                },
                Reply::Nak {
                    cmd: code::START,
                    reason: Reason::BadLength
                },
            ]
        );
        let st = d.status();
        assert_eq!((st.bad_crc, st.bad_frames), (1, 2));
        assert_eq!(d.core().chain(), before);
        assert!(!d.core().outputs().aborted);
    }
}
