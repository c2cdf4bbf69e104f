//! The configuration parameters (CONFIGURE, READ_CONFIG): code, name, register, width,
//! signedness, value after reset, when it may be set and what it means, each written once in
//! [`with_params!`]'s list.
//!
//! The list makes [`Param`] and [`PARAMS`] here; the model's configuration registers and the
//! fabric's configuration ports are made from the same list by calling [`with_params!`] with
//! a macro of their own, so a parameter's width and reset value exist in one place.

use crate::widths::{max_of, D_BITS, GAIN_BITS};

/// When a parameter may be set (CONFIGURE is refused otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Settable {
    /// In any state.
    Always,
    /// While the axis is at rest: no program plays, no stop runs and v = a = j = 0
    /// (otherwise BUSY).
    AtRest,
    /// While the axis is Disabled (otherwise NOT_DISABLED).
    Disabled,
}

impl Settable {
    /// As the parameter table says it.
    pub fn name(self) -> &'static str {
        match self {
            Settable::Always => "any time",
            Settable::AtRest => "at rest",
            Settable::Disabled => "Disabled",
        }
    }
}

/// A parameter's value after reset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Reset {
    /// This value.
    Value(i128),
    /// Its maximum.
    Max,
    /// The design's: chosen when the Verilog is generated (the tick divider from the clock and
    /// Ts, the input polarity from the board file).
    Design,
}

/// One parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParamSpec {
    /// The parameter.
    pub param: Param,
    /// Its name in docs/PROTOCOL.md.
    pub name: &'static str,
    /// Its register's name (the model's field, the fabric's port).
    pub register: &'static str,
    /// The register's width.
    pub bits: u32,
    /// The register holds two's complement (its largest value is `2^(bits-1) − 1`); values
    /// below 0 are refused either way.
    pub signed: bool,
    /// After reset.
    pub reset: Reset,
    /// When it may be set.
    pub settable: Settable,
    /// The block that reads it: `core`, `io`, `host` (the executor itself) or `servo`.
    pub group: &'static str,
    /// What it means (may name constants as `{NAME}`).
    pub meaning: &'static str,
}

impl ParamSpec {
    /// The largest value CONFIGURE takes (a larger one is refused with BAD_ARGUMENT).
    pub const fn max(&self) -> i128 {
        max_of(self.bits, self.signed)
    }

    /// The value after reset, given the design's value for [`Reset::Design`].
    pub const fn reset_value(&self, design: i128) -> i128 {
        match self.reset {
            Reset::Value(v) => v,
            Reset::Max => self.max(),
            Reset::Design => design,
        }
    }
}

/// Calls `$callback! { $($extra)* group { Variant = code, "NAME", register: Type, bits,
/// signed|unsigned, reset, Settable, "meaning"; … } … }` with every configuration parameter,
/// grouped by the block that reads it (`core`, `io`, `host`: the executor itself, `servo`):
/// the one list of them.
#[macro_export]
macro_rules! with_params {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)*
            // Read by the motion core.
            core {
                TickDivider = 1, "TICK_DIVIDER", tick_divider: u32, 32, unsigned, Design, AtRest,
                    "clocks per tick − 1: Ts = (value + 1) / clock (PING reports the clock); from the third clock after the one that executes CONFIGURE (the write and the tick are registers), so the tick being counted ends when the clocks counted since the last tick reach the new value (at once if they are past it)";
                StopJerk = 5, "STOP_JERK", stop_jerk: i128, $crate::widths::D_BITS, signed, Value(0), AtRest,
                    "the stop's jerk limit, raw (jerk LSBs per tick); 0 = unset: POWER 1 is refused";
                StopAccel = 6, "STOP_ACCEL", stop_accel: i128, $crate::widths::D_BITS, signed, Value(0), AtRest,
                    "the stop's acceleration limit, raw (≥ STOP_JERK)";
            }
            // Read by the I/O blocks.
            io {
                PwmPeriod = 2, "PWM_PERIOD", pwm_period: u16, 16, unsigned, Value(0), Always,
                    "PWM period in clocks; 0 turns the PWM off";
                EncoderFilter = 3, "ENCODER_FILTER", encoder_filter: u16, 16, unsigned, Value(0), Always,
                    "encoder glitch filter, clocks";
                InputPolarity = 8, "INPUT_POLARITY", input_polarity: u8, 3, unsigned, Design, Disabled,
                    "bit 0 inverts limit_pos, bit 1 limit_neg, bit 2 estop";
                InputFilter = 9, "INPUT_FILTER", input_filter: u16, 16, unsigned, Value(0), Disabled,
                    "glitch filter of the limit and emergency-stop inputs, clocks";
            }
            // Read by the executor itself.
            host {
                TelemetryPeriod = 4, "TELEMETRY_PERIOD", telemetry_period: u32, 32, unsigned, Value(0), Always,
                    "ticks between TELEMETRY frames while the chain is driven; **0 (the default) sends none**";
                WatchdogMs = 7, "WATCHDOG_MS", watchdog_ms: u32, 32, unsigned, Value(1000), Always,
                    "host watchdog, ms; 0 turns it off";
            }
            // Read by the position controller.
            servo {
                ServoPeriod = 10, "SERVO_PERIOD", servo_period: u16, 16, unsigned, Value(0), Disabled,
                    "the position controller's sample period, ticks; 0 turns it off (duty 0, no following-error check)";
                Kp = 11, "KP", kp: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "proportional gain: Kp · 2^32 with Kp in PWM clocks per count of following error";
                Ki = 12, "KI", ki: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "integral gain: Ki · 2^32, PWM clocks per count·sample";
                Kd = 13, "KD", kd: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "derivative gain: Kd · 2^32, PWM clocks per count/sample";
                Kv = 14, "KV", kv: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "velocity feed-forward: Kv · 2^16, PWM clocks per count/tick of the reference velocity";
                Ka = 15, "KA", ka: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "acceleration feed-forward: Ka · 2^8, PWM clocks per count/tick²";
                IntegralLimit = 16, "INTEGRAL_LIMIT", integral_limit: i64, $crate::widths::GAIN_BITS, signed, Value(0), Always,
                    "the integrator's bound, counts·samples·2^16 (0: no integral action)";
                OutputLimit = 17, "OUTPUT_LIMIT", output_limit: u16, 16, signed, Max, Always,
                    "the duty's bound, PWM clocks (the PWM period bounds it too)";
                FollowingLimit = 18, "FOLLOWING_LIMIT", following_limit: u32, 32, signed, Value(0), Disabled,
                    "following-error limit, counts: beyond it the amplifier is disabled at once (FOLLOWING_ERROR); with SERVO_PERIOD ≠ 0, POWER 1 is refused while it is 0";
                DFilter = 19, "D_FILTER", d_filter: u8, 4, unsigned, Value(0), Always,
                    "the derivative's low-pass: F += Δe − F/2^k, D = F/2^k (about 2^k samples; 0: none)";
            }
        }
    };
}

