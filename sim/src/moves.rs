//! Random move streams for co-simulation: positive and negative, tiny and long, every order,
//! limits drawn log-uniformly so that each limit is the active one in some moves and phases
//! are empty in others; a few moves run with a tick divider, a few are aborted midway and many
//! get a controlled stop at a random clock (with random stop limits, some of them too low for
//! the state the stop begins from), some with a second request or an abort during the stop.
//! A share of the moves that play to their end is replanned on the way: a chain of program
//! swaps at random ticks (docs/PROTOCOL.md, SWAP_AT), drawn in the co-simulation from
//! `replan_seed` (see `crate::cosim`). A share of the moves are PLCopen event streams instead:
//! random scripts of commands played through the host axis and its driver.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_model::format::Quantity;
use snapgen_model::stop::StopLimits;
use snapgen_model::Format;
use snapgen_plan::{Method, MoveRequest};

/// Which planners the stream uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrderMix {
    /// Order 2 only.
    Two,
    /// Order 3 and seed 001's duration method.
    Three,
    /// Order 4 only.
    Four,
    /// All of them.
    Mixed,
}

impl std::str::FromStr for OrderMix {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "2" => Ok(OrderMix::Two),
            "3" => Ok(OrderMix::Three),
            "4" => Ok(OrderMix::Four),
            "mixed" => Ok(OrderMix::Mixed),
            _ => Err(format!("order mix {s:?}: use 2, 3, 4 or mixed")),
        }
    }
}

/// One move of a stream.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveSpec {
    /// What to plan.
    pub request: MoveRequest,
    /// Tick period the host plans with (the fabric's tick is `tick_div + 1` clocks).
    pub ts: f64,
    /// Clocks per tick minus one.
    pub tick_div: u32,
    /// Stop (abort) this many clocks after the start, if set.
    pub abort_after: Option<u64>,
    /// Controlled stop this many clocks after the start, if set.
    pub stop_after: Option<u64>,
    /// The stop's limits (raw, at `ts`).
    pub stop_limits: StopLimits,
    /// Request the stop again this many clocks after the first request (ignored by the core).
    pub stop_again_after: Option<u64>,
    /// Abort this many clocks after the stop request (cancels the stop).
    pub abort_stop_after: Option<u64>,
    /// Online replans of this move (program swaps at random ticks; 0: none).
    pub replans: u8,
    /// Seed of the replans' random choices (when, where to, with which limits), and of a
    /// stream's script.
    pub replan_seed: u64,
    /// Events of a PLCopen event stream played instead of the move (0: none): random
    /// MC_MoveAbsolute (every buffer mode), MC_MoveVelocity, MC_Halt and override changes
    /// through the host axis (`crate::cosim`).
    pub stream: u8,
}

impl MoveSpec {
    /// `request` planned at `ts`, played to its end at one tick per clock.
    pub fn plain(request: MoveRequest, ts: f64) -> Self {
        MoveSpec {
            request,
            ts,
            tick_div: 0,
            abort_after: None,
            stop_after: None,
            stop_limits: StopLimits::default(),
            stop_again_after: None,
            abort_stop_after: None,
            replans: 0,
            replan_seed: 0,
            stream: 0,
        }
    }
}

/// A deterministic stream of random moves.
pub struct MoveStream {
    rng: StdRng,
    mix: OrderMix,
    stop_share: f64,
    replan_share: f64,
    stream_share: f64,
}

/// The share of moves given a controlled stop by default.
pub const DEFAULT_STOP_SHARE: f64 = 0.25;
/// The share of the remaining moves replanned on the way by default.
pub const DEFAULT_REPLAN_SHARE: f64 = 0.2;
/// The share of the moves played as PLCopen event streams by default.
pub const DEFAULT_STREAM_SHARE: f64 = 0.1;

/// A number drawn log-uniformly from `lo..=hi`.
pub fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    rng.gen_range(lo.ln()..=hi.ln()).exp()
}

impl MoveStream {
    /// The stream for `seed`: a share `stream_share` of the moves are PLCopen event streams
    /// (3 to 12 events); of the others, a share `stop_share` get a controlled stop (each
    /// stopping tick takes the stop unit's decision, about 140 clocks) and a share
    /// `replan_share` of the rest 1 to 8 online replans.
    pub fn new(
        seed: u64,
        mix: OrderMix,
        stop_share: f64,
        replan_share: f64,
        stream_share: f64,
    ) -> Self {
        MoveStream {
            rng: StdRng::seed_from_u64(seed),
            mix,
            stop_share: stop_share.clamp(0.0, 1.0),
            replan_share: replan_share.clamp(0.0, 1.0),
            stream_share: stream_share.clamp(0.0, 1.0),
        }
    }

