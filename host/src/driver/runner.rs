//! The driver's runner: the state of a run (the axis, the swap armed, the board's clock as
//! the host knows it, the link's measured overhead) and what it does — polls compared with
//! the prediction, changes planned and uploaded ahead of the link's latency (a head first, the
//! rest as extensions), SWAP_ATs armed and retried when late.

use crate::axis::compose::{Refusal, Request};
use crate::axis::{AxisErrorId, Goal, HostAxis};
use crate::link::Link;
use crate::protocol::{Command, Reason, Reply, StateReply};
use snapgen_model::chain::ChainState;
use snapgen_model::program::Program;

use super::{read_state, RunError, SwapRecord};

pub(super) fn regs(s: &StateReply) -> ChainState {
    ChainState {
        x: s.x,
        v: s.v,
        a: s.a,
        j: s.j,
    }
}

/// Ticks in `ms` milliseconds at Ts.
pub(super) fn ticks_of(ms: f64, ts: f64) -> u64 {
    (ms * 1e-3 / ts).round().max(0.0) as u64
}

pub(super) fn too_slow() -> RunError {
    RunError::Board {
        what: "SWAP_AT",
        detail: "LATE again and again: the link is too slow for the swaps this script needs".into(),
    }
}

/// Bytes of `c`'s frame.
pub(super) fn frame_bytes(c: &Command, f: &snapgen_model::format::Format) -> usize {
    c.to_frame(0, f).to_bytes().len()
}

/// The frames a run sends and reads, in bytes (fixed by the format: computed once).
#[derive(Clone, Copy, Debug)]
pub(super) struct FrameBytes {
    /// READ_STATE and its STATE reply.
    pub(super) read: usize,
    /// The STATE reply alone.
    pub(super) state: usize,
    /// One LOAD_SEGMENT and its ACK.
    pub(super) load: usize,
    /// COMMIT, SWAP_AT and their ACKs.
    pub(super) arm: usize,
}

impl FrameBytes {
    pub(super) fn of(f: &snapgen_model::format::Format, s: StateReply) -> Self {
        let ack = Reply::Ack { cmd: 0 }.to_frame(0).to_bytes().len();
        let state = Reply::State(s).to_frame(0).to_bytes().len();
        let load = Command::LoadSegment {
            index: 0,
            segment: snapgen_model::program::Segment { ticks: 1, snap: 0 },
        };
        FrameBytes {
            read: frame_bytes(&Command::ReadState, f) + state,
            state,
            load: frame_bytes(&load, f) + ack,
            arm: frame_bytes(&Command::Commit { count: 0 }, f)
                + frame_bytes(&Command::SwapAt { tick: 0 }, f)
                + 2 * ack,
        }
    }
}

/// The first upload's sizes a change tries, fewest first (segments; the last is the whole
/// program memory): a head of the change goes up and is swapped to, the rest follows as
/// extensions while it plays (docs/ONLINE.md, "How a change is made").
pub(super) const HEADS: [usize; 7] = [6, 8, 10, 12, 16, 24, usize::MAX];

/// The first `n` segments of `p`.
pub(super) fn head(p: &Program, n: usize) -> Program {
    Program {
        segments: p.segments[..n.min(p.segments.len())].to_vec(),
    }
}

/// SWAP_AT attempts before a command is given up as the link being too slow.
pub(super) const LATE_TRIES: u32 = 8;

pub(super) struct Runner<'l, L: Link> {
    pub(super) link: &'l mut L,
    /// The board's tick (s): the driver counts in ticks, the link in seconds.
    pub(super) ts: f64,
    pub(super) axis: HostAxis,
    pub(super) checks: u64,
    pub(super) last: StateReply,
    /// Host ticks a request takes beyond its bytes on the wire, the largest seen.
    pub(super) overhead: f64,
    /// The armed swap's tick, until it has passed.
    pub(super) armed: Option<u64>,
    /// The tick the board's program (as armed) ends on.
    pub(super) covered: u64,
    /// Swaps that only uploaded the rest of a long change.
    pub(super) extensions: u32,
    /// Ticks between polls.
    pub(super) poll_ticks: u64,
    /// Ticks of lead beyond an upload's estimate ([`RunOptions::safety_ticks`]).
    ///
    /// [`RunOptions::safety_ticks`]: super::RunOptions::safety_ticks
    pub(super) safety: u64,
    /// The host's clock when the last READ_STATE's reply had come.
    pub(super) polled: f64,
    /// That reply's ticks on the wire.
    pub(super) reply_wire: f64,
    /// Host ticks the longest planning of a change took (0 on a virtual board, whose clock
    /// stands still while the host computes).
    pub(super) planning: u64,
    /// Frame sizes.
    pub(super) bytes: FrameBytes,
    /// The last tick the upload of the rest of the running change may wait past
    /// ([`Runner::defer_deadline`]), once found; cleared when the board's program or the
    /// timeline changes.
    pub(super) defer_until: Option<u64>,
}

