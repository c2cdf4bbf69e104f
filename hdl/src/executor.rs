//! The command executor and axis state machine (docs/PROTOCOL.md; the reference, clock for
//! clock, is `snapgen_model::io::executor::Executor`).
//!
//! On each frame with a good CRC it checks the command (code, length, arguments, then the axis
//! state), applies its effect (a segment write, a count, a start, a stop, a configuration
//! register, the amplifier, an error reset) and queues its reply; a bad CRC or a dropped
//! frame queues a NAK with sequence 0. A command with an effect whose code, sequence and CRC
//! equal the last such command's is a retry: its reply is queued again, nothing else happens.
//! A frame that arrives with the reply queue full is dropped unanswered and flagged.
//!
//! The axis state machine (PLCopen's, seed 000 Figure 1) also moves by itself: the emergency
//! stop (ErrorStop, amplifier off, motion aborted at once), motion toward an active limit
//! switch or an expired host watchdog (ErrorStop through the controlled stop), and the end of
//! a move or a stop (Standstill). Telemetry is requested every `TELEMETRY_PERIOD` ticks while
//! the chain is driven and once when it stops being driven.
//!
//! Every output is registered. The block writes its own Verilog — a next-state block that
//! follows the model's statements in order, then one register block — with every code,
//! length, reason, parameter and state written from `snapgen_model::protocol`'s tables
//! ([`crate::protocol_v`]). rust-hdl's simulator runs the model itself; what is checked is the
//! Verilog, against the model, on every clock of the I/O top's co-simulation (`snapgen-sim`).

use rust_hdl::prelude::*;
use snapgen_model::io::executor::{
    Executor as ExecutorModel, ExecutorInputs, ExecutorOutputs, ReplyDesc,
};
use snapgen_model::io::frame_rx::FrameRxOutputs;
use snapgen_model::protocol::{
    command_spec, AxisState, ErrorId, Param, Reason, Settable, COMMANDS, DEFAULT_WATCHDOG_MS,
    PARAMS,
};
use snapgen_model::timing::Dividers;

use crate::frame_rx::PAYLOAD_BYTES;
use crate::protocol_v::{self, error_name, param_name, reason_name, state_name};
use crate::sim_bits::{from_i128, to_u128};
use crate::{ADDR_BITS, D_BITS, INDEX_BITS, TICK_BITS};

/// Bits of the received payload the executor reads.
pub const PAYLOAD_BITS: usize = 8 * PAYLOAD_BYTES;

/// The executor.
#[derive(LogicBlock)]
pub struct Executor {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Pulse: a frame with a good CRC.
    pub frame: Signal<In, Bit>,
    /// Pulse: a frame with a bad CRC.
    pub bad_crc: Signal<In, Bit>,
    /// Pulse: a partial frame was dropped.
    pub dropped: Signal<In, Bit>,
    /// Pulse: UART framing error.
    pub line_error: Signal<In, Bit>,
    /// The frame's command.
    pub cmd: Signal<In, Bits<8>>,
    /// Its sequence number.
    pub seq: Signal<In, Bits<8>>,
    /// Its payload length.
    pub len: Signal<In, Bits<8>>,
    /// Its last payload bytes, the last one in bits 7:0.
    pub payload: Signal<In, Bits<PAYLOAD_BITS>>,
    /// The CRC it carried.
    pub crc: Signal<In, Bits<16>>,
    /// Core: a program plays.
    pub busy: Signal<In, Bit>,
    /// Core: a controlled stop is requested or runs.
    pub stopping: Signal<In, Bit>,
    /// Core: the standby program's segment count.
    pub standby_count: Signal<In, Bits<INDEX_BITS>>,
    /// Core: the tick enable.
    pub tick: Signal<In, Bit>,
    /// Core: the chain is at rest (v = a = j = 0).
    pub at_rest: Signal<In, Bit>,
    /// Core: the axis heads forward.
    pub heading_pos: Signal<In, Bit>,
    /// Core: the axis heads backward.
    pub heading_neg: Signal<In, Bit>,
    /// The reply queue is full.
    pub queue_full: Signal<In, Bit>,
    /// Positive limit switch (filtered, polarity applied).
    pub limit_pos: Signal<In, Bit>,
    /// Negative limit switch.
    pub limit_neg: Signal<In, Bit>,
    /// Emergency stop.
    pub estop: Signal<In, Bit>,
    /// The encoder's count of illegal transitions.
    pub encoder_errors: Signal<In, Bits<16>>,
    /// The controller: the following error is beyond its limit.
    pub following_fault: Signal<In, Bit>,
    /// The controller skipped a sample.
    pub servo_overrun_in: Signal<In, Bit>,
    /// The parameter whose value `read_value` gives (the reply transmitter's head).
    pub read_param: Signal<In, Bits<8>>,
    /// Core: the time base (ticks since reset).
    pub ticks: Signal<In, Bits<64>>,
    /// Core: a program swap is armed.
    pub swap_pending: Signal<In, Bit>,
    /// Core: write one segment.
    pub write_enable: Signal<Out, Bit>,
    /// Core: segment address.
    pub write_address: Signal<Out, Bits<ADDR_BITS>>,
    /// Core: segment ticks.
    pub write_ticks: Signal<Out, Bits<TICK_BITS>>,
    /// Core: segment snap.
    pub write_snap: Signal<Out, Bits<D_BITS>>,
    /// Core: set the standby count.
    pub count_enable: Signal<Out, Bit>,
    /// Core: the count.
    pub count_value: Signal<Out, Bits<INDEX_BITS>>,
    /// Core: start.
    pub start: Signal<Out, Bit>,
    /// Core: arm a program swap for the tick after `swap_last`.
    pub swap: Signal<Out, Bit>,
    /// Core: the low 32 bits of the swap's tick minus one.
    pub swap_last: Signal<Out, Bits<32>>,
    /// Core: controlled stop.
    pub stop: Signal<Out, Bit>,
    /// Core: abort (the emergency stop, a following error).
    pub abort_move: Signal<Out, Bit>,
    /// Core: the reference takes the encoder's position (POWER 1 from Disabled).
    pub load: Signal<Out, Bit>,
    /// TICK_DIVIDER.
    pub tick_div: Signal<Out, Bits<32>>,
    /// PWM_PERIOD.
    pub pwm_period: Signal<Out, Bits<16>>,
    /// ENCODER_FILTER.
    pub encoder_filter: Signal<Out, Bits<16>>,
    /// STOP_JERK.
    pub stop_jerk: Signal<Out, Bits<D_BITS>>,
    /// STOP_ACCEL.
    pub stop_accel: Signal<Out, Bits<D_BITS>>,
    /// INPUT_POLARITY.
    pub input_polarity: Signal<Out, Bits<3>>,
    /// INPUT_FILTER.
    pub input_filter: Signal<Out, Bits<16>>,
    /// SERVO_PERIOD.
    pub servo_period: Signal<Out, Bits<16>>,
    /// KP.
    pub kp: Signal<Out, Bits<48>>,
    /// KI.
    pub ki: Signal<Out, Bits<48>>,
    /// KD.
    pub kd: Signal<Out, Bits<48>>,
    /// KV.
    pub kv: Signal<Out, Bits<48>>,
    /// KA.
    pub ka: Signal<Out, Bits<48>>,
    /// INTEGRAL_LIMIT.
    pub integral_limit: Signal<Out, Bits<48>>,
    /// OUTPUT_LIMIT.
    pub output_limit: Signal<Out, Bits<16>>,
    /// FOLLOWING_LIMIT.
    pub following_limit: Signal<Out, Bits<32>>,
    /// D_FILTER.
    pub d_filter: Signal<Out, Bits<4>>,
    /// The value of parameter `read_param` (combinational; 0 for an unknown one).
    pub read_value: Signal<Out, Bits<D_BITS>>,
    /// The axis state.
    pub state: Signal<Out, Bits<3>>,
    /// Why in ErrorStop.
    pub error: Signal<Out, Bits<3>>,
    /// The amplifier is enabled.
    pub amplifier: Signal<Out, Bit>,
    /// A UART framing error was seen.
    pub uart_error: Signal<Out, Bit>,
    /// A frame was dropped with the reply queue full.
    pub reply_overflow: Signal<Out, Bit>,
    /// The encoder's error count at the last RESET command (an encoder error shows while the
    /// count differs).
    pub encoder_errors_seen: Signal<Out, Bits<16>>,
    /// The controller skipped a sample (since reset or the last RESET command).
    pub servo_overrun: Signal<Out, Bit>,
    /// Frames with a bad CRC.
    pub bad_crc_count: Signal<Out, Bits<16>>,
    /// Frames with a bad length, an unknown command, or cut short.
    pub bad_frames_count: Signal<Out, Bits<16>>,
    /// Pulse: queue a reply.
    pub reply: Signal<Out, Bit>,
    /// Its kind.
    pub reply_kind: Signal<Out, Bits<3>>,
    /// The command it answers.
    pub reply_cmd: Signal<Out, Bits<8>>,
    /// Its sequence number.
    pub reply_seq: Signal<Out, Bits<8>>,
    /// The NAK reason or the CONFIG parameter.
    pub reply_aux: Signal<Out, Bits<8>>,
    /// Pulse: send telemetry.
    pub telemetry: Signal<Out, Bit>,
    _sim: Sim,
}

