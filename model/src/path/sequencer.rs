//! The path sequencer clock by clock (the fabric's `snapgen_path_sequencer`,
//! `hdl/verilog/path_sequencer.v`, register for register; issue 22): the ring of path segments
//! the host writes ahead of the motion, and on each tick the choice of the segment the path
//! length `s` lies in, the interpolator's load ([`super::engine`]) and its start.
//!
//! **The ring.** [`PATH_SLOTS`] segments, each a span (its start on the path and its length),
//! a shape (the interpolator's shape ports) and one word per axis (start and share), all in
//! memories with a registered read (block RAM). Segments have wrapping [`PATH_INDEX_BITS`]-bit
//! indices, so a path may be as long as the host likes: it writes segment `i`, every word, and
//! then `extend`s the path to it. The window of segments the sequencer may use is
//! `oldest..=last`. A write is accepted in order (to the segment after the highest written
//! since reset, or to the highest while it is not yet in the path) and into a free slot or one
//! whose segment is more than one before the current (so neither the current segment nor the
//! one before it, where a seek may step back on that very clock, is overwritten); it moves
//! `oldest` past the segment whose slot it takes. An extension takes in every segment written:
//! its index must be the highest written, and it comes on a clock after that segment's last
//! write. Anything else sets the sticky `refused`.
//!
//! **A tick.** On `tick`, when idle: `commit` (one clock) if a computation has ended since
//! the last, so the axes take the positions of the tick before, all at once; then, unless the
//! path is empty, `s` is latched and the seek runs. Each step reads the current segment's span
//! (two clocks: every read passes the block RAM's register and one more, so that its slow
//! output drives only a register), forms `r = s − start` and `r − length` (each a
//! [`X_BITS`]-bit difference over two clocks, its halves split at [`SPLIT`]; their comparisons
//! with a cell on a clock of their own: routed timing) and moves back a segment if `r < 0`
//! (unless at `oldest`) or on if `r ≥ length` (unless at `last`), never both ways in one seek
//! (spans end to end never need it; a gap between two, a host's error, would make it go to and
//! fro). Where it stops it clamps `r` as [`super::interp::Path::at`] does: at the path's first
//! segment (when none has been forgotten since reset) back to a cell before its start, at
//! `last` up to a cell beyond its end, elsewhere to the segment (so below the oldest segment
//! kept, at its start). If the interpolator does not hold that segment yet, the sequencer loads
//! its shape with axis 0, then the other axes one per clock (axis 0 twice: the read takes two
//! clocks), then starts it at the offset and waits for `done`. A `tick` while all this runs is
//! `late` (sticky): the tick is dropped and the axes keep their positions.
//!
//! So, while `s` stays within the window, the positions committed at a tick are `Path::at(s)`
//! of the tick before, on the segments written (tested against `Path::at` in this module and
//! at every commit of the co-simulation's stream, `snapgen_sim::path_seq`). [`worst_clocks`]
//! bounds the clocks a tick needs.

use snapgen_spec::widths::{
    AXIS_BITS, FRAC_BITS, MAX_AXES, PATH_INDEX_BITS, PATH_SLOTS, RATE_BITS, SHARE_BITS, X_BITS,
};

use super::engine::{self, LoadError};
use super::interp::Segment;
use crate::chain::wrap;
use crate::ports::{InterpInputs, PathSeqInputs, PathSeqOutputs};

/// Where the seek's [`X_BITS`]-bit differences are split: the low bits on one clock, the rest
/// with the borrow on the next.
pub const SPLIT: u32 = 56;

/// Clocks of one seek step (two for the read, two for `r`, two for `r − length`, one for the
/// comparisons with a cell, the decision).
pub const STEP_CLOCKS: u64 = 8;

const _: () = {
    assert!(SPLIT < X_BITS && X_BITS - SPLIT <= SPLIT);
    assert!(
        FRAC_BITS + 32 == X_BITS,
        "the clamps read the whole cells as 32 bits"
    );
    assert!(PATH_INDEX_BITS == 16 && (PATH_SLOTS as usize) < 1 << 15);
};

