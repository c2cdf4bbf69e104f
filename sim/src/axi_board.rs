//! A virtual board behind AXI4-Lite: the AXI top (`snapgen_axi`) as the model
//! (`snapgen_model::io::axi::AxiDevice`) or Verilated with the model in lockstep (every output
//! compared on every clock), its registers reached through the handshakes a processor's
//! interconnect makes, clock by clock, as [`snapgen_host::uio::Registers`]: the host's UIO
//! link ([`snapgen_host::uio::RegisterTransport`]) runs on it the same code it runs on a
//! `/dev/uioN` mapping. Time is the board's own (its clocks), so a latency measured here is
//! the design's, to the clock. The encoder follows the reference as an ideal motor would
//! ([`Peer`]).

use snapgen_host::link::{FramedLink, LinkError, RetryPolicy};
use snapgen_host::uio::{RegisterTransport, Registers};
use snapgen_model::device::Design;
use snapgen_model::io::axi::AxiDevice;
use snapgen_model::peer::Peer;
use snapgen_model::ports::{AxiInputs, AxiOutputs};
use snapgen_spec::axi::RESP_OKAY;

use crate::axi::{encode_inputs, encode_outputs, AXI_OUTPUTS, OUT_SLOTS, OUT_WORDS};
use crate::layout::{first_difference, PortMismatch};
use crate::verilated::Verilated;
use crate::SimError;

/// Clocks run per call while the bus is idle.
const IDLE_CHUNK: u64 = 64;
/// Clocks a register access may take before the board is declared dead.
const ACCESS_LIMIT: u64 = 1000;

/// A virtual AXI board.
pub struct AxiBoard {
    design: Design,
    model: AxiDevice,
    fabric: Option<Verilated>,
    peer: Peer,
    outputs: AxiOutputs,
    clocks: u64,
    accesses: u64,
    access_clocks: u64,
    mismatches: u64,
    first_mismatch: Option<PortMismatch>,
    ins: Vec<u32>,
    outs: Vec<u32>,
    want: Vec<u32>,
}

impl AxiBoard {
    /// The model of `design`'s AXI top.
    pub fn model(design: &Design) -> Self {
        Self::with(design, None)
    }

    /// The Verilated AXI top of `design` (built, or found in the build cache) with the model
    /// in lockstep: every output of every clock compared ([`AxiBoard::mismatches`]).
    pub fn lockstep(design: &Design) -> Result<Self, SimError> {
        let verilog = snapgen_hdl::axi_top::axi_sources_text(design);
        let built = crate::build::build_axi(&verilog, false)?;
        let fabric = crate::axi::open(&built.library, None)?;
        Ok(Self::with(design, Some(fabric)))
    }

    fn with(design: &Design, fabric: Option<Verilated>) -> Self {
        let mut peer = Peer::new(design.dividers.uart_divisor);
        peer.wiring = design.input_polarity;
        peer.follow = true;
        let model = AxiDevice::new(design);
        let outputs = model.outputs();
        AxiBoard {
            design: *design,
            model,
            fabric,
            peer,
            outputs,
            clocks: 0,
            accesses: 0,
            access_clocks: 0,
            mismatches: 0,
            first_mismatch: None,
            ins: Vec::new(),
            outs: Vec::new(),
            want: Vec::new(),
        }
    }

    /// The design.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// Clocks run since power-up.
    pub fn clocks(&self) -> u64 {
        self.clocks
    }

    /// Clocks whose outputs differed, fabric against model (0 for the model alone).
    pub fn mismatches(&self) -> u64 {
        self.mismatches
    }

    /// The first of them.
    pub fn first_mismatch(&self) -> Option<&PortMismatch> {
        self.first_mismatch.as_ref()
    }

    /// The world around the board: switches, encoder.
    pub fn peer(&mut self) -> &mut Peer {
        &mut self.peer
    }

    /// Mean clocks a register access took so far.
    pub fn clocks_per_access(&self) -> f64 {
        if self.accesses == 0 {
            5.0
        } else {
            self.access_clocks as f64 / self.accesses as f64
        }
    }

    /// The outputs as they stand.
    pub fn outputs(&self) -> &AxiOutputs {
        &self.outputs
    }

    /// Runs clocks with the AXI inputs `bus` (its pins from the peer) for each: `bus` says, for
    /// the outputs before each clock, what the master drives. Returns after `clocks` clocks or
    /// as soon as `bus` returns None (the outputs after the last clock are kept).
    fn run(&mut self, clocks: u64, mut bus: impl FnMut(&AxiOutputs) -> Option<AxiInputs>) {
        let mut left = clocks;
        while left > 0 {
            let Some(axi) = bus(&self.outputs) else {
                return;
            };
            let i = crate::axi::with_pins(&self.peer.inputs(), axi);
            let o = self.model.clock(&i);
            if let Some(f) = &mut self.fabric {
                self.ins.clear();
                self.ins.extend_from_slice(&encode_inputs(&i));
                f.run_each(&self.ins, &mut self.outs);
                self.want.clear();
                self.want.extend_from_slice(&encode_outputs(&o));
                if self.outs != self.want {
                    self.mismatches += 1;
                    if self.first_mismatch.is_none() {
                        self.first_mismatch = first_difference(
                            &AXI_OUTPUTS,
                            &OUT_SLOTS,
                            OUT_WORDS,
                            self.clocks,
                            &self.outs,
                            &self.want,
                        );
                    }
                }
            }
            self.peer.observe_status(&o.status);
            self.outputs = o;
            self.clocks += 1;
            left -= 1;
        }
    }

