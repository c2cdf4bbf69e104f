//! The reply transmitter (the reference is `snapgen_model::io::reply_tx::ReplyTx`). When idle
//! it takes the reply queue's head, or else a pending telemetry frame, reads its payload from
//! the live values of that clock (a reply reports the device as it is when the reply starts:
//! docs/PROTOCOL.md), and writes the frame — start byte, length, code, sequence, payload, CRC
//! low then high — into the transmit FIFO one byte per clock while the FIFO is not full.
//! Frames are never interleaved; telemetry waits while a reply is queued.
//!
//! Every payload is laid out by its table in `snapgen_model::protocol` (`IDENTITY_FIELDS`,
//! `STATE_FIELDS`, `CONFIG_FIELDS`; the status block arrives laid out), and the CRC is the
//! model's ([`crate::crc16::crc16_function`]). The payload is held in a shift register and
//! sent from its low byte, so no byte multiplexer over 61 positions is needed. Written as
//! Verilog; the model runs in rust-hdl's simulator.

use rust_hdl::prelude::*;
use snapgen_model::io::executor::{Config, ReplyDesc, ReplyKind};
use snapgen_model::io::reply_tx::{Live, ReplyTx as TxModel, ReplyTxInputs};
use snapgen_model::protocol::{
    payload_bytes, Field, Identity, Param, StateReply, Status, CONFIG_FIELDS, CRC_INIT,
    IDENTITY_FIELDS, STATE_FIELDS,
};
use snapgen_model::stop::StopLimits;

use crate::crc16::crc16_function;
use crate::protocol_v;
use crate::sim_bits::{to_i128, to_u128};
use crate::status_block::STATUS_BITS;
use crate::{D_BITS, X_BITS};

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
    pub head_kind: Signal<In, Bits<3>>,
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
    pub tick_div: Signal<In, Bits<32>>,
    /// STOP_JERK.
    pub stop_jerk: Signal<In, Bits<D_BITS>>,
    /// STOP_ACCEL.
    pub stop_accel: Signal<In, Bits<D_BITS>>,
    /// The value of the parameter `head_aux` names (the executor's `read_value`): a CONFIG
    /// reply's value.
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
    /// Write `fifo_data` now (combinational).
    pub fifo_write: Signal<Out, Bit>,
    /// The byte.
    pub fifo_data: Signal<Out, Bits<8>>,
    _sim: Sim,
}

/// The model and the design's identity.
#[derive(Clone, Debug, Default)]
struct Sim {
    model: TxModel,
    identity: Identity,
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
            tick_div: Default::default(),
            stop_jerk: Default::default(),
            stop_accel: Default::default(),
            config_value: Default::default(),
            ticks: Default::default(),
            x: Default::default(),
            v: Default::default(),
            a: Default::default(),
            j: Default::default(),
            pop: Default::default(),
            fifo_write: Default::default(),
            fifo_data: Default::default(),
            _sim: Sim {
                model: TxModel::new(),
                identity,
            },
        }
    }

    fn inputs(&self) -> ReplyTxInputs {
        ReplyTxInputs {
            reset: self.reset.val(),
            head: self.head_valid.val().then(|| ReplyDesc {
                kind: ReplyKind::from_bits(self.head_kind.val().to_u64() as u8),
                cmd: self.head_cmd.val().to_u64() as u8,
                seq: self.head_seq.val().to_u64() as u8,
                aux: self.head_aux.val().to_u64() as u8,
            }),
            telemetry: self.telemetry.val(),
            fifo_full: self.fifo_full.val(),
        }
    }

    fn live(&self) -> Live {
        // The configuration as far as this block sees it: the identity's live fields, and the
        // value of the parameter the head reply reads.
        let mut config = Config {
            tick_div: self.tick_div.val().to_u64() as u32,
            stop: StopLimits {
                jerk: to_u128(self.stop_jerk.val()) as i128,
                accel: to_u128(self.stop_accel.val()) as i128,
            },
            ..Default::default()
        };
        if let Some(p) = Param::from_byte(self.head_aux.val().to_u64() as u8) {
            config.set(p, to_u128(self.config_value.val()) as i128);
        }
        let sb = self.status.val();
        let bytes: Vec<u8> = (0..STATUS_BITS / 8)
            .map(|k| sb.get_bits::<8>(8 * k).to_u64() as u8)
            .collect();
        Live {
            status: Status::from_payload(&bytes).expect("the status block's length"),
            state: StateReply {
                ticks: self.ticks.val().to_u64(),
                x: to_i128(self.x.val()),
                v: to_i128(self.v.val()),
                a: to_i128(self.a.val()),
                j: to_i128(self.j.val()),
            },
            config,
            identity: self._sim.identity,
        }
    }
}

impl Default for ReplyTx {
    fn default() -> Self {
        ReplyTx::new(crate::io_top::default_design().identity())
    }
}

impl Logic for ReplyTx {
    fn update(&mut self) {
        let i = self.inputs();
        if self.clock.pos_edge() {
            let live = self.live();
            self._sim.model.clock(&i, &live);
        }
        let o = self._sim.model.outputs(&i);
        self.pop.next = o.pop;
        self.fifo_write.next = o.fifo_write;
        self.fifo_data.next = u64::from(o.fifo_data).into();
    }

