//! Command executor (the reference is `snapgen_model::device::Device`): on each good frame it
//! checks the command and its length and arguments, drives the motion core for one clock
//! (segment write, count, start, stop), updates the configuration, and requests the reply. Bad
//! CRCs and dropped frames are counted and NAKed; a UART framing error raises an error flag. A
//! LOAD_SEGMENT, COMMIT, START, STOP, ABORT or CONFIGURE with the same command and sequence as
//! the last such one is answered again without executing it. STOP is the controlled stop: the
//! core ends the cruise segment (named by a two-byte COMMIT) and decelerates as planned. While a move runs, a telemetry
//! request goes out every `telemetry_period` ticks, and one when it ends.

use rust_hdl::prelude::*;

use crate::{ADDR_BITS, D_BITS, INDEX_BITS, TICK_BITS};

/// Reply kinds (as `reply_packer::kind`).
const K_VERSION: u64 = 0;
const K_ACK: u64 = 1;
const K_NAK: u64 = 2;
const K_STATUS: u64 = 3;
const K_POSITION: u64 = 4;

/// The executor.
#[derive(LogicBlock)]
pub struct Executor {
    /// Fabric clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset.
    pub reset: Signal<In, Bit>,
    /// Pulse: a frame with a good CRC.
    pub frame: Signal<In, Bit>,
    /// Pulse: a bad CRC.
    pub bad_crc: Signal<In, Bit>,
    /// Pulse: a partial frame was dropped.
    pub dropped: Signal<In, Bit>,
    /// Pulse: UART framing error.
    pub line_error: Signal<In, Bit>,
    /// Frame command.
    pub cmd: Signal<In, Bits<8>>,
    /// Frame sequence.
    pub seq: Signal<In, Bits<8>>,
    /// Frame payload length.
    pub len: Signal<In, Bits<8>>,
    /// LOAD_SEGMENT index.
    pub seg_index: Signal<In, Bits<8>>,
    /// LOAD_SEGMENT ticks.
    pub seg_ticks: Signal<In, Bits<TICK_BITS>>,
    /// LOAD_SEGMENT snap.
    pub seg_snap: Signal<In, Bits<D_BITS>>,
    /// Last payload byte (COMMIT count, or the cruise of a two-byte COMMIT).
    pub commit_count: Signal<In, Bits<8>>,
    /// Payload byte before the last (count of a two-byte COMMIT).
    pub commit_first: Signal<In, Bits<8>>,
    /// CONFIGURE parameter.
    pub cfg_param: Signal<In, Bits<8>>,
    /// CONFIGURE value.
    pub cfg_value: Signal<In, Bits<32>>,
    /// Core: playing.
    pub busy: Signal<In, Bit>,
    /// Core: tick enable.
    pub tick: Signal<In, Bit>,
    /// Core: standby program's segment count.
    pub standby_count: Signal<In, Bits<INDEX_BITS>>,
    /// Tick divider after reset.
    pub tick_div_default: Signal<In, Bits<32>>,
    /// Core: write a segment.
    pub write_enable: Signal<Out, Bit>,
    /// Core: segment address.
    pub write_address: Signal<Out, Bits<ADDR_BITS>>,
    /// Core: segment ticks.
    pub write_ticks: Signal<Out, Bits<TICK_BITS>>,
    /// Core: segment snap.
    pub write_snap: Signal<Out, Bits<D_BITS>>,
    /// Core: set the count.
    pub count_enable: Signal<Out, Bit>,
    /// Core: count value.
    pub count_value: Signal<Out, Bits<INDEX_BITS>>,
    /// Core: cruise segment of the program (63: none).
    pub cruise_value: Signal<Out, Bits<INDEX_BITS>>,
    /// Core: controlled stop.
    pub soft_stop: Signal<Out, Bit>,
    /// Core: start.
    pub start: Signal<Out, Bit>,
    /// Core: stop (abort).
    pub stop: Signal<Out, Bit>,
    /// Configuration: tick divider.
    pub tick_div: Signal<Out, Bits<32>>,
    /// Configuration: PWM period.
    pub pwm_period: Signal<Out, Bits<32>>,
    /// Configuration: encoder filter.
    pub encoder_filter: Signal<Out, Bits<32>>,
    /// Frames dropped for a bad CRC.
    pub bad_crc_count: Signal<Out, Bits<16>>,
    /// Frames dropped for a bad length, an unknown command or a cut.
    pub bad_frames_count: Signal<Out, Bits<16>>,
    /// Error flags (bit 1: UART framing error seen).
    pub errors: Signal<Out, Bits<8>>,
    /// Pulse: send a reply.
    pub reply: Signal<Out, Bit>,
    /// Reply kind.
    pub reply_kind: Signal<Out, Bits<3>>,
    /// Reply command field.
    pub reply_cmd: Signal<Out, Bits<8>>,
    /// Reply sequence.
    pub reply_seq: Signal<Out, Bits<8>>,
    /// Reply NAK reason.
    pub reply_reason: Signal<Out, Bits<8>>,
    /// Pulse: send telemetry.
    pub telemetry: Signal<Out, Bit>,
    we: DFF<Bit>,
    wa: DFF<Bits<ADDR_BITS>>,
    wt: DFF<Bits<TICK_BITS>>,
    ws: DFF<Bits<D_BITS>>,
    ce: DFF<Bit>,
    cv: DFF<Bits<INDEX_BITS>>,
    cr: DFF<Bits<INDEX_BITS>>,
    ss: DFF<Bit>,
    st: DFF<Bit>,
    sp: DFF<Bit>,
    tick_div_reg: DFF<Bits<32>>,
    tel_period: DFF<Bits<32>>,
    tel_left: DFF<Bits<32>>,
    pwm_reg: DFF<Bits<32>>,
    filter_reg: DFF<Bits<32>>,
    crc_count: DFF<Bits<16>>,
    frames_count: DFF<Bits<16>>,
    errors_reg: DFF<Bits<8>>,
    rq: DFF<Bit>,
    rk: DFF<Bits<3>>,
    rc: DFF<Bits<8>>,
    rs: DFF<Bits<8>>,
    rr: DFF<Bits<8>>,
    last_valid: DFF<Bit>,
    last_cmd: DFF<Bits<8>>,
    last_seq: DFF<Bits<8>>,
    last_kind: DFF<Bits<3>>,
    last_reason: DFF<Bits<8>>,
    tel: DFF<Bit>,
    was_busy: DFF<Bit>,
    kind: Signal<Local, Bits<3>>,
    reason: Signal<Local, Bits<8>>,
    counted: Signal<Local, Bit>,
    effect: Signal<Local, Bit>,
    k_version: Constant<Bits<3>>,
    k_ack: Constant<Bits<3>>,
    k_nak: Constant<Bits<3>>,
    k_status: Constant<Bits<3>>,
    k_position: Constant<Bits<3>>,
    c_ping: Constant<Bits<8>>,
    c_load: Constant<Bits<8>>,
    c_commit: Constant<Bits<8>>,
    c_start: Constant<Bits<8>>,
    c_stop: Constant<Bits<8>>,
    c_abort: Constant<Bits<8>>,
    c_status: Constant<Bits<8>>,
    c_config: Constant<Bits<8>>,
    c_position: Constant<Bits<8>>,
    r_bad_crc: Constant<Bits<8>>,
    r_bad_length: Constant<Bits<8>>,
    r_unknown: Constant<Bits<8>>,
    r_busy: Constant<Bits<8>>,
    r_bad_argument: Constant<Bits<8>>,
    r_no_program: Constant<Bits<8>>,
    r_framing: Constant<Bits<8>>,
    b0: Constant<Bits<8>>,
    b1: Constant<Bits<8>>,
    b2: Constant<Bits<8>>,
    b3: Constant<Bits<8>>,
    b4: Constant<Bits<8>>,
    b5: Constant<Bits<8>>,
    b18: Constant<Bits<8>>,
    b32: Constant<Bits<8>>,
    b255: Constant<Bits<8>>,
    no_cruise: Constant<Bits<INDEX_BITS>>,
    t0: Constant<Bits<32>>,
    t1: Constant<Bits<32>>,
    n0: Constant<Bits<16>>,
    n1: Constant<Bits<16>>,
    i0: Constant<Bits<INDEX_BITS>>,
    flag_framing: Constant<Bits<8>>,
}

