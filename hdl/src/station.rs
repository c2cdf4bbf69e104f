//! The station: the motion core behind the command executor, with the encoder decoder, the
//! PWM generator, the limit-switch and emergency-stop inputs and the amplifier enable; all of
//! the I/O top but its transport (`snapgen_io_station`, in `snapgen_io.v`). A front hands it
//! the command stream's bytes and takes its replies' bytes: the UART of [`crate::io_top`], the
//! AXI4-Lite slave of `snapgen_axi.v`. Its reference, clock for clock, is
//! `snapgen_model::station::Station`.
//!
//! ```text
//! link_valid/data → ByteFifo → FrameRx → Executor ─→ MotionCore (sequencer, stop unit, chain)
//!                                          │  ↑ status, registers
//!                                          ↓  │
//! reply_ready/data ← ByteFifo ← ReplyTx ← ReplyQueue          StatusBlock → status
//! enc_a/b/i → QuadratureDecoder → encoder count;  limit±, e-stop → InputFilter → Executor
//! chain x, v, a + encoder count → Servo (PID + feed-forward, following-error limit) → duty
//! pwm/dir ← PwmGenerator (off while the amplifier is disabled);  amplifier
//! ```
//!
//! LEDs: idle, busy (a program plays or a stop runs), fault (ErrorStop, a framing error on the
//! link or an encoder error seen), heartbeat. `status` is the status block as the device would report
//! it now: for co-simulation and debugging (a board top may leave it open; synthesis trims it).

use rust_hdl::prelude::*;
use snapgen_model::device::Design;
use snapgen_spec::AxisState;

use crate::block_with_ports;
use crate::byte_fifo::ByteFifo;
use crate::core::MotionCore;
use crate::emit::{Note, Waiver};
use crate::executor::Executor;
use crate::frame_rx::FrameRx;
use crate::input_filter::InputFilter;
use crate::pwm::PwmGenerator;
use crate::quadrature::QuadratureDecoder;
use crate::reply_queue::ReplyQueue;
use crate::reply_tx::ReplyTx;
use crate::servo::Servo;
use crate::status_block::{FlagsWord, StatusBlock};

const _: () = assert!(
    crate::servo::REFERENCE_LOW == 64
        && crate::servo::VELOCITY_LOW == 48
        && crate::servo::ACCEL_LOW == 40
);

/// Lint waivers of the station, written into its Verilog beside each declaration.
pub const WAIVERS: [Waiver; 7] = [
    unused(
        "encoder_index_seen",
        "the index pulse is counted for a later homing command",
    ),
    unused(
        "encoder_index_count",
        "the index pulse is counted for a later homing command",
    ),
    unused(
        "rx_fifo_full",
        "the frame receiver takes a byte every clock: it never fills",
    ),
    unused(
        "core_active_bank",
        "the bank is internal to the core; the status reports playing/done",
    ),
    unused(
        "core_segment",
        "the status reports ticks and position, not the segment index",
    ),
    unused(
        "core_stop_over",
        "reported through the status block's STOP_OVER_LIMITS flag input",
    ),
    unused(
        "exec_input_polarity",
        "bit by bit: each input's polarity is one bit of it",
    ),
];

const fn unused(signal: &'static str, reason: &'static str) -> Waiver {
    Waiver {
        module: "station",
        signal,
        note: Note::LintOff("UNUSEDSIGNAL"),
        reason,
    }
}

snapgen_spec::with_station_ports!(block_with_ports! {
    /// The station; its ports are the spec's `with_station_ports!` list.
    pub struct Station(design: Design) {
        rx_fifo: ByteFifo = Default::default(),
        frames: FrameRx = Default::default(),
        exec: Executor = Executor::new(design.dividers, design.input_polarity),
        core: MotionCore = Default::default(),
        queue: ReplyQueue = Default::default(),
        reply_tx: ReplyTx = ReplyTx::new(design.identity()),
        tx_fifo: ByteFifo = Default::default(),
        encoder: QuadratureDecoder<32> = Default::default(),
        pwm_gen: PwmGenerator = Default::default(),
        servo: Servo = Default::default(),
        flags_word: FlagsWord = Default::default(),
        status_block: StatusBlock = Default::default(),
        limit_pos_in: InputFilter = InputFilter::new(false),
        limit_neg_in: InputFilter = InputFilter::new(false),
        estop_in: InputFilter = InputFilter::new(false),
        heartbeat: DFF<Bits<32>> = Default::default(),
        limit_pos_seen: Signal<Local, Bit> = Default::default(),
        limit_neg_seen: Signal<Local, Bit> = Default::default(),
        estop_seen: Signal<Local, Bit> = Default::default(),
        encoder_error: Signal<Local, Bit> = Default::default(),
        timeout: Constant<Bits<32>> = Constant::new(u64::from(design.dividers.frame_timeout).into()),
        beat_mask: Constant<Bits<32>> = Constant::new((1u64 << design.dividers.heartbeat_bit).into()),
        one: Constant<Bits<32>> = Constant::new(1.into()),
        zero32: Constant<Bits<32>> = Constant::new(0.into()),
        zero16: Constant<Bits<16>> = Constant::new(0.into()),
        error_stop: Constant<Bits<8>> = Constant::new((AxisState::ErrorStop as u64).into()),
    }
});

