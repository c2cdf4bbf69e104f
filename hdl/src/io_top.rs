//! The I/O top: the station ([`crate::station`]) behind a UART (what a board top
//! instantiates; `snapgen_io.v`, which holds the station too). Its reference, clock for
//! clock, is `snapgen_model::device::Device`.
//!
//! ```text
//! uart_rx → UartRx → link_valid/data ─→ Station ─→ pwm, dir, amplifier, LEDs, status
//! uart_tx ← UartTx ← reply_ready/data ─┘   ↑ enc_a/b/i, limit±, estop
//! ```
//!
//! The UART takes a reply byte when it is idle; its framing errors are the station's link
//! errors (UART_ERROR).

use rust_hdl::prelude::*;
use snapgen_model::device::Design;

use crate::block_with_ports;
use crate::emit::{Note, Waiver};
use crate::station::Station;
use crate::uart_rx::UartRx;
use crate::uart_tx::UartTx;

/// Lint waivers of the UART top, written into its Verilog beside each declaration.
pub const WAIVERS: [Waiver; 5] = [
    unused("station_ticks"),
    unused("station_x"),
    unused("station_v"),
    unused("station_a"),
    unused("station_j"),
];

const fn unused(signal: &'static str) -> Waiver {
    Waiver {
        module: "",
        signal,
        note: Note::LintOff("UNUSEDSIGNAL"),
        reason:
            "the chain's registers are for a front's snapshot: the UART reads them with READ_STATE",
    }
}

snapgen_spec::with_io_top_ports!(block_with_ports! {
    /// The I/O top; its ports are the spec's `with_io_top_ports!` list.
    pub struct IoTop(design: Design) {
        uart_in: UartRx = Default::default(),
        uart_out: UartTx = Default::default(),
        station: Station = Station::new(design),
        divisor: Constant<Bits<16>> = Constant::new(u64::from(design.dividers.uart_divisor).into()),
    }
});

impl IoTop {
    /// The top for `design` (its dividers, and its identity for PING).
    pub fn new(design: Design) -> Self {
        IoTop::build(design)
    }
}

impl Default for IoTop {
    fn default() -> Self {
        IoTop::new(crate::defaults::default_design())
    }
}

impl Logic for IoTop {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, uart_in, uart_out, station);
        self.uart_in.rx.next = self.uart_rx.val();
        self.uart_in.divisor.next = self.divisor.val();
        self.station.reset.next = self.reset.val();
        self.station.link_valid.next = self.uart_in.valid.val();
        self.station.link_data.next = self.uart_in.data.val();
        self.station.link_error.next = self.uart_in.framing_error.val();
        // The UART takes the reply stream's next byte whenever it is idle.
        self.station.reply_take.next = !self.uart_out.busy.val();
        self.uart_out.start.next = self.station.reply_ready.val() & !self.uart_out.busy.val();
        self.uart_out.data.next = self.station.reply_data.val();
        self.uart_out.divisor.next = self.divisor.val();
        self.uart_tx.next = self.uart_out.tx.val();
        self.station.estop.next = self.estop.val();
        self.station.enc_a.next = self.enc_a.val();
        self.station.enc_b.next = self.enc_b.val();
        self.station.enc_i.next = self.enc_i.val();
        self.station.limit_pos.next = self.limit_pos.val();
        self.station.limit_neg.next = self.limit_neg.val();
        self.led_idle.next = self.station.led_idle.val();
        self.led_busy.next = self.station.led_busy.val();
        self.led_fault.next = self.station.led_fault.val();
        self.led_heartbeat.next = self.station.led_heartbeat.val();
        self.pwm.next = self.station.pwm.val();
        self.dir.next = self.station.dir.val();
        self.amplifier.next = self.station.amplifier.val();
        self.status.next = self.station.status.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn io_top_is_synthesizable() {
        crate::synth_check::synth_block("io_top", IoTop::default());
    }
}