/// The model, for rust-hdl's simulator, and what the Verilog is generated for.
#[derive(Clone, Debug, Default)]
struct Sim {
    model: ExecutorModel,
    dividers: Dividers,
    input_polarity: u8,
}

impl Executor {
    /// An executor for a design with these dividers (the tick divider after reset and the
    /// watchdog's clocks per millisecond) and input polarity after reset.
    pub fn new(dividers: Dividers, input_polarity: u8) -> Self {
        Executor {
            clock: Default::default(),
            reset: Default::default(),
            frame: Default::default(),
            bad_crc: Default::default(),
            dropped: Default::default(),
            line_error: Default::default(),
            cmd: Default::default(),
            seq: Default::default(),
            len: Default::default(),
            payload: Default::default(),
            crc: Default::default(),
            busy: Default::default(),
            stopping: Default::default(),
            standby_count: Default::default(),
            tick: Default::default(),
            at_rest: Default::default(),
            heading_pos: Default::default(),
            heading_neg: Default::default(),
            queue_full: Default::default(),
            limit_pos: Default::default(),
            limit_neg: Default::default(),
            estop: Default::default(),
            encoder_errors: Default::default(),
            following_fault: Default::default(),
            servo_overrun_in: Default::default(),
            read_param: Default::default(),
            ticks: Default::default(),
            swap_pending: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_ticks: Default::default(),
            write_snap: Default::default(),
            count_enable: Default::default(),
            count_value: Default::default(),
            start: Default::default(),
            swap: Default::default(),
            swap_last: Default::default(),
            stop: Default::default(),
            abort_move: Default::default(),
            load: Default::default(),
            tick_div: Default::default(),
            pwm_period: Default::default(),
            encoder_filter: Default::default(),
            stop_jerk: Default::default(),
            stop_accel: Default::default(),
            input_polarity: Default::default(),
            input_filter: Default::default(),
            servo_period: Default::default(),
            kp: Default::default(),
            ki: Default::default(),
            kd: Default::default(),
            kv: Default::default(),
            ka: Default::default(),
            integral_limit: Default::default(),
            output_limit: Default::default(),
            following_limit: Default::default(),
            d_filter: Default::default(),
            read_value: Default::default(),
            state: Default::default(),
            error: Default::default(),
            amplifier: Default::default(),
            uart_error: Default::default(),
            reply_overflow: Default::default(),
            encoder_errors_seen: Default::default(),
            servo_overrun: Default::default(),
            bad_crc_count: Default::default(),
            bad_frames_count: Default::default(),
            reply: Default::default(),
            reply_kind: Default::default(),
            reply_cmd: Default::default(),
            reply_seq: Default::default(),
            reply_aux: Default::default(),
            telemetry: Default::default(),
            _sim: Sim {
                model: ExecutorModel::new(
                    dividers.tick_div,
                    dividers.clocks_per_ms,
                    input_polarity,
                ),
                dividers,
                input_polarity,
            },
        }
    }
}

impl Default for Executor {
    fn default() -> Self {
        Executor::new(crate::io_top::default_dividers(), 0)
    }
}

