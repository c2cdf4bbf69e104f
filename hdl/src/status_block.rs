//! The status block (docs/PROTOCOL.md, "Status"): the `STATUS`/`TELEMETRY` payload, byte 0 in
//! bits 7:0, laid out by `snapgen_model::protocol::STATUS_FIELDS` and its flags by
//! `snapgen_model::protocol::flag::ALL` (the Verilog is written from those tables).
//! Combinational. The reply transmitter sends it; the I/O top also brings it out for
//! co-simulation, where every field is compared with the device model on every clock.

use rust_hdl::prelude::*;
use snapgen_model::protocol::{flag, payload_bytes, Status, STATUS_FIELDS};

use crate::protocol_v::{ERROR_BITS, STATE_BITS};
use crate::sim_bits::from_u128;

/// Bits of the status block.
pub const STATUS_BITS: usize = 8 * payload_bytes(&STATUS_FIELDS);

const _: () = assert!(STATUS_BITS == 240);

/// The status block.
#[derive(LogicBlock, Default)]
pub struct StatusBlock {
    /// Axis state.
    pub state: Signal<In, Bits<3>>,
    /// Error identifier.
    pub error: Signal<In, Bits<3>>,
    /// Flag PLAYING.
    pub playing: Signal<In, Bit>,
    /// Flag DONE.
    pub done: Signal<In, Bit>,
    /// Flag CUT.
    pub cut: Signal<In, Bit>,
    /// Flag STOPPING.
    pub stopping: Signal<In, Bit>,
    /// Flag STOP_OVER_LIMITS.
    pub stop_over: Signal<In, Bit>,
    /// Flag AMPLIFIER.
    pub amplifier: Signal<In, Bit>,
    /// Flag LIMIT_POSITIVE.
    pub limit_pos: Signal<In, Bit>,
    /// Flag LIMIT_NEGATIVE.
    pub limit_neg: Signal<In, Bit>,
    /// Flag EMERGENCY_STOP.
    pub estop: Signal<In, Bit>,
    /// Flag ENCODER_ERROR.
    pub encoder_error: Signal<In, Bit>,
    /// Flag UART_ERROR.
    pub uart_error: Signal<In, Bit>,
    /// Flag REPLY_OVERFLOW.
    pub reply_overflow: Signal<In, Bit>,
    /// Flag SERVO_OVERRUN.
    pub servo_overrun: Signal<In, Bit>,
    /// Flag SWAP_PENDING.
    pub swap_pending: Signal<In, Bit>,
    /// Ticks since the last start.
    pub tick_count: Signal<In, Bits<32>>,
    /// Position in output LSBs (low 32 bits).
    pub position: Signal<In, Bits<32>>,
    /// The velocity register's top 32 bits.
    pub velocity: Signal<In, Bits<32>>,
    /// Encoder count.
    pub encoder: Signal<In, Bits<32>>,
    /// Frames with a bad CRC.
    pub bad_crc: Signal<In, Bits<16>>,
    /// Frames dropped otherwise.
    pub bad_frames: Signal<In, Bits<16>>,
    /// The peak following error since START.
    pub following_peak: Signal<In, Bits<32>>,
    /// The controller's duty (two's complement).
    pub duty: Signal<In, Bits<16>>,
    /// The block, byte 0 in bits 7:0.
    pub status: Signal<Out, Bits<STATUS_BITS>>,
}

/// The flag ports, by flag.
const FLAG_PORTS: [(u16, &str); 14] = [
    (flag::PLAYING, "playing"),
    (flag::DONE, "done"),
    (flag::CUT, "cut"),
    (flag::STOPPING, "stopping"),
    (flag::STOP_OVER_LIMITS, "stop_over"),
    (flag::AMPLIFIER, "amplifier"),
    (flag::LIMIT_POSITIVE, "limit_pos"),
    (flag::LIMIT_NEGATIVE, "limit_neg"),
    (flag::EMERGENCY_STOP, "estop"),
    (flag::ENCODER_ERROR, "encoder_error"),
    (flag::UART_ERROR, "uart_error"),
    (flag::REPLY_OVERFLOW, "reply_overflow"),
    (flag::SERVO_OVERRUN, "servo_overrun"),
    (flag::SWAP_PENDING, "swap_pending"),
];

