//! The top-level core: the motion core behind the UART command interface, with the encoder
//! decoder and the PWM generator (what a board top instantiates; `snapgen verilog --top io`).
//!
//! ```text
//! uart_rx → UartRx → ByteFifo → FrameRx → Executor → MotionCore
//!                                  │          │ status
//! uart_tx ← UartTx ← ByteFifo ← ReplyTx ←─────┘
//! enc_a/b/i → QuadratureDecoder → encoder count (status, PWM)
//! pwm/dir ← PwmGenerator (duty = position − encoder count, saturated: a unity-gain
//!           proportional position loop; period set by CONFIGURE)
//! ```
//!
//! LEDs: 0 idle, 1 busy, 2 fault (aborted, a UART framing error or an encoder error seen),
//! 3 heartbeat.

use rust_hdl::prelude::*;

use crate::byte_fifo::ByteFifo;
use crate::core::MotionCore;
use crate::executor::Executor;
use crate::frame_rx::FrameRx;
use crate::pwm::PwmGenerator;
use crate::quadrature::QuadratureDecoder;
use crate::reply_tx::ReplyTx;
use crate::uart_rx::UartRx;
use crate::uart_tx::UartTx;

/// Top-level settings fixed at generation.
#[derive(Clone, Copy, Debug)]
pub struct IoTopConfig {
    /// Fabric clocks per UART bit (1085: 115 200 baud at 125 MHz).
    pub uart_divisor: u16,
    /// Inter-byte timeout in clocks (2 500 000: 20 ms at 125 MHz).
    pub frame_timeout: u32,
    /// Tick divider after reset (1249: Ts = 10 µs at 125 MHz).
    pub tick_div: u32,
    /// Heartbeat LED: bit of a free-running counter (26: ~1 Hz at 125 MHz).
    pub heartbeat_bit: usize,
}

impl Default for IoTopConfig {
    fn default() -> Self {
        IoTopConfig {
            uart_divisor: snapgen_model::io::uart::DIVISOR_115200_AT_125MHZ,
            frame_timeout: 2_500_000,
            tick_div: 1249,
            heartbeat_bit: 26,
        }
    }
}

/// The top-level core.
#[derive(LogicBlock)]
pub struct IoTop {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset, active high.
    pub reset: Signal<In, Bit>,
    /// UART receive pin.
    pub uart_rx: Signal<In, Bit>,
    /// UART transmit pin.
    pub uart_tx: Signal<Out, Bit>,
    /// Encoder channel A.
    pub enc_a: Signal<In, Bit>,
    /// Encoder channel B.
    pub enc_b: Signal<In, Bit>,
    /// Encoder index.
    pub enc_i: Signal<In, Bit>,
    /// PWM output.
    pub pwm: Signal<Out, Bit>,
    /// Direction output.
    pub dir: Signal<Out, Bit>,
    /// LED 0: idle.
    pub led_idle: Signal<Out, Bit>,
    /// LED 1: busy.
    pub led_busy: Signal<Out, Bit>,
    /// LED 2: fault.
    pub led_fault: Signal<Out, Bit>,
    /// LED 3: heartbeat.
    pub led_heartbeat: Signal<Out, Bit>,
    /// The reference position in output LSBs, for simulation (a virtual board's encoder
    /// follows it) and a future motor model; a board top leaves it unconnected.
    pub ref_position: Signal<Out, Bits<32>>,
    uart_in: UartRx,
    frames: FrameRx,
    exec: Executor,
    core: MotionCore,
    replies: ReplyTx,
    fifo: ByteFifo,
    rx_fifo: ByteFifo,
    uart_out: UartTx,
    encoder: QuadratureDecoder<32>,
    pwm_gen: PwmGenerator,
    heartbeat: DFF<Bits<32>>,
    error: Signal<Local, Bits<32>>,
    duty: Signal<Local, Bits<16>>,
    divisor: Constant<Bits<16>>,
    timeout: Constant<Bits<32>>,
    tick_div_default: Constant<Bits<32>>,
    beat_mask: Constant<Bits<32>>,
    one: Constant<Bits<32>>,
    zero32: Constant<Bits<32>>,
    zero17: Constant<Bits<17>>,
    ones17: Constant<Bits<17>>,
    duty_max: Constant<Bits<16>>,
    duty_min: Constant<Bits<16>>,
    zero8: Constant<Bits<8>>,
    zero16: Constant<Bits<16>>,
    state_busy: Constant<Bits<8>>,
    state_done: Constant<Bits<8>>,
    state_aborted: Constant<Bits<8>>,
}

