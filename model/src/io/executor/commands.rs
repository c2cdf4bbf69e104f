//! The executor's commands: a frame with a good CRC checked (code, length, arguments, then the
//! axis state: the refusal table of docs/PROTOCOL.md, `snapgen_spec::refusals`), its effect
//! applied and its reply queued, retries answered again without effect.

use snapgen_spec::codes::command_spec;
use snapgen_spec::widths::{ADDR_BITS, INDEX_BITS, MAX_SEGMENTS};
use snapgen_spec::{code, AxisState, Param, Reason, Settable};

use super::*;

impl Executor {
    /// Queues `r` unless the queue is full (then the overflow is flagged).
    pub(super) fn queue(&mut self, i: &ExecutorInputs, r: ReplyDesc) -> bool {
        if i.queue_full {
            self.out.reply_overflow = true;
            false
        } else {
            self.out.reply = Some(r);
            true
        }
    }

    /// A frame with a good CRC. True when it is executed: answered, of its command's length
    /// and not a retry (whether refused or not).
    pub(super) fn command(&mut self, i: &ExecutorInputs, s: AxisState, cfg: Config) -> bool {
        let rx = &i.rx;
        let (c, seq) = (rx.cmd, rx.seq);
        if i.queue_full {
            self.out.reply_overflow = true;
            return false;
        }
        let Some(spec) = command_spec(c) else {
            self.out.bad_frames = self.out.bad_frames.wrapping_add(1);
            self.out.reply = Some(nak(c, seq, Reason::UnknownCommand));
            return false;
        };
        if rx.len != spec.len {
            self.out.bad_frames = self.out.bad_frames.wrapping_add(1);
            self.out.reply = Some(nak(c, seq, Reason::BadLength));
            return false;
        }
        if spec.effect {
            if let Some((lc, ls, lcrc, reply)) = self.last {
                if (lc, ls, lcrc) == (c, seq, rx.crc) {
                    // A retry: the same answer, no effect.
                    self.out.reply = Some(reply);
                    return false;
                }
            }
        }
        let ack = ReplyDesc {
            kind: ReplyKind::Ack,
            cmd: c,
            seq,
            aux: 0,
        };
        if c == code::PING {
            // A new host session: no command before it is retried.
            self.last = None;
        }
        let reply = match self.check(i, s, cfg) {
            Err(reason) => nak(c, seq, reason),
            Ok(()) => match c {
                code::PING => data(ReplyKind::Identity, c, seq, 0),
                code::READ_STATUS => data(ReplyKind::Status, c, seq, 0),
                code::READ_STATE => data(ReplyKind::State, c, seq, 0),
                code::READ_CONFIG => data(ReplyKind::Config, c, seq, rx.get(&CFG_PARAM) as u8),
                _ => {
                    self.effect(i, s);
                    ack
                }
            },
        };
        self.out.reply = Some(reply);
        if spec.effect {
            self.last = Some((c, seq, rx.crc, reply));
        }
        true
    }

