//! The fabric's frame receiver (`snapgen_hdl::frame_rx::FrameRx`), clock by clock: hunts for
//! the start byte, takes a length above [`DEVICE_MAX_PAYLOAD`] as noise (a start byte there
//! starts a new frame), checks the CRC-16 over length, command, sequence and payload, and pulses
//! `frame` or `bad_crc` one clock after the last CRC byte, with the command, sequence, length,
//! the payload (byte `k` of `n` at bits `8(n−1−k)..`) and the received CRC. A frame cut short
//! by an inter-byte gap of `timeout` clocks, or by a UART framing error, is dropped with a
//! `dropped` pulse. At the byte level it decodes as the host's `Decoder::device` (`snapgen_host::protocol`).

use snapgen_spec::fields::Field;
use snapgen_spec::wire::{crc16_step, CRC_INIT, DEVICE_MAX_PAYLOAD, START};

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

    /// Field `f` of the last frame's payload (sign-extended when the field is signed).
    pub fn get(&self, f: &Field) -> i128 {
        self.get_as(f, usize::from(self.len))
    }

    /// Field `f` of the last `len` payload bytes received, whatever the frame's length (how
    /// the fabric wires a field it reads before the length is checked).
    pub fn get_as(&self, f: &Field, len: usize) -> i128 {
        let mut bytes = [0u8; 32];
        for (k, b) in bytes.iter_mut().enumerate().take(len.min(32)) {
            *b = self.payload[len - 1 - k];
        }
        snapgen_spec::fields::get(&bytes, f)
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
