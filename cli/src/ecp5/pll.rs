//! The ECP5's PLL (EHXPLLL) for the board top: the dividers that make the fabric clock
//! exactly from the oscillator (pure arithmetic), and their Verilog.

/// The EHXPLLL's limits (Lattice's ECP5 data sheet, sysCLOCK PLL; the ones Project Trellis's
/// `ecppll` applies): the input 8–400 MHz, the phase detector's input (the oscillator over
/// `CLKI_DIV`) 3.125–400 MHz, the VCO 400–800 MHz, the output 3.125–400 MHz.
const IN_HZ: std::ops::RangeInclusive<u64> = 8_000_000..=400_000_000;
/// See [`IN_HZ`].
const PFD_HZ: std::ops::RangeInclusive<u64> = 3_125_000..=400_000_000;
/// See [`IN_HZ`].
const VCO_HZ: std::ops::RangeInclusive<u64> = 400_000_000..=800_000_000;
/// See [`IN_HZ`].
const OUT_HZ: std::ops::RangeInclusive<u64> = 3_125_000..=400_000_000;
/// Divider ranges: `CLKI_DIV`, `CLKFB_DIV`, `CLKOP_DIV`.
const CLKI_DIV: std::ops::RangeInclusive<u32> = 1..=128;
/// See [`CLKI_DIV`].
const CLKFB_DIV: std::ops::RangeInclusive<u32> = 1..=80;
/// See [`CLKI_DIV`].
const CLKOP_DIV: std::ops::RangeInclusive<u32> = 1..=128;

/// An EHXPLLL setting with the primary output (CLKOP) fed back: the output is
/// `f_in · CLKFB_DIV / CLKI_DIV`, the VCO runs at the output times `CLKOP_DIV`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PllSetting {
    /// Reference divider.
    pub clki_div: u32,
    /// Feedback divider.
    pub clkfb_div: u32,
    /// Output divider.
    pub clkop_div: u32,
}

/// A PLL output the EHXPLLL cannot make exactly from the oscillator.
#[derive(Debug, thiserror::Error)]
#[error("no ECP5 PLL setting makes exactly {fout_hz} Hz from {fin_hz} Hz (the fabric's clock must be exact: the UART's divisor and Ts are counted in it; the PLL takes 8–400 MHz in and gives 3.125–400 MHz out); {nearest}")]
pub struct PllError {
    /// Oscillator.
    pub fin_hz: u64,
    /// Asked output.
    pub fout_hz: u64,
    /// The nearest outputs that can be made ("nearest: A Hz, B Hz"), or why none can.
    pub nearest: String,
}

/// The setting that makes exactly `fout_hz` from `fin_hz`: the phase detector and the VCO within
/// their ranges; of several, the one whose VCO is nearest 600 MHz (the middle of its range),
/// then the smallest reference divider.
pub fn solve_pll(fin_hz: u64, fout_hz: u64) -> Result<PllSetting, PllError> {
    let mut best: Option<(u64, PllSetting)> = None;
    let mut reachable: Vec<u64> = Vec::new();
    for clki_div in CLKI_DIV.filter(|_| IN_HZ.contains(&fin_hz)) {
        // The phase detector's input, exactly: f_in / CLKI_DIV within its range.
        let pfd_lo = u64::from(clki_div) * PFD_HZ.start();
        let pfd_hi = u64::from(clki_div) * PFD_HZ.end();
        if !(pfd_lo..=pfd_hi).contains(&fin_hz) {
            continue;
        }
        for clkfb_div in CLKFB_DIV {
            // The output, exactly: f_in · CLKFB_DIV / CLKI_DIV (a whole number of Hz or none).
            let num = fin_hz * u64::from(clkfb_div);
            if num % u64::from(clki_div) != 0 {
                continue;
            }
            let fout = num / u64::from(clki_div);
            if !OUT_HZ.contains(&fout) {
                continue;
            }
            for clkop_div in CLKOP_DIV {
                let vco = fout * u64::from(clkop_div);
                if !VCO_HZ.contains(&vco) {
                    continue;
                }
                if fout != fout_hz {
                    reachable.push(fout);
                    continue;
                }
                let s = PllSetting {
                    clki_div,
                    clkfb_div,
                    clkop_div,
                };
                let score = vco.abs_diff(600_000_000);
                if best.is_none_or(|(b, _)| score < b) {
                    best = Some((score, s));
                }
            }
        }
    }
    if let Some((_, s)) = best {
        return Ok(s);
    }
    Err(PllError {
        fin_hz,
        fout_hz,
        nearest: crate::fpga::nearest_clocks(reachable, fout_hz),
    })
}