/// The sequencer's states (`state` in the fabric).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum State {
    /// Waiting for a tick.
    #[default]
    Idle = 0,
    /// The current segment's words are read (the memory's own register).
    Read = 1,
    /// They pass the read's second register (for routed timing: the block RAM's slow output
    /// drives nothing but a register).
    Fetch = 2,
    /// `s − start`, low half.
    OffsetLow = 3,
    /// `s − start`, high half.
    OffsetHigh = 4,
    /// `r − length`, low half.
    PastLow = 5,
    /// `r − length`, high half.
    PastHigh = 6,
    /// `r` and `r − length` compared with a cell (registered for routed timing).
    Judge = 7,
    /// Back, on, or here (the offset clamped).
    Decide = 8,
    /// The axes are offered to the interpolator (`load_axis`; the shape with the first).
    LoadAxis = 9,
    /// The interpolator computes (`start` on the first clock).
    Wait = 10,
}

/// A segment's shape word (the interpolator's shape ports, at their widths).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShapeWord {
    /// An arc.
    pub arc: bool,
    /// Counter-clockwise.
    pub ccw: bool,
    /// The plane's first axis.
    pub plane_first: u8,
    /// The plane's second axis.
    pub plane_second: u8,
    /// The centre on the first plane axis.
    pub centre_first: i128,
    /// The centre on the second plane axis.
    pub centre_second: i128,
    /// The radius at the start.
    pub radius: i128,
    /// The radius's growth.
    pub growth: i128,
    /// The angle at the start.
    pub start_angle: u64,
    /// The angular rate.
    pub rate: i128,
}

/// A write taken on one clock, made on the next (the fabric registers the host's write before
/// the block RAM takes it: routed timing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Pending {
    slot: usize,
    span: Option<(i128, i128)>,
    shape: Option<ShapeWord>,
    /// The axis and its word.
    axis: Option<(usize, (i128, i128))>,
}

/// The ring's memories (block RAM in the fabric).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Ring {
    /// The write taken on the last clock.
    pending: Pending,
    /// Spans: (start, length) per slot.
    span: Vec<(i128, i128)>,
    /// Shapes per slot.
    shape: Vec<ShapeWord>,
    /// (from, share) per slot and axis (`slot · MAX_AXES + axis`).
    axis: Vec<(i128, i128)>,
}

/// The sequencer's registers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Registers {
    /// State.
    pub state: State,
    /// The current segment.
    pub k: u16,
    /// The oldest segment still in the ring.
    pub oldest: u16,
    /// The path's last segment (`oldest − 1` while empty).
    pub last: u16,
    /// The highest segment written since reset (`last` or after it; `oldest − 1` before any).
    pub highest: u16,
    /// The seek's moves this tick: it moved on (bit 0), back (bit 1).
    pub moved: u8,
    /// No segment has been forgotten since reset (`oldest` is the path's first).
    pub whole: bool,
    /// The interpolator holds segment [`Registers::loaded`].
    pub loaded_valid: bool,
    /// The segment the interpolator holds.
    pub loaded: u16,
    /// A computation has ended since the last commit.
    pub fresh: bool,
    /// The path length latched at the tick.
    pub s: i128,
    /// The span read (the memory's registered output) …
    pub span_m: (i128, i128),
    /// … and a clock later.
    pub span_q: (i128, i128),
    /// The shape read …
    pub shape_m: ShapeWord,
    /// … and a clock later.
    pub shape_q: ShapeWord,
    /// The axis word read …
    pub axis_m: (i128, i128),
    /// … and a clock later.
    pub axis_q: (i128, i128),
    /// The axis whose word is read next.
    pub a_read: u8,
    /// The axis of `axis_m` …
    pub a_m: u8,
    /// … and of `axis_q`.
    pub a_q: u8,
    /// `r = s − start`.
    pub r: i128,
    /// `r − length`.
    pub past: i128,
    /// The low half of a difference, and its borrow (the fabric's split; see [`SPLIT`]).
    pub low: (u128, bool),
    /// `r` is more than a cell below 0.
    pub under_cell: bool,
    /// `r − length` is more than a cell above 0.
    pub over_cell: bool,
}

/// The path sequencer: its memories, registers and outputs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PathSequencer {
    /// Axes of the design (1 to [`MAX_AXES`], fixed at generation).
    axes: u8,
    /// The ring.
    ring: Ring,
    /// The registers.
    pub reg: Registers,
    /// The outputs' registers.
    out: PathSeqOutputs,
}

/// Why a sequencer cannot be made.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SequencerError {
    /// The axis count is out of range.
    #[error("a path design has 1 to {MAX_AXES} axes, not {0}")]
    Axes(u8),
}