    /// Arguments and axis state: why the command is refused, if it is.
    fn check(&self, i: &ExecutorInputs, s: AxisState, cfg: Config) -> Result<(), Reason> {
        let rx = &i.rx;
        // The core's `at_rest` is a register, one clock old: on the clock after the chain was
        // driven (its last tick may have moved it) it does not count.
        let rested = i.core.at_rest && !self.was_driven;
        let moving = i.core.busy || i.core.stopping || !rested;
        // In ErrorStop with the amplifier off and the axis at rest nothing can move, as while
        // Disabled: the parameters settable only while Disabled may be set (INPUT_POLARITY
        // made the emergency stop read active: it can be set back, then RESET).
        let inert = s == AxisState::ErrorStop && !self.out.amplifier && !moving;
        let toward_limit =
            (self.first_direction > 0 && i.limit_pos) || (self.first_direction < 0 && i.limit_neg);
        let refuse = match rx.cmd {
            code::LOAD_SEGMENT
                if rx.get(&SEG_INDEX) >= i128::from(MAX_SEGMENTS) || rx.get(&SEG_TICKS) == 0 =>
            {
                Some(Reason::BadArgument)
            }
            code::COMMIT if rx.get(&COMMIT_COUNT) > i128::from(MAX_SEGMENTS) => {
                Some(Reason::BadArgument)
            }
            code::LOAD_SEGMENT | code::COMMIT if i.core.swap_pending => Some(Reason::SwapPending),
            code::SWAP_AT if self.swap_lead as i64 >= SWAP_REACH => Some(Reason::BadArgument),
            code::START => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ if i.core.busy => Some(Reason::Busy),
                _ if i.core.stopping => Some(Reason::Stopping),
                _ if i.core.swap_pending => Some(Reason::SwapPending),
                _ if i.core.standby_count == 0 => Some(Reason::NoProgram),
                _ if !rested => Some(Reason::Busy),
                _ if toward_limit => Some(Reason::Limit),
                _ => None,
            },
            code::SWAP_AT => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ if i.core.stopping => Some(Reason::Stopping),
                _ if i.core.swap_pending => Some(Reason::SwapPending),
                _ if i.core.standby_count == 0 => Some(Reason::NoProgram),
                // The lead is one clock old and the core arms one clock later: the time base
                // may have ticked twice by then, and the core wants three ticks of lead.
                _ if (self.swap_lead as i64) < SWAP_MIN_LEAD => Some(Reason::Late),
                _ if rested && !i.core.busy && toward_limit => Some(Reason::Limit),
                _ => None,
            },
            code::STOP if s == AxisState::Disabled => Some(Reason::NotEnabled),
            code::HALT => match s {
                AxisState::Disabled => Some(Reason::NotEnabled),
                AxisState::ErrorStop => Some(Reason::AxisError),
                AxisState::Stopping => Some(Reason::Stopping),
                _ => None,
            },
            code::CONFIGURE => {
                let value = rx.get(&CFG_VALUE);
                match Param::from_byte(rx.get(&CFG_PARAM) as u8) {
                    None => Some(Reason::BadArgument),
                    Some(p) if value < 0 || value > p.max() => Some(Reason::BadArgument),
                    Some(p) => match p.settable() {
                        Settable::AtRest if moving => Some(Reason::Busy),
                        Settable::Disabled if !(s == AxisState::Disabled || inert) => {
                            Some(Reason::NotDisabled)
                        }
                        _ if s != AxisState::Disabled && !stop_pair_valid(cfg, p, value) => {
                            Some(Reason::BadArgument)
                        }
                        _ => None,
                    },
                }
            }
            code::READ_CONFIG if Param::from_byte(rx.get(&CFG_PARAM) as u8).is_none() => {
                Some(Reason::BadArgument)
            }
            code::POWER => match rx.get(&POWER_ON) {
                2.. => Some(Reason::BadArgument),
                1 if s == AxisState::ErrorStop => Some(Reason::AxisError),
                1 if s == AxisState::Disabled
                    && (!cfg.stop_limits().valid()
                        || (cfg.servo_period != 0 && cfg.following_limit == 0)) =>
                {
                    Some(Reason::NotConfigured)
                }
                0 if moving => Some(Reason::Busy),
                _ => None,
            },
            code::RESET if s == AxisState::ErrorStop && (moving || i.estop) => {
                Some(Reason::AxisError)
            }
            _ => None,
        };
        refuse.map_or(Ok(()), Err)
    }

    /// The effect of an accepted command.
    fn effect(&mut self, i: &ExecutorInputs, s: AxisState) {
        let rx = &i.rx;
        let o = &mut self.out;
        match rx.cmd {
            code::LOAD_SEGMENT => {
                let c = &mut o.command;
                c.write_enable = true;
                // The address is the index's low bits (the index was checked).
                c.write_address = (rx.get(&SEG_INDEX) as u8) & ((1 << ADDR_BITS) - 1);
                c.write_ticks = rx.get(&SEG_TICKS) as u32;
                c.write_snap = rx.get(&SEG_SNAP);
                if c.write_address == 0 {
                    self.first_direction = c.write_snap.signum() as i8;
                }
            }
            code::COMMIT => {
                o.command.count_enable = true;
                o.command.count_value = (rx.get(&COMMIT_COUNT) as u8) & ((1 << INDEX_BITS) - 1);
            }
            code::START => {
                o.command.start = true;
                o.state = AxisState::DiscreteMotion;
                // The banks swap: the new standby program is empty.
                self.first_direction = 0;
            }
            code::SWAP_AT => {
                o.command.swap = true;
                o.command.swap_last = (rx.get(&SWAP_TICK) as u64).wrapping_sub(1) as u32;
                o.state = AxisState::DiscreteMotion;
                // The banks swap at the tick; no upload is taken before that.
                self.first_direction = 0;
            }
            code::STOP if s != AxisState::ErrorStop => {
                o.command.stop = true;
                o.state = AxisState::Stopping;
            }
            code::HALT if matches!(s, AxisState::DiscreteMotion | AxisState::ContinuousMotion) => {
                o.command.stop = true;
            }
            code::CONFIGURE => {
                // Written on the next clock (`Executor::clock`).
                let p = Param::from_byte(rx.get(&CFG_PARAM) as u8).expect("checked");
                self.configure = Some((p, rx.get(&CFG_VALUE)));
            }
            code::POWER => match (rx.get(&POWER_ON) == 1, s) {
                (true, AxisState::Disabled) => {
                    o.amplifier = true;
                    o.state = AxisState::Standstill;
                    // MC_Power: the axis holds where it is.
                    o.command.load = true;
                }
                (true, _) => {}
                (false, st) => {
                    o.amplifier = false;
                    if st == AxisState::Standstill {
                        o.state = AxisState::Disabled;
                    }
                }
            },
            code::RESET => {
                // The sticky flags clear in any state.
                o.uart_error = false;
                o.reply_overflow = false;
                o.servo_overrun = false;
                o.encoder_errors_seen = i.encoder_errors;
                if s == AxisState::ErrorStop {
                    o.error = ErrorId::None;
                    o.state = if o.amplifier {
                        AxisState::Standstill
                    } else {
                        AxisState::Disabled
                    };
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::frame_rx::FrameRxOutputs;

    /// The reply to POWER 0 on a clock with the chain at rest by the core's (registered)
    /// `at_rest`, busy and stopping low, after a clock with the chain driven or not (each
    /// read by the executor a clock after it is presented: its inputs are registered).
    fn power_off_reply(driven_before: bool) -> Option<ReplyDesc> {
        let mut e = Executor::new(0, 1000, 0);
        e.clock(&ExecutorInputs {
            reset: true,
            ..Default::default()
        });
        let mut i = ExecutorInputs::default();
        i.core.at_rest = true;
        i.core.busy = driven_before;
        e.clock(&i);
        i.core.busy = false;
        i.rx = FrameRxOutputs {
            frame: true,
            cmd: code::POWER,
            seq: 1,
            len: 1,
            ..Default::default()
        };
        e.clock(&i);
        i.rx.frame = false;
        e.clock(&i).reply
    }

    #[test]
    fn a_chain_driven_on_the_last_clock_is_not_taken_for_at_rest() {
        // A program's last tick may move the chain (a one-tick program from rest): on the
        // next clock busy is low and the core's at_rest, a clock old, still says at rest. The
        // axis moves: POWER 0 is refused.
        let reply = power_off_reply(true).expect("a reply");
        assert_eq!(
            (reply.kind, reply.aux),
            (ReplyKind::Nak, Reason::Busy as u8)
        );
        // A clock later, or with the chain not driven before, it is taken.
        let reply = power_off_reply(false).expect("a reply");
        assert_eq!(reply.kind, ReplyKind::Ack);
    }
}