impl Default for Executor {
    fn default() -> Self {
        let b = |v: u64| Constant::new(Bits::<8>::from(v));
        Executor {
            clock: Default::default(),
            reset: Default::default(),
            frame: Default::default(),
            bad_crc: Default::default(),
            dropped: Default::default(),
            line_error: Default::default(),
            cmd: Default::default(),
            seq: Default::default(),
            len: Default::default(),
            seg_index: Default::default(),
            seg_ticks: Default::default(),
            seg_snap: Default::default(),
            commit_count: Default::default(),
            commit_first: Default::default(),
            cfg_param: Default::default(),
            cfg_value: Default::default(),
            busy: Default::default(),
            tick: Default::default(),
            standby_count: Default::default(),
            tick_div_default: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_ticks: Default::default(),
            write_snap: Default::default(),
            count_enable: Default::default(),
            count_value: Default::default(),
            cruise_value: Default::default(),
            soft_stop: Default::default(),
            start: Default::default(),
            stop: Default::default(),
            tick_div: Default::default(),
            pwm_period: Default::default(),
            encoder_filter: Default::default(),
            bad_crc_count: Default::default(),
            bad_frames_count: Default::default(),
            errors: Default::default(),
            reply: Default::default(),
            reply_kind: Default::default(),
            reply_cmd: Default::default(),
            reply_seq: Default::default(),
            reply_reason: Default::default(),
            telemetry: Default::default(),
            we: Default::default(),
            wa: Default::default(),
            wt: Default::default(),
            ws: Default::default(),
            ce: Default::default(),
            cv: Default::default(),
            cr: Default::default(),
            ss: Default::default(),
            st: Default::default(),
            sp: Default::default(),
            tick_div_reg: Default::default(),
            tel_period: Default::default(),
            tel_left: Default::default(),
            pwm_reg: Default::default(),
            filter_reg: Default::default(),
            crc_count: Default::default(),
            frames_count: Default::default(),
            errors_reg: Default::default(),
            rq: Default::default(),
            rk: Default::default(),
            rc: Default::default(),
            rs: Default::default(),
            rr: Default::default(),
            last_valid: Default::default(),
            last_cmd: Default::default(),
            last_seq: Default::default(),
            last_kind: Default::default(),
            last_reason: Default::default(),
            tel: Default::default(),
            was_busy: Default::default(),
            kind: Default::default(),
            reason: Default::default(),
            counted: Default::default(),
            effect: Default::default(),
            k_version: Constant::new(K_VERSION.into()),
            k_ack: Constant::new(K_ACK.into()),
            k_nak: Constant::new(K_NAK.into()),
            k_status: Constant::new(K_STATUS.into()),
            k_position: Constant::new(K_POSITION.into()),
            c_ping: b(0x01),
            c_load: b(0x02),
            c_commit: b(0x03),
            c_start: b(0x04),
            c_stop: b(0x05),
            c_abort: b(0x06),
            c_status: b(0x07),
            c_config: b(0x08),
            c_position: b(0x09),
            r_bad_crc: b(1),
            r_bad_length: b(2),
            r_unknown: b(3),
            r_busy: b(4),
            r_bad_argument: b(5),
            r_no_program: b(6),
            r_framing: b(7),
            b0: b(0),
            b1: b(1),
            b2: b(2),
            b3: b(3),
            b4: b(4),
            b5: b(5),
            b18: b(18),
            b32: b(32),
            b255: b(255),
            no_cruise: Constant::new(63.into()),
            t0: Constant::new(0.into()),
            t1: Constant::new(1.into()),
            n0: Constant::new(0.into()),
            n1: Constant::new(1.into()),
            i0: Constant::new(0.into()),
            flag_framing: b(2),
        }
    }
}

