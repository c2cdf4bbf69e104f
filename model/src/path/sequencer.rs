//! The path sequencer clock by clock (the fabric's `snapgen_path_sequencer`,
//! `hdl/verilog/path_sequencer.v`, register for register; issue 22): the ring of path segments
//! the host writes ahead of the motion, and on each tick the choice of the segment the path
//! length `s` lies in, the interpolator's load ([`super::engine`]) and its start.
//!
//! **The ring.** [`PATH_SLOTS`] segments, each a span (its start on the path and its length),
//! a shape (the interpolator's shape ports) and one word per axis (start and share), all in
//! memories with a registered read (block RAM). Segments have wrapping [`PATH_INDEX_BITS`]-bit
//! indices, so a path may be as long as the host likes: it writes segment `i` and then
//! `extend`s the path to it. The window of segments the sequencer may use is `oldest..=last`:
//! a write is accepted only after `last` and less than [`PATH_SLOTS`] ahead of the current
//! segment (so it never overwrites the current one or any after it), and moves `oldest` past
//! the segment whose slot it takes; an extension is accepted ahead of `last` and within the
//! ring. Anything else sets the sticky `refused`.
//!
//! **A tick.** On `tick`, when idle: `commit` (one clock) if a computation has ended since
//! the last, so the axes take the positions of the tick before, all at once; then, unless the
//! path is empty, `s` is latched and the seek runs. Each step reads the current segment's
//! span (two clocks), forms `r = s − start` and `r − length` (each a [`X_BITS`]-bit difference over two
//! clocks, its halves split at [`SPLIT`], for routed timing; their comparisons with a cell on
//! a clock of their own) and moves back a segment if `r < 0`
//! (unless at `oldest`) or on if `r ≥ length` (unless at `last`). Where it stops it clamps `r`
//! as [`super::interp::Path::at`] does: at the path's first segment (when no segment has been
//! forgotten since reset) back to a cell before its start, at `last` up to a cell beyond its
//! end, elsewhere to the segment. If the interpolator does not hold that segment yet, the
//! sequencer loads its shape with axis 0, then the other axes one per clock (axis 0 twice: the
//! read takes two clocks), then starts it at the offset and waits for `done`. Every memory
//! read passes two registers (the block RAM's own and one more), so that the block RAM's slow
//! output drives only a register: routed timing. A `tick` while all this runs is `late` (sticky): the tick is
//! dropped and the axes keep their positions.
//!
//! So, while `s` stays within the window, the positions committed at a tick are
//! `Path::at(s)` of the tick before, on the segments written (tested against `Path::at` in
//! this module and on every tick of the co-simulation's stream, `snapgen_sim::path_seq`).
//! [`worst_clocks`] bounds the clocks a tick needs.

use snapgen_spec::widths::{
    AXIS_BITS, FRAC_BITS, MAX_AXES, PATH_INDEX_BITS, PATH_SLOTS, RATE_BITS, SHARE_BITS, X_BITS,
};

use super::engine;
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
    Fetch = 10,
    /// `s − start`, low half.
    OffsetLow = 2,
    /// `s − start`, high half.
    OffsetHigh = 3,
    /// `r − length`, low half.
    PastLow = 4,
    /// `r − length`, high half.
    PastHigh = 5,
    /// `r` and `r − length` compared with a cell (registered for routed timing).
    Judge = 11,
    /// Back, on, or here (the offset clamped).
    Decide = 6,
    /// The axes are offered to the interpolator (`load_axis`; the shape with the first).
    LoadAxis = 7,
    /// The interpolator computes (`start` on the first clock).
    Wait = 8,
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