impl IoTop {
    /// The top with these settings.
    pub fn new(cfg: IoTopConfig) -> Self {
        IoTop {
            clock: Default::default(),
            reset: Default::default(),
            uart_rx: Default::default(),
            uart_tx: Default::default(),
            enc_a: Default::default(),
            enc_b: Default::default(),
            enc_i: Default::default(),
            pwm: Default::default(),
            dir: Default::default(),
            led_idle: Default::default(),
            led_busy: Default::default(),
            led_fault: Default::default(),
            led_heartbeat: Default::default(),
            ref_position: Default::default(),
            uart_in: Default::default(),
            frames: Default::default(),
            exec: Default::default(),
            core: Default::default(),
            replies: Default::default(),
            fifo: Default::default(),
            rx_fifo: Default::default(),
            uart_out: Default::default(),
            encoder: Default::default(),
            pwm_gen: Default::default(),
            heartbeat: Default::default(),
            error: Default::default(),
            duty: Default::default(),
            divisor: Constant::new(u64::from(cfg.uart_divisor).into()),
            timeout: Constant::new(u64::from(cfg.frame_timeout).into()),
            tick_div_default: Constant::new(u64::from(cfg.tick_div).into()),
            beat_mask: Constant::new((1u64 << cfg.heartbeat_bit).into()),
            one: Constant::new(1.into()),
            zero32: Constant::new(0.into()),
            zero17: Constant::new(0.into()),
            ones17: Constant::new(0x1FFFF.into()),
            duty_max: Constant::new(0x7FFF.into()),
            duty_min: Constant::new(0x8000.into()),
            zero8: Constant::new(0.into()),
            zero16: Constant::new(0.into()),
            state_busy: Constant::new(1.into()),
            state_done: Constant::new(2.into()),
            state_aborted: Constant::new(4.into()),
        }
    }
}

impl Default for IoTop {
    fn default() -> Self {
        IoTop::new(IoTopConfig::default())
    }
}

