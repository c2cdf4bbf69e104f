//! The reply transmitter (the reference is `snapgen_model::io::reply_tx::ReplyTx`). When idle
//! it takes the reply queue's head, or else a pending telemetry frame, and writes the frame —
//! start byte, length, code, sequence, payload, CRC low then high — into the transmit FIFO one
//! byte per clock while the FIFO is not full; it reads the payload from the live values
//! [`PAYLOAD_DELAY`] clocks after the start, a CONFIG reply's value a clock before that from
//! the executor, which registers the parameter `read_param` names (a reply reports the device
//! as it is when the reply starts: docs/PROTOCOL.md). Frames are never interleaved; telemetry
//! waits while a reply is queued.
//!
//! Every payload is laid out by its table in `snapgen_spec::fields` (`IDENTITY_FIELDS`,
//! `STATE_FIELDS`, `CONFIG_FIELDS`; the status block arrives laid out), and the CRC is the
//! model's ([`crate::crc16::crc16_function`]). The payload is held in a shift register and
//! sent from its low byte, so no byte multiplexer over 61 positions is needed. Written as
//! Verilog (the template `hdl/verilog/reply_tx.v`); rust-hdl's own simulator does not run it:
//! the Verilog is checked against the model on every clock of the I/O top's co-simulation.

use rust_hdl::prelude::*;
use snapgen_spec::fields::{
    payload_bytes, AckPayload, Field, Identity, NakPayload, CONFIG_FIELDS, IDENTITY_FIELDS,
    NAK_FIELDS, STATE_FIELDS,
};
use snapgen_spec::wire::CRC_INIT;

use snapgen_model::io::reply_tx::PAYLOAD_DELAY;

use crate::crc16::crc16_function;
use crate::template::{fill, Holes};

/// The transmitter's template.
const TEMPLATE: &str = include_str!("../verilog/reply_tx.v");
use crate::protocol_v::{self, KIND_BITS};
use crate::status_block::STATUS_BITS;
use crate::{D_BITS, X_BITS};

// The Verilog reads the CONFIG value on one clock and the payload on the next.
const _: () = assert!(PAYLOAD_DELAY == 2);

/// The longest payload (the `STATE` reply).
pub const MAX_PAYLOAD: usize = {
    let mut m = payload_bytes(&IDENTITY_FIELDS);
    if payload_bytes(&STATE_FIELDS) > m {
        m = payload_bytes(&STATE_FIELDS);
    }
    m
};

/// The transmitter.
#[derive(LogicBlock)]
pub struct ReplyTx {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// The reply queue has a head.
    pub head_valid: Signal<In, Bit>,
    /// Its kind.
    pub head_kind: Signal<In, Bits<{ KIND_BITS as usize }>>,
    /// The command it answers.
    pub head_cmd: Signal<In, Bits<8>>,
    /// Its sequence number.
    pub head_seq: Signal<In, Bits<8>>,
    /// Its NAK reason or CONFIG parameter.
    pub head_aux: Signal<In, Bits<8>>,
    /// Pulse: send telemetry.
    pub telemetry: Signal<In, Bit>,
    /// The transmit FIFO is full.
    pub fifo_full: Signal<In, Bit>,
    /// The status block.
    pub status: Signal<In, Bits<STATUS_BITS>>,
    /// TICK_DIVIDER.
    pub tick_divider: Signal<In, Bits<32>>,
    /// STOP_JERK.
    pub stop_jerk: Signal<In, Bits<D_BITS>>,
    /// STOP_ACCEL.
    pub stop_accel: Signal<In, Bits<D_BITS>>,
    /// The value of the parameter this block's CONFIG reply names (the executor's
    /// registered `read_value`, from `read_param` two clocks before): a CONFIG reply's value.
    pub config_value: Signal<In, Bits<D_BITS>>,
    /// Ticks since reset.
    pub ticks: Signal<In, Bits<64>>,
    /// Position register.
    pub x: Signal<In, Bits<X_BITS>>,
    /// Velocity register.
    pub v: Signal<In, Bits<D_BITS>>,
    /// Acceleration register.
    pub a: Signal<In, Bits<D_BITS>>,
    /// Jerk register.
    pub j: Signal<In, Bits<D_BITS>>,
    /// Take the queue's head now (combinational).
    pub pop: Signal<Out, Bit>,
    /// The parameter a CONFIG reply reads, as it is after this edge (combinational: the
    /// executor registers it decoded as this block registers it at the reply's start).
    pub read_param: Signal<Out, Bits<8>>,
    /// Write `fifo_data` now (combinational).
    pub fifo_write: Signal<Out, Bit>,
    /// The byte.
    pub fifo_data: Signal<Out, Bits<8>>,
    _identity: Identity,
}

impl ReplyTx {
    /// A transmitter for a design with this identity (its tick divider and stop limits are
    /// taken live from the configuration).
    pub fn new(identity: Identity) -> Self {
        ReplyTx {
            clock: Default::default(),
            reset: Default::default(),
            head_valid: Default::default(),
            head_kind: Default::default(),
            head_cmd: Default::default(),
            head_seq: Default::default(),
            head_aux: Default::default(),
            telemetry: Default::default(),
            fifo_full: Default::default(),
            status: Default::default(),
            tick_divider: Default::default(),
            stop_jerk: Default::default(),
            stop_accel: Default::default(),
            config_value: Default::default(),
            ticks: Default::default(),
            x: Default::default(),
            v: Default::default(),
            a: Default::default(),
            j: Default::default(),
            pop: Default::default(),
            read_param: Default::default(),
            fifo_write: Default::default(),
            fifo_data: Default::default(),
            _identity: identity,
        }
    }
}