    /// Runs `clocks` clocks with the bus idle.
    pub fn idle(&mut self, clocks: u64) {
        self.run(clocks, |_| Some(idle()));
    }

    fn timeout(&self, what: &str, offset: u32) -> LinkError {
        LinkError::Io(format!(
            "the AXI slave did not answer a {what} of {offset:#x} within {ACCESS_LIMIT} clocks"
        ))
    }
}

/// The bus at rest: no request, ready for responses.
fn idle() -> AxiInputs {
    AxiInputs {
        s_axi_bready: true,
        s_axi_rready: true,
        ..Default::default()
    }
}

impl Registers for AxiBoard {
    fn read(&mut self, offset: u32) -> Result<u32, LinkError> {
        let start = self.clocks;
        let (mut asked, mut answer) = (false, None);
        self.run(ACCESS_LIMIT, |o| {
            if asked && o.s_axi_rvalid {
                answer = Some((o.s_axi_rdata, o.s_axi_rresp));
            }
            if answer.is_some() && !o.s_axi_rvalid {
                return None;
            }
            let mut i = idle();
            if !asked {
                i.s_axi_arvalid = true;
                i.s_axi_araddr = offset as u8;
                asked = o.s_axi_arready;
            }
            Some(i)
        });
        self.accesses += 1;
        self.access_clocks += self.clocks - start;
        match answer {
            Some((data, RESP_OKAY)) => Ok(data),
            Some((_, resp)) => Err(LinkError::Io(format!(
                "the station answered a read of {offset:#x} with response {resp} (SLVERR)"
            ))),
            None => Err(self.timeout("read", offset)),
        }
    }

    fn write(&mut self, offset: u32, value: u32) -> Result<(), LinkError> {
        let start = self.clocks;
        let (mut aw, mut w, mut answer) = (false, false, None);
        self.run(ACCESS_LIMIT, |o| {
            if aw && w && o.s_axi_bvalid {
                answer = Some(o.s_axi_bresp);
            }
            if answer.is_some() && !o.s_axi_bvalid {
                return None;
            }
            let mut i = idle();
            if !aw {
                i.s_axi_awvalid = true;
                i.s_axi_awaddr = offset as u8;
                aw = o.s_axi_awready;
            }
            if !w {
                i.s_axi_wvalid = true;
                i.s_axi_wdata = value;
                i.s_axi_wstrb = 0xF;
                w = o.s_axi_wready;
            }
            Some(i)
        });
        self.accesses += 1;
        self.access_clocks += self.clocks - start;
        match answer {
            Some(RESP_OKAY) => Ok(()),
            Some(resp) => Err(LinkError::Io(format!(
                "the station answered a write of {offset:#x} with response {resp} (SLVERR)"
            ))),
            None => Err(self.timeout("write", offset)),
        }
    }

    fn wait_irq(&mut self, seconds: f64) -> Result<bool, LinkError> {
        let mut left = self.clocks_of(seconds).max(1);
        while left > 0 {
            if self.outputs.irq {
                return Ok(true);
            }
            let n = left.min(IDLE_CHUNK);
            let mut seen = false;
            self.run(n, |o| {
                seen |= o.irq;
                (!seen).then(idle)
            });
            if seen {
                return Ok(true);
            }
            left -= n;
        }
        Ok(self.outputs.irq)
    }

    fn now(&self) -> f64 {
        self.clocks as f64 / f64::from(self.design.clock_hz)
    }

    fn sleep(&mut self, seconds: f64) {
        let n = self.clocks_of(seconds);
        self.idle(n);
    }

    fn access_time(&self) -> f64 {
        self.clocks_per_access() / f64::from(self.design.clock_hz)
    }
}

impl AxiBoard {
    fn clocks_of(&self, seconds: f64) -> u64 {
        (seconds.max(0.0) * f64::from(self.design.clock_hz)).round() as u64
    }
}

/// The host's medium to `board`: its registers (the UIO link's code up to the `mmap`). Fails
/// unless the board's `ID` and `VERSION` are this host's (the board is reset first).
pub fn axi_transport(mut board: AxiBoard) -> Result<RegisterTransport<AxiBoard>, LinkError> {
    // Power-up: the reset the peer gives, then a few clocks.
    board.idle(16);
    RegisterTransport::open(board)
}

/// The host's link to `board` over its registers ([`axi_transport`]): the framed protocol
/// with the one retry policy, sequence numbers from 0 (a simulation repeats).
pub fn axi_link(board: AxiBoard) -> Result<FramedLink<RegisterTransport<AxiBoard>>, LinkError> {
    Ok(FramedLink::new(
        axi_transport(board)?,
        RetryPolicy::default(),
        0,
    ))
}