    /// The next move (the caller skips moves that do not plan or are too long).
    pub fn next_move(&mut self) -> MoveSpec {
        let r = &mut self.rng;
        let kind = match self.mix {
            OrderMix::Two => 2,
            OrderMix::Three => {
                if r.gen_bool(0.3) {
                    1
                } else {
                    3
                }
            }
            OrderMix::Four => 4,
            OrderMix::Mixed => [1, 2, 3, 4, 4][r.gen_range(0..5)],
        };
        // Distance: 10 % tiny (1–20 LSB), 10 % long, the rest in between; either sign.
        let size: f64 = r.gen();
        let mut distance = if size < 0.1 {
            f64::from(r.gen_range(1..=20)) * 1e-6
        } else if size < 0.2 {
            log_uniform(r, 1.0, 20.0)
        } else {
            log_uniform(r, 1e-3, 2.0)
        };
        if r.gen_bool(0.5) {
            distance = -distance;
        }
        let v = log_uniform(r, 0.05, 20.0);
        let a = log_uniform(r, 1.0, 2000.0);
        let j = log_uniform(r, 50.0, 1e6);
        let d = log_uniform(r, 1e3, 1e9);
        let method = match kind {
            1 => Method::Duration {
                duration: log_uniform(r, 0.002, 0.5),
                gamma: r.gen_range(0.05..=0.5),
                phi: r.gen_range(0.05..=0.5),
            },
            2 => Method::Order2 { vmax: v, amax: a },
            3 => Method::Order3 {
                vmax: v,
                amax: a,
                jmax: j,
            },
            _ => Method::Order4 {
                vmax: v,
                amax: a,
                jmax: j,
                dmax: d,
            },
        };
        // The fabric ticks every `tick_div + 1` clocks whatever Ts the host plans with; Ts only
        // sets how many ticks a move takes.
        let ts = [1e-5, 1e-4, 1e-4, 1e-4, 1e-3][r.gen_range(0..5)];
        let tick_div = if r.gen_bool(0.1) {
            r.gen_range(1..=3)
        } else {
            0
        };
        let abort_after = if r.gen_bool(0.03) {
            Some(r.gen_range(1..2000))
        } else {
            None
        };
        let stop_after = if abort_after.is_none() && r.gen_bool(self.stop_share) {
            Some(log_uniform(r, 1.0, 400_000.0) as u64)
        } else {
            None
        };
        // Stop limits, raw at this Ts: an acceleration that stops the move's top speed in
        // 2 to 1000 ticks and a jerk that reaches it in 1 to 500 ticks, so that stops last
        // tens to about a thousand ticks (each stop tick waits for the stop unit's decision)
        // and some begin decelerating harder than their limits allow.
        let f = Format::with_ts(ts);
        let v_raw = (v * f.scale(Quantity::Velocity)).max(1.0);
        let a_raw = a * f.scale(Quantity::Acceleration);
        let mut accel = ((v_raw / log_uniform(r, 2.0, 1000.0)) as i128).max(1);
        if r.gen_bool(0.4) {
            // Below the move's own acceleration: a stop during its deceleration begins over.
            accel = ((a_raw * log_uniform(r, 0.05, 1.0)).max(v_raw / 1000.0) as i128).max(1);
        }
        let mut jerk = ((accel as f64 / log_uniform(r, 1.0, 500.0)) as i128).clamp(1, accel);
        if r.gen_bool(0.4) {
            // Below the move's own jerk: a stop while the move's acceleration is high may
            // not release it in time.
            let j_raw = j * f.scale(Quantity::Jerk) * log_uniform(r, 0.01, 1.0);
            jerk = (j_raw.max(accel as f64 / 500.0) as i128).clamp(1, accel);
        }
        let stop_again_after = stop_after
            .filter(|_| r.gen_bool(0.2))
            .map(|_| r.gen_range(1..3000));
        let abort_stop_after = stop_after
            .filter(|_| r.gen_bool(0.1))
            .map(|_| r.gen_range(1..3000));
        let replans =
            if abort_after.is_none() && stop_after.is_none() && r.gen_bool(self.replan_share) {
                r.gen_range(1..=8)
            } else {
                0
            };
        let replan_seed = r.gen();
        // Drawn last, so that a stream share of 0 leaves every other draw as it was.
        let stream = if self.stream_share > 0.0 && r.gen_bool(self.stream_share) {
            r.gen_range(3..=12)
        } else {
            0
        };
        MoveSpec {
            request: MoveRequest { distance, method },
            ts,
            tick_div,
            abort_after: abort_after.filter(|_| stream == 0),
            stop_after: stop_after.filter(|_| stream == 0),
            stop_limits: StopLimits { jerk, accel },
            stop_again_after,
            abort_stop_after,
            replans: if stream == 0 { replans } else { 0 },
            replan_seed,
            stream,
        }
    }
}