/// The board top's clock generator: an EHXPLLL making `clk` from the oscillator `osc`, and its
/// lock flag `pll_locked` (the board top holds the design in reset until it is set).
pub fn pll_verilog(osc: &str, fin_hz: u64, fout_hz: u64, s: &PllSetting) -> String {
    let mhz = |f: u64| {
        let t = format!("{:.6}", f as f64 / 1e6);
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let vco = fout_hz * u64::from(s.clkop_div);
    format!(
        "    // The fabric clock: the ECP5's PLL makes {fout} MHz from the {fin} MHz oscillator
    // ({fin} MHz / CLKI_DIV {ki} x CLKFB_DIV {kf}, CLKOP fed back; VCO {vco} MHz = {fout} MHz x
    // CLKOP_DIV {ko}). The loop-filter attributes are the values Project Trellis's ecppll writes.
    wire clk;
    wire pll_locked;
    (* FREQUENCY_PIN_CLKI=\"{fin}\" *)
    (* FREQUENCY_PIN_CLKOP=\"{fout}\" *)
    (* ICP_CURRENT=\"12\" *) (* LPF_RESISTOR=\"8\" *) (* MFG_ENABLE_FILTEROPAMP=\"1\" *) (* MFG_GMCREF_SEL=\"2\" *)
    EHXPLLL #(
        .PLLRST_ENA(\"DISABLED\"),
        .INTFB_WAKE(\"DISABLED\"),
        .STDBY_ENABLE(\"DISABLED\"),
        .DPHASE_SOURCE(\"DISABLED\"),
        .OUTDIVIDER_MUXA(\"DIVA\"),
        .CLKOP_ENABLE(\"ENABLED\"),
        .CLKI_DIV({ki}),
        .CLKFB_DIV({kf}),
        .CLKOP_DIV({ko}),
        .CLKOP_CPHASE({cphase}),   // no phase shift asked: CLKOP is fed back, so the loop aligns it
        .CLKOP_FPHASE(0),
        .FEEDBK_PATH(\"CLKOP\")
    ) pll (
        .CLKI({osc}),
        .CLKFB(clk),
        .CLKOP(clk),
        .LOCK(pll_locked),
        .RST(1'b0),
        .STDBY(1'b0),
        .PHASESEL0(1'b0),
        .PHASESEL1(1'b0),
        .PHASEDIR(1'b0),
        .PHASESTEP(1'b0),
        .PHASELOADREG(1'b0),
        .PLLWAKESYNC(1'b0),
        .ENCLKOP(1'b0)
    );
",
        fin = mhz(fin_hz),
        fout = mhz(fout_hz),
        vco = mhz(vco),
        ki = s.clki_div,
        kf = s.clkfb_div,
        ko = s.clkop_div,
        cphase = s.clkop_div - 1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The output and the VCO, recomputed from the dividers.
    fn check(fin: u64, fout: u64) {
        let s = solve_pll(fin, fout).unwrap();
        assert_eq!(
            fin * u64::from(s.clkfb_div),
            fout * u64::from(s.clki_div),
            "{s:?}"
        );
        let vco = fout * u64::from(s.clkop_div);
        assert!((400_000_000..=800_000_000).contains(&vco), "{s:?}");
        let pfd = fin as f64 / f64::from(s.clki_div);
        assert!((3.125e6..=400e6).contains(&pfd), "{s:?}");
    }

    #[test]
    fn pll_settings_make_the_clock_exactly() {
        // ecppll's own answer for 25 → 75 MHz: CLKI_DIV 1, CLKFB_DIV 3, CLKOP_DIV 8.
        assert_eq!(
            solve_pll(25_000_000, 75_000_000).unwrap(),
            PllSetting {
                clki_div: 1,
                clkfb_div: 3,
                clkop_div: 8
            }
        );
        for fout in [
            25_000_000,
            50_000_000,
            62_500_000,
            80_000_000,
            100_000_000,
            125_000_000,
        ] {
            check(25_000_000, fout);
        }
        check(12_000_000, 48_000_000);
    }

    #[test]
    fn a_clock_the_pll_cannot_make_is_refused_with_the_nearest() {
        let e = solve_pll(25_000_000, 77_777_777).unwrap_err().to_string();
        assert!(
            e.contains("no ECP5 PLL setting makes exactly 77777777 Hz"),
            "{e}"
        );
        // Each clock it offers instead can be made.
        let nearest = e.split("nearest: ").nth(1).unwrap();
        for f in nearest.split(", ") {
            let hz: u64 = f.trim_end_matches(" Hz").parse().unwrap();
            check(25_000_000, hz);
        }
        assert_eq!(nearest.split(", ").count(), 2, "{e}");
        // Beyond the output's range, and from an oscillator below the PLL's input range.
        assert!(solve_pll(25_000_000, 500_000_000).is_err());
        let e = solve_pll(5_000_000, 75_000_000).unwrap_err().to_string();
        assert!(
            e.contains("it can make no clock from this oscillator"),
            "{e}"
        );
    }
}
