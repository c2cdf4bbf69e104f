//! The fabric's timing: from a clock frequency, a baud rate and a tick period to the integer
//! dividers the hardware counts, checked so that what the board does is what was asked.
//!
//! * UART: `divisor = round(clock / baud)` clocks per bit, 16 bits; the baud rate that results
//!   must be within [`MAX_BAUD_ERROR`] of the one asked for (8N1 tolerates a few per cent
//!   between the two ends together; the receiver is tested at ±2 %).
//! * Tick: `Ts · clock` must be a whole number `n` of clocks (`tick_div = n − 1`, 32 bits): a
//!   Ts the clock cannot count exactly would make every plan run at the wrong speed.
//! * Frame timeout: [`FRAME_TIMEOUT_S`] (20 ms) of clocks.
//! * Heartbeat: the counter bit that toggles at about 1 Hz.

use serde::{Deserialize, Serialize};

/// Largest relative difference between the baud rate asked for and the one the divisor gives.
pub const MAX_BAUD_ERROR: f64 = 0.01;
/// The inter-byte gap after which a partial frame is dropped (docs/PROTOCOL.md).
pub const FRAME_TIMEOUT_S: f64 = 0.02;
/// The default baud rate.
pub const DEFAULT_BAUD: u32 = 115_200;
/// The default fabric clock (the Zybo Z7-10's oscillator).
pub const DEFAULT_CLOCK_HZ: u64 = 125_000_000;

/// What the fabric is generated for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Fabric clock (Hz).
    pub clock_hz: u64,
    /// UART baud rate.
    pub baud: u32,
    /// Tick period after reset (s).
    pub ts: f64,
}

impl Default for Timing {
    fn default() -> Self {
        Timing {
            clock_hz: DEFAULT_CLOCK_HZ,
            baud: DEFAULT_BAUD,
            ts: crate::DEFAULT_FORMAT.ts,
        }
    }
}

/// The integer dividers of a [`Timing`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Dividers {
    /// Clocks per UART bit.
    pub uart_divisor: u16,
    /// Clocks per tick minus one.
    pub tick_div: u32,
    /// Inter-byte timeout in clocks.
    pub frame_timeout: u32,
    /// Bit of a free-running clock counter that toggles at about 1 Hz.
    pub heartbeat_bit: usize,
    /// Clocks per millisecond (the host watchdog counts milliseconds).
    pub clocks_per_ms: u32,
}

/// A timing the hardware cannot count.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TimingError {
    /// Clock out of range.
    #[error("clock frequency {0} Hz is out of range: give 1 MHz to 1 GHz (e.g. --clock-hz 125e6)")]
    Clock(u64),
    /// Baud rate of zero or above the clock.
    #[error(
        "baud rate {baud} is out of range for a {clock_hz} Hz clock: give 1200 to clock/4 baud"
    )]
    Baud {
        /// Asked for.
        baud: u32,
        /// Clock.
        clock_hz: u64,
    },
    /// The divisor does not fit or gives another baud rate.
    #[error("{baud} baud from a {clock_hz} Hz clock needs {divisor:.2} clocks per bit; {rounded} gives {actual:.0} baud ({error_pct:.2} % off, more than {max_pct} %): choose a baud rate the clock divides (e.g. {suggest})")]
    BaudError {
        /// Asked for.
        baud: u32,
        /// Clock.
        clock_hz: u64,
        /// Exact clocks per bit.
        divisor: f64,
        /// Rounded.
        rounded: u64,
        /// Baud that gives.
        actual: f64,
        /// Error in per cent.
        error_pct: f64,
        /// Limit in per cent.
        max_pct: f64,
        /// A baud rate that works.
        suggest: u64,
    },
    /// Ts not a whole number of clocks.
    #[error("Ts = {ts} s is {clocks} clocks of the {clock_hz} Hz clock, not a whole number: use {below} s or {above} s")]
    Ts {
        /// Asked for.
        ts: f64,
        /// Clock.
        clock_hz: u64,
        /// Ts · clock.
        clocks: f64,
        /// The nearest Ts below.
        below: f64,
        /// The nearest Ts above.
        above: f64,
    },
    /// Ts out of the divider's range.
    #[error("Ts = {ts} s is out of range for a {clock_hz} Hz clock: give 1 to 2^32 clocks ({min} s to {max} s)")]
    TsRange {
        /// Asked for.
        ts: f64,
        /// Clock.
        clock_hz: u64,
        /// Shortest.
        min: f64,
        /// Longest.
        max: f64,
    },
}