impl Default for ReplyTx {
    fn default() -> Self {
        ReplyTx::new(crate::defaults::default_design().identity())
    }
}

impl Logic for ReplyTx {
    fn update(&mut self) {}

    fn connect(&mut self) {
        self.pop.connect();
        self.read_param.connect();
        self.fifo_write.connect();
        self.fifo_data.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(reply_tx_verilog(&self._identity))
    }
}

/// A payload as a Verilog concatenation (last field first), each field's expression given by
/// `source` with its width in bits (checked against the table).
fn payload(fields: &[Field], source: impl Fn(&str) -> (String, usize)) -> String {
    let parts: Vec<String> = fields
        .iter()
        .rev()
        .map(|f| {
            let (expr, bits) = source(f.name);
            assert_eq!(bits, 8 * f.bytes, "payload field {}", f.name);
            expr
        })
        .collect();
    format!("{{{}}}", parts.join(", "))
}

fn constant(bits: usize, value: u64) -> (String, usize) {
    (format!("{bits}'d{value}"), bits)
}

/// The transmitter's Verilog body for a design with identity `id`.
pub fn reply_tx_verilog(id: &Identity) -> String {
    let identity = payload(&IDENTITY_FIELDS, |name| match name {
        "protocol" => constant(8, u64::from(id.protocol)),
        "design_hash" => constant(32, u64::from(id.design_hash)),
        "clock_hz" => constant(32, u64::from(id.clock_hz)),
        "baud" => constant(32, u64::from(id.baud)),
        "tick_divider" => ("tick_divider".into(), 32),
        "x_bits" => constant(8, u64::from(id.x_bits)),
        "v_bits" => constant(8, u64::from(id.v_bits)),
        "a_bits" => constant(8, u64::from(id.a_bits)),
        "j_bits" => constant(8, u64::from(id.j_bits)),
        "d_bits" => constant(8, u64::from(id.d_bits)),
        "frac_bits" => constant(8, u64::from(id.frac_bits)),
        "tick_bits" => constant(8, u64::from(id.tick_bits)),
        "max_segments" => constant(8, u64::from(id.max_segments)),
        "snap_bytes" => constant(8, u64::from(id.snap_bytes)),
        "stop_jerk" => ("stop_jerk".into(), D_BITS),
        "stop_accel" => ("stop_accel".into(), D_BITS),
        other => panic!("identity field {other} has no source"),
    });
    let state = payload(&STATE_FIELDS, |name| match name {
        "ticks" => ("ticks".into(), 64),
        "x" => ("x".into(), X_BITS),
        "v" | "a" | "j" => (name.to_string(), D_BITS),
        other => panic!("state field {other} has no source"),
    });
    let config = payload(&CONFIG_FIELDS, |name| match name {
        "param" => ("aux_q".into(), 8),
        "value" => ("config_value".into(), D_BITS),
        other => panic!("config field {other} has no source"),
    });
    let nak = payload(&NAK_FIELDS, |name| match name {
        "cmd" => ("cmd_q".into(), 8),
        "reason" => ("aux_q".into(), 8),
        other => panic!("nak field {other} has no source"),
    });
    let pad = |expr: &str, bytes: usize| {
        let bits = 8 * bytes;
        if bits == 8 * MAX_PAYLOAD {
            expr.to_string()
        } else {
            format!("{{{}'d0, {expr}}}", 8 * MAX_PAYLOAD - bits)
        }
    };
    let status_bytes = STATUS_BITS / 8;
    let holes = Holes::new()
        .value("ID_TOP", 8 * payload_bytes(&IDENTITY_FIELDS) - 1)
        .value("STATE_TOP", 8 * payload_bytes(&STATE_FIELDS) - 1)
        .value("CONFIG_TOP", 8 * payload_bytes(&CONFIG_FIELDS) - 1)
        .value("IDENTITY", identity)
        .value("STATE", state)
        .value("CONFIG", config)
        .value("PAYLOAD_TOP", 8 * MAX_PAYLOAD - 1)
        .value("PAYLOAD_DELAY", PAYLOAD_DELAY)
        .value("PAYLOAD_BITS", 8 * MAX_PAYLOAD)
        .value("ID_BYTES", payload_bytes(&IDENTITY_FIELDS))
        .value(
            "ID_PADDED",
            pad("identity_payload", payload_bytes(&IDENTITY_FIELDS)),
        )
        .value("ACK_BYTES", AckPayload::BYTES)
        .value("ACK_PADDED", pad("cmd_q", AckPayload::BYTES))
        .value("NAK_BYTES", NakPayload::BYTES)
        .value("NAK_PADDED", pad(&nak, NakPayload::BYTES))
        .value("STATUS_BYTES", status_bytes)
        .value("STATUS_PADDED", pad("status", status_bytes))
        .value("STATE_BYTES", payload_bytes(&STATE_FIELDS))
        .value(
            "STATE_PADDED",
            pad("state_payload", payload_bytes(&STATE_FIELDS)),
        )
        .value("CONFIG_BYTES", payload_bytes(&CONFIG_FIELDS))
        .value(
            "CONFIG_PADDED",
            pad("config_payload", payload_bytes(&CONFIG_FIELDS)),
        )
        .block("crc_function", crc16_function());
    let body =
        fill("reply_tx.v", TEMPLATE, &holes).expect("the reply transmitter's template is filled");
    let mut params = protocol_v::localparams();
    params.push(protocol_v::LocalParam::new(
        "CRC_INIT",
        16,
        u64::from(CRC_INIT),
    ));
    protocol_v::with_localparams(&params, &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_tx_is_synthesizable() {
        crate::synth_check::synth_block("reply_tx", ReplyTx::default());
    }
}