/// The clocks a tick needs at most, for `axes` axes, when the path length moves on by at most
/// `segments` segments (or back by one) since the tick before: the seek's steps, the load of a
/// new segment, the interpolator's computation of an arc and the clock back to idle. A tick
/// shorter than this may be `late`.
pub fn worst_clocks(axes: u8, segments: u64) -> u64 {
    STEP_CLOCKS * (segments + 1) + 1 + u64::from(axes) + engine::clocks(true, axes) + 3
}

/// The clocks' inputs that write segment `index` of a path, starting at `start` on `s` (raw),
/// into a sequencer of `axes` axes: its span and shape on one clock, then one axis per clock
/// (every other input at rest). Refuses a segment the interpolator could not follow
/// ([`engine::load_inputs`]).
pub fn segment_writes(
    index: u16,
    start: i128,
    segment: &Segment,
    axes: u8,
) -> Result<Vec<PathSeqInputs>, LoadError> {
    let words = engine::load_inputs(segment, axes)?;
    let sh = &words[0];
    let mut out = vec![PathSeqInputs {
        seg_index: index,
        write_span: true,
        seg_start: start,
        seg_length: segment.length,
        write_shape: true,
        seg_arc: sh.arc,
        seg_ccw: sh.ccw,
        seg_plane_first: sh.plane_first,
        seg_plane_second: sh.plane_second,
        seg_centre_first: sh.centre_first,
        seg_centre_second: sh.centre_second,
        seg_radius: sh.radius,
        seg_growth: sh.growth,
        seg_start_angle: sh.start_angle,
        seg_rate: sh.rate,
        ..Default::default()
    }];
    out.extend(words[1..].iter().map(|w| PathSeqInputs {
        seg_index: index,
        write_axis: true,
        seg_axis: w.axis,
        seg_from: w.from,
        seg_share: w.share,
        ..Default::default()
    }));
    Ok(out)
}

/// `a − b` as the fabric forms it over two clocks: the low [`SPLIT`] bits and their borrow
/// (`low`, from the clock before), then the high bits less the borrow, joined.
fn join(a: i128, b: i128, low: (u128, bool)) -> i128 {
    let high = (a >> SPLIT) - (b >> SPLIT) - i128::from(low.1);
    wrap((high << SPLIT) | low.0 as i128, X_BITS)
}

/// `a − b` as the fabric's wrapping index difference (unsigned).
fn ahead(a: u16, b: u16) -> u16 {
    a.wrapping_sub(b)
}

impl PathSequencer {
    /// A sequencer of `axes` axes at power-up: empty, idle.
    pub fn new(axes: u8) -> Result<Self, SequencerError> {
        if !(1..=MAX_AXES as u8).contains(&axes) {
            return Err(SequencerError::Axes(axes));
        }
        let slots = PATH_SLOTS as usize;
        Ok(PathSequencer {
            axes,
            ring: Ring {
                pending: Pending::default(),
                span: vec![(0, 0); slots],
                shape: vec![ShapeWord::default(); slots],
                axis: vec![(0, 0); slots * MAX_AXES as usize],
            },
            reg: Registers {
                state: State::Idle,
                k: 0,
                oldest: 0,
                last: u16::MAX,
                highest: u16::MAX,
                moved: 0,
                whole: true,
                loaded_valid: false,
                loaded: 0,
                fresh: false,
                s: 0,
                span_m: (0, 0),
                span_q: (0, 0),
                shape_m: ShapeWord::default(),
                shape_q: ShapeWord::default(),
                axis_m: (0, 0),
                axis_q: (0, 0),
                a_read: 0,
                a_m: 0,
                a_q: 0,
                r: 0,
                past: 0,
                low: (0, false),
                under_cell: false,
                over_cell: false,
            },
            out: PathSeqOutputs {
                empty: true,
                ..Default::default()
            },
        })
    }

    /// The outputs after the last clock.
    pub fn outputs(&self) -> PathSeqOutputs {
        self.out
    }

    /// The interpolator's inputs these outputs drive (its `reset` is the sequencer's).
    pub fn interp_inputs(o: &PathSeqOutputs, reset: bool) -> InterpInputs {
        InterpInputs {
            reset,
            load_shape: o.load_shape,
            arc: o.arc,
            ccw: o.ccw,
            plane_first: o.plane_first,
            plane_second: o.plane_second,
            centre_first: o.centre_first,
            centre_second: o.centre_second,
            radius: o.radius,
            growth: o.growth,
            start_angle: o.start_angle,
            rate: o.rate,
            load_axis: o.load_axis,
            axis: o.axis,
            from: o.from,
            share: o.share,
            start: o.start,
            offset: o.offset,
        }
    }

