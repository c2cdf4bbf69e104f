//! The device: the whole I/O top (`snapgen_hdl::io_top::IoTop`), clock by clock — what a board
//! running the snapgen fabric does with its pins: the station ([`crate::station`]) behind a
//! UART. It is the reference the Verilated I/O top is
//! compared with on every clock (every bit of `uart_tx`, PWM, direction, amplifier enable,
//! LEDs and the status block), and what `snapgen board --pty --model` serves.
//!
//! ```text
//! uart_rx → UartRx → link ─→ Station ─→ pwm, dir, amplifier, LEDs, status
//! uart_tx ← UartTx ← reply ─┘
//! ```

use crate::core::CoreModel;
use crate::format::Format;
use crate::io::servo::Servo;
use crate::io::uart::{RxOutputs, UartRx, UartTx};
pub use crate::ports::{IoInputs, IoOutputs};
use crate::program::Program;
use crate::station::{station_inputs, station_pins, Station};
use crate::timing::{Dividers, Timing, TimingError};
use snapgen_spec::wire::PROTOCOL_VERSION;
use snapgen_spec::{Identity, Status};

/// What a design was generated with: its format, dividers and identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// The fixed-point format.
    pub format: Format,
    /// The clock, UART and tick dividers.
    pub dividers: Dividers,
    /// Fabric clock (Hz).
    pub clock_hz: u32,
    /// UART baud rate.
    pub baud: u32,
    /// Hash of the generated design (docs/HDL.md).
    pub design_hash: u32,
    /// The limit and emergency-stop inputs' polarity after reset (`INPUT_POLARITY`: bit 0
    /// inverts limit+, bit 1 limit−, bit 2 the emergency stop), from the board file.
    pub input_polarity: u8,
}

/// FNV-1a, 32 bits (offset basis 0x811C9DC5, prime 0x01000193): the design hash.
pub fn fnv1a32(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811C_9DC5u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    })
}

impl Design {
    /// The design of `timing` in `format`, with design hash 0 (the generator computes the
    /// real one from its Verilog). Its `baud` is the rate the UART really runs at:
    /// `clock / divisor`, rounded (115 207 for 115 200 baud from 125 MHz).
    pub fn from_timing(format: &Format, timing: &Timing) -> Result<Self, TimingError> {
        let dividers = timing.dividers()?;
        Ok(Design {
            format: *format,
            dividers,
            clock_hz: timing.clock_hz as u32,
            baud: (timing.clock_hz as f64 / f64::from(dividers.uart_divisor)).round() as u32,
            design_hash: 0,
            input_polarity: 0,
        })
    }

    /// The tick period after reset (s).
    pub fn ts(&self) -> f64 {
        (f64::from(self.dividers.tick_div) + 1.0) / f64::from(self.clock_hz)
    }

    /// The identity the design reports (its tick divider and stop limits are live values).
    pub fn identity(&self) -> Identity {
        let f = &self.format;
        let w = f.widths;
        Identity {
            protocol: PROTOCOL_VERSION,
            design_hash: self.design_hash,
            clock_hz: self.clock_hz,
            baud: self.baud,
            tick_divider: self.dividers.tick_div,
            x_bits: w.x as u8,
            v_bits: w.v as u8,
            a_bits: w.a as u8,
            j_bits: w.j as u8,
            d_bits: w.d as u8,
            frac_bits: crate::FRAC_BITS as u8,
            tick_bits: f.tick_bits as u8,
            max_segments: f.max_segments as u8,
            snap_bytes: Program::snap_bytes(f) as u8,
            stop_jerk: 0,
            stop_accel: 0,
        }
    }
}

/// The device model: the station behind a UART.
#[derive(Clone, Debug)]
pub struct Device {
    design: Design,
    uart_rx: UartRx,
    uart_rx_out: RxOutputs,
    uart_tx: UartTx,
    uart_tx_line: bool,
    station: Station,
}

impl Device {
    /// A device in its power-up state (every register 0, lines idle); apply a reset before
    /// use ([`Device::powered_up`] does).
    pub fn new(design: &Design) -> Self {
        Device {
            design: *design,
            uart_rx: UartRx::new(),
            uart_rx_out: RxOutputs::default(),
            uart_tx: UartTx::new(),
            uart_tx_line: true,
            station: Station::new(design),
        }
    }

    /// A device after `clocks` clocks of reset (lines idle).
    pub fn powered_up(design: &Design, clocks: u32) -> Self {
        let mut d = Device::new(design);
        let reset = IoInputs {
            reset: true,
            uart_rx: true,
            ..Default::default()
        };
        for _ in 0..clocks {
            d.clock(&reset);
        }
        d
    }

    /// The design.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// The station behind the UART.
    pub fn station(&self) -> &Station {
        &self.station
    }

    /// The core model.
    pub fn core(&self) -> &CoreModel {
        self.station.core()
    }

    /// The command executor's outputs (its reply pulse marks the clock a frame is executed).
    pub fn executor_outputs(&self) -> crate::io::executor::ExecutorOutputs {
        self.station.executor_outputs()
    }

    /// True while part of a frame has been received.
    pub fn mid_frame(&self) -> bool {
        self.station.mid_frame()
    }

    /// The status block, from the blocks' registered values.
    pub fn status(&self) -> Status {
        self.station.status()
    }

    /// The controller.
    pub fn servo(&self) -> &Servo {
        self.station.servo()
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> IoOutputs {
        let s = self.station.outputs();
        station_pins!(
            s,
            IoOutputs {
                uart_tx: self.uart_tx_line,
            }
        )
    }

    /// One rising clock edge with the pins `i`; returns the outputs after it.
    pub fn clock(&mut self, i: &IoInputs) -> IoOutputs {
        let divisor = self.design.dividers.uart_divisor;
        let s = self.station.outputs();
        // The UART takes the reply stream's next byte whenever it is idle.
        let take = !self.uart_tx.busy();
        let station_in = station_inputs!(i, {
            link_valid: self.uart_rx_out.valid,
            link_data: self.uart_rx_out.data,
            link_error: self.uart_rx_out.framing_error,
            reply_take: take,
        });
        self.uart_rx_out = self.uart_rx.clock(i.uart_rx, divisor);
        self.station.clock(&station_in);
        self.uart_tx_line = self
            .uart_tx
            .clock(s.reply_ready && take, s.reply_data, divisor)
            .tx;
        self.outputs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a32_check_values() {
        // The published test vectors of FNV-1a 32.
        assert_eq!(fnv1a32(b""), 0x811C_9DC5);
        assert_eq!(fnv1a32(b"a"), 0xE40C_292C);
        assert_eq!(fnv1a32(b"foobar"), 0xBF9C_F968);
    }
}