impl Logic for Executor {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let mut payload = [0u8; 32];
            let p = to_u128(self.payload.val());
            let high = self.payload.val().get_bits::<16>(128).to_u64();
            for (k, b) in payload.iter_mut().take(PAYLOAD_BYTES).enumerate() {
                *b = if k < 16 {
                    (p >> (8 * k)) as u8
                } else {
                    (high >> (8 * (k - 16))) as u8
                };
            }
            let i = ExecutorInputs {
                reset: self.reset.val(),
                rx: FrameRxOutputs {
                    frame: self.frame.val(),
                    bad_crc: self.bad_crc.val(),
                    dropped: self.dropped.val(),
                    cmd: self.cmd.val().to_u64() as u8,
                    seq: self.seq.val().to_u64() as u8,
                    len: self.len.val().to_u64() as u8,
                    payload,
                    crc: self.crc.val().to_u64() as u16,
                },
                line_error: self.line_error.val(),
                busy: self.busy.val(),
                stopping: self.stopping.val(),
                standby_count: self.standby_count.val().to_u64() as u8,
                tick: self.tick.val(),
                at_rest: self.at_rest.val(),
                heading_positive: self.heading_pos.val(),
                heading_negative: self.heading_neg.val(),
                encoder_errors: self.encoder_errors.val().to_u64() as u16,
                following_fault: self.following_fault.val(),
                servo_overrun: self.servo_overrun_in.val(),
                queue_full: self.queue_full.val(),
                limit_positive: self.limit_pos.val(),
                limit_negative: self.limit_neg.val(),
                emergency_stop: self.estop.val(),
                ticks: self.ticks.val().to_u64(),
                swap_pending: self.swap_pending.val(),
            };
            self._sim.model.clock(&i);
        }
        let o: ExecutorOutputs = self._sim.model.outputs();
        let c = o.config;
        self.write_enable.next = o.write_enable;
        self.write_address.next = u64::from(o.write_address).into();
        self.write_ticks.next = u64::from(o.write_ticks).into();
        self.write_snap.next = from_i128(o.write_snap);
        self.count_enable.next = o.count_enable;
        self.count_value.next = u64::from(o.count_value).into();
        self.start.next = o.start;
        self.swap.next = o.swap;
        self.swap_last.next = u64::from(o.swap_last).into();
        self.stop.next = o.stop;
        self.abort_move.next = o.abort;
        self.load.next = o.load;
        self.tick_div.next = u64::from(c.tick_div).into();
        self.pwm_period.next = u64::from(c.pwm_period).into();
        self.encoder_filter.next = u64::from(c.encoder_filter).into();
        self.stop_jerk.next = from_i128(c.stop.jerk);
        self.stop_accel.next = from_i128(c.stop.accel);
        self.input_polarity.next = u64::from(c.input_polarity).into();
        self.input_filter.next = u64::from(c.input_filter).into();
        self.servo_period.next = u64::from(c.servo.period).into();
        self.kp.next = (c.servo.kp as u64).into();
        self.ki.next = (c.servo.ki as u64).into();
        self.kd.next = (c.servo.kd as u64).into();
        self.kv.next = (c.servo.kv as u64).into();
        self.ka.next = (c.servo.ka as u64).into();
        self.integral_limit.next = (c.servo.integral_limit as u64).into();
        self.output_limit.next = u64::from(c.servo.output_limit).into();
        self.following_limit.next = u64::from(c.servo.following_limit).into();
        self.d_filter.next = u64::from(c.servo.d_filter).into();
        self.read_value.next = from_i128(
            Param::from_byte(self.read_param.val().to_u64() as u8).map_or(0, |p| c.get(p)),
        );
        self.state.next = (o.state as u64).into();
        self.error.next = (o.error as u64).into();
        self.amplifier.next = o.amplifier;
        self.uart_error.next = o.uart_error;
        self.reply_overflow.next = o.reply_overflow;
        self.encoder_errors_seen.next = u64::from(o.encoder_errors_seen).into();
        self.servo_overrun.next = o.servo_overrun;
        self.bad_crc_count.next = u64::from(o.bad_crc).into();
        self.bad_frames_count.next = u64::from(o.bad_frames).into();
        let r: ReplyDesc = o.reply.unwrap_or_default();
        self.reply.next = o.reply.is_some();
        self.reply_kind.next = (r.kind as u64).into();
        self.reply_cmd.next = u64::from(r.cmd).into();
        self.reply_seq.next = u64::from(r.seq).into();
        self.reply_aux.next = u64::from(r.aux).into();
        self.telemetry.next = o.telemetry;
    }

    fn connect(&mut self) {
        self.write_enable.connect();
        self.write_address.connect();
        self.write_ticks.connect();
        self.write_snap.connect();
        self.count_enable.connect();
        self.count_value.connect();
        self.start.connect();
        self.swap.connect();
        self.swap_last.connect();
        self.stop.connect();
        self.abort_move.connect();
        self.load.connect();
        self.tick_div.connect();
        self.pwm_period.connect();
        self.encoder_filter.connect();
        self.stop_jerk.connect();
        self.stop_accel.connect();
        self.input_polarity.connect();
        self.input_filter.connect();
        self.servo_period.connect();
        self.kp.connect();
        self.ki.connect();
        self.kd.connect();
        self.kv.connect();
        self.ka.connect();
        self.integral_limit.connect();
        self.output_limit.connect();
        self.following_limit.connect();
        self.d_filter.connect();
        self.read_value.connect();
        self.state.connect();
        self.error.connect();
        self.amplifier.connect();
        self.uart_error.connect();
        self.reply_overflow.connect();
        self.encoder_errors_seen.connect();
        self.servo_overrun.connect();
        self.bad_crc_count.connect();
        self.bad_frames_count.connect();
        self.reply.connect();
        self.reply_kind.connect();
        self.reply_cmd.connect();
        self.reply_seq.connect();
        self.reply_aux.connect();
        self.telemetry.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(executor_verilog(
            &self._sim.dividers,
            self._sim.input_polarity,
        ))
    }
}

/// `|value[103:k]`: the CONFIGURE value is above `max = 2^k − 1` (its sign bit is checked
/// apart).
fn above_max(param: Param) -> String {
    let max = param.max();
    let k = (max + 1).trailing_zeros();
    assert_eq!(
        max + 1,
        1i128 << k,
        "{}: a maximum of 2^k - 1",
        param.name()
    );
    if k >= D_BITS as u32 - 1 {
        "1'b0".to_string()
    } else {
        format!("(|cfg_value[{}:{k}])", D_BITS - 2)
    }
}