    /// The slot of segment `i`.
    fn slot(i: u16) -> usize {
        usize::from(i) % PATH_SLOTS as usize
    }

    /// One clock edge with inputs `i`.
    pub fn clock(&mut self, i: &PathSeqInputs) {
        let old = self.reg;
        // Registered memory reads (the value before this clock's writes).
        let slot = Self::slot(old.k);
        let r = &mut self.reg;
        r.span_m = self.ring.span[slot];
        r.shape_m = self.ring.shape[slot];
        r.axis_m = self.ring.axis[slot * MAX_AXES as usize + usize::from(old.a_read)];
        r.a_m = old.a_read;
        (r.span_q, r.shape_q, r.axis_q, r.a_q) = (old.span_m, old.shape_m, old.axis_m, old.a_m);
        // The write taken on the last clock lands (after the reads: read before write).
        let w = std::mem::take(&mut self.ring.pending);
        if let Some(v) = w.span {
            self.ring.span[w.slot] = v;
        }
        if let Some(v) = w.shape {
            self.ring.shape[w.slot] = v;
        }
        if let Some((k, v)) = w.axis {
            self.ring.axis[w.slot * MAX_AXES as usize + k] = v;
        }
        self.out.load_shape = false;
        self.out.load_axis = false;
        self.out.start = false;
        self.out.commit = false;
        if i.reset {
            r.state = State::Idle;
            r.k = 0;
            r.oldest = 0;
            r.last = u16::MAX;
            r.highest = u16::MAX;
            r.whole = true;
            r.loaded_valid = false;
            r.fresh = false;
            self.out.late = false;
            self.out.refused = false;
        } else {
            self.write(&old, i);
            self.advance(&old, i);
        }
        self.publish();
    }

    /// The host's side: writes and extensions, judged on the registers before the clock (an
    /// extension to a segment comes on a clock after its last write).
    fn write(&mut self, old: &Registers, i: &PathSeqInputs) {
        let index = i.seg_index;
        let slots = PATH_SLOTS as u16;
        let any = i.write_span || i.write_shape || i.write_axis;
        // In order: the segment after the highest written, or more words of the highest while
        // it is not yet in the path; and into a free slot, or one whose segment is more than
        // one before the current (so neither the current segment nor the one before it, where
        // a seek may step back on this very clock, is overwritten).
        // (In order, the window oldest..=highest is at most a ring: a new segment takes a free
        // slot unless the ring is full, and then forgets the oldest, which must be more than
        // one before the current; the highest's slot is its own already.)
        let is_next = index == old.highest.wrapping_add(1);
        let is_highest = index == old.highest && old.highest != old.last;
        let full = ahead(old.highest, old.oldest) == slots - 1;
        let in_order = is_next || is_highest;
        let in_ring = is_highest || !full || ahead(index, old.k) < slots - 1;
        let axis = i.seg_axis & ((1 << AXIS_BITS) - 1);
        let axis_ok = !i.write_axis || axis < self.axes;
        if any && in_order && in_ring && axis_ok {
            if is_next {
                self.reg.highest = index;
            }
            let w = &mut self.ring.pending;
            w.slot = Self::slot(index);
            if i.write_span {
                w.span = Some((wrap(i.seg_start, X_BITS), wrap(i.seg_length, X_BITS)));
            }
            if i.write_shape {
                w.shape = Some(ShapeWord {
                    arc: i.seg_arc,
                    ccw: i.seg_ccw,
                    plane_first: i.seg_plane_first & ((1 << AXIS_BITS) - 1),
                    plane_second: i.seg_plane_second & ((1 << AXIS_BITS) - 1),
                    centre_first: wrap(i.seg_centre_first, X_BITS),
                    centre_second: wrap(i.seg_centre_second, X_BITS),
                    radius: wrap(i.seg_radius, X_BITS),
                    growth: wrap(i.seg_growth, SHARE_BITS),
                    start_angle: i.seg_start_angle,
                    rate: wrap(i.seg_rate, RATE_BITS),
                });
            }
            if i.write_axis {
                w.axis = Some((
                    usize::from(axis),
                    (wrap(i.seg_from, X_BITS), wrap(i.seg_share, SHARE_BITS)),
                ));
            }
            if is_next && full {
                // The slot held segment `index − PATH_SLOTS`, the oldest: forgotten.
                self.reg.oldest = old.oldest.wrapping_add(1);
                self.reg.whole = false;
            }
        } else if any {
            self.out.refused = true;
        }
        if i.extend {
            // Every segment written and not yet in the path: `seg_index` must be the highest
            // written (the host and the fabric agree on what the path now is).
            if index == old.highest && old.highest != old.last {
                self.reg.last = index;
            } else {
                self.out.refused = true;
            }
        }
    }

