//! The AXI4-Lite handshake rules (AMBA AXI and ACE Protocol Specification, A3.2 and B1), checked
//! clock by clock on the fabric's own outputs and the master's inputs, apart from the
//! comparison with the model: a slave that agrees with a wrong model still breaks a rule here.
//!
//! * Once VALID is high it stays high, its payload unchanged, until the handshake (both
//!   directions: AW, W, AR from the master; B, R from the slave).
//! * A write response only for a write whose address and data have both been handshaken and
//!   not yet answered; read data only for an address handshaken and not yet answered.
//! * BVALID and RVALID low on the clock after a reset clock (a reset ends every transaction:
//!   the master may drop its requests on a reset clock).

use snapgen_model::ports::{AxiInputs, AxiOutputs};

/// A broken rule: the clock (from 0) and what.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AxiViolation {
    /// Clock.
    pub clock: u64,
    /// The rule.
    pub rule: &'static str,
}

impl std::fmt::Display for AxiViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "AXI rule broken at clock {}: {}", self.clock, self.rule)
    }
}

/// The checker's memory of the last clock and the handshakes so far.
#[derive(Clone, Debug, Default)]
pub struct AxiChecker {
    clock: u64,
    last: Option<(AxiInputs, AxiOutputs)>,
    aw: u64,
    w: u64,
    b: u64,
    ar: u64,
    r: u64,
}

impl AxiChecker {
    /// A checker before the first clock.
    pub fn new() -> Self {
        Self::default()
    }

    /// One clock: `i` the inputs at its edge, `o` the outputs during the clock (before the
    /// edge), `after` the outputs after it.
    pub fn clock(
        &mut self,
        i: &AxiInputs,
        o: &AxiOutputs,
        after: &AxiOutputs,
    ) -> Result<(), AxiViolation> {
        let at = self.clock;
        self.clock += 1;
        let fail = |rule| Err(AxiViolation { clock: at, rule });
        if let Some((pi, po)) = self.last {
            // Held until the handshake, payload unchanged (the master's requests: unless a
            // reset ends them on this clock).
            let aw_waited = !i.reset && pi.s_axi_awvalid && !po.s_axi_awready;
            if aw_waited && (!i.s_axi_awvalid || i.s_axi_awaddr != pi.s_axi_awaddr) {
                return fail("AWVALID dropped or AWADDR changed before AWREADY");
            }
            let w_waited = !i.reset && pi.s_axi_wvalid && !po.s_axi_wready;
            let w_same = i.s_axi_wdata == pi.s_axi_wdata && i.s_axi_wstrb == pi.s_axi_wstrb;
            if w_waited && (!i.s_axi_wvalid || !w_same) {
                return fail("WVALID dropped or WDATA/WSTRB changed before WREADY");
            }
            let ar_waited = !i.reset && pi.s_axi_arvalid && !po.s_axi_arready;
            if ar_waited && (!i.s_axi_arvalid || i.s_axi_araddr != pi.s_axi_araddr) {
                return fail("ARVALID dropped or ARADDR changed before ARREADY");
            }
            let b_waited = !pi.reset && po.s_axi_bvalid && !pi.s_axi_bready;
            if b_waited && (!o.s_axi_bvalid || o.s_axi_bresp != po.s_axi_bresp) {
                return fail("BVALID dropped or BRESP changed before BREADY");
            }
            let r_waited = !pi.reset && po.s_axi_rvalid && !pi.s_axi_rready;
            let r_same = o.s_axi_rdata == po.s_axi_rdata && o.s_axi_rresp == po.s_axi_rresp;
            if r_waited && (!o.s_axi_rvalid || !r_same) {
                return fail("RVALID dropped or RDATA/RRESP changed before RREADY");
            }
            // A new response needs its request.
            if o.s_axi_bvalid && !b_waited && (self.aw <= self.b || self.w <= self.b) {
                return fail("BVALID without a write address and data to answer");
            }
            if o.s_axi_rvalid && !r_waited && self.ar <= self.r {
                return fail("RVALID without a read address to answer");
            }
        }
        if i.reset {
            // A reset ends every transaction.
            self.last = Some((*i, *o));
            (self.aw, self.w, self.b, self.ar, self.r) = (0, 0, 0, 0, 0);
            if after.s_axi_bvalid || after.s_axi_rvalid {
                return fail("BVALID or RVALID high after a reset clock");
            }
            return Ok(());
        }
        self.aw += u64::from(i.s_axi_awvalid && o.s_axi_awready);
        self.w += u64::from(i.s_axi_wvalid && o.s_axi_wready);
        self.b += u64::from(o.s_axi_bvalid && i.s_axi_bready);
        self.ar += u64::from(i.s_axi_arvalid && o.s_axi_arready);
        self.r += u64::from(o.s_axi_rvalid && i.s_axi_rready);
        self.last = Some((*i, *o));
        Ok(())
    }
}