macro_rules! param_table {
    ( $( $group:ident { $( $var:ident = $code:literal, $name:literal, $reg:ident : $ty:ty, $bits:expr, $sign:ident,
         $reset:ident $(($rv:expr))?, $settable:ident, $meaning:literal; )* } )* ) => {
        /// Configuration parameters (CONFIGURE, READ_CONFIG).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[repr(u8)]
        pub enum Param {
            $( $( #[doc = $meaning] $var = $code, )* )*
        }

        /// Every parameter, in code order (docs/PROTOCOL.md, "Parameters").
        pub const PARAMS: [ParamSpec; [$($($code),*),*].len()] = sort_by_code([
            $( $( ParamSpec {
                param: Param::$var,
                name: $name,
                register: stringify!($reg),
                bits: $bits,
                signed: $crate::__signed!($sign),
                reset: Reset::$reset $(($rv))?,
                settable: Settable::$settable,
                group: stringify!($group),
                meaning: $meaning,
            }, )* )*
        ]);

        impl Param {
            /// Every parameter, in code order.
            pub const ALL: [Param; PARAMS.len()] = {
                let mut all = [Param::TickDivider; PARAMS.len()];
                let mut k = 0;
                while k < PARAMS.len() {
                    all[k] = PARAMS[k].param;
                    k += 1;
                }
                all
            };

            /// From the parameter byte.
            pub fn from_byte(b: u8) -> Option<Self> {
                match b {
                    $( $( $code => Some(Param::$var), )* )*
                    _ => None,
                }
            }
        }
    };
}

/// `params` in code order (a const insertion sort: the list is grouped by reader).
const fn sort_by_code<const N: usize>(mut params: [ParamSpec; N]) -> [ParamSpec; N] {
    let mut i = 1;
    while i < N {
        let mut k = i;
        while k > 0 && (params[k - 1].param as u8) > (params[k].param as u8) {
            let t = params[k - 1];
            params[k - 1] = params[k];
            params[k] = t;
            k -= 1;
        }
        i += 1;
    }
    params
}

with_params!(param_table! {});

impl Param {
    /// Its row of [`PARAMS`].
    pub const fn spec(self) -> &'static ParamSpec {
        &PARAMS[self as usize - 1]
    }

    /// Its name in docs/PROTOCOL.md.
    pub const fn name(self) -> &'static str {
        self.spec().name
    }

    /// When it may be set.
    pub const fn settable(self) -> Settable {
        self.spec().settable
    }

    /// The largest value it takes (a larger one is refused with BAD_ARGUMENT).
    pub const fn max(self) -> i128 {
        self.spec().max()
    }
}

impl std::fmt::Display for Param {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

const _: () = {
    let mut k = 0;
    while k < PARAMS.len() {
        assert!(
            PARAMS[k].param as usize == k + 1,
            "PARAMS is in code order from 1"
        );
        assert!(PARAMS[k].bits <= D_BITS, "a value fits CONFIGURE's payload");
        k += 1;
    }
    assert!(Param::Kp.max() == (1 << (GAIN_BITS - 1)) - 1);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maxima_by_hand() {
        assert_eq!(Param::StopJerk.max(), (1i128 << 103) - 1);
        assert_eq!(Param::TickDivider.max(), i128::from(u32::MAX));
        assert_eq!(Param::InputPolarity.max(), 7);
        assert_eq!(Param::OutputLimit.max(), 32_767);
        assert_eq!(Param::FollowingLimit.max(), i128::from(i32::MAX));
        assert_eq!(Param::DFilter.max(), 15);
        assert_eq!(Param::OutputLimit.spec().reset_value(0), 32_767);
        assert_eq!(Param::WatchdogMs.spec().reset_value(0), 1000);
        assert_eq!(Param::TickDivider.spec().reset_value(1249), 1249);
        for p in Param::ALL {
            assert_eq!(Param::from_byte(p as u8), Some(p));
            assert_eq!(p.spec().param, p);
        }
        assert_eq!(Param::from_byte(0), None);
        assert_eq!(Param::from_byte(20), None);
    }
}