    /// The state machine (registers read from `old`, as a clock edge does).
    fn advance(&mut self, old: &Registers, i: &PathSeqInputs) {
        let axes = self.axes;
        let (r, out) = (&mut self.reg, &mut self.out);
        let cell = 1i128 << FRAC_BITS;
        // Whole cells of a value (its top 32 bits, signed).
        let cells = |x: i128| x >> FRAC_BITS;
        let half = |x: i128| (x as u128) & ((1u128 << SPLIT) - 1);
        let empty = old.last.wrapping_add(1) == old.oldest;
        match old.state {
            State::Idle => {
                if i.tick {
                    if old.fresh {
                        out.commit = true;
                        r.fresh = false;
                    }
                    if !empty {
                        r.s = wrap(i.s, X_BITS);
                        r.a_read = 0;
                        r.moved = 0;
                        r.state = State::Read;
                    }
                }
            }
            State::Read => r.state = State::Fetch,
            State::Fetch => r.state = State::OffsetLow,
            State::OffsetLow => {
                let d = half(old.s) as i128 - half(old.span_q.0) as i128;
                r.low = (half(d), d < 0);
                r.state = State::OffsetHigh;
            }
            State::OffsetHigh => {
                r.r = join(old.s, old.span_q.0, old.low);
                r.state = State::PastLow;
            }
            State::PastLow => {
                let d = half(old.r) as i128 - half(old.span_q.1) as i128;
                r.low = (half(d), d < 0);
                r.state = State::PastHigh;
            }
            State::PastHigh => {
                r.past = join(old.r, old.span_q.1, old.low);
                r.state = State::Judge;
            }
            State::Judge => {
                r.under_cell = cells(old.r) < -1;
                r.over_cell = cells(old.past) >= 1 && old.past != cell;
                r.state = State::Decide;
            }
            State::Decide => {
                let (at_oldest, at_last) = (old.k == old.oldest, old.k == old.last);
                let below = old.r < 0;
                let beyond = old.past >= 0;
                // A seek never turns back (spans end to end never need it; a gap between two
                // would make it go to and fro): it stops where it would.
                if below && !at_oldest && old.moved & 1 == 0 {
                    r.k = old.k.wrapping_sub(1);
                    r.moved = old.moved | 2;
                    r.state = State::Read;
                } else if beyond && !at_last && old.moved & 2 == 0 {
                    r.k = old.k.wrapping_add(1);
                    r.moved = old.moved | 1;
                    r.state = State::Read;
                } else {
                    let first = at_oldest && old.whole;
                    // Below a cell before the first segment's start, or below any other's.
                    let under = if first { old.under_cell } else { below };
                    // More than a cell beyond the last segment's end, or beyond another's (a
                    // seek stopped at a gap).
                    let over = if at_last { old.over_cell } else { beyond };
                    out.offset = if under {
                        if first {
                            -cell
                        } else {
                            0
                        }
                    } else if over && at_last {
                        wrap(old.span_q.1 + cell, X_BITS)
                    } else if over {
                        old.span_q.1
                    } else {
                        old.r
                    };
                    if old.loaded_valid && old.loaded == old.k {
                        out.start = true;
                        r.state = State::Wait;
                    } else {
                        // The shape and axis 0 (read since the seek began), then the
                        // others as the reads bring them (axis 0 twice: the read's latency).
                        out.load_shape = true;
                        out.load_axis = true;
                        r.a_read = 1;
                        r.loaded_valid = true;
                        r.loaded = old.k;
                        r.state = State::LoadAxis;
                    }
                }
            }
            State::LoadAxis => {
                r.a_read = old.a_read.wrapping_add(1) & ((1 << AXIS_BITS) - 1);
                if old.a_q == axes - 1 {
                    out.start = true;
                    r.state = State::Wait;
                } else {
                    out.load_axis = true;
                }
            }
            State::Wait => {
                if i.done {
                    r.fresh = true;
                    r.state = State::Idle;
                }
            }
        }
        if i.tick && old.state != State::Idle {
            out.late = true;
        }
    }

