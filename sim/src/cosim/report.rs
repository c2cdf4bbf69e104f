//! What a co-simulation run did: its counts of moves, stops, swaps and streams, the clocks
//! and ticks compared, and the first mismatch.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::Mismatch;

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct CosimReport {
    /// Moves played.
    pub moves: usize,
    /// Moves aborted midway.
    pub aborted: usize,
    /// Positions loaded at rest (the reference taking an encoder's position).
    pub loads: usize,
    /// Moves given a controlled stop.
    pub stopped: usize,
    /// Stops aborted on the way by the stream.
    pub stops_aborted: usize,
    /// Stops aborted for running past [`MAX_STOP_CLOCKS`](super::core_moves::MAX_STOP_CLOCKS).
    pub stops_timed_out: usize,
    /// Stops that began outside their limits (and landed regardless of them).
    pub stops_over: usize,
    /// Stops after which the chain was not at rest (must be 0).
    pub stops_not_at_rest: usize,
    /// Moves the stream drew but the planner refused or that were too long (skipped).
    pub skipped: usize,
    /// Program swaps played (online replans from the state at their tick).
    pub replans: usize,
    /// Replans the online planner refused, by reason (its error's variant): not played.
    pub replans_refused: BTreeMap<String, usize>,
    /// Replans longer than the stream keeps (`MAX_MOVE_TICKS`): not played.
    pub replans_too_long: usize,
    /// Swaps armed for a tick already reached (each must change nothing).
    pub late_swaps: usize,
    /// Late swaps the core armed anyway (must be 0).
    pub late_swaps_taken: usize,
    /// Timely swaps the core did not arm (must be 0).
    pub swaps_not_armed: usize,
    /// Armed swaps cancelled by a controlled stop before their tick.
    pub swaps_cancelled: usize,
    /// PLCopen event streams played (each a random script through the host axis and its
    /// driver).
    pub streams: usize,
    /// Program swaps the streams' driver made (each planned from the exact state at its tick
    /// and armed ahead of the link), extensions of long changes among them.
    pub stream_swaps: usize,
    /// Of `stream_swaps`, those that only uploaded the rest of a change longer than the
    /// program memory.
    pub stream_extensions: usize,
    /// Commands the streams gave.
    pub stream_commands: usize,
    /// Commands that ended in Error, by ErrorID (a planner refusal, a link too slow).
    pub stream_errors: BTreeMap<String, usize>,
    /// Streams whose driver read registers that differ from its prediction (must be 0).
    pub streams_diverged: usize,
    /// What each diverged stream read, and the axis's state and error ID then.
    pub divergences: Vec<String>,
    /// Streams whose run ended otherwise in error, by message.
    pub streams_failed: BTreeMap<String, usize>,
    /// Streams not at rest when their run ended (a velocity held, a failed run), stopped
    /// with the board's STOP (the random scripts end at rest: must be 0).
    pub streams_stopped: usize,
    /// Clocks compared.
    pub clocks: u64,
    /// Ticks compared (clocks on which the chain stepped with a program or a stop).
    pub ticks: u64,
    /// Seconds spent clocking and comparing.
    pub seconds: f64,
    /// The first mismatch.
    pub mismatch: Option<Mismatch>,
    /// Waves written.
    pub vcd: Option<PathBuf>,
    /// The library was already built.
    pub cached_build: bool,
    /// Moves after which the clock-accurate model did not stand where the planner said.
    pub planner_disagreements: usize,
    /// Worker threads the sessions ran on (one per core, at most one per session).
    pub threads: usize,
}

impl CosimReport {
    /// Adds a session's counts to this report (its timing, waves and mismatch stay out).
    pub fn add(&mut self, r: &CosimReport) {
        self.moves += r.moves;
        self.aborted += r.aborted;
        self.loads += r.loads;
        self.stopped += r.stopped;
        self.stops_aborted += r.stops_aborted;
        self.stops_timed_out += r.stops_timed_out;
        self.stops_over += r.stops_over;
        self.stops_not_at_rest += r.stops_not_at_rest;
        self.skipped += r.skipped;
        self.replans += r.replans;
        self.replans_too_long += r.replans_too_long;
        self.late_swaps += r.late_swaps;
        self.late_swaps_taken += r.late_swaps_taken;
        self.swaps_not_armed += r.swaps_not_armed;
        self.swaps_cancelled += r.swaps_cancelled;
        self.streams += r.streams;
        self.stream_swaps += r.stream_swaps;
        self.stream_extensions += r.stream_extensions;
        self.stream_commands += r.stream_commands;
        self.streams_diverged += r.streams_diverged;
        self.divergences.extend(r.divergences.iter().cloned());
        self.streams_stopped += r.streams_stopped;
        self.clocks += r.clocks;
        self.ticks += r.ticks;
        self.planner_disagreements += r.planner_disagreements;
        for (mine, theirs) in [
            (&mut self.replans_refused, &r.replans_refused),
            (&mut self.stream_errors, &r.stream_errors),
            (&mut self.streams_failed, &r.streams_failed),
        ] {
            for (k, n) in theirs {
                *mine.entry(k.clone()).or_default() += n;
            }
        }
    }

    /// Swaps the core handled against the rules: a late one armed or a timely one not (both
    /// must be 0).
    pub fn swap_faults(&self) -> usize {
        self.late_swaps_taken + self.swaps_not_armed
    }

    /// Ticks per second.
    pub fn ticks_per_second(&self) -> f64 {
        self.ticks as f64 / self.seconds.max(1e-9)
    }
}
