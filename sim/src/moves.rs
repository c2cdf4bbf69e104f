//! Random move streams for co-simulation: positive and negative, tiny and long, every order,
//! limits drawn log-uniformly so that each limit is the active one in some moves and phases
//! are empty in others; a few moves run with a tick divider, a few are aborted midway and a few
//! get a controlled stop.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use snapgen_model::{Method, MoveRequest};

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
    pub stop_after: Option<u64>,
    /// Controlled stop this many clocks after the start, if set.
    pub soft_stop_after: Option<u64>,
}

/// A deterministic stream of random moves.
pub struct MoveStream {
    rng: StdRng,
    mix: OrderMix,
}

fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    rng.gen_range(lo.ln()..=hi.ln()).exp()
}

impl MoveStream {
    /// The stream for `seed`.
    pub fn new(seed: u64, mix: OrderMix) -> Self {
        MoveStream {
            rng: StdRng::seed_from_u64(seed),
            mix,
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
        let stop_after = if r.gen_bool(0.03) {
            Some(r.gen_range(1..2000))
        } else {
            None
        };
        let soft_stop_after = if stop_after.is_none() && r.gen_bool(0.05) {
            Some(r.gen_range(1..20_000))
        } else {
            None
        };
        MoveSpec {
            request: MoveRequest { distance, method },
            ts,
            tick_div,
            stop_after,
            soft_stop_after,
        }
    }
}