    /// The outputs that are registers or memory reads as they stand.
    fn publish(&mut self) {
        let (o, r) = (&mut self.out, &self.reg);
        let sh = r.shape_q;
        o.arc = sh.arc;
        o.ccw = sh.ccw;
        o.plane_first = sh.plane_first;
        o.plane_second = sh.plane_second;
        o.centre_first = sh.centre_first;
        o.centre_second = sh.centre_second;
        o.radius = sh.radius;
        o.growth = sh.growth;
        o.start_angle = sh.start_angle;
        o.rate = sh.rate;
        o.axis = r.a_q;
        o.from = r.axis_q.0;
        o.share = r.axis_q.1;
        o.path_segment = r.k;
        o.running = r.state != State::Idle;
        o.empty = r.last.wrapping_add(1) == r.oldest;
    }
}

#[cfg(test)]
mod tests {
    use super::super::cordic::Turn;
    use super::super::engine::Engine;
    use super::super::interp::{Path, Shape};
    use super::*;

    const ONE: i128 = 1 << 62;
    const CELL: i128 = 1 << FRAC_BITS;

    /// A sequencer and its interpolator, with the axes' registers the commits fill.
    struct Bench {
        seq: PathSequencer,
        engine: Engine,
        inputs: PathSeqInputs,
        /// Positions the interpolator wrote since the last commit.
        next: Vec<i128>,
        /// The positions committed at the last commit.
        committed: Vec<i128>,
        commits: u64,
    }

    impl Bench {
        fn new(axes: u8) -> Self {
            Bench {
                seq: PathSequencer::new(axes).unwrap(),
                engine: Engine::new(axes),
                inputs: PathSeqInputs::default(),
                next: vec![0; usize::from(axes)],
                committed: vec![0; usize::from(axes)],
                commits: 0,
            }
        }

        fn clock(&mut self) {
            let o = self.seq.outputs();
            if o.commit {
                self.committed = self.next.clone();
                self.commits += 1;
            }
            let e = self.engine.outputs();
            self.inputs.done = e.done;
            if e.out_write {
                self.next[usize::from(e.out_axis)] = e.out_value;
            }
            let ii = PathSequencer::interp_inputs(&o, self.inputs.reset);
            self.seq.clock(&self.inputs);
            self.engine.clock(&ii);
            self.inputs = PathSeqInputs {
                s: self.inputs.s,
                ..Default::default()
            };
        }

        /// Writes segment `index` (its span and shape, every axis), then extends the path.
        fn append(&mut self, index: u16, start: i128, g: &Segment) {
            for w in segment_writes(index, start, g, self.seq.axes).expect("loads") {
                self.inputs = w;
                self.clock();
            }
            self.inputs.seg_index = index;
            self.inputs.extend = true;
            self.clock();
        }

        /// A tick at `s`, then the clocks to the next; the positions of the tick before.
        fn tick(&mut self, s: i128, clocks: u64) -> Vec<i128> {
            self.inputs.tick = true;
            self.inputs.s = s;
            for _ in 0..clocks {
                self.clock();
            }
            self.committed.clone()
        }
    }

    fn line(from: Vec<i128>, dir: Vec<i128>, length: i128) -> Segment {
        Segment {
            length,
            shape: Shape::Line { from, dir },
        }
    }

    fn quarter_arc() -> Segment {
        Segment {
            length: 1 << 100,
            shape: Shape::Arc {
                plane: [0, 1],
                centre: [0, 0],
                radius: 1 << 100,
                growth: 0,
                start: Turn(0),
                rate: 1 << (62 + super::super::interp::RATE_SHIFT - 100),
                ccw: true,
                from: vec![1 << 100, 0, 5],
                dir: vec![0, 0, ONE / 4],
            },
        }
    }