impl Station {
    /// The station for `design` (its dividers, and its identity for PING).
    pub fn new(design: Design) -> Self {
        Station::build(design)
    }
}

impl Default for Station {
    fn default() -> Self {
        Station::new(crate::defaults::default_design())
    }
}

impl Logic for Station {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(
            self,
            clock,
            rx_fifo,
            frames,
            exec,
            core,
            queue,
            reply_tx,
            tx_fifo,
            encoder,
            pwm_gen,
            servo,
            limit_pos_in,
            limit_neg_in,
            estop_in
        );
        dff_setup!(self, clock, heartbeat);
        self.heartbeat.d.next = self.heartbeat.q.val() + self.one.val();
        // Receive path: received bytes pass through a small FIFO; the frame receiver takes
        // one per clock.
        self.rx_fifo.write.next = self.link_valid.val();
        self.rx_fifo.write_data.next = self.link_data.val();
        self.rx_fifo.read.next = !self.rx_fifo.empty.val();
        self.frames.reset.next = self.reset.val();
        self.frames.data.next = self.rx_fifo.data.val();
        self.frames.valid.next = !self.rx_fifo.empty.val();
        self.frames.line_error.next = self.link_error.val();
        self.frames.timeout.next = self.timeout.val();
        // Limit switches and the emergency stop: synchronised, filtered, polarity applied.
        self.limit_pos_in.pin.next = self.limit_pos.val();
        self.limit_neg_in.pin.next = self.limit_neg.val();
        self.estop_in.pin.next = self.estop.val();
        self.limit_pos_in.filter.next = self.exec.input_filter.val();
        self.limit_neg_in.filter.next = self.exec.input_filter.val();
        self.estop_in.filter.next = self.exec.input_filter.val();
        self.limit_pos_seen.next =
            self.limit_pos_in.level.val() ^ self.exec.input_polarity.val().get_bit(0);
        self.limit_neg_seen.next =
            self.limit_neg_in.level.val() ^ self.exec.input_polarity.val().get_bit(1);
        self.estop_seen.next =
            self.estop_in.level.val() ^ self.exec.input_polarity.val().get_bit(2);
        // Executor.
        self.exec.reset.next = self.reset.val();
        self.exec.frame.next = self.frames.frame.val();
        self.exec.bad_crc.next = self.frames.bad_crc.val();
        self.exec.dropped.next = self.frames.dropped.val();
        self.exec.line_error.next = self.link_error.val();
        self.exec.cmd.next = self.frames.cmd.val();
        self.exec.seq.next = self.frames.seq.val();
        self.exec.len.next = self.frames.len.val();
        self.exec.payload.next = self.frames.payload.val();
        self.exec.crc.next = self.frames.crc.val();
        self.exec.busy.next = self.core.busy.val();
        self.exec.stopping.next = self.core.stopping.val();
        self.exec.standby_count.next = self.core.standby_count.val();
        self.exec.ticks.next = self.core.ticks.val();
        self.exec.swap_pending.next = self.core.swap_pending.val();
        self.exec.tick.next = self.core.tick.val();
        self.exec.at_rest.next = self.core.at_rest.val();
        self.exec.encoder_errors.next = self.encoder.errors.val();
        self.exec.following_fault.next = self.servo.fault.val();
        self.exec.servo_overrun_in.next = self.servo.overrun.val();
        self.exec.read_param.next = self.reply_tx.read_param.val();
        self.exec.heading_pos.next = self.core.heading_pos.val();
        self.exec.heading_neg.next = self.core.heading_neg.val();
        self.exec.queue_full.next = self.queue.full.val();
        self.exec.limit_pos.next = self.limit_pos_seen.val();
        self.exec.limit_neg.next = self.limit_neg_seen.val();
        self.exec.estop.next = self.estop_seen.val();
        // Motion core.
        self.core.reset.next = self.reset.val();
        self.core.tick_div.next = self.exec.tick_divider.val();
        self.core.start.next = self.exec.start.val();
        self.core.swap.next = self.exec.swap.val();
        self.core.swap_last.next = self.exec.swap_last.val();
        self.core.abort_move.next = self.exec.abort_move.val();
        self.core.stop.next = self.exec.stop.val();
        self.core.load.next = self.exec.load.val();
        self.core.load_position.next = self.encoder.count.val();
        self.core.stop_jerk.next = self.exec.stop_jerk.val();
        self.core.stop_accel.next = self.exec.stop_accel.val();
        self.core.write_enable.next = self.exec.write_enable.val();
        self.core.write_address.next = self.exec.write_address.val();
        self.core.write_ticks.next = self.exec.write_ticks.val();
        self.core.write_snap.next = self.exec.write_snap.val();
        self.core.count_enable.next = self.exec.count_enable.val();
        self.core.count_value.next = self.exec.count_value.val();
        // Encoder.
        self.encoder.a.next = self.enc_a.val();
        self.encoder.b.next = self.enc_b.val();
        self.encoder.index.next = self.enc_i.val();
        self.encoder.filter.next = self.exec.encoder_filter.val();
        self.encoder.clear.next = self.reset.val();
        // Encoder errors since reset or the last RESET command.
        self.encoder_error.next = self.encoder.errors.val() != self.exec.encoder_errors_seen.val();
        // The status block: its flags, then its fields.
        self.flags_word.playing.next = self.core.busy.val();
        self.flags_word.done.next = self.core.done.val();
        self.flags_word.cut.next = self.core.aborted.val();
        self.flags_word.stopping.next = self.core.stopping.val();
        self.flags_word.stop_over.next = self.core.stop_over.val();
        self.flags_word.amplifier.next = self.exec.amplifier.val();
        self.flags_word.limit_pos.next = self.limit_pos_seen.val();
        self.flags_word.limit_neg.next = self.limit_neg_seen.val();
        self.flags_word.estop.next = self.estop_seen.val();
        self.flags_word.encoder_error.next = self.encoder_error.val();
        self.flags_word.uart_error.next = self.exec.uart_error.val();
        self.flags_word.reply_overflow.next = self.exec.reply_overflow.val();
        self.flags_word.servo_overrun.next = self.exec.servo_overrun.val();
        self.flags_word.swap_pending.next = self.core.swap_pending.val();
        self.status_block.state.next = self.exec.state.val();
        self.status_block.error.next = self.exec.error.val();
        self.status_block.flags.next = self.flags_word.flags.val();
        self.status_block.tick_count.next = self.core.tick_count.val();
        self.status_block.position.next = self.core.position.val();
        // rust-hdl workaround: the bit index is a literal (`#[hdl_gen]` copies const names
        // into the Verilog); the top 32 of the 104-bit velocity register.
        self.status_block.velocity.next = self.core.v.val().get_bits::<32>(72);
        self.status_block.encoder.next = self.encoder.count.val();
        self.status_block.bad_crc.next = self.exec.bad_crc_count.val();
        self.status_block.bad_frames.next = self.exec.bad_frames_count.val();
        self.status_block.following_peak.next = self.servo.peak.val();
        self.status_block.duty.next = self.servo.duty.val();
        self.status.next = self.status_block.status.val();
        // Replies and telemetry.
        self.queue.reset.next = self.reset.val();
        self.queue.push.next = self.exec.reply.val();
        self.queue.push_kind.next = self.exec.reply_kind.val();
        self.queue.push_cmd.next = self.exec.reply_cmd.val();
        self.queue.push_seq.next = self.exec.reply_seq.val();
        self.queue.push_aux.next = self.exec.reply_aux.val();
        self.queue.pop.next = self.reply_tx.pop.val();
        self.reply_tx.reset.next = self.reset.val();
        self.reply_tx.head_valid.next = self.queue.head_valid.val();
        self.reply_tx.head_kind.next = self.queue.head_kind.val();
        self.reply_tx.head_cmd.next = self.queue.head_cmd.val();
        self.reply_tx.head_seq.next = self.queue.head_seq.val();
        self.reply_tx.head_aux.next = self.queue.head_aux.val();
        self.reply_tx.telemetry.next = self.exec.telemetry.val();
        self.reply_tx.fifo_full.next = self.tx_fifo.full.val();
        self.reply_tx.status.next = self.status_block.status.val();
        self.reply_tx.tick_divider.next = self.exec.tick_divider.val();
        self.reply_tx.stop_jerk.next = self.exec.stop_jerk.val();
        self.reply_tx.stop_accel.next = self.exec.stop_accel.val();
        self.reply_tx.config_value.next = self.exec.read_value.val();
        self.reply_tx.ticks.next = self.core.ticks.val();
        self.reply_tx.x.next = self.core.x.val();
        self.reply_tx.v.next = self.core.v.val();
        self.reply_tx.a.next = self.core.a.val();
        self.reply_tx.j.next = self.core.j.val();
        // Transmit path: a FIFO the front takes from.
        self.tx_fifo.write.next = self.reply_tx.fifo_write.val();
        self.tx_fifo.write_data.next = self.reply_tx.fifo_data.val();
        self.tx_fifo.read.next = !self.tx_fifo.empty.val() & self.reply_take.val();
        self.reply_ready.next = !self.tx_fifo.empty.val();
        self.reply_data.next = self.tx_fifo.data.val();
        // The chain's registers, for a front's snapshot.
        self.ticks.next = self.core.ticks.val();
        self.x.next = self.core.x.val();
        self.v.next = self.core.v.val();
        self.a.next = self.core.a.val();
        self.j.next = self.core.j.val();
        // The position controller; its duty drives the PWM (off without the amplifier).
        self.servo.reset.next = self.reset.val();
        // Not on the clock the reference loads the encoder's position (POWER 1): the
        // controller's first sample comes after the load, never from the old reference.
        self.servo.enable.next = self.exec.amplifier.val() & !self.exec.load.val();
        self.servo.tick.next = self.core.tick.val();
        self.servo.start.next = self.exec.start.val();
        // rust-hdl workaround: literal bit indices (crate::servo's REFERENCE_LOW, VELOCITY_LOW,
        // ACCEL_LOW; checked below).
        self.servo.ref_position.next = self.core.x.val().get_bits::<48>(64);
        self.servo.velocity.next = self.core.v.val().get_bits::<56>(48);
        self.servo.accel.next = self.core.a.val().get_bits::<64>(40);
        self.servo.count.next = self.encoder.count.val();
        self.servo.servo_period.next = self.exec.servo_period.val();
        self.servo.kp.next = self.exec.kp.val();
        self.servo.ki.next = self.exec.ki.val();
        self.servo.kd.next = self.exec.kd.val();
        self.servo.kv.next = self.exec.kv.val();
        self.servo.ka.next = self.exec.ka.val();
        self.servo.integral_limit.next = self.exec.integral_limit.val();
        self.servo.output_limit.next = self.exec.output_limit.val();
        self.servo.following_limit.next = self.exec.following_limit.val();
        self.servo.d_filter.next = self.exec.d_filter.val();
        self.pwm_gen.period.next = self.exec.pwm_period.val();
        self.pwm_gen.duty.next = self.servo.duty.val();
        self.pwm_gen.enable.next = self.exec.pwm_period.val() != self.zero16.val();
        self.pwm_gen.fault.next = !self.exec.amplifier.val();
        self.pwm.next = self.pwm_gen.pwm.val();
        self.dir.next = self.pwm_gen.dir.val();
        self.amplifier.next = self.exec.amplifier.val();
        // LEDs.
        self.led_idle.next = !self.core.busy.val() & !self.core.stopping.val();
        self.led_busy.next = self.core.busy.val() | self.core.stopping.val();
        self.led_fault.next = (self.exec.state.val() == self.error_stop.val())
            | self.exec.uart_error.val()
            | self.encoder_error.val();
        self.led_heartbeat.next =
            (self.heartbeat.q.val() & self.beat_mask.val()) != self.zero32.val();
    }
}

// (Synthesised whole by the I/O top's test, which holds it: `io_top::tests`.)