impl Logic for Executor {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            we,
            wa,
            wt,
            ws,
            ce,
            cv,
            cr,
            ss,
            st,
            sp,
            tick_div_reg,
            tel_period,
            tel_left,
            pwm_reg,
            filter_reg,
            crc_count,
            frames_count,
            errors_reg,
            rq,
            rk,
            rc,
            rs,
            rr,
            last_valid,
            last_cmd,
            last_seq,
            last_kind,
            last_reason,
            tel,
            was_busy
        );
        self.we.d.next = false;
        self.ce.d.next = false;
        self.ss.d.next = false;
        self.st.d.next = false;
        self.sp.d.next = false;
        self.rq.d.next = false;
        self.tel.d.next = false;
        self.was_busy.d.next = self.busy.val();
        // Decode the frame: reply kind and reason; `counted` marks a bad frame.
        self.kind.next = self.k_nak.val();
        self.reason.next = self.r_unknown.val();
        self.counted.next = false;
        self.effect.next = (self.cmd.val() == self.c_load.val())
            | (self.cmd.val() == self.c_commit.val())
            | (self.cmd.val() == self.c_start.val())
            | (self.cmd.val() == self.c_stop.val())
            | (self.cmd.val() == self.c_abort.val())
            | (self.cmd.val() == self.c_config.val());
        if self.cmd.val() == self.c_ping.val() {
            if self.len.val() == self.b0.val() {
                self.kind.next = self.k_version.val();
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_load.val() {
            if self.len.val() == self.b18.val() {
                if (self.seg_index.val() < self.b32.val()) & (self.seg_ticks.val() != self.t0.val())
                {
                    self.kind.next = self.k_ack.val();
                } else {
                    self.reason.next = self.r_bad_argument.val();
                }
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_commit.val() {
            if self.len.val() == self.b1.val() {
                if self.commit_count.val() <= self.b32.val() {
                    self.kind.next = self.k_ack.val();
                } else {
                    self.reason.next = self.r_bad_argument.val();
                }
            } else if self.len.val() == self.b2.val() {
                // Count, then the cruise segment (< 32, or 255 for none).
                if (self.commit_first.val() <= self.b32.val())
                    & ((self.commit_count.val() < self.b32.val())
                        | (self.commit_count.val() == self.b255.val()))
                {
                    self.kind.next = self.k_ack.val();
                } else {
                    self.reason.next = self.r_bad_argument.val();
                }
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_start.val() {
            if self.len.val() == self.b0.val() {
                if self.busy.val() {
                    self.reason.next = self.r_busy.val();
                } else if self.standby_count.val() == self.i0.val() {
                    self.reason.next = self.r_no_program.val();
                } else {
                    self.kind.next = self.k_ack.val();
                }
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if (self.cmd.val() == self.c_stop.val()) | (self.cmd.val() == self.c_abort.val()) {
            if self.len.val() == self.b0.val() {
                self.kind.next = self.k_ack.val();
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_status.val() {
            if self.len.val() == self.b0.val() {
                self.kind.next = self.k_status.val();
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_position.val() {
            if self.len.val() == self.b0.val() {
                self.kind.next = self.k_position.val();
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else if self.cmd.val() == self.c_config.val() {
            if self.len.val() == self.b5.val() {
                if (self.cfg_param.val() >= self.b1.val()) & (self.cfg_param.val() <= self.b4.val())
                {
                    self.kind.next = self.k_ack.val();
                } else {
                    self.reason.next = self.r_bad_argument.val();
                }
            } else {
                self.reason.next = self.r_bad_length.val();
                self.counted.next = true;
            }
        } else {
            self.counted.next = true;
        }
        if self.reset.val() {
            self.tick_div_reg.d.next = self.tick_div_default.val();
            self.tel_period.d.next = self.t0.val();
            self.tel_left.d.next = self.t0.val();
            self.pwm_reg.d.next = self.t0.val();
            self.filter_reg.d.next = self.t0.val();
            self.crc_count.d.next = self.n0.val();
            self.frames_count.d.next = self.n0.val();
            self.errors_reg.d.next = self.b0.val();
            self.last_valid.d.next = false;
        } else if self.frame.val() {
            self.rq.d.next = true;
            self.rs.d.next = self.seq.val();
            self.rc.d.next = self.cmd.val();
            if self.effect.val()
                & self.last_valid.q.val()
                & (self.cmd.val() == self.last_cmd.q.val())
                & (self.seq.val() == self.last_seq.q.val())
            {
                // A retry: the same answer, no effect.
                self.rk.d.next = self.last_kind.q.val();
                self.rr.d.next = self.last_reason.q.val();
            } else {
                self.rk.d.next = self.kind.val();
                self.rr.d.next = self.reason.val();
                if self.counted.val() {
                    self.frames_count.d.next = self.frames_count.q.val() + self.n1.val();
                }
                if self.kind.val() == self.k_ack.val() {
                    if self.cmd.val() == self.c_load.val() {
                        self.we.d.next = true;
                        self.wa.d.next = self.seg_index.val().get_bits::<ADDR_BITS>(0);
                        self.wt.d.next = self.seg_ticks.val();
                        self.ws.d.next = self.seg_snap.val();
                    }
                    if self.cmd.val() == self.c_commit.val() {
                        self.ce.d.next = true;
                        if self.len.val() == self.b1.val() {
                            self.cv.d.next = self.commit_count.val().get_bits::<INDEX_BITS>(0);
                            self.cr.d.next = self.no_cruise.val();
                        } else {
                            self.cv.d.next = self.commit_first.val().get_bits::<INDEX_BITS>(0);
                            self.cr.d.next = self.commit_count.val().get_bits::<INDEX_BITS>(0);
                        }
                    }
                    if self.cmd.val() == self.c_stop.val() {
                        self.ss.d.next = true;
                    }
                    if self.cmd.val() == self.c_start.val() {
                        self.st.d.next = true;
                    }
                    if self.cmd.val() == self.c_abort.val() {
                        self.sp.d.next = true;
                    }
                    if self.cmd.val() == self.c_config.val() {
                        if self.cfg_param.val() == self.b1.val() {
                            self.tick_div_reg.d.next = self.cfg_value.val();
                        }
                        if self.cfg_param.val() == self.b2.val() {
                            self.pwm_reg.d.next = self.cfg_value.val();
                        }
                        if self.cfg_param.val() == self.b3.val() {
                            self.filter_reg.d.next = self.cfg_value.val();
                        }
                        if self.cfg_param.val() == self.b4.val() {
                            self.tel_period.d.next = self.cfg_value.val();
                            self.tel_left.d.next = self.cfg_value.val();
                        }
                    }
                }
                if self.effect.val() {
                    self.last_valid.d.next = true;
                    self.last_cmd.d.next = self.cmd.val();
                    self.last_seq.d.next = self.seq.val();
                    self.last_kind.d.next = self.kind.val();
                    self.last_reason.d.next = self.reason.val();
                }
            }
        } else if self.bad_crc.val() {
            self.crc_count.d.next = self.crc_count.q.val() + self.n1.val();
            self.rq.d.next = true;
            self.rk.d.next = self.k_nak.val();
            self.rc.d.next = self.b0.val();
            self.rs.d.next = self.b0.val();
            self.rr.d.next = self.r_bad_crc.val();
        } else if self.dropped.val() {
            self.frames_count.d.next = self.frames_count.q.val() + self.n1.val();
            self.rq.d.next = true;
            self.rk.d.next = self.k_nak.val();
            self.rc.d.next = self.b0.val();
            self.rs.d.next = self.b0.val();
            self.rr.d.next = self.r_framing.val();
        }
        if self.line_error.val() & !self.reset.val() {
            self.errors_reg.d.next = self.errors_reg.q.val() | self.flag_framing.val();
        }
        // Telemetry while a move runs, and once when it ends.
        if !self.reset.val() & (self.tel_period.q.val() != self.t0.val()) {
            if self.tick.val() & self.busy.val() {
                if self.tel_left.q.val() <= self.t1.val() {
                    self.tel.d.next = true;
                    self.tel_left.d.next = self.tel_period.q.val();
                } else {
                    self.tel_left.d.next = self.tel_left.q.val() - self.t1.val();
                }
            }
            if self.was_busy.q.val() & !self.busy.val() {
                self.tel.d.next = true;
                self.tel_left.d.next = self.tel_period.q.val();
            }
        }
        self.write_enable.next = self.we.q.val();
        self.write_address.next = self.wa.q.val();
        self.write_ticks.next = self.wt.q.val();
        self.write_snap.next = self.ws.q.val();
        self.count_enable.next = self.ce.q.val();
        self.count_value.next = self.cv.q.val();
        self.cruise_value.next = self.cr.q.val();
        self.soft_stop.next = self.ss.q.val();
        self.start.next = self.st.q.val();
        self.stop.next = self.sp.q.val();
        self.tick_div.next = self.tick_div_reg.q.val();
        self.pwm_period.next = self.pwm_reg.q.val();
        self.encoder_filter.next = self.filter_reg.q.val();
        self.bad_crc_count.next = self.crc_count.q.val();
        self.bad_frames_count.next = self.frames_count.q.val();
        self.errors.next = self.errors_reg.q.val();
        self.reply.next = self.rq.q.val();
        self.reply_kind.next = self.rk.q.val();
        self.reply_cmd.next = self.rc.q.val();
        self.reply_seq.next = self.rs.q.val();
        self.reply_reason.next = self.rr.q.val();
        self.telemetry.next = self.tel.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn executor_is_synthesizable() {
        let mut uut = Executor::default();
        uut.connect_all();
        let v = crate::verilog::direct_clocks(&generate_verilog(&uut));
        yosys_validate("executor", &v).unwrap();
        crate::synth_check::synth_xilinx("executor", &v);
    }
}