    #[test]
    fn ticks_follow_the_path_rule_across_segments() {
        let path = Path {
            segments: vec![
                line(vec![0, -(1 << 90), 0], vec![0, ONE, 0], 1 << 90),
                line(vec![0, 0, 0], vec![0, 0, 0], 0),
                line(vec![0, 0, 0], vec![ONE, 0, 0], 1 << 100),
                quarter_arc(),
                line(vec![0, 1 << 100, 5 + (1 << 98)], vec![0, 0, ONE], 1 << 90),
                line(
                    vec![0, 1 << 100, 5 + (1 << 98) + (1 << 90)],
                    vec![0, 0, 0],
                    0,
                ),
            ],
        };
        let mut b = Bench::new(3);
        let clocks = worst_clocks(3, 1);
        let mut start = 0;
        for (k, g) in path.segments.iter().enumerate() {
            b.append(k as u16, start, g);
            start += g.length;
        }
        let total = path.length();
        let points: Vec<i128> = (-3..=40)
            .map(|k| k * (total / 36) + (k * 7919) % 1000)
            .chain([
                -CELL - 5,
                -CELL + 5,
                total + CELL + 5,
                total + CELL - 5,
                1 << 100,
            ])
            .collect();
        let mut previous = None;
        for &s in &points {
            let got = b.tick(s, clocks);
            if let Some(p) = previous {
                assert_eq!(got, path.at(p).unwrap(), "the positions at s = {p}");
            }
            previous = Some(s);
        }
        let o = b.seq.outputs();
        assert!(!o.late && !o.refused && !o.empty, "{o:?}");
        assert_eq!(b.commits, points.len() as u64 - 1);
    }

    #[test]
    fn worst_clocks_bounds_a_tick_that_moves_on_a_segment_into_an_arc() {
        // Arcs end to end; each tick one segment on, so each tick seeks a step, loads an arc
        // and computes it: the busiest tick there is (a tick must not be shorter).
        for axes in [2u8, 4, 8] {
            let mut b = Bench::new(axes);
            let arc = quarter_arc();
            let g = |k: u16| {
                let mut g = arc.clone();
                if let Shape::Arc { from, dir, .. } = &mut g.shape {
                    from.resize(usize::from(axes), i128::from(k));
                    dir.resize(usize::from(axes), 0);
                }
                g
            };
            for k in 0..8u16 {
                b.append(k, i128::from(k) << 100, &g(k));
            }
            let mut longest = 0;
            for k in 0..8i128 {
                b.inputs.tick = true;
                b.inputs.s = (k << 100) + (1 << 99);
                b.clock();
                let mut n = 1;
                while b.seq.outputs().running {
                    b.clock();
                    n += 1;
                }
                longest = longest.max(n);
            }
            let bound = worst_clocks(axes, 1);
            assert!(
                longest <= bound && longest + 4 >= bound,
                "{axes}: {longest} vs {bound}"
            );
        }
    }

    #[test]
    fn segments_are_written_in_order_and_the_one_before_the_current_is_kept() {
        let g = |k: i128| line(vec![k << 20], vec![ONE], 1 << 20);
        // Out of order after a reset (segment 0 is the next), and an extension past the
        // highest written: refused.
        let mut b = Bench::new(1);
        b.inputs.seg_index = 5;
        b.inputs.write_span = true;
        b.clock();
        assert!(b.seq.outputs().refused);
        let mut b = Bench::new(1);
        b.append(0, 0, &g(0));
        b.inputs.seg_index = 2;
        b.inputs.extend = true;
        b.clock();
        assert!(b.seq.outputs().refused, "segment 1 was never written");
        // Rewriting a segment already in the path, or extending to less than every segment
        // written: refused.
        let mut b = Bench::new(1);
        b.append(0, 0, &g(0));
        b.append(1, 1 << 20, &g(1));
        b.inputs.seg_index = 1;
        b.inputs.write_span = true;
        b.clock();
        assert!(b.seq.outputs().refused, "segment 1 is in the path");
        let mut b = Bench::new(1);
        for k in 0..3u16 {
            b.inputs.seg_index = k;
            b.inputs.write_span = true;
            b.clock();
        }
        b.inputs.seg_index = 1;
        b.inputs.extend = true;
        b.clock();
        assert!(b.seq.outputs().refused, "segment 2 is written too");
        // A write and the extension to it on one clock: the extension is too early.
        let mut b = Bench::new(1);
        b.inputs = PathSeqInputs {
            seg_index: 0,
            write_span: true,
            extend: true,
            ..Default::default()
        };
        b.clock();
        assert!(b.seq.outputs().refused && b.seq.outputs().empty);
        // The ring full ahead of segment 3: segment 3 + 63 would take the slot of segment 2,
        // where a seek may step back, so it waits; 3 + 62 (taking segment 1's) does not.
        let mut b = Bench::new(1);
        for k in 0..66u16 {
            if k == 64 {
                b.tick(3 << 20, worst_clocks(1, 4));
                b.tick(3 << 20, worst_clocks(1, 4));
                assert_eq!(b.seq.reg.k, 3);
            }
            b.append(k, i128::from(k) << 20, &g(i128::from(k)));
            assert!(!b.seq.outputs().refused, "segment {k}");
        }
        assert_eq!((b.seq.reg.oldest, b.seq.reg.whole), (2, false));
        b.inputs.seg_index = 66;
        b.inputs.write_span = true;
        b.clock();
        assert!(b.seq.outputs().refused);
        // Stepping back from segment 3 to 2 (the one kept): the rule's positions.
        let before = (3 << 20) - 5;
        b.tick(before, worst_clocks(1, 4));
        assert_eq!(b.tick(before, worst_clocks(1, 4)), g(2).at((1 << 20) - 5));
        assert_eq!(b.seq.reg.k, 2);
        // Below the oldest kept, the sequencer stays on its start (the path before is gone).
        b.tick(1 << 20, worst_clocks(1, 4));
        assert_eq!(b.tick(1 << 20, worst_clocks(1, 4)), g(2).at(0));
        assert!(!b.seq.outputs().late);
    }