impl Timing {
    /// The dividers, or why the hardware cannot count this timing.
    pub fn dividers(&self) -> Result<Dividers, TimingError> {
        let clock = self.clock_hz;
        if !(1_000_000..=1_000_000_000).contains(&clock) {
            return Err(TimingError::Clock(clock));
        }
        let f = clock as f64;
        if self.baud < 1200 || u64::from(self.baud) > clock / 4 {
            return Err(TimingError::Baud {
                baud: self.baud,
                clock_hz: clock,
            });
        }
        let exact = f / f64::from(self.baud);
        let rounded = exact.round() as u64;
        let actual = f / rounded as f64;
        let error = (actual - f64::from(self.baud)).abs() / f64::from(self.baud);
        if rounded > u64::from(u16::MAX) || error > MAX_BAUD_ERROR {
            return Err(TimingError::BaudError {
                baud: self.baud,
                clock_hz: clock,
                divisor: exact,
                rounded,
                actual,
                error_pct: 100.0 * error,
                max_pct: 100.0 * MAX_BAUD_ERROR,
                suggest: clock / rounded.clamp(4, u64::from(u16::MAX)),
            });
        }
        let min_ts = 1.0 / f;
        let max_ts = (1u64 << 32) as f64 / f;
        if !(self.ts.is_finite() && self.ts >= min_ts * (1.0 - 1e-12) && self.ts <= max_ts) {
            return Err(TimingError::TsRange {
                ts: self.ts,
                clock_hz: clock,
                min: min_ts,
                max: max_ts,
            });
        }
        let clocks = self.ts * f;
        let n = clocks.round();
        if (clocks - n).abs() > 1e-6 * clocks.max(1.0) {
            return Err(TimingError::Ts {
                ts: self.ts,
                clock_hz: clock,
                clocks,
                below: clocks.floor().max(1.0) / f,
                above: clocks.ceil() / f,
            });
        }
        let heartbeat_bit = (63 - clock.leading_zeros()) as usize;
        Ok(Dividers {
            uart_divisor: rounded as u16,
            tick_div: (n as u64 - 1) as u32,
            frame_timeout: (FRAME_TIMEOUT_S * f).round() as u32,
            heartbeat_bit,
            clocks_per_ms: (f / 1000.0).round() as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_the_zybo_at_115200_and_10_us() {
        let d = Timing::default().dividers().unwrap();
        assert_eq!(d.uart_divisor, 1085);
        assert_eq!(d.uart_divisor, crate::io::uart::DIVISOR_115200_AT_125MHZ);
        assert_eq!(d.tick_div, 1249);
        assert_eq!(d.frame_timeout, 2_500_000);
        // 2^26 clocks is 0.54 s: the heartbeat bit toggles at about 1 Hz.
        assert_eq!(d.heartbeat_bit, 26);
    }

    #[test]
    fn other_clocks_and_rates() {
        let d = Timing {
            clock_hz: 100_000_000,
            baud: 921_600,
            ts: 20e-6,
        }
        .dividers()
        .unwrap();
        // 100e6 / 921600 = 108.5: 109 gives 917 431 baud, 0.45 % off.
        assert_eq!((d.uart_divisor, d.tick_div), (109, 1999));
    }

    #[test]
    fn bad_timings_say_what_to_use() {
        let t = |clock_hz, baud, ts| Timing { clock_hz, baud, ts }.dividers();
        let e = t(125_000_000, 115_200, 1.0001e-5).unwrap_err();
        assert!(matches!(e, TimingError::Ts { .. }), "{e}");
        assert!(
            e.to_string().contains("use 0.00001 s or 0.000010008 s"),
            "{e}"
        );
        // 3 Mbaud from 125 MHz: 41.67 clocks, 42 gives 2.976 Mbaud (0.8 %): accepted.
        assert!(t(125_000_000, 3_000_000, 1e-5).is_ok());
        // 3 Mbaud from 10 MHz: 3.33 clocks, out of range.
        assert!(matches!(
            t(10_000_000, 3_000_000, 1e-5),
            Err(TimingError::Baud { .. })
        ));
        // 1 Mbaud from 125 MHz: 125 clocks, exact.
        assert!(t(125_000_000, 1_000_000, 1e-5).is_ok());
        // 4 Mbaud from 50 MHz: 12.5 → 13, 3.8 % off.
        assert!(matches!(
            t(50_000_000, 4_000_000, 1e-5),
            Err(TimingError::BaudError { .. })
        ));
        assert!(matches!(t(0, 115_200, 1e-5), Err(TimingError::Clock(0))));
        assert!(matches!(
            t(125_000_000, 115_200, 1e3),
            Err(TimingError::TsRange { .. })
        ));
    }
}
