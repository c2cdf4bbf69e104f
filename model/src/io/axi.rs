//! The AXI4-Lite front (`snapgen_axi`), clock by clock: the register map of
//! [`snapgen_spec::axi`] in front of the station ([`crate::station`]) — the same command
//! executor as the UART's, one behaviour behind two transports.
//!
//! The slave takes one write and one read at a time:
//!
//! * **Write.** `AWREADY` is high while no write address is held, `WREADY` while no write data
//!   is; each is held when its handshake happens (in either order). On the clock after both are
//!   held, with no write response waiting, the write takes effect: `BVALID` rises with OKAY, or
//!   SLVERR for an address outside the map or a register that is not writable (nothing
//!   changes), and both are released. `BVALID` falls on the clock `BREADY` is high.
//! * **Read.** `ARREADY` is high while no read data waits; on the handshake the register is
//!   read (a read of `REPLY` takes the waiting byte) into `RDATA`/`RRESP` and `RVALID` rises;
//!   it falls on the clock `RREADY` is high.
//! * **Command stream.** A write of `COMMAND` (byte lane 0 strobed) hands its byte to the
//!   station on the next clock; the station's frame receiver takes one byte a clock, and a write
//!   takes at least two clocks, so no byte waits.
//! * **Interrupt.** DONE (the flag rose), FAULT (the state became ErrorStop) and SWAP (the flag
//!   SWAP_PENDING fell) are latched from the station's status until written 1 in `IRQ_STATUS`;
//!   REPLY is the level "a reply byte waits". `irq` is registered: high on the clock after an
//!   enabled cause is set.
//!
//! Every register's value is a function of the registers before the edge, as in the fabric.

use snapgen_spec::axi::{
    at, Access, Register, Snap, ADDR_BITS, IRQ_ALL, IRQ_DONE, IRQ_FAULT, IRQ_LATCHED, IRQ_REPLY,
    IRQ_SWAP, REPLY_VALID, RESP_OKAY, RESP_SLVERR, STATUS_DONE_BIT, STATUS_STATE_LSB,
    STATUS_SWAP_PENDING_BIT,
};
use snapgen_spec::{AxisState, Status};

use crate::device::Design;
use crate::ports::{AxiInputs, AxiOutputs, StationOutputs};
use crate::station::{station_inputs, station_pins, Station};

/// What `SNAPSHOT` latches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Snapshot {
    /// The status block.
    pub status: Status,
    /// Ticks since reset.
    pub ticks: u64,
    /// Position register, raw.
    pub x: i128,
    /// Velocity register, raw.
    pub v: i128,
    /// Acceleration register, raw.
    pub a: i128,
    /// Jerk register, raw.
    pub j: i128,
}

impl Snapshot {
    /// Word `word` of the register that latches the station's port `snap.port`
    /// (`Register::snap`: status, ticks, x, v, a, j), widened as `snap.signed` says.
    fn word(&self, snap: &Snap, word: u32) -> u32 {
        let wide = |v: i128| {
            if 32 * word >= 128 {
                // Past the value's 128 bits: its sign, or zeros.
                if snap.signed && v < 0 {
                    u32::MAX
                } else {
                    0
                }
            } else {
                (v >> (32 * word)) as u32
            }
        };
        match snap.port {
            "status" => {
                let bytes = status_bytes(&self.status);
                (0..4).fold(0, |w, k| {
                    let b = bytes.get(4 * word as usize + k).copied().unwrap_or(0);
                    w | u32::from(b) << (8 * k)
                })
            }
            "ticks" => wide(i128::from(self.ticks)),
            "x" => wide(self.x),
            "v" => wide(self.v),
            "a" => wide(self.a),
            "j" => wide(self.j),
            _ => 0,
        }
    }
}

/// The AXI4-Lite slave's registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AxiSlave {
    aw_full: bool,
    aw_addr: u8,
    w_full: bool,
    w_data: u32,
    w_strb: u8,
    b_valid: bool,
    b_resp: u8,
    r_valid: bool,
    r_data: u32,
    r_resp: u8,
    link_valid: bool,
    link_data: u8,
    irq_enable: u32,
    irq_latched: u32,
    was_done: bool,
    was_fault: bool,
    was_swap_pending: bool,
    irq: bool,
    snapshot: Snapshot,
}

/// The station's `status` port as bytes (byte 0 in bits 7:0).
fn status_bytes(s: &Status) -> [u8; Status::BYTES] {
    let mut bytes = [0u8; Status::BYTES];
    s.write_payload(&mut bytes);
    bytes
}

/// Bit `bit` of the status block's bytes.
fn status_bit(bytes: &[u8; Status::BYTES], bit: u32) -> bool {
    bytes[bit as usize / 8] >> (bit % 8) & 1 == 1
}