impl Logic for IoTop {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(
            self, clock, uart_in, rx_fifo, frames, exec, core, replies, fifo, uart_out, encoder,
            pwm_gen
        );
        dff_setup!(self, clock, heartbeat);
        self.heartbeat.d.next = self.heartbeat.q.val() + self.one.val();
        // Receive path.
        self.uart_in.rx.next = self.uart_rx.val();
        self.uart_in.divisor.next = self.divisor.val();
        self.frames.reset.next = self.reset.val();
        // Received bytes pass through a small FIFO; the frame receiver takes one per clock.
        self.rx_fifo.write.next = self.uart_in.valid.val();
        self.rx_fifo.write_data.next = self.uart_in.data.val();
        self.rx_fifo.read.next = !self.rx_fifo.empty.val();
        self.frames.data.next = self.rx_fifo.data.val();
        self.frames.valid.next = !self.rx_fifo.empty.val();
        self.frames.line_error.next = self.uart_in.framing_error.val();
        self.frames.timeout.next = self.timeout.val();
        // Executor.
        self.exec.reset.next = self.reset.val();
        self.exec.frame.next = self.frames.frame.val();
        self.exec.bad_crc.next = self.frames.bad_crc.val();
        self.exec.dropped.next = self.frames.dropped.val();
        self.exec.line_error.next = self.uart_in.framing_error.val();
        self.exec.cmd.next = self.frames.cmd.val();
        self.exec.seq.next = self.frames.seq.val();
        self.exec.len.next = self.frames.len.val();
        self.exec.seg_index.next = self.frames.seg_index.val();
        self.exec.seg_ticks.next = self.frames.seg_ticks.val();
        self.exec.seg_snap.next = self.frames.seg_snap.val();
        self.exec.commit_count.next = self.frames.commit_count.val();
        self.exec.commit_first.next = self.frames.commit_first.val();
        self.exec.cfg_param.next = self.frames.cfg_param.val();
        self.exec.cfg_value.next = self.frames.cfg_value.val();
        self.exec.busy.next = self.core.busy.val();
        self.exec.tick.next = self.core.tick.val();
        self.exec.standby_count.next = self.core.standby_count.val();
        self.exec.tick_div_default.next = self.tick_div_default.val();
        // Motion core.
        self.core.reset.next = self.reset.val();
        self.core.tick_div.next = self.exec.tick_div.val();
        self.core.start.next = self.exec.start.val();
        self.core.stop.next = self.exec.stop.val();
        self.core.write_enable.next = self.exec.write_enable.val();
        self.core.write_address.next = self.exec.write_address.val();
        self.core.write_ticks.next = self.exec.write_ticks.val();
        self.core.write_snap.next = self.exec.write_snap.val();
        self.core.count_enable.next = self.exec.count_enable.val();
        self.core.count_value.next = self.exec.count_value.val();
        self.core.cruise_value.next = self.exec.cruise_value.val();
        self.core.soft_stop.next = self.exec.soft_stop.val();
        // Encoder.
        self.encoder.a.next = self.enc_a.val();
        self.encoder.b.next = self.enc_b.val();
        self.encoder.index.next = self.enc_i.val();
        self.encoder.filter.next = self.exec.encoder_filter.val().get_bits::<16>(0);
        self.encoder.clear.next = self.reset.val();
        // Replies and telemetry.
        self.replies.reset.next = self.reset.val();
        self.replies.request.next = self.exec.reply.val();
        self.replies.kind.next = self.exec.reply_kind.val();
        self.replies.cmd.next = self.exec.reply_cmd.val();
        self.replies.seq.next = self.exec.reply_seq.val();
        self.replies.reason.next = self.exec.reply_reason.val();
        self.replies.telemetry.next = self.exec.telemetry.val();
        self.replies.state.next = self.zero8.val();
        if self.core.busy.val() {
            self.replies.state.next = self.state_busy.val();
        }
        if self.core.done.val() {
            self.replies.state.next = self.state_done.val();
        }
        if self.core.aborted.val() {
            self.replies.state.next = self.state_aborted.val();
        }
        // Error flags: bit 0 encoder error seen, bit 1 UART framing error seen.
        if self.encoder.errors.val() != self.zero16.val() {
            self.replies.errors.next = self.exec.errors.val() | self.state_busy.val();
        } else {
            self.replies.errors.next = self.exec.errors.val();
        }
        self.replies.tick_count.next = self.core.tick_count.val();
        self.replies.position.next = self.core.position.val();
        self.replies.velocity.next = self.core.v.val().get_bits::<32>(72);
        self.replies.encoder.next = self.encoder.count.val();
        self.replies.bad_crc.next = self.exec.bad_crc_count.val();
        self.replies.bad_frames.next = self.exec.bad_frames_count.val();
        self.replies.x.next = self.core.x.val();
        self.replies.fifo_full.next = self.fifo.full.val();
        // Transmit path: FIFO into the UART.
        self.fifo.write.next = self.replies.fifo_write.val();
        self.fifo.write_data.next = self.replies.fifo_data.val();
        self.fifo.read.next = !self.fifo.empty.val() & !self.uart_out.busy.val();
        self.uart_out.start.next = !self.fifo.empty.val() & !self.uart_out.busy.val();
        self.uart_out.data.next = self.fifo.data.val();
        self.uart_out.divisor.next = self.divisor.val();
        self.uart_tx.next = self.uart_out.tx.val();
        // PWM: duty = position − encoder count, saturated to 16 bits.
        self.error.next = self.core.position.val() - self.encoder.count.val();
        if self.error.val().get_bit(31) {
            if self.error.val().get_bits::<17>(15) == self.ones17.val() {
                self.duty.next = self.error.val().get_bits::<16>(0);
            } else {
                self.duty.next = self.duty_min.val();
            }
        } else if self.error.val().get_bits::<17>(15) == self.zero17.val() {
            self.duty.next = self.error.val().get_bits::<16>(0);
        } else {
            self.duty.next = self.duty_max.val();
        }
        self.pwm_gen.period.next = self.exec.pwm_period.val().get_bits::<16>(0);
        self.pwm_gen.duty.next = self.duty.val();
        self.pwm_gen.enable.next = self.exec.pwm_period.val() != self.zero32.val();
        self.pwm_gen.fault.next = self.core.aborted.val();
        self.pwm.next = self.pwm_gen.pwm.val();
        self.dir.next = self.pwm_gen.dir.val();
        self.ref_position.next = self.core.position.val();
        // LEDs.
        self.led_idle.next = !self.core.busy.val();
        self.led_busy.next = self.core.busy.val();
        self.led_fault.next = self.core.aborted.val()
            | (self.exec.errors.val() != self.zero8.val())
            | (self.encoder.errors.val() != self.zero16.val());
        self.led_heartbeat.next =
            (self.heartbeat.q.val() & self.beat_mask.val()) != self.zero32.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn io_top_is_synthesizable() {
        let mut uut = IoTop::default();
        uut.connect_all();
        let v = crate::verilog::direct_clocks(&generate_verilog(&uut));
        yosys_validate("io_top", &v).unwrap();
        crate::synth_check::synth_xilinx("io_top", &v);
    }
}