    #[test]
    fn a_gap_between_spans_stops_the_seek_instead_of_going_to_and_fro() {
        // Segment 1 starts 2^20 after segment 0 ends (a host's error): s in the gap.
        let mut b = Bench::new(1);
        let g0 = line(vec![0], vec![ONE], 1 << 20);
        let g1 = line(vec![2 << 20], vec![ONE], 1 << 20);
        b.append(0, 0, &g0);
        b.append(1, 2 << 20, &g1);
        let s = 3 << 19;
        b.tick(s, worst_clocks(1, 2));
        assert!(!b.seq.outputs().running, "the seek ended");
        // On from segment 0, then it would go back: it stops on segment 1's start.
        assert_eq!(b.tick(s, worst_clocks(1, 2)), g1.at(0));
        assert!(!b.seq.outputs().late);
    }

    #[test]
    fn a_tick_too_soon_is_late_and_dropped() {
        let mut b = Bench::new(2);
        let g = line(vec![0, 0], vec![ONE, ONE / 2], 1 << 90);
        b.append(0, 0, &g);
        b.tick(1 << 80, 5);
        let held = b.committed.clone();
        b.tick(2 << 80, worst_clocks(2, 1));
        assert!(b.seq.outputs().late);
        assert_eq!(b.committed, held, "no commit on a dropped tick");
        b.tick(3 << 80, worst_clocks(2, 1));
        assert_eq!(b.committed, g.at(1 << 80), "the first tick's computation");
    }

    #[test]
    fn writes_that_would_overwrite_the_path_ahead_are_refused() {
        let mut b = Bench::new(1);
        let g = |k: i128| line(vec![k << 20], vec![ONE], 1 << 20);
        for k in 0..PATH_SLOTS as u16 {
            b.append(k, i128::from(k) << 20, &g(i128::from(k)));
        }
        assert!(!b.seq.outputs().refused);
        // The ring is full: segment 64 would take segment 0's slot, the current one.
        b.append(PATH_SLOTS as u16, 64 << 20, &g(64));
        assert!(b.seq.outputs().refused);
        assert_eq!(b.seq.reg.last, PATH_SLOTS as u16 - 1);
        // Once the path has moved on, it is taken, and segment 0 is forgotten.
        let mut b = Bench::new(1);
        for k in 0..PATH_SLOTS as u16 {
            b.append(k, i128::from(k) << 20, &g(i128::from(k)));
        }
        b.tick(3 << 20, worst_clocks(1, 4));
        b.tick(3 << 20, worst_clocks(1, 4));
        assert_eq!(b.seq.reg.k, 3);
        b.append(PATH_SLOTS as u16, 64 << 20, &g(64));
        let o = b.seq.outputs();
        assert!(!o.refused && !o.late, "{o:?}");
        assert_eq!(
            (b.seq.reg.oldest, b.seq.reg.last, b.seq.reg.whole),
            (1, 64, false)
        );
        // Rewriting a segment of the path, or an axis the design lacks: refused.
        let mut c = Bench::new(1);
        c.append(0, 0, &g(0));
        c.inputs.seg_index = 0;
        c.inputs.write_span = true;
        c.clock();
        assert!(c.seq.outputs().refused);
        let mut d = Bench::new(1);
        d.inputs.write_axis = true;
        d.inputs.seg_axis = 1;
        d.clock();
        assert!(d.seq.outputs().refused);
        assert_eq!(PathSequencer::new(9), Err(SequencerError::Axes(9)));
    }
}
