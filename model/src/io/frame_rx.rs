//! The fabric's frame receiver (`snapgen_hdl::frame_rx::FrameRx`), clock by clock: hunts for
//! the start byte, takes a length above [`DEVICE_MAX_PAYLOAD`] as noise (a start byte there
//! starts a new frame), checks the CRC-16 over length, command, sequence and payload, and pulses
//! `frame` or `bad_crc` one clock after the last CRC byte, with the command, sequence, length,
//! the payload (byte `k` of `n` at bits `8(n−1−k)..`) and the received CRC. A frame cut short
//! by an inter-byte gap of `timeout` clocks, or by a UART framing error, is dropped with a
//! `dropped` pulse. At the byte level it decodes as [`crate::protocol::Decoder::device`].

use crate::protocol::{crc16_step, CRC_INIT, DEVICE_MAX_PAYLOAD, START};

/// The receiver's states.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum State {
    #[default]
    Hunt,
    Len,
    Cmd,
    Seq,
    Payload,
    CrcLow,
    CrcHigh,
}

/// Inputs of one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameRxInputs {
    /// Synchronous reset.
    pub reset: bool,
    /// Byte.
    pub data: u8,
    /// `data` is valid this clock.
    pub valid: bool,
    /// UART framing error this clock.
    pub line_error: bool,
    /// Inter-byte timeout in clocks.
    pub timeout: u32,
}

/// Outputs after a clock edge (all registered).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameRxOutputs {
    /// Pulse: a frame with a good CRC.
    pub frame: bool,
    /// Pulse: a frame with a bad CRC.
    pub bad_crc: bool,
    /// Pulse: a partial frame was dropped.
    pub dropped: bool,
    /// Command of the last frame.
    pub cmd: u8,
    /// Sequence number of the last frame.
    pub seq: u8,
    /// Payload length of the last frame.
    pub len: u8,
    /// The last payload bytes, the last one in bits 7:0 (256 bits).
    pub payload: [u8; 32],
    /// The CRC the last frame carried (its low byte first on the wire).
    pub crc: u16,
}

impl FrameRxOutputs {
    /// Payload byte `k` of the last frame (which had `len` bytes); 0 past its end.
    pub fn byte(&self, k: usize) -> u8 {
        let n = usize::from(self.len);
        // payload[0] is bits 7:0: the last byte received.
        if k < n {
            self.payload[n - 1 - k]
        } else {
            0
        }
    }

    /// Little-endian field of `bytes` bytes at payload byte `at`, as u128.
    pub fn field(&self, at: usize, bytes: usize) -> u128 {
        (0..bytes).fold(0u128, |acc, i| {
            acc | (u128::from(self.byte(at + i)) << (8 * i))
        })
    }
}

/// The receiver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameRx {
    state: State,
    crc: u16,
    crc_lo: u8,
    left: u8,
    idle: u32,
    out: FrameRxOutputs,
}

