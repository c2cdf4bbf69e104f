//! The co-simulation's AXI4-Lite master: writes and reads issued in order, the next one's
//! address (and data) sent while up to [`MAX_OUTSTANDING`] earlier ones await their responses
//! (so the slave's AWREADY, WREADY and ARREADY back-pressure is met), each channel's VALID
//! raised after a random delay and held until its handshake, random BREADY/RREADY
//! back-pressure, random values on every line a VALID does not qualify.

use std::collections::VecDeque;

use rand::rngs::StdRng;
use rand::Rng;
use snapgen_model::ports::{AxiInputs, AxiOutputs};

/// A finished transaction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Done {
    /// A write and its response.
    Write {
        /// Byte address.
        addr: u8,
        /// Response.
        resp: u8,
    },
    /// A read, its data and response.
    Read {
        /// Byte address.
        addr: u8,
        /// Data.
        data: u32,
        /// Response.
        resp: u8,
    },
}

#[derive(Clone, Copy, Debug)]
struct Write {
    addr: u8,
    data: u32,
    strb: u8,
    aw_wait: u32,
    w_wait: u32,
    aw_done: bool,
    w_done: bool,
}

#[derive(Clone, Copy, Debug)]
struct Read {
    addr: u8,
    wait: u32,
}

/// Transactions of a kind whose requests are handed over and whose responses have not come.
pub const MAX_OUTSTANDING: usize = 2;

/// The master.
pub struct AxiMaster {
    writes: VecDeque<(u8, u32, u8)>,
    reads: VecDeque<u8>,
    write: Option<Write>,
    read: Option<Read>,
    /// Writes handed over, awaiting their responses, oldest first.
    write_wait: VecDeque<u8>,
    /// Reads handed over, awaiting their data.
    read_wait: VecDeque<u8>,
    /// Probability that BREADY (RREADY) is high on a clock.
    pub ready_odds: f64,
    /// Most clocks a VALID waits after its transaction begins.
    pub max_wait: u32,
    /// Finished transactions, oldest first.
    pub done: VecDeque<Done>,
}

impl AxiMaster {
    /// An idle master.
    pub fn new() -> Self {
        AxiMaster {
            writes: VecDeque::new(),
            reads: VecDeque::new(),
            write: None,
            read: None,
            write_wait: VecDeque::new(),
            read_wait: VecDeque::new(),
            ready_odds: 0.7,
            max_wait: 3,
            done: VecDeque::new(),
        }
    }

    /// Queues a write of `data` with strobes `strb` to byte address `addr`.
    pub fn write(&mut self, addr: u32, data: u32, strb: u8) {
        self.writes.push_back((addr as u8, data, strb));
    }

    /// Queues a read of byte address `addr`.
    pub fn read(&mut self, addr: u32) {
        self.reads.push_back(addr as u8);
    }

    /// Drops every transaction, queued or in flight (a reset: the slave forgets them).
    pub fn abort(&mut self) {
        self.writes.clear();
        self.reads.clear();
        self.write = None;
        self.read = None;
        self.write_wait.clear();
        self.read_wait.clear();
    }

    /// Writes queued or in flight.
    pub fn writes_pending(&self) -> usize {
        self.writes.len() + usize::from(self.write.is_some()) + self.write_wait.len()
    }

    /// Reads queued or in flight.
    pub fn reads_pending(&self) -> usize {
        self.reads.len() + usize::from(self.read.is_some()) + self.read_wait.len()
    }

    /// This clock's AXI inputs into `i` (the other fields untouched).
    pub fn drive(&mut self, r: &mut StdRng, i: &mut AxiInputs) {
        if self.write.is_none() && self.write_wait.len() < MAX_OUTSTANDING {
            if let Some((addr, data, strb)) = self.writes.pop_front() {
                self.write = Some(Write {
                    addr,
                    data,
                    strb,
                    aw_wait: r.gen_range(0..=self.max_wait),
                    w_wait: r.gen_range(0..=self.max_wait),
                    aw_done: false,
                    w_done: false,
                });
            }
        }
        if self.read.is_none() && self.read_wait.len() < MAX_OUTSTANDING {
            if let Some(addr) = self.reads.pop_front() {
                self.read = Some(Read {
                    addr,
                    wait: r.gen_range(0..=self.max_wait),
                });
            }
        }
        // Unqualified lines carry noise.
        i.s_axi_awaddr = r.gen();
        i.s_axi_wdata = r.gen();
        i.s_axi_wstrb = r.gen_range(0..16);
        i.s_axi_araddr = r.gen();
        i.s_axi_awvalid = false;
        i.s_axi_wvalid = false;
        i.s_axi_arvalid = false;
        if let Some(w) = &mut self.write {
            if !w.aw_done && w.aw_wait == 0 {
                i.s_axi_awvalid = true;
                i.s_axi_awaddr = w.addr;
            }
            if !w.w_done && w.w_wait == 0 {
                i.s_axi_wvalid = true;
                i.s_axi_wdata = w.data;
                i.s_axi_wstrb = w.strb;
            }
            w.aw_wait = w.aw_wait.saturating_sub(1);
            w.w_wait = w.w_wait.saturating_sub(1);
        }
        if let Some(rd) = &mut self.read {
            if rd.wait == 0 {
                i.s_axi_arvalid = true;
                i.s_axi_araddr = rd.addr;
            }
            rd.wait = rd.wait.saturating_sub(1);
        }
        i.s_axi_bready = r.gen_bool(self.ready_odds);
        i.s_axi_rready = r.gen_bool(self.ready_odds);
    }

    /// After the edge: `i` the inputs it drove, `o` the slave's outputs before the edge (a
    /// handshake is VALID and READY both high at the edge).
    pub fn after_edge(&mut self, i: &AxiInputs, o: &AxiOutputs) {
        // Responses first: a request handed over at this edge is answered later.
        if o.s_axi_bvalid && i.s_axi_bready {
            let addr = self.write_wait.pop_front().unwrap_or(u8::MAX);
            self.done.push_back(Done::Write {
                addr,
                resp: o.s_axi_bresp,
            });
        }
        if o.s_axi_rvalid && i.s_axi_rready {
            let addr = self.read_wait.pop_front().unwrap_or(u8::MAX);
            self.done.push_back(Done::Read {
                addr,
                data: o.s_axi_rdata,
                resp: o.s_axi_rresp,
            });
        }
        if let Some(w) = &mut self.write {
            w.aw_done |= i.s_axi_awvalid && o.s_axi_awready;
            w.w_done |= i.s_axi_wvalid && o.s_axi_wready;
            if w.aw_done && w.w_done {
                self.write_wait.push_back(w.addr);
                self.write = None;
            }
        }
        if let Some(rd) = &mut self.read {
            if i.s_axi_arvalid && o.s_axi_arready {
                self.read_wait.push_back(rd.addr);
                self.read = None;
            }
        }
    }
}

impl Default for AxiMaster {
    fn default() -> Self {
        Self::new()
    }
}