/// Each configuration register: parameter, register name, width.
const CONFIG_REGS: [(Param, &str, usize); 19] = [
    (Param::TickDivider, "tick_div", 32),
    (Param::PwmPeriod, "pwm_period", 16),
    (Param::EncoderFilter, "encoder_filter", 16),
    (Param::TelemetryPeriod, "telemetry_period", 32),
    (Param::StopJerk, "stop_jerk", D_BITS),
    (Param::StopAccel, "stop_accel", D_BITS),
    (Param::WatchdogMs, "watchdog_ms", 32),
    (Param::InputPolarity, "input_polarity", 3),
    (Param::InputFilter, "input_filter", 16),
    (Param::ServoPeriod, "servo_period", 16),
    (Param::Kp, "kp", 48),
    (Param::Ki, "ki", 48),
    (Param::Kd, "kd", 48),
    (Param::Kv, "kv", 48),
    (Param::Ka, "ka", 48),
    (Param::IntegralLimit, "integral_limit", 48),
    (Param::OutputLimit, "output_limit", 16),
    (Param::FollowingLimit, "following_limit", 32),
    (Param::DFilter, "d_filter", 4),
];

const _: () = assert!(CONFIG_REGS.len() == PARAMS.len());

/// The executor's Verilog body.
pub fn executor_verilog(d: &Dividers, input_polarity: u8) -> String {
    let s = |x: AxisState| state_name(x);
    let e = |x: ErrorId| error_name(x);
    let r = |x: Reason| reason_name(x);
    let spec = |code: u8| command_spec(code).expect("a known command");
    let n_seg = spec(snapgen_model::protocol::code::LOAD_SEGMENT).len as usize;
    let n_cfg = spec(snapgen_model::protocol::code::CONFIGURE).len as usize;
    let max_segments = snapgen_model::DEFAULT_FORMAT.max_segments;
    // The command table: known, length, effect.
    let mut table = String::new();
    for c in COMMANDS {
        table.push_str(&format!(
            "   CMD_{0}: begin known = 1'b1; want_len = LEN_{0}; has_effect = 1'b{1}; end\n",
            c.name,
            u8::from(c.effect)
        ));
    }
    // Parameters: known, above the maximum, the register written.
    let mut known_param = Vec::new();
    let mut at_rest_param = vec!["1'b0".to_string()];
    let mut disabled_param = vec!["1'b0".to_string()];
    let mut over = String::new();
    let mut set = String::new();
    let mut regs = String::new();
    let mut holds = String::new();
    let mut resets = String::new();
    let mut clocked = String::new();
    let mut outs = String::new();
    let mut read = String::new();
    for (param, name, bits) in CONFIG_REGS {
        let pn = param_name(param);
        known_param.push(format!("(q == {pn})"));
        match param.settable() {
            Settable::AtRest => at_rest_param.push(format!("(q == {pn})")),
            Settable::Disabled => disabled_param.push(format!("(q == {pn})")),
            Settable::Always => {}
        }
        over.push_str(&format!("   {pn}: cfg_over = {};\n", above_max(param)));
        set.push_str(&format!(
            "               {pn}: n_{name} = cfg_value[{}:0];\n",
            bits - 1
        ));
        regs.push_str(&format!(
            "reg [{0}:0] {name}_q = {bits}'d0, n_{name};\n",
            bits - 1
        ));
        holds.push_str(&format!("   n_{name} = {name}_q;\n"));
        let reset = match param {
            Param::TickDivider => "TICK_DIV_DEFAULT".to_string(),
            Param::WatchdogMs => "WATCHDOG_DEFAULT".to_string(),
            Param::InputPolarity => "POLARITY_DEFAULT".to_string(),
            Param::OutputLimit => format!("16'd{}", i16::MAX),
            _ => format!("{bits}'d0"),
        };
        resets.push_str(&format!("      {name}_q <= {reset};\n"));
        clocked.push_str(&format!("      {name}_q <= n_{name};\n"));
        read.push_str(&format!(
            "   {pn}: read_value = {};\n",
            if bits == D_BITS {
                format!("{name}_q")
            } else {
                format!("{{{}'d0, {name}_q}}", D_BITS - bits)
            }
        ));
        // TELEMETRY_PERIOD and WATCHDOG_MS are the executor's own; the rest leave it.
        if !matches!(param, Param::TelemetryPeriod | Param::WatchdogMs) {
            outs.push_str(&format!("   {name} = {name}_q;\n"));
        }
    }
    let body = format!(
        r#"
// ---- Generation constants ---------------------------------------------------------------------
localparam [31:0] TICK_DIV_DEFAULT = 32'd{tick_div};   // clocks per tick - 1 after reset
localparam [31:0] CLOCKS_PER_MS = 32'd{clocks_per_ms};      // the watchdog's prescaler
localparam [31:0] WATCHDOG_DEFAULT = 32'd{watchdog};     // ms
localparam [2:0] POLARITY_DEFAULT = 3'd{input_polarity};      // INPUT_POLARITY after reset
localparam [7:0] MAX_SEGMENTS = 8'd{max_segments};

// ---- The frame's fields (byte k of an n-byte payload is payload[8(n-1-k) +: 8]) ----------------
wire [7:0] seg_index = {seg_index};
wire [31:0] seg_ticks = {seg_ticks};
wire [103:0] seg_snap = {seg_snap};
wire [7:0] arg0 = payload[7:0];                  // the byte of a one-byte payload
wire [7:0] cfg_param = {cfg_param};
wire [103:0] cfg_value = {cfg_value};
wire [63:0] swap_tick = {swap_tick};

// ---- The command table: known, payload length, has an effect (a retry is not executed) --------
reg known;
reg [7:0] want_len;
reg has_effect;
always @(*) begin
   known = 1'b0;
   want_len = 8'd0;
   has_effect = 1'b0;
   case (cmd)
{table}   default: ;
   endcase
end

function automatic param_known(input [7:0] q);
   param_known = {known_param};
endfunction

function automatic param_at_rest(input [7:0] q);   // set only while the axis is at rest
   param_at_rest = {at_rest_param};
endfunction

function automatic param_disabled(input [7:0] q);  // set only while Disabled
   param_disabled = {disabled_param};
endfunction

reg cfg_over;                                    // the CONFIGURE value is above its maximum
always @(*) begin
   cfg_over = 1'b0;
   case (cfg_param)
{over}   default: ;
   endcase
end

// ---- Registers --------------------------------------------------------------------------------
reg [2:0] state_q = {s_disabled}, n_state;
reg [15:0] enc_seen_q = 16'd0, n_enc_seen;       // encoder errors at the last RESET command
reg servo_overrun_q = 1'b0, n_servo_overrun;     // the controller skipped a sample
reg load_q = 1'b0, n_load;                       // the reference takes the encoder's position
reg first_pos_q = 1'b0, n_first_pos;             // the standby program's segment 0 heads +
reg first_neg_q = 1'b0, n_first_neg;             // ... or −
reg [2:0] error_q = {e_none}, n_error;
reg amplifier_q = 1'b0, n_amplifier;
reg uart_error_q = 1'b0, n_uart_error;
reg overflow_q = 1'b0, n_overflow;
reg [15:0] bad_crc_q = 16'd0, n_bad_crc;
reg [15:0] bad_frames_q = 16'd0, n_bad_frames;
{regs}reg write_enable_q = 1'b0, n_write_enable;
reg [4:0] write_address_q = 5'd0, n_write_address;
reg [31:0] write_ticks_q = 32'd0, n_write_ticks;
reg [103:0] write_snap_q = 104'd0, n_write_snap;
reg count_enable_q = 1'b0, n_count_enable;
reg [5:0] count_value_q = 6'd0, n_count_value;
reg start_q = 1'b0, n_start;
reg swap_q = 1'b0, n_swap;
reg [31:0] swap_last_q = 32'd0, n_swap_last;
reg stop_q = 1'b0, n_stop;
reg abort_q = 1'b0, n_abort;
reg reply_q = 1'b0, n_reply;
reg [2:0] reply_kind_q = 3'd0, n_reply_kind;
reg [7:0] reply_cmd_q = 8'd0, n_reply_cmd;
reg [7:0] reply_seq_q = 8'd0, n_reply_seq;
reg [7:0] reply_aux_q = 8'd0, n_reply_aux;
reg telemetry_q = 1'b0, n_telemetry;
// The last command with an effect: code, sequence, CRC and its reply.
reg last_valid_q = 1'b0, n_last_valid;
reg [7:0] last_cmd_q = 8'd0, n_last_cmd;
reg [7:0] last_seq_q = 8'd0, n_last_seq;
reg [15:0] last_crc_q = 16'd0, n_last_crc;
reg [2:0] last_kind_q = 3'd0, n_last_kind;
reg [7:0] last_aux_q = 8'd0, n_last_aux;
// The watchdog: clocks of the current millisecond, milliseconds since the last good frame.
reg [31:0] prescale_q = 32'd0, n_prescale;
reg [31:0] watchdog_count_q = 32'd0, n_watchdog_count;
// Telemetry: ticks to the next frame; whether the chain was driven on the last clock.
reg [31:0] telemetry_left_q = 32'd0, n_telemetry_left;
reg was_driven_q = 1'b0, n_was_driven;

// ---- Arguments and axis state: why the command is refused (0: accepted) ----------------------
// The axis moves: a program plays, a stop runs, or v, a or j is not 0.
wire moving = busy || stopping || !at_rest;
wire stop_limits_valid = (stop_jerk_q != 104'd0) && (stop_jerk_q <= stop_accel_q);
// With the controller on, POWER 1 wants a following-error limit.
wire servo_ready = (servo_period_q == 16'd0) || (following_limit_q != 32'd0);
// The stop limits a CONFIGURE would leave valid (0 < jerk <= accel): each parameter's case
// compares the new value with the other register (two comparators side by side, off the
// parameter's multiplexer).
wire jerk_pair_valid = (cfg_value != 104'd0) && (cfg_value <= stop_accel_q);
wire accel_pair_valid = (stop_jerk_q != 104'd0) && (stop_jerk_q <= cfg_value);
wire cfg_pair_valid = (cfg_param == {p_stop_jerk}) ? jerk_pair_valid
   : ((cfg_param == {p_stop_accel}) ? accel_pair_valid : 1'b1);
// SWAP_AT: how far its tick lies beyond the time base (signed, wrap-safe), registered every
// clock (the payload is complete a byte before the frame is): one clock old when the frame is
// executed, and the core arms one clock later, so the time base may have ticked twice by then;
// the core wants three ticks of lead.
reg [63:0] swap_lead_q = 64'd0;
always @(posedge clock) swap_lead_q <= reset ? 64'd0 : (swap_tick - ticks);
wire swap_late = swap_lead_q[63] || (swap_lead_q < 64'd{min_lead});
wire swap_far = !swap_lead_q[63] && (swap_lead_q[62:31] != 32'd0);   // the core compares 32 bits
wire [31:0] swap_before = swap_tick[31:0] - 32'd1;   // the core's swap_last: T − 1, low bits
wire toward_limit = (first_pos_q && limit_pos) || (first_neg_q && limit_neg);
reg [7:0] reason;
always @(*) begin
   reason = 8'd0;
   case (cmd)
   CMD_LOAD_SEGMENT:
      if ((seg_index >= MAX_SEGMENTS) || (seg_ticks == 32'd0)) reason = {r_bad_argument};
      else if (swap_pending) reason = {r_swap_pending};
   CMD_COMMIT:
      if (arg0 > MAX_SEGMENTS) reason = {r_bad_argument};
      else if (swap_pending) reason = {r_swap_pending};
   CMD_START:
      if (state_q == {s_disabled}) reason = {r_not_enabled};
      else if (state_q == {s_error}) reason = {r_axis_error};
      else if (state_q == {s_stopping}) reason = {r_stopping};
      else if (busy) reason = {r_busy};
      else if (stopping) reason = {r_stopping};
      else if (swap_pending) reason = {r_swap_pending};
      else if (standby_count == 6'd0) reason = {r_no_program};
      else if (!at_rest) reason = {r_busy};
      else if (toward_limit) reason = {r_limit};
   CMD_SWAP_AT:
      if (swap_far) reason = {r_bad_argument};
      else if (state_q == {s_disabled}) reason = {r_not_enabled};
      else if (state_q == {s_error}) reason = {r_axis_error};
      else if (state_q == {s_stopping}) reason = {r_stopping};
      else if (stopping) reason = {r_stopping};
      else if (swap_pending) reason = {r_swap_pending};
      else if (standby_count == 6'd0) reason = {r_no_program};
      else if (swap_late) reason = {r_late};
      else if (at_rest && !busy && toward_limit) reason = {r_limit};
   CMD_STOP:
      if (state_q == {s_disabled}) reason = {r_not_enabled};
   CMD_HALT:
      if (state_q == {s_disabled}) reason = {r_not_enabled};
      else if (state_q == {s_error}) reason = {r_axis_error};
      else if (state_q == {s_stopping}) reason = {r_stopping};
   CMD_CONFIGURE:
      if (!param_known(cfg_param) || cfg_value[103] || cfg_over) reason = {r_bad_argument};
      else if (param_at_rest(cfg_param) && moving) reason = {r_busy};
      else if (param_disabled(cfg_param) && (state_q != {s_disabled})) reason = {r_not_disabled};
      else if ((state_q != {s_disabled}) && ((cfg_param == {p_stop_jerk}) || (cfg_param == {p_stop_accel}))
            && !cfg_pair_valid) reason = {r_bad_argument};
   CMD_READ_CONFIG:
      if (!param_known(arg0)) reason = {r_bad_argument};
   CMD_POWER:
      if (arg0 > 8'd1) reason = {r_bad_argument};
      else if (arg0 == 8'd1) begin
         if (state_q == {s_error}) reason = {r_axis_error};
         else if ((state_q == {s_disabled}) && (!stop_limits_valid || !servo_ready))
            reason = {r_not_configured};
      end else if (moving) reason = {r_busy};
   CMD_RESET:
      if ((state_q == {s_error}) && (moving || estop)) reason = {r_axis_error};
   default: ;
   endcase
end

wire retry = has_effect && last_valid_q && (cmd == last_cmd_q) && (seq == last_seq_q)
   && (crc == last_crc_q);
wire expired = (watchdog_ms_q != 32'd0) && (watchdog_count_q >= watchdog_ms_q);
wire settling = start_q || stop_q || swap_q;     // a start, stop or swap the core takes now
wire driven = busy || stopping;

// ---- Next state, in the model's order ------------------------------------------------------
always @(*) begin
   // Pulses last one clock; everything else holds.
   n_write_enable = 1'b0;
   n_count_enable = 1'b0;
   n_start = 1'b0;
   n_swap = 1'b0;
   n_swap_last = swap_last_q;
   n_stop = 1'b0;
   n_abort = 1'b0;
   n_reply = 1'b0;
   n_telemetry = 1'b0;
   n_state = state_q;
   n_enc_seen = enc_seen_q;
   n_servo_overrun = servo_overrun_q;
   n_load = 1'b0;
   n_first_pos = first_pos_q;
   n_first_neg = first_neg_q;
   n_error = error_q;
   n_amplifier = amplifier_q;
   n_uart_error = uart_error_q;
   n_overflow = overflow_q;
   n_bad_crc = bad_crc_q;
   n_bad_frames = bad_frames_q;
{holds}   n_write_address = write_address_q;
   n_write_ticks = write_ticks_q;
   n_write_snap = write_snap_q;
   n_count_value = count_value_q;
   n_reply_kind = reply_kind_q;
   n_reply_cmd = reply_cmd_q;
   n_reply_seq = reply_seq_q;
   n_reply_aux = reply_aux_q;
   n_last_valid = last_valid_q;
   n_last_cmd = last_cmd_q;
   n_last_seq = last_seq_q;
   n_last_crc = last_crc_q;
   n_last_kind = last_kind_q;
   n_last_aux = last_aux_q;
   n_telemetry_left = telemetry_left_q;

   // Telemetry while the chain is driven, and once when it stops being driven, from the period
   // and countdown before this clock (a CONFIGURE of the period, below, restarts the countdown).
   if (telemetry_period_q != 32'd0) begin
      if (tick && driven) begin
         if (telemetry_left_q <= 32'd1) begin
            n_telemetry = 1'b1;
            n_telemetry_left = telemetry_period_q;
         end else n_telemetry_left = telemetry_left_q - 32'd1;
      end
      if (was_driven_q && !driven) begin
         n_telemetry = 1'b1;
         n_telemetry_left = telemetry_period_q;
      end
   end
   n_was_driven = driven;

   // The watchdog: milliseconds since the last good frame (saturating).
   n_prescale = prescale_q + 32'd1;
   n_watchdog_count = watchdog_count_q;
   if (frame) begin
      n_prescale = 32'd0;
      n_watchdog_count = 32'd0;
   end else if (prescale_q + 32'd1 >= CLOCKS_PER_MS) begin
      n_prescale = 32'd0;
      if (watchdog_count_q != 32'hffff_ffff) n_watchdog_count = watchdog_count_q + 32'd1;
   end

   // Frames.
   if (line_error) n_uart_error = 1'b1;
   if (servo_overrun_in) n_servo_overrun = 1'b1;
   if (bad_crc) begin
      n_bad_crc = bad_crc_q + 16'd1;
      if (queue_full) n_overflow = 1'b1;
      else begin
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_cmd = 8'd0;
         n_reply_seq = 8'd0;
         n_reply_aux = {r_bad_crc};
      end
   end else if (dropped) begin
      n_bad_frames = bad_frames_q + 16'd1;
      if (queue_full) n_overflow = 1'b1;
      else begin
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_cmd = 8'd0;
         n_reply_seq = 8'd0;
         n_reply_aux = {r_framing};
      end
   end else if (frame) begin
      n_reply_cmd = cmd;
      n_reply_seq = seq;
      if (queue_full) n_overflow = 1'b1;
      else if (!known || (len != want_len)) begin
         n_bad_frames = bad_frames_q + 16'd1;
         n_reply = 1'b1;
         n_reply_kind = K_NAK;
         n_reply_aux = known ? {r_bad_length} : {r_unknown_command};
      end else if (retry) begin
         // A retry: the same answer, no effect.
         n_reply = 1'b1;
         n_reply_kind = last_kind_q;
         n_reply_aux = last_aux_q;
      end else begin
         // PING: a new host session; no command before it is retried.
         if (cmd == CMD_PING) n_last_valid = 1'b0;
         n_reply = 1'b1;
         n_reply_kind = K_ACK;
         n_reply_aux = 8'd0;
         if (reason != 8'd0) begin
            n_reply_kind = K_NAK;
            n_reply_aux = reason;
         end else case (cmd)
         CMD_PING: n_reply_kind = K_IDENTITY;
         CMD_READ_STATUS: n_reply_kind = K_STATUS;
         CMD_READ_STATE: n_reply_kind = K_STATE;
         CMD_READ_CONFIG: begin
            n_reply_kind = K_CONFIG;
            n_reply_aux = arg0;
         end
         CMD_LOAD_SEGMENT: begin
            n_write_enable = 1'b1;
            n_write_address = seg_index[4:0];
            n_write_ticks = seg_ticks;
            n_write_snap = seg_snap;
            if (seg_index[4:0] == 5'd0) begin
               n_first_pos = !seg_snap[103] && (seg_snap != 104'd0);
               n_first_neg = seg_snap[103];
            end
         end
         CMD_COMMIT: begin
            n_count_enable = 1'b1;
            n_count_value = arg0[5:0];
         end
         CMD_START: begin
            n_start = 1'b1;
            n_state = {s_discrete};
            // The banks swap: the new standby program is empty.
            n_first_pos = 1'b0;
            n_first_neg = 1'b0;
         end
         CMD_SWAP_AT: begin
            n_swap = 1'b1;
            n_swap_last = swap_before;
            n_state = {s_discrete};
            // The banks swap at the tick; no upload is taken before that.
            n_first_pos = 1'b0;
            n_first_neg = 1'b0;
         end
         CMD_STOP:
            if (state_q != {s_error}) begin
               n_stop = 1'b1;
               n_state = {s_stopping};
            end
         CMD_HALT:
            if ((state_q == {s_discrete}) || (state_q == {s_continuous})) n_stop = 1'b1;
         CMD_CONFIGURE: begin
            case (cfg_param)
{set}            default: ;
            endcase
            if (cfg_param == {p_telemetry}) n_telemetry_left = cfg_value[31:0];
         end
         CMD_POWER:
            if (arg0 == 8'd1) begin
               if (state_q == {s_disabled}) begin
                  n_amplifier = 1'b1;
                  n_state = {s_standstill};
                  n_load = 1'b1;                 // MC_Power: the axis holds where it is
               end
            end else begin
               n_amplifier = 1'b0;
               if (state_q == {s_standstill}) n_state = {s_disabled};
            end
         CMD_RESET: begin
            // The sticky flags clear in any state.
            n_uart_error = 1'b0;
            n_overflow = 1'b0;
            n_servo_overrun = 1'b0;
            n_enc_seen = encoder_errors;
            if (state_q == {s_error}) begin
               n_error = {e_none};
               n_state = amplifier_q ? {s_standstill} : {s_disabled};
            end
         end
         default: ;
         endcase
         if (has_effect) begin
            n_last_valid = 1'b1;
            n_last_cmd = cmd;
            n_last_seq = seq;
            n_last_crc = crc;
            n_last_kind = n_reply_kind;
            n_last_aux = n_reply_aux;
         end
      end
   end

   // The axis by itself: the end of a move or a stop (at rest: Standstill; a program that ended
   // moving: a controlled stop into ErrorStop), then the errors (the emergency stop last: it
   // overrides everything).
   if (((n_state == {s_discrete}) || (n_state == {s_continuous}) || (n_state == {s_stopping}))
         && (state_q == n_state) && !busy && !stopping && !settling
         && !(at_rest && swap_pending)) begin   // a swap armed at rest: a start to come
      if (at_rest) n_state = {s_standstill};
      else begin
         n_stop = 1'b1;
         n_state = {s_error};
         n_error = {e_program_end};
      end
   end
   if (expired && ((state_q == {s_discrete}) || (state_q == {s_continuous}))) begin
      n_stop = 1'b1;
      n_state = {s_error};
      n_error = {e_watchdog};
   end
   if ((state_q != {s_error}) && (state_q != {s_disabled})) begin
      if (limit_pos && heading_pos) begin
         n_stop = 1'b1;
         n_state = {s_error};
         n_error = {e_limit_pos};
      end else if (limit_neg && heading_neg) begin
         n_stop = 1'b1;
         n_state = {s_error};
         n_error = {e_limit_neg};
      end
   end
   if (following_fault && n_amplifier) begin
      n_abort = 1'b1;
      n_stop = 1'b0;
      n_start = 1'b0;
      n_swap = 1'b0;
      n_amplifier = 1'b0;
      n_state = {s_error};
      n_error = {e_following};
   end
   if (estop && !((state_q == {s_error}) && (error_q == {e_estop}))) begin
      n_abort = 1'b1;
      n_stop = 1'b0;
      n_start = 1'b0;
      n_swap = 1'b0;
      n_amplifier = 1'b0;
      n_state = {s_error};
      n_error = {e_estop};
   end

end

always @(posedge clock) begin
   if (reset) begin
      state_q <= {s_disabled};
      enc_seen_q <= 16'd0;
      servo_overrun_q <= 1'b0;
      load_q <= 1'b0;
      first_pos_q <= 1'b0;
      first_neg_q <= 1'b0;
      error_q <= {e_none};
      amplifier_q <= 1'b0;
      uart_error_q <= 1'b0;
      overflow_q <= 1'b0;
      bad_crc_q <= 16'd0;
      bad_frames_q <= 16'd0;
{resets}      write_enable_q <= 1'b0;
      write_address_q <= 5'd0;
      write_ticks_q <= 32'd0;
      write_snap_q <= 104'd0;
      count_enable_q <= 1'b0;
      count_value_q <= 6'd0;
      start_q <= 1'b0;
      swap_q <= 1'b0;
      swap_last_q <= 32'd0;
      stop_q <= 1'b0;
      abort_q <= 1'b0;
      reply_q <= 1'b0;
      reply_kind_q <= 3'd0;
      reply_cmd_q <= 8'd0;
      reply_seq_q <= 8'd0;
      reply_aux_q <= 8'd0;
      telemetry_q <= 1'b0;
      last_valid_q <= 1'b0;
      last_cmd_q <= 8'd0;
      last_seq_q <= 8'd0;
      last_crc_q <= 16'd0;
      last_kind_q <= 3'd0;
      last_aux_q <= 8'd0;
      prescale_q <= 32'd0;
      watchdog_count_q <= 32'd0;
      telemetry_left_q <= 32'd0;
      was_driven_q <= 1'b0;
   end else begin
      state_q <= n_state;
      enc_seen_q <= n_enc_seen;
      servo_overrun_q <= n_servo_overrun;
      load_q <= n_load;
      first_pos_q <= n_first_pos;
      first_neg_q <= n_first_neg;
      error_q <= n_error;
      amplifier_q <= n_amplifier;
      uart_error_q <= n_uart_error;
      overflow_q <= n_overflow;
      bad_crc_q <= n_bad_crc;
      bad_frames_q <= n_bad_frames;
{clocked}      write_enable_q <= n_write_enable;
      write_address_q <= n_write_address;
      write_ticks_q <= n_write_ticks;
      write_snap_q <= n_write_snap;
      count_enable_q <= n_count_enable;
      count_value_q <= n_count_value;
      start_q <= n_start;
      swap_q <= n_swap;
      swap_last_q <= n_swap_last;
      stop_q <= n_stop;
      abort_q <= n_abort;
      reply_q <= n_reply;
      reply_kind_q <= n_reply_kind;
      reply_cmd_q <= n_reply_cmd;
      reply_seq_q <= n_reply_seq;
      reply_aux_q <= n_reply_aux;
      telemetry_q <= n_telemetry;
      last_valid_q <= n_last_valid;
      last_cmd_q <= n_last_cmd;
      last_seq_q <= n_last_seq;
      last_crc_q <= n_last_crc;
      last_kind_q <= n_last_kind;
      last_aux_q <= n_last_aux;
      prescale_q <= n_prescale;
      watchdog_count_q <= n_watchdog_count;
      telemetry_left_q <= n_telemetry_left;
      was_driven_q <= n_was_driven;
   end
end

always @(*) begin
   write_enable = write_enable_q;
   write_address = write_address_q;
   write_ticks = write_ticks_q;
   write_snap = write_snap_q;
   count_enable = count_enable_q;
   count_value = count_value_q;
   start = start_q;
   swap = swap_q;
   swap_last = swap_last_q;
   stop = stop_q;
   abort_move = abort_q;
   load = load_q;
   servo_overrun = servo_overrun_q;
{outs}   state = state_q;
   error = error_q;
   amplifier = amplifier_q;
   uart_error = uart_error_q;
   reply_overflow = overflow_q;
   encoder_errors_seen = enc_seen_q;
   // READ_CONFIG's value, for the reply transmitter.
   read_value = {d_bits}'d0;
   case (read_param)
{read}   default: ;
   endcase
   bad_crc_count = bad_crc_q;
   bad_frames_count = bad_frames_q;
   reply = reply_q;
   reply_kind = reply_kind_q;
   reply_cmd = reply_cmd_q;
   reply_seq = reply_seq_q;
   reply_aux = reply_aux_q;
   telemetry = telemetry_q;
end
"#,
        tick_div = d.tick_div,
        clocks_per_ms = d.clocks_per_ms,
        watchdog = DEFAULT_WATCHDOG_MS,
        input_polarity = input_polarity,
        at_rest_param = at_rest_param.join(" || "),
        disabled_param = disabled_param.join(" || "),
        max_segments = max_segments,
        seg_index = protocol_v::received_field("payload", n_seg, 0, 1),
        seg_ticks = protocol_v::received_field("payload", n_seg, 1, 4),
        seg_snap = protocol_v::received_field("payload", n_seg, 5, 13),
        cfg_param = protocol_v::received_field("payload", n_cfg, 0, 1),
        cfg_value = protocol_v::received_field("payload", n_cfg, 1, 13),
        swap_tick = protocol_v::received_field(
            "payload",
            spec(snapgen_model::protocol::code::SWAP_AT).len as usize,
            0,
            8
        ),
        table = table,
        known_param = known_param.join(" || "),
        over = over,
        set = set,
        regs = regs,
        holds = holds,
        resets = resets,
        clocked = clocked,
        outs = outs,
        s_disabled = s(AxisState::Disabled),
        s_standstill = s(AxisState::Standstill),
        s_discrete = s(AxisState::DiscreteMotion),
        s_continuous = s(AxisState::ContinuousMotion),
        s_stopping = s(AxisState::Stopping),
        s_error = s(AxisState::ErrorStop),
        e_none = e(ErrorId::None),
        e_estop = e(ErrorId::EmergencyStop),
        e_limit_pos = e(ErrorId::LimitPositive),
        e_limit_neg = e(ErrorId::LimitNegative),
        e_watchdog = e(ErrorId::Watchdog),
        e_program_end = e(ErrorId::ProgramEnd),
        e_following = e(ErrorId::FollowingError),
        read = read,
        d_bits = D_BITS,
        r_bad_crc = r(Reason::BadCrc),
        r_bad_length = r(Reason::BadLength),
        r_unknown_command = r(Reason::UnknownCommand),
        r_busy = r(Reason::Busy),
        r_bad_argument = r(Reason::BadArgument),
        r_no_program = r(Reason::NoProgram),
        r_framing = r(Reason::Framing),
        r_not_enabled = r(Reason::NotEnabled),
        r_axis_error = r(Reason::AxisError),
        r_stopping = r(Reason::Stopping),
        r_not_configured = r(Reason::NotConfigured),
        r_limit = r(Reason::Limit),
        r_not_disabled = r(Reason::NotDisabled),
        r_late = r(Reason::Late),
        min_lead = snapgen_model::io::executor::SWAP_MIN_LEAD,
        r_swap_pending = r(Reason::SwapPending),
        p_stop_jerk = param_name(Param::StopJerk),
        p_stop_accel = param_name(Param::StopAccel),
        p_telemetry = param_name(Param::TelemetryPeriod),
    );
    protocol_v::with_params(&protocol_v::all(), &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn executor_is_synthesizable() {
        crate::synth_check::synth_block("executor", Executor::default());
    }

    #[test]
    fn every_code_comes_from_the_protocol_table() {
        let v = executor_verilog(&crate::io_top::default_dividers(), 0);
        for c in COMMANDS {
            assert!(
                v.contains(&format!("localparam [7:0] CMD_{} = 8'd{};", c.name, c.code)),
                "{}",
                c.name
            );
        }
        // No command code typed as a literal in a case label.
        assert!(!v.contains("8'h0"), "a literal code");
    }
}