const _: () = assert!(FLAG_PORTS.len() == flag::ALL.len());

impl StatusBlock {
    fn flag_values(&self) -> [bool; 14] {
        [
            self.playing.val(),
            self.done.val(),
            self.cut.val(),
            self.stopping.val(),
            self.stop_over.val(),
            self.amplifier.val(),
            self.limit_pos.val(),
            self.limit_neg.val(),
            self.estop.val(),
            self.encoder_error.val(),
            self.uart_error.val(),
            self.reply_overflow.val(),
            self.servo_overrun.val(),
            self.swap_pending.val(),
        ]
    }
}

impl Logic for StatusBlock {
    fn update(&mut self) {
        let flags = FLAG_PORTS
            .iter()
            .zip(self.flag_values())
            .filter(|(_, on)| *on)
            .fold(0u16, |f, ((bit, _), _)| f | bit);
        let s = Status {
            state: self.state.val().to_u64() as u8,
            error: self.error.val().to_u64() as u8,
            flags,
            tick_count: self.tick_count.val().to_u64() as u32,
            position: self.position.val().to_u64() as i32,
            velocity: self.velocity.val().to_u64() as i32,
            encoder: self.encoder.val().to_u64() as i32,
            bad_crc: self.bad_crc.val().to_u64() as u16,
            bad_frames: self.bad_frames.val().to_u64() as u16,
            following_peak: self.following_peak.val().to_u64() as u32,
            duty: self.duty.val().to_u64() as i16,
        };
        let p = s.to_payload();
        let low = p[..16]
            .iter()
            .enumerate()
            .fold(0u128, |v, (k, &b)| v | (u128::from(b) << (8 * k)));
        let mut b: Bits<STATUS_BITS> = from_u128(low);
        for (k, &byte) in p.iter().enumerate().skip(16) {
            for bit in 0..8 {
                b = b.replace_bit(8 * k + bit, (byte >> bit) & 1 == 1);
            }
        }
        self.status.next = b;
    }

    fn connect(&mut self) {
        self.status.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(status_verilog())
    }
}

/// The block's Verilog body.
pub fn status_verilog() -> String {
    // The flags word, bit by bit from the table.
    let mut flag_bits = vec!["1'b0".to_string(); 16];
    for (bit, port) in FLAG_PORTS {
        flag_bits[bit.trailing_zeros() as usize] = port.to_string();
    }
    flag_bits.reverse();
    let source = |name: &str| -> (String, usize) {
        match name {
            "state" => (format!("{{{}'d0, state}}", 8 - STATE_BITS), 8),
            "error" => (format!("{{{}'d0, error}}", 8 - ERROR_BITS), 8),
            "flags" => (format!("{{{}}}", flag_bits.join(", ")), 16),
            "tick_count" | "position" | "velocity" | "encoder" | "following_peak" => {
                (name.to_string(), 32)
            }
            "bad_crc" | "bad_frames" | "duty" => (name.to_string(), 16),
            other => panic!("status field {other} has no source"),
        }
    };
    let parts: Vec<String> = STATUS_FIELDS
        .iter()
        .rev()
        .map(|f| {
            let (expr, bits) = source(f.name);
            assert_eq!(bits, 8 * f.bytes, "status field {}", f.name);
            expr
        })
        .collect();
    format!(
        "// Fields, last first (snapgen_model::protocol::STATUS_FIELDS).\nalways @(*) status = {{{}}};\n",
        parts.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_block_is_synthesizable() {
        crate::synth_check::synth_block("status_block", StatusBlock::default());
    }
}