impl AxiSlave {
    /// The slave's AXI outputs and interrupt as they stand (the station's pins are added by
    /// [`AxiDevice::outputs`]).
    fn outputs(&self, o: &mut AxiOutputs) {
        o.s_axi_awready = !self.aw_full;
        o.s_axi_wready = !self.w_full;
        o.s_axi_bvalid = self.b_valid;
        o.s_axi_bresp = self.b_resp;
        o.s_axi_arready = !self.r_valid;
        o.s_axi_rvalid = self.r_valid;
        o.s_axi_rdata = self.r_data;
        o.s_axi_rresp = self.r_resp;
        o.irq = self.irq;
    }

    /// `IRQ_STATUS` as a read returns it.
    fn irq_status(&self, st: &StationOutputs) -> u32 {
        self.irq_latched | if st.reply_ready { IRQ_REPLY } else { 0 }
    }

    /// A read of byte address `addr`: data and response.
    fn read(&self, addr: u8, st: &StationOutputs) -> (u32, u8) {
        match at(u32::from(addr)) {
            Some((r, _)) if !r.access.readable() => (0, RESP_SLVERR),
            Some((r, word)) => (self.value(r, word, st), RESP_OKAY),
            None => (0, RESP_SLVERR),
        }
    }

    fn value(&self, r: &Register, word: u32, st: &StationOutputs) -> u32 {
        match r.name {
            "REPLY" if st.reply_ready => REPLY_VALID | u32::from(st.reply_data),
            "REPLY" => 0,
            "IRQ_STATUS" => self.irq_status(st),
            "IRQ_ENABLE" => self.irq_enable,
            _ => match &r.snap {
                Some(snap) => self.snapshot.word(snap, word),
                None => r.reset,
            },
        }
    }

    /// The station's link inputs from the registers and this clock's AXI inputs.
    fn link(&self, i: &AxiInputs) -> (bool, u8, bool) {
        let take = i.s_axi_arvalid
            && !self.r_valid
            && matches!(at(u32::from(i.s_axi_araddr)), Some((r, _)) if r.access == Access::ReadTakes);
        (self.link_valid, self.link_data, take)
    }

    /// One rising edge: `i` the AXI inputs, `st` the station's outputs before the edge.
    fn clock(&mut self, i: &AxiInputs, st: &StationOutputs) {
        if i.reset {
            *self = AxiSlave::default();
            return;
        }
        let before = *self;
        // Write: the held address and data take effect together.
        let fire = before.aw_full && before.w_full && !before.b_valid;
        self.link_valid = false;
        let mut clear = 0;
        if fire {
            let lane0 = before.w_strb & 1 == 1;
            let reg = at(u32::from(before.aw_addr)).map(|(r, _)| r);
            let ok = reg.is_some_and(|r| r.access.writable());
            match reg.map(|r| r.name) {
                Some("COMMAND") if lane0 => {
                    self.link_valid = true;
                    self.link_data = before.w_data as u8;
                }
                Some("IRQ_STATUS") if lane0 => clear = before.w_data & IRQ_LATCHED,
                Some("IRQ_ENABLE") if lane0 => self.irq_enable = before.w_data & IRQ_ALL,
                Some("SNAPSHOT") => {
                    self.snapshot = Snapshot {
                        status: st.status,
                        ticks: st.ticks,
                        x: st.x,
                        v: st.v,
                        a: st.a,
                        j: st.j,
                    }
                }
                _ => {}
            }
            self.b_resp = if ok { RESP_OKAY } else { RESP_SLVERR };
        }
        self.b_valid = fire || (before.b_valid && !i.s_axi_bready);
        self.aw_full = !fire && (before.aw_full || i.s_axi_awvalid);
        if !before.aw_full && i.s_axi_awvalid {
            self.aw_addr = i.s_axi_awaddr & addr_mask();
        }
        self.w_full = !fire && (before.w_full || i.s_axi_wvalid);
        if !before.w_full && i.s_axi_wvalid {
            self.w_data = i.s_axi_wdata;
            self.w_strb = i.s_axi_wstrb & 0xF;
        }
        // Read.
        let ar_fire = i.s_axi_arvalid && !before.r_valid;
        if ar_fire {
            (self.r_data, self.r_resp) = before.read(i.s_axi_araddr & addr_mask(), st);
        }
        self.r_valid = ar_fire || (before.r_valid && !i.s_axi_rready);
        // Interrupt causes, from the status before the edge.
        let bytes = status_bytes(&st.status);
        let done = status_bit(&bytes, STATUS_DONE_BIT);
        // The state byte is ErrorStop.
        let fault = bytes[STATUS_STATE_LSB as usize / 8] == AxisState::ErrorStop as u8;
        let swap = status_bit(&bytes, STATUS_SWAP_PENDING_BIT);
        let mut events = 0;
        if done && !before.was_done {
            events |= IRQ_DONE;
        }
        if fault && !before.was_fault {
            events |= IRQ_FAULT;
        }
        if !swap && before.was_swap_pending {
            events |= IRQ_SWAP;
        }
        self.irq_latched = (before.irq_latched & !clear) | events;
        self.was_done = done;
        self.was_fault = fault;
        self.was_swap_pending = swap;
        self.irq = before.irq_status(st) & before.irq_enable != 0;
    }
}