/// The ring's memories (block RAM in the fabric).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Ring {
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
                span: vec![(0, 0); slots],
                shape: vec![ShapeWord::default(); slots],
                axis: vec![(0, 0); slots * MAX_AXES as usize],
            },
            reg: Registers {
                state: State::Idle,
                k: 0,
                oldest: 0,
                last: u16::MAX,
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
        self.out.load_shape = false;
        self.out.load_axis = false;
        self.out.start = false;
        self.out.commit = false;
        if i.reset {
            r.state = State::Idle;
            r.k = 0;
            r.oldest = 0;
            r.last = u16::MAX;
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

    /// The host's side: writes and extensions, judged on the registers before the clock.
    fn write(&mut self, old: &Registers, i: &PathSeqInputs) {
        let index = i.seg_index;
        let slots = PATH_SLOTS as u16;
        let forward = |d: u16| d != 0 && d < 1 << 15;
        let any = i.write_span || i.write_shape || i.write_axis;
        let in_ring = forward(ahead(index, old.last)) && ahead(index, old.k) < slots;
        let axis = i.seg_axis & ((1 << AXIS_BITS) - 1);
        let axis_ok = !i.write_axis || axis < self.axes;
        if any && in_ring && axis_ok {
            let slot = Self::slot(index);
            if i.write_span {
                self.ring.span[slot] = (wrap(i.seg_start, X_BITS), wrap(i.seg_length, X_BITS));
            }
            if i.write_shape {
                self.ring.shape[slot] = ShapeWord {
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
                };
            }
            if i.write_axis {
                self.ring.axis[slot * MAX_AXES as usize + usize::from(axis)] =
                    (wrap(i.seg_from, X_BITS), wrap(i.seg_share, SHARE_BITS));
            }
            if ahead(index, old.oldest) >= slots {
                // The slot held segment `index − PATH_SLOTS`: forgotten.
                self.reg.oldest = index.wrapping_sub(slots - 1);
                self.reg.whole = false;
            }
        } else if any {
            self.out.refused = true;
        }
        if i.extend {
            if forward(ahead(index, old.last)) && ahead(index, old.oldest) < slots {
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
                r.r = wrap(old.s - old.span_q.0, X_BITS);
                r.state = State::PastLow;
            }
            State::PastLow => {
                let d = half(old.r) as i128 - half(old.span_q.1) as i128;
                r.low = (half(d), d < 0);
                r.state = State::PastHigh;
            }
            State::PastHigh => {
                r.past = wrap(old.r - old.span_q.1, X_BITS);
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
                if below && !at_oldest {
                    r.k = old.k.wrapping_sub(1);
                    r.state = State::Read;
                } else if beyond && !at_last {
                    r.k = old.k.wrapping_add(1);
                    r.state = State::Read;
                } else {
                    let first = at_oldest && old.whole;
                    // Below a cell before the first segment's start, or below any other's.
                    let under = if first { old.under_cell } else { below };
                    // More than a cell beyond the last segment's end.
                    let over = at_last && old.over_cell;
                    out.offset = if under {
                        if first {
                            -cell
                        } else {
                            0
                        }
                    } else if over {
                        wrap(old.span_q.1 + cell, X_BITS)
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
        o.segment = r.k;
        o.running = r.state != State::Idle;
        o.empty = r.last.wrapping_add(1) == r.oldest;
    }
}

#[cfg(test)]
mod tests {
    use super::super::cordic::Turn;
    use super::super::engine::{load_inputs, Engine};
    use super::super::interp::{Path, Segment, Shape};
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
            let axes = self.seq.axes;
            let words = load_inputs(g, axes).expect("loads");
            self.inputs = PathSeqInputs {
                seg_index: index,
                write_span: true,
                seg_start: start,
                seg_length: g.length,
                ..Default::default()
            };
            let w = &words[0];
            self.inputs.write_shape = true;
            self.inputs.seg_arc = w.arc;
            self.inputs.seg_ccw = w.ccw;
            self.inputs.seg_plane_first = w.plane_first;
            self.inputs.seg_plane_second = w.plane_second;
            self.inputs.seg_centre_first = w.centre_first;
            self.inputs.seg_centre_second = w.centre_second;
            self.inputs.seg_radius = w.radius;
            self.inputs.seg_growth = w.growth;
            self.inputs.seg_start_angle = w.start_angle;
            self.inputs.seg_rate = w.rate;
            self.clock();
            for w in &words[1..] {
                self.inputs = PathSeqInputs {
                    seg_index: index,
                    write_axis: true,
                    seg_axis: w.axis,
                    seg_from: w.from,
                    seg_share: w.share,
                    ..Default::default()
                };
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