impl FrameRx {
    /// A receiver hunting for a start byte.
    pub fn new() -> Self {
        Self::default()
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> FrameRxOutputs {
        self.out
    }

    /// True while part of a frame has been received.
    pub fn mid_frame(&self) -> bool {
        self.state != State::Hunt
    }

    /// One clock.
    pub fn clock(&mut self, i: &FrameRxInputs) -> FrameRxOutputs {
        let o = &mut self.out;
        o.frame = false;
        o.bad_crc = false;
        o.dropped = false;
        if i.valid && self.state == State::Payload && !i.reset {
            o.payload.copy_within(0..31, 1);
            o.payload[0] = i.data;
        }
        if i.reset {
            self.state = State::Hunt;
            self.idle = 0;
        } else if i.line_error {
            if self.state != State::Hunt {
                o.dropped = true;
            }
            self.state = State::Hunt;
            self.idle = 0;
        } else if i.valid {
            self.idle = 0;
            let b = i.data;
            match self.state {
                State::Hunt => {
                    if b == START {
                        self.state = State::Len;
                        self.crc = CRC_INIT;
                    }
                }
                State::Len => {
                    if usize::from(b) > DEVICE_MAX_PAYLOAD {
                        // Not a frame: a start byte here starts one.
                        if b != START {
                            self.state = State::Hunt;
                        }
                        self.crc = CRC_INIT;
                    } else {
                        o.len = b;
                        self.crc = crc16_step(self.crc, b);
                        self.state = State::Cmd;
                    }
                }
                State::Cmd => {
                    o.cmd = b;
                    self.crc = crc16_step(self.crc, b);
                    self.state = State::Seq;
                }
                State::Seq => {
                    o.seq = b;
                    self.crc = crc16_step(self.crc, b);
                    self.left = o.len;
                    self.state = if o.len == 0 {
                        State::CrcLow
                    } else {
                        State::Payload
                    };
                }
                State::Payload => {
                    self.crc = crc16_step(self.crc, b);
                    self.left = self.left.wrapping_sub(1);
                    if self.left == 0 {
                        self.state = State::CrcLow;
                    }
                }
                State::CrcLow => {
                    self.crc_lo = b;
                    self.state = State::CrcHigh;
                }
                State::CrcHigh => {
                    let got = u16::from_le_bytes([self.crc_lo, b]);
                    o.crc = got;
                    if got == self.crc {
                        o.frame = true;
                    } else {
                        o.bad_crc = true;
                    }
                    self.state = State::Hunt;
                }
            }
        } else if self.state != State::Hunt {
            if self.idle >= i.timeout {
                self.state = State::Hunt;
                o.dropped = true;
                self.idle = 0;
            } else {
                self.idle += 1;
            }
        }
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::DEFAULT_FORMAT;
    use crate::protocol::{Command, Decoded, Decoder, Param};
    use proptest::prelude::*;

    /// Byte by byte (one a clock, with gaps shorter than the timeout), the receiver finds the
    /// frames the device decoder finds, with the same command, sequence and payload.
    fn feed(bytes: &[u8]) -> Vec<Decoded> {
        let mut rx = FrameRx::new();
        let mut out = Vec::new();
        let got = |o: FrameRxOutputs, out: &mut Vec<Decoded>| {
            if o.frame {
                out.push(Decoded::Frame(crate::protocol::Frame {
                    cmd: o.cmd,
                    seq: o.seq,
                    payload: (0..usize::from(o.len)).map(|k| o.byte(k)).collect(),
                }));
            }
            if o.bad_crc {
                out.push(Decoded::BadCrc);
            }
        };
        for &b in bytes {
            let o = rx.clock(&FrameRxInputs {
                data: b,
                valid: true,
                timeout: 100,
                ..Default::default()
            });
            got(o, &mut out);
            let o = rx.clock(&FrameRxInputs {
                timeout: 100,
                ..Default::default()
            });
            got(o, &mut out);
        }
        out
    }

    proptest! {
        #[test]
        fn decodes_as_the_device_decoder(bytes in proptest::collection::vec(any::<u8>(), 0..300), frames in 0usize..4, seed in any::<u64>()) {
            let f = DEFAULT_FORMAT;
            let mut stream = bytes;
            for k in 0..frames {
                let c = Command::Configure { param: Param::WatchdogMs, value: i128::from(seed as u16) + k as i128 };
                let at = (seed as usize + 7 * k) % (stream.len() + 1);
                let frame = c.to_frame(k as u8, &f).to_bytes();
                stream.splice(at..at, frame);
            }
            let mut d = Decoder::device();
            let want: Vec<Decoded> = stream.iter().filter_map(|&b| d.push(b)).collect();
            prop_assert_eq!(feed(&stream), want);
        }
    }

    #[test]
    fn a_gap_drops_a_partial_frame() {
        let mut rx = FrameRx::new();
        for b in [START, 3, 1] {
            rx.clock(&FrameRxInputs {
                data: b,
                valid: true,
                timeout: 5,
                ..Default::default()
            });
        }
        let idle = FrameRxInputs {
            timeout: 5,
            ..Default::default()
        };
        let drops: Vec<bool> = (0..8).map(|_| rx.clock(&idle).dropped).collect();
        assert_eq!(
            drops,
            [false, false, false, false, false, true, false, false]
        );
        assert!(!rx.mid_frame());
    }
}