impl<L: Link> Runner<'_, L> {
    /// The host's clock in board ticks.
    pub(super) fn host_ticks(&self) -> f64 {
        self.link.now() / self.ts
    }

    /// Board ticks one byte takes on the wire.
    pub(super) fn byte_ticks(&self) -> f64 {
        self.link.byte_time() / self.ts
    }

    /// Lets `ticks` board ticks pass.
    pub(super) fn wait_ticks(&mut self, ticks: u64) {
        self.link.wait(ticks as f64 * self.ts);
    }

    /// READ_STATE, compared with the prediction; the axis's outcomes updated.
    pub(super) fn poll(&mut self) -> Result<StateReply, RunError> {
        let t0 = self.host_ticks();
        let s = read_state(self.link)?;
        self.polled = self.host_ticks();
        self.reply_wire = self.bytes.state as f64 * self.byte_ticks();
        let wire = self.bytes.read as f64 * self.byte_ticks();
        self.overhead = self.overhead.max(self.polled - t0 - wire);
        let want = self
            .axis
            .timeline
            .state_at(s.ticks, &self.axis.settings.format);
        if regs(&s) != want {
            let _ = self.link.ask(&Command::Stop);
            return Err(RunError::Diverged {
                tick: s.ticks,
                got: Box::new(regs(&s)),
                want: Box::new(want),
            });
        }
        self.checks += 1;
        self.axis.update(s.ticks);
        if self.armed.is_some_and(|t| s.ticks >= t) {
            self.armed = None;
        }
        self.last = s;
        Ok(s)
    }

    pub(super) fn expect_ack(&mut self, c: &Command) -> Result<Result<(), Reason>, RunError> {
        match self.link.ask(c)? {
            Reply::Ack { .. } => Ok(Ok(())),
            Reply::Nak { reason, .. } => Ok(Err(reason)),
            r => Err(RunError::Board {
                what: "an upload",
                detail: format!("{r:?}"),
            }),
        }
    }

    /// Plans, uploads and arms the requests due together (events `events`, the first due on
    /// tick `due`): the swap's record (None when none was needed) and the requests refused.
    #[allow(clippy::type_complexity)]
    pub(super) fn change(
        &mut self,
        events: &[usize],
        due: u64,
        reqs: &[Request],
    ) -> Result<(Option<SwapRecord>, Vec<(Request, Refusal)>), RunError> {
        let mut late_retries = 0;
        let mut margin = 1.0;
        loop {
            // An armed swap must have passed before the standby bank is written again.
            if let Some(t) = self.armed {
                // Waited for from the board's tick now (its last reply has come since), then
                // seen a round trip later, as [`Runner::seen_ticks`] has it; a poll at least
                // every poll period meanwhile (the watchdog's food: a swap armed seconds
                // ahead on a slow tick once let it expire).
                let now = self.board_now();
                if now < t {
                    self.wait_ticks((t - now).min(self.poll_ticks));
                }
                self.poll()?;
                continue;
            }
            if late_retries > 0 {
                // Late: the board's clock read again. Otherwise the last poll (the run loop's,
                // which found the change due) dates the board's tick.
                self.poll()?;
            }
            let t0 = self.host_ticks();
            let now = self.board_now();
            let f = self.axis.settings.format;
            // The first upload carries the change's first segments only, as few as let the
            // rest follow in time (`coverable`) and leave the standby bank free a while
            // (`roomy`): the swap's lead, and so the latency, is that upload's; the rest goes
            // up as extensions while the first part plays. A head that keeps the board going
            // but is not roomy is taken when no larger one keeps it going.
            let mut found = None;
            let mut fallback: Option<(
                u64,
                crate::axis::Change,
                Vec<(Request, Refusal)>,
                usize,
                bool,
            )> = None;
            for first in HEADS {
                let first = first.min(f.max_segments);
                // The lead is the head's upload ([`Runner::lead`]) and the planning time seen;
                // planned again while the program found needs a longer head than guessed.
                let mut guess = first.min(self.axis.timeline.program_from(now, &f).segments.len());
                let mut tries = 0;
                let (at, c, refused) = loop {
                    let at = now + self.lead(guess, margin) + self.planning;
                    tries += 1;
                    match self.axis.plan_batch(at, reqs) {
                        (None, refused) => return Ok((None, refused)),
                        (Some(c), refused) => {
                            let up = first.min(c.program.segments.len());
                            if up <= guess || tries == 4 {
                                break (at, c, refused);
                            }
                            guess = up;
                        }
                    }
                };
                // A roomy head is worth at most twice the lead of the smallest one that keeps
                // the board going.
                if let Some((small, ..)) = &fallback {
                    if at - now > 2 * (small - now) {
                        break;
                    }
                }
                let keeps = self.coverable(&c.timeline, at, first);
                if keeps && self.roomy(&c.timeline, at, first) {
                    found = Some((at, c, refused, first, true));
                    break;
                }
                if keeps && fallback.is_none() {
                    fallback = Some((at, c, refused, first, true));
                } else if first >= f.max_segments && fallback.is_none() {
                    found = Some((at, c, refused, first, keeps));
                }
            }
            let Some((at, c, refused, first, keeps)) = found.or(fallback) else {
                unreachable!("the last head is the whole program memory, kept or not");
            };
            // Planning takes host time a serial port's board does not wait for (a virtual
            // board's clock stands still meanwhile): the longest seen goes into later leads.
            self.planning = self
                .planning
                .max((self.host_ticks() - t0).max(0.0).ceil() as u64);
            if self.needs_extension() && !self.extension_fits(at) {
                // The board would play out what it holds before this swap, or before the rest
                // of the running change could follow a NAK LATE of it (taken, the change makes
                // that rest moot): upload that rest first (its swap is then waited for above).
                self.extend(true)?;
                continue;
            }
            if c.program.segments.is_empty() {
                // Nothing plays from `at` (the axis rests before it): no swap is needed.
                self.axis.apply(c);
                self.defer_until = None;
                return Ok((None, refused));
            }
            if !keeps {
                // Taken, the change would leave the board without program: refused whole,
                // nothing changes on the board.
                let error = AxisErrorId::LinkTooSlow {
                    segments: self.axis.settings.format.max_segments,
                };
                let mut all = refused;
                for &q in reqs {
                    if !all.iter().any(|(r, _)| *r == q) {
                        let command = match q {
                            Request::Command(k) => Some(k),
                            Request::Override(_) => None,
                        };
                        all.push((
                            q,
                            Refusal {
                                command,
                                error: error.clone(),
                            },
                        ));
                    }
                }
                return Ok((None, all));
            }
            let upload = head(&c.program, first);
            match self.arm(at, &upload)? {
                Ok(()) => {
                    let segments = upload.segments.len();
                    self.axis.apply(c);
                    let record = SwapRecord {
                        events: events.to_vec(),
                        tick: at,
                        latency_ticks: at.saturating_sub(due),
                        segments,
                        late_retries,
                    };
                    return Ok((Some(record), refused));
                }
                Err(()) if late_retries < LATE_TRIES => {
                    // Nothing changed on the board: plan again with more lead.
                    late_retries += 1;
                    margin *= 2.0;
                }
                Err(()) => return Err(too_slow()),
            }
        }
    }

    /// Uploads `program` and arms its swap at `at`: `Err(())` when SWAP_AT came too late
    /// (nothing changed on the board).
    pub(super) fn arm(
        &mut self,
        at: u64,
        program: &snapgen_model::program::Program,
    ) -> Result<Result<(), ()>, RunError> {
        let refused = |what: &'static str, reason: Reason| RunError::Board {
            what,
            detail: reason.name().to_string(),
        };
        let t0 = self.host_ticks();
        for (k, s) in program.segments.iter().enumerate() {
            let cmd = Command::LoadSegment {
                index: k as u8,
                segment: *s,
            };
            self.expect_ack(&cmd)?
                .map_err(|r| refused("LOAD_SEGMENT", r))?;
        }
        let count = program.segments.len() as u8;
        self.expect_ack(&Command::Commit { count })?
            .map_err(|r| refused("COMMIT", r))?;
        let swap = self.expect_ack(&Command::SwapAt { tick: at })?;
        // The overhead per request, as this upload measured it (a board may answer a
        // LOAD_SEGMENT slower than a READ_STATE).
        let n = program.segments.len();
        let extra = (self.host_ticks() - t0 - self.upload_wire(n)) / (n + 2) as f64;
        self.overhead = self.overhead.max(extra);
        match swap {
            Ok(()) => {
                self.armed = Some(at);
                self.covered = at + program.total_ticks();
                self.defer_until = None;
                Ok(Ok(()))
            }
            Err(Reason::Late) => Ok(Err(())),
            Err(r) => Err(refused("SWAP_AT", r)),
        }
    }

    /// True when the timeline goes on past the program the board holds.
    pub(super) fn needs_extension(&self) -> bool {
        let f = self.axis.settings.format;
        !self
            .axis
            .timeline
            .program_from(self.covered, &f)
            .segments
            .is_empty()
    }

    /// Whether `timeline`, swapped to at `at` with its first `first` segments, can be kept on
    /// the board: that upload, and each later one of at most the program memory, must be
    /// followed, once its swap has passed and been seen
    /// ([`Runner::seen_ticks`] later), by the upload of the rest (as [`Runner::extend`] leads
    /// it) armed before the board has played what it holds.
    pub(super) fn coverable(
        &self,
        timeline: &crate::axis::Timeline,
        at: u64,
        first: usize,
    ) -> bool {
        let f = self.axis.settings.format;
        let mut swap = at;
        let mut most = first.min(f.max_segments);
        loop {
            let rest = timeline.segments_from(swap, &f);
            if rest.len() <= most {
                return true;
            }
            let held = Program {
                segments: rest[..most].to_vec(),
            };
            most = f.max_segments;
            let covered = swap + held.total_ticks();
            // The next upload: what is left once the swap has been seen (at most; later, less
            // is left), at most the program memory.
            let seen = swap + self.seen_ticks();
            let left = timeline.segments_from(seen, &f).len().min(most);
            let next = seen + self.lead(left, 1.0);
            if next >= covered {
                return false;
            }
            swap = next;
        }
    }

    /// Whether a head of `first` segments of `timeline`, swapped to at `at`, leaves the
    /// standby bank free long enough: the upload of the rest can wait (three of its leads
    /// before the head ends, as [`Runner::defer_deadline`] has it) for as long as another such
    /// head takes to go up, so a command that comes meanwhile does not wait behind it. A head
    /// of the whole change always does.
    pub(super) fn roomy(&self, timeline: &crate::axis::Timeline, at: u64, first: usize) -> bool {
        let f = self.axis.settings.format;
        let rest = timeline.segments_from(at, &f);
        if rest.len() <= first {
            return true;
        }
        let covered = at
            + rest[..first]
                .iter()
                .map(|s| u64::from(s.ticks))
                .sum::<u64>();
        let seen = at + self.seen_ticks();
        let left = timeline.segments_from(seen, &f).len().min(f.max_segments);
        seen + 3 * self.lead(left, 1.0) + self.lead(first, 1.0) < covered
    }

    /// The last tick past which the upload of the rest of the running change can wait: the
    /// board's program end less a poll and three leads of that upload (a NAK LATE and a retry
    /// at twice the lead), when from there it still fits ([`Runner::extension_fits`]) and every
    /// later upload still follows in time ([`Runner::coverable`] from the latest swap that
    /// leaves); else `tick − 1`: at once.
    pub(super) fn defer_deadline(&self, tick: u64) -> u64 {
        let f = self.axis.settings.format;
        let at_once = tick.saturating_sub(1);
        // What the upload will carry: from the segment playing then on, at most the program
        // memory; first guessed as the rest after the board's program and one more, then
        // counted from the deadline that guess gives (earlier: more), a few times.
        let mut carried = self.axis.timeline.segments_from(self.covered, &f).len() + 1;
        for _ in 0..4 {
            let lead = self.lead(carried.min(f.max_segments), 1.0);
            let Some(deadline) = self.covered.checked_sub(self.seen_ticks() + 3 * lead + 1) else {
                return at_once;
            };
            if deadline < tick {
                return at_once;
            }
            let counted = self.axis.timeline.program_from(deadline, &f).segments.len();
            if counted <= carried.min(f.max_segments) {
                let latest = deadline + self.seen_ticks() + 2 * lead;
                return if self.coverable(&self.axis.timeline, latest, f.max_segments) {
                    deadline
                } else {
                    at_once
                };
            }
            carried = counted;
        }
        at_once
    }

    /// Whether the rest of the running change, uploaded a poll after `tick`, is armed before
    /// the board has played what it holds.
    pub(super) fn extension_fits(&self, tick: u64) -> bool {
        self.extension_swap(tick + self.seen_ticks(), 1.0) < self.covered
    }

    /// The earliest tick the rest of the running change, uploaded from board tick `tick`, can
    /// be swapped to with `margin`: the first `at` whose upload (the timeline's program from
    /// `at`) takes no more than `at − tick` as [`Runner::lead`] has it. A later swap carries
    /// fewer segments, so the condition, once met, holds on: found by bisection.
    pub(super) fn extension_swap(&self, tick: u64, margin: f64) -> u64 {
        let f = self.axis.settings.format;
        let fits = |at: u64| {
            let n = self.axis.timeline.segments_from(at, &f).len();
            at >= tick + self.lead(n.min(f.max_segments), margin)
        };
        let mut hi = tick
            + self.lead(
                self.axis
                    .timeline
                    .segments_from(tick, &f)
                    .len()
                    .min(f.max_segments),
                margin,
            );
        let mut lo = tick;
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        hi
    }

    /// When the timeline goes on past the program the board holds (a change longer than
    /// the program memory), uploads the rest and swaps to it before the board's ends: at
    /// once when `now`, else when it can wait no longer ([`Runner::defer_deadline`]), the
    /// standby bank free meanwhile (a change that comes makes this upload moot).
    pub(super) fn extend(&mut self, now: bool) -> Result<(), RunError> {
        let f = self.axis.settings.format;
        let mut margin = 1.0;
        for _ in 0..LATE_TRIES {
            if self.armed.is_some() || !self.needs_extension() {
                return Ok(());
            }
            let tick = self.board_now();
            if !now && margin == 1.0 {
                let until = match self.defer_until {
                    Some(u) => u,
                    None => *self.defer_until.insert(self.defer_deadline(tick)),
                };
                if tick <= until {
                    return Ok(());
                }
            }
            let at = self.extension_swap(tick, margin);
            if at >= self.covered {
                return Err(too_slow());
            }
            let program = self.axis.timeline.program_from(at, &f);
            if self.arm(at, &program)?.is_ok() {
                self.extensions += 1;
                return Ok(());
            }
            margin *= 2.0;
            self.poll()?;
        }
        Err(too_slow())
    }

    /// The board's tick now, as the host knows it: the last READ_STATE's tick, and the ticks
    /// since (its reply's time on the wire, and the host's clock since it came).
    pub(super) fn board_now(&self) -> u64 {
        let since = self.reply_wire + (self.host_ticks() - self.polled).max(0.0);
        self.last.ticks + since.ceil() as u64
    }

    /// Host ticks from a swap to the end of the poll that sees it has passed, at the most: a
    /// poll period, and two READ_STATE round trips (the one under way when the swap passes
    /// reads the tick before it).
    pub(super) fn seen_ticks(&self) -> u64 {
        let round_trip = self.bytes.read as f64 * self.byte_ticks() + self.overhead;
        self.poll_ticks + (2.0 * round_trip).ceil() as u64
    }

    /// Host ticks the upload of `n` segments takes: LOAD_SEGMENTs, COMMIT and SWAP_AT with
    /// their acknowledgements on the wire ([`Runner::upload_wire`]), and the measured overhead
    /// per request.
    pub(super) fn upload_ticks(&self, n: usize) -> f64 {
        self.upload_wire(n) + (n + 2) as f64 * self.overhead
    }

    /// Host ticks the frames of an upload of `n` segments take on the wire.
    pub(super) fn upload_wire(&self, n: usize) -> f64 {
        (n * self.bytes.load + self.bytes.arm) as f64 * self.byte_ticks()
    }

    /// The lead a swap of an upload of `n` segments is armed with: its time
    /// ([`Runner::upload_ticks`]) with a quarter more, times `margin` (doubled after each
    /// NAK LATE), and the safety lead ([`Runner::safety`]).
    pub(super) fn lead(&self, n: usize, margin: f64) -> u64 {
        (self.upload_ticks(n) * 1.25 * margin).ceil() as u64 + self.safety
    }

    /// True when nothing will move any more without a new command.
    pub(super) fn settled(&self, now: u64) -> bool {
        let t = &self.axis.timeline;
        now >= t.end_tick()
            && self.armed.is_none()
            && t.parts
                .last()
                .is_none_or(|p| !matches!(p.goal, Goal::Velocity(v) if v != 0.0))
    }
}