    fn connect(&mut self) {
        self.pop.connect();
        self.fifo_write.connect();
        self.fifo_data.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(reply_tx_verilog(&self._sim.identity))
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
        "tick_divider" => ("tick_div".into(), 32),
        "x_bits" => constant(8, u64::from(id.widths[0])),
        "v_bits" => constant(8, u64::from(id.widths[1])),
        "a_bits" => constant(8, u64::from(id.widths[2])),
        "j_bits" => constant(8, u64::from(id.widths[3])),
        "d_bits" => constant(8, u64::from(id.widths[4])),
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
        "param" => ("head_aux".into(), 8),
        "value" => ("config_value".into(), D_BITS),
        other => panic!("config field {other} has no source"),
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
    let body = format!(
        r#"
localparam [15:0] CRC_INIT = 16'h{crc_init:04x};

// ---- The reply launched on this clock, and its payload (byte 0 in bits 7:0) -------------------
wire launch_head = !active_q && head_valid;
wire launch_telemetry = !active_q && !head_valid && (pending_q || telemetry);
wire [2:0] kind = launch_head ? head_kind : K_TELEMETRY;
wire [{id_top}:0] identity_payload = {identity};
wire [{state_top}:0] state_payload = {state};
wire [{config_top}:0] config_payload = {config};
reg [7:0] new_len;
reg [7:0] new_code;
reg [{payload_top}:0] new_payload;
always @(*) begin
   case (kind)
   K_IDENTITY: begin
      new_len = 8'd{id_bytes};
      new_code = RC_IDENTITY;
      new_payload = {id_padded};
   end
   K_ACK: begin
      new_len = 8'd1;
      new_code = RC_ACK;
      new_payload = {ack_padded};
   end
   K_NAK: begin
      new_len = 8'd2;
      new_code = RC_NAK;
      new_payload = {nak_padded};
   end
   K_STATUS: begin
      new_len = 8'd{status_bytes};
      new_code = RC_STATUS;
      new_payload = {status_padded};
   end
   K_STATE: begin
      new_len = 8'd{state_bytes};
      new_code = RC_STATE;
      new_payload = {state_padded};
   end
   K_CONFIG: begin
      new_len = 8'd{config_bytes};
      new_code = RC_CONFIG;
      new_payload = {config_padded};
   end
   default: begin                                // telemetry: the status block
      new_len = 8'd{status_bytes};
      new_code = RC_TELEMETRY;
      new_payload = {status_padded};
   end
   endcase
end

// ---- The frame being written ---------------------------------------------------------------
reg active_q = 1'b0;
reg [7:0] index_q = 8'd0;                        // byte of the frame written next
reg [7:0] len_q = 8'd0;
reg [7:0] code_q = 8'd0;
reg [7:0] seq_q = 8'd0;
reg [{payload_top}:0] payload_q = {payload_bits}'d0;   // the bytes not yet written, next in 7:0
reg [15:0] crc_q = 16'd0;
reg pending_q = 1'b0;                            // a telemetry frame waits
wire writing = !reset && active_q && !fifo_full;
wire [7:0] payload_end = len_q + 8'd4;           // index of the CRC's low byte
reg [7:0] data;
always @(*) begin
   if (index_q == 8'd0) data = START_BYTE;
   else if (index_q == 8'd1) data = len_q;
   else if (index_q == 8'd2) data = code_q;
   else if (index_q == 8'd3) data = seq_q;
   else if (index_q < payload_end) data = payload_q[7:0];
   else if (index_q == payload_end) data = crc_q[7:0];
   else data = crc_q[15:8];
end

{crc_fn}
always @(posedge clock) begin
   if (reset) begin
      active_q <= 1'b0;
      index_q <= 8'd0;
      pending_q <= 1'b0;
   end else begin
      if (!active_q) begin
         if (launch_head || launch_telemetry) begin
            active_q <= 1'b1;
            index_q <= 8'd0;
            len_q <= new_len;
            code_q <= new_code;
            seq_q <= launch_head ? head_seq : 8'd0;
            payload_q <= new_payload;
            crc_q <= CRC_INIT;
         end
      end else if (writing) begin
         if ((index_q >= 8'd1) && (index_q < payload_end)) crc_q <= crc16_step(crc_q, data);
         if ((index_q >= 8'd4) && (index_q < payload_end)) payload_q <= payload_q >> 8;
         index_q <= index_q + 8'd1;
         if (index_q == payload_end + 8'd1) active_q <= 1'b0;
      end
      if (launch_telemetry) pending_q <= 1'b0;
      else if (telemetry) pending_q <= 1'b1;
   end
end

always @(*) begin
   pop = !reset && launch_head;
   fifo_write = writing;
   fifo_data = data;
end
"#,
        crc_init = CRC_INIT,
        id_top = 8 * payload_bytes(&IDENTITY_FIELDS) - 1,
        state_top = 8 * payload_bytes(&STATE_FIELDS) - 1,
        config_top = 8 * payload_bytes(&CONFIG_FIELDS) - 1,
        identity = identity,
        state = state,
        config = config,
        payload_top = 8 * MAX_PAYLOAD - 1,
        payload_bits = 8 * MAX_PAYLOAD,
        id_bytes = payload_bytes(&IDENTITY_FIELDS),
        id_padded = pad("identity_payload", payload_bytes(&IDENTITY_FIELDS)),
        ack_padded = pad("head_cmd", 1),
        nak_padded = pad("{head_aux, head_cmd}", 2),
        status_bytes = status_bytes,
        status_padded = pad("status", status_bytes),
        state_bytes = payload_bytes(&STATE_FIELDS),
        state_padded = pad("state_payload", payload_bytes(&STATE_FIELDS)),
        config_bytes = payload_bytes(&CONFIG_FIELDS),
        config_padded = pad("config_payload", payload_bytes(&CONFIG_FIELDS)),
        crc_fn = crc16_function(),
    );
    protocol_v::with_params(&protocol_v::all(), &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_tx_is_synthesizable() {
        crate::synth_check::synth_block("reply_tx", ReplyTx::default());
    }
}