/// The address bits the slave decodes.
const fn addr_mask() -> u8 {
    ((1u32 << ADDR_BITS) - 1) as u8
}

/// The AXI4-Lite top (`snapgen_axi`): the slave in front of the station.
#[derive(Clone, Debug)]
pub struct AxiDevice {
    slave: AxiSlave,
    station: Station,
}

impl AxiDevice {
    /// An AXI top in its power-up state; apply a reset before use ([`AxiDevice::powered_up`]
    /// does).
    pub fn new(design: &Design) -> Self {
        AxiDevice {
            slave: AxiSlave::default(),
            station: Station::new(design),
        }
    }

    /// An AXI top after `clocks` clocks of reset (every input low).
    pub fn powered_up(design: &Design, clocks: u32) -> Self {
        let mut d = AxiDevice::new(design);
        let reset = AxiInputs {
            reset: true,
            ..Default::default()
        };
        for _ in 0..clocks {
            d.clock(&reset);
        }
        d
    }

    /// The station behind the slave.
    pub fn station(&self) -> &Station {
        &self.station
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> AxiOutputs {
        let s = self.station.outputs();
        let mut o = station_pins!(
            s,
            AxiOutputs {
                ..Default::default()
            }
        );
        self.slave.outputs(&mut o);
        o
    }

    /// One rising clock edge with the inputs `i`; returns the outputs after it.
    pub fn clock(&mut self, i: &AxiInputs) -> AxiOutputs {
        let s = self.station.outputs();
        let (link_valid, link_data, reply_take) = self.slave.link(i);
        let station_in = station_inputs!(i, {
            link_valid,
            link_data,
            link_error: false,
            reply_take,
        });
        self.slave.clock(i, &s);
        self.station.clock(&station_in);
        self.outputs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use snapgen_spec::axi::{offset_of, ID_MAGIC};

    fn design() -> Design {
        let format = crate::format::DEFAULT_FORMAT;
        Design::from_timing(&format, &crate::timing::Timing::default()).unwrap()
    }

    /// A write then a read through the handshakes, every channel's VALID raised at once.
    fn write(d: &mut AxiDevice, addr: u32, data: u32) -> u8 {
        let mut i = AxiInputs {
            s_axi_awvalid: true,
            s_axi_awaddr: addr as u8,
            s_axi_wvalid: true,
            s_axi_wdata: data,
            s_axi_wstrb: 0xF,
            s_axi_bready: true,
            ..Default::default()
        };
        for _ in 0..10 {
            let before = d.outputs();
            d.clock(&i);
            // A handshake happens at the edge where VALID and READY are both high.
            i.s_axi_awvalid &= !before.s_axi_awready;
            i.s_axi_wvalid &= !before.s_axi_wready;
            if before.s_axi_bvalid {
                return before.s_axi_bresp;
            }
        }
        panic!("no write response")
    }

    fn read(d: &mut AxiDevice, addr: u32) -> (u32, u8) {
        let i = AxiInputs {
            s_axi_arvalid: true,
            s_axi_araddr: addr as u8,
            ..Default::default()
        };
        d.clock(&i);
        let o = d.outputs();
        assert!(o.s_axi_rvalid);
        d.clock(&AxiInputs {
            s_axi_rready: true,
            ..Default::default()
        });
        (o.s_axi_rdata, o.s_axi_rresp)
    }

    #[test]
    fn identity_registers_and_errors() {
        let mut d = AxiDevice::powered_up(&design(), 4);
        assert_eq!(read(&mut d, offset_of("ID")), (ID_MAGIC, RESP_OKAY));
        assert_eq!(read(&mut d, offset_of("COMMAND")), (0, RESP_SLVERR));
        assert_eq!(read(&mut d, 0xFC), (0, RESP_SLVERR));
        assert_eq!(write(&mut d, offset_of("ID"), 1), RESP_SLVERR);
        assert_eq!(write(&mut d, offset_of("IRQ_ENABLE"), 0xFF), RESP_OKAY);
        assert_eq!(read(&mut d, offset_of("IRQ_ENABLE")), (IRQ_ALL, RESP_OKAY));
    }
}
