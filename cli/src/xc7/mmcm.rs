//! The 7-series MMCM (MMCME2_BASE) for a Xilinx board top: the dividers that make the fabric
//! clock exactly from the oscillator (pure arithmetic), and their Verilog.

/// The MMCM's limits for speed grade -1 (Xilinx DS187, Zynq-7000 Z-7010/7015/7020 switching
/// characteristics, MMCM table; the faster grades' ranges contain these): the input
/// 10–800 MHz, the phase detector's input (the oscillator over `DIVCLK_DIVIDE`) 10–450 MHz, the
/// VCO 600–1200 MHz, the output 4.69–800 MHz.
const IN_HZ: std::ops::RangeInclusive<u64> = 10_000_000..=800_000_000;
/// See [`IN_HZ`].
const PFD_HZ: std::ops::RangeInclusive<u64> = 10_000_000..=450_000_000;
/// See [`IN_HZ`].
const VCO_HZ: std::ops::RangeInclusive<u64> = 600_000_000..=1_200_000_000;
/// See [`IN_HZ`].
const OUT_HZ: std::ops::RangeInclusive<u64> = 4_690_000..=800_000_000;
/// Divider ranges (UG472, MMCM attributes; whole numbers only here): `DIVCLK_DIVIDE` (D),
/// `CLKFBOUT_MULT_F` (M), `CLKOUT0_DIVIDE_F` (O).
const DIVCLK_DIVIDE: std::ops::RangeInclusive<u32> = 1..=106;
/// See [`DIVCLK_DIVIDE`].
const CLKFBOUT_MULT: std::ops::RangeInclusive<u32> = 2..=64;
/// See [`DIVCLK_DIVIDE`].
const CLKOUT0_DIVIDE: std::ops::RangeInclusive<u32> = 1..=128;

/// An MMCME2_BASE setting: the VCO runs at `f_in · M / D`, the fabric clock (CLKOUT0) at the
/// VCO over `O`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MmcmSetting {
    /// Input divider D (`DIVCLK_DIVIDE`).
    pub divclk_divide: u32,
    /// Feedback multiplier M (`CLKFBOUT_MULT_F`).
    pub clkfbout_mult: u32,
    /// Output divider O (`CLKOUT0_DIVIDE_F`).
    pub clkout0_divide: u32,
}

/// A fabric clock the MMCM cannot make exactly from the oscillator.
#[derive(Debug, thiserror::Error)]
#[error("no 7-series MMCM setting makes exactly {fout_hz} Hz from {fin_hz} Hz (the fabric's clock must be exact: the UART's divisor and Ts are counted in it; the MMCM takes 10–800 MHz in, its VCO runs at 600–1200 MHz and its output divides the VCO by 1 to 128); {nearest}")]
pub struct MmcmError {
    /// Oscillator.
    pub fin_hz: u64,
    /// Asked output.
    pub fout_hz: u64,
    /// The nearest outputs that can be made ("nearest: A Hz, B Hz"), or why none can.
    pub nearest: String,
}

/// The setting that makes exactly `fout_hz` from `fin_hz`: the phase detector and the VCO within
/// their ranges; of several, the one with the smallest input divider (the phase detector at its
/// fastest), then the fastest VCO (AMD's advice for the least output jitter, UG949).
pub fn solve_mmcm(fin_hz: u64, fout_hz: u64) -> Result<MmcmSetting, MmcmError> {
    let mut best: Option<(u64, MmcmSetting)> = None;
    let mut reachable: Vec<u64> = Vec::new();
    for d in DIVCLK_DIVIDE.filter(|_| IN_HZ.contains(&fin_hz)) {
        // The phase detector's input, f_in / D, within its range (it need not be whole Hz).
        if fin_hz < u64::from(d) * PFD_HZ.start() || fin_hz > u64::from(d) * PFD_HZ.end() {
            continue;
        }
        for m in CLKFBOUT_MULT {
            // The VCO, exactly: f_in · M / D (a whole number of Hz or none).
            let num = fin_hz * u64::from(m);
            if num % u64::from(d) != 0 {
                continue;
            }
            let vco = num / u64::from(d);
            if !VCO_HZ.contains(&vco) {
                continue;
            }
            for o in CLKOUT0_DIVIDE {
                if vco % u64::from(o) != 0 {
                    continue;
                }
                let fout = vco / u64::from(o);
                if !OUT_HZ.contains(&fout) {
                    continue;
                }
                if fout != fout_hz {
                    reachable.push(fout);
                    continue;
                }
                let s = MmcmSetting {
                    divclk_divide: d,
                    clkfbout_mult: m,
                    clkout0_divide: o,
                };
                // The smallest D (the loop's order: the first D that works), then the fastest VCO.
                if best.is_none_or(|(b, bs)| bs.divclk_divide == d && vco > b) {
                    best = Some((vco, s));
                }
            }
        }
    }
    if let Some((_, s)) = best {
        return Ok(s);
    }
    Err(MmcmError {
        fin_hz,
        fout_hz,
        nearest: crate::fpga::nearest_clocks(reachable, fout_hz),
    })
}

/// The board top's clock generator: an MMCME2_BASE making `clk` (through a global buffer) from
/// the oscillator `osc`, and its lock flag `pll_locked` (the board top holds the design in reset
/// until it is set); its other outputs are left unconnected. The feedback runs from CLKFBOUT to CLKFBIN inside the MMCM's tile: the
/// fabric clock need not be phase-aligned with the oscillator (every input is synchronised).
pub fn mmcm_verilog(osc: &str, fin_hz: u64, fout_hz: u64, s: &MmcmSetting) -> String {
    let mhz = |f: u64| {
        let t = format!("{:.6}", f as f64 / 1e6);
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let vco = fin_hz * u64::from(s.clkfbout_mult) / u64::from(s.divclk_divide);
    format!(
        "    // The fabric clock: the MMCM makes {fout} MHz from the {fin} MHz oscillator
    // ({fin} MHz / DIVCLK_DIVIDE {d} x CLKFBOUT_MULT_F {m} = VCO {vco} MHz; / CLKOUT0_DIVIDE_F {o}),
    // through a global clock buffer. Vivado derives the fabric clock's constraint from the
    // oscillator's (the XDC) and these dividers.
    wire clk;
    wire clk_mmcm;
    wire clk_feedback;
    wire pll_locked;
    MMCME2_BASE #(
        .BANDWIDTH(\"OPTIMIZED\"),
        .CLKIN1_PERIOD({period:.3}),
        .DIVCLK_DIVIDE({d}),
        .CLKFBOUT_MULT_F({m}.0),
        .CLKFBOUT_PHASE(0.0),
        .CLKOUT0_DIVIDE_F({o}.0),
        .CLKOUT0_DUTY_CYCLE(0.5),
        .CLKOUT0_PHASE(0.0),
        .REF_JITTER1(0.010),
        .STARTUP_WAIT(\"FALSE\")
    ) mmcm (
        .CLKIN1({osc}),
        .CLKFBIN(clk_feedback),
        .CLKFBOUT(clk_feedback),
        .CLKOUT0(clk_mmcm),
        .LOCKED(pll_locked),
        .PWRDWN(1'b0),
        .RST(1'b0)
    );
    BUFG clock_buffer (
        .I(clk_mmcm),
        .O(clk)
    );
",
        fin = mhz(fin_hz),
        fout = mhz(fout_hz),
        vco = mhz(vco),
        period = 1e9 / fin_hz as f64,
        d = s.divclk_divide,
        m = s.clkfbout_mult,
        o = s.clkout0_divide,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The output, the VCO and the phase detector, recomputed from the dividers.
    fn check(fin: u64, fout: u64) -> MmcmSetting {
        let s = solve_mmcm(fin, fout).unwrap();
        let vco = fin * u64::from(s.clkfbout_mult) / u64::from(s.divclk_divide);
        assert_eq!(
            fin * u64::from(s.clkfbout_mult),
            vco * u64::from(s.divclk_divide),
            "{s:?}"
        );
        assert_eq!(vco, fout * u64::from(s.clkout0_divide), "{s:?}");
        assert!((600_000_000..=1_200_000_000).contains(&vco), "{s:?}");
        let pfd = fin as f64 / f64::from(s.divclk_divide);
        assert!((10e6..=450e6).contains(&pfd), "{s:?}");
        s
    }

    #[test]
    fn mmcm_settings_make_the_clock_exactly() {
        // The Zybo's 125 MHz into 100 MHz: D = 1, then VCO 1 000 MHz, the fastest with it
        // (1 125 is not a multiple of 100 MHz; D = 5 would reach 1 200).
        assert_eq!(
            check(125_000_000, 100_000_000),
            MmcmSetting {
                divclk_divide: 1,
                clkfbout_mult: 8,
                clkout0_divide: 10
            }
        );
        for fout in [
            25_000_000,
            50_000_000,
            62_500_000,
            75_000_000,
            80_000_000,
            125_000_000,
            150_000_000,
        ] {
            check(125_000_000, fout);
        }
        check(100_000_000, 100_000_000);
    }

    #[test]
    fn impossible_clocks_are_refused_with_the_nearest() {
        let e = solve_mmcm(125_000_000, 99_999_999).unwrap_err().to_string();
        assert!(
            e.contains("exactly 99999999 Hz") && e.contains("nearest: "),
            "{e}"
        );
        let e = solve_mmcm(5_000_000, 100_000_000).unwrap_err().to_string();
        assert!(e.contains("no clock from this oscillator"), "{e}");
    }
}
