//! The configuration registers (CONFIGURE, READ_CONFIG), made from `snapgen_spec`'s parameter
//! list: [`Config`] has one field per parameter, named as its register and typed as the list
//! says, and [`ServoConfig`] the `servo` group's (the position controller's configuration).

use snapgen_spec::params::{Param, PARAMS};

macro_rules! config_structs {
    (
        $( $group:ident { $( $var:ident = $code:literal, $name:literal, $reg:ident : $ty:ty, $bits:expr,
            $sign:ident, $reset:ident $(($rv:expr))?, $settable:ident, $meaning:literal; )* } )*
    ) => {
        /// The configuration registers, one per parameter.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct Config {
            $( $( #[doc = $meaning] pub $reg: $ty, )* )*
        }

        impl Config {
            /// The value of `p`.
            #[allow(clippy::unnecessary_cast)]
            pub fn get(&self, p: Param) -> i128 {
                match p {
                    $( $( Param::$var => self.$reg as i128, )* )*
                }
            }

            /// Sets `p` to `v` (in range: CONFIGURE checks it).
            pub fn set(&mut self, p: Param, v: i128) {
                match p {
                    $( $( Param::$var => self.$reg = v as $ty, )* )*
                }
            }
        }
    };
}

snapgen_spec::with_params!(config_structs! {});

macro_rules! servo_struct {
    (
        core { $($c:tt)* }
        io { $($i:tt)* }
        host { $($h:tt)* }
        servo { $( $var:ident = $code:literal, $name:literal, $reg:ident : $ty:ty, $bits:expr,
            $sign:ident, $reset:ident $(($rv:expr))?, $settable:ident, $meaning:literal; )* }
    ) => {
        /// The position controller's configuration: the `servo` group of the parameters.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct ServoConfig {
            $( #[doc = $meaning] pub $reg: $ty, )*
        }

        impl ServoConfig {
            /// Its parameters, in the list's order.
            pub const PARAMS: [Param; [$($code),*].len()] = [$(Param::$var),*];
        }

        impl Config {
            /// The controller's configuration.
            pub fn servo(&self) -> ServoConfig {
                ServoConfig { $( $reg: self.$reg, )* }
            }

            /// Sets the controller's configuration.
            pub fn set_servo(&mut self, s: &ServoConfig) {
                $( self.$reg = s.$reg; )*
            }
        }
    };
}

snapgen_spec::with_params!(servo_struct! {});

impl Config {
    /// After reset: every parameter's reset value (docs/PROTOCOL.md, "Parameters"), the
    /// design's where the list says so: `tick_divider` and `input_polarity` as generated.
    pub fn after_reset(tick_divider: u32, input_polarity: u8) -> Self {
        let mut c = Config::default();
        for p in PARAMS {
            let design = match p.param {
                Param::TickDivider => i128::from(tick_divider),
                Param::InputPolarity => i128::from(input_polarity),
                _ => 0,
            };
            c.set(p.param, p.reset_value(design));
        }
        c
    }

    /// The stop's limits.
    pub fn stop_limits(&self) -> crate::stop::StopLimits {
        crate::stop::StopLimits {
            jerk: self.stop_jerk,
            accel: self.stop_accel,
        }
    }
}

impl ServoConfig {
    /// What CONFIGURE writes for this configuration: every parameter of the group with its
    /// value, those set only while Disabled first (through [`Config::get`]: one mapping of
    /// fields to parameters for the device and for every host).
    pub fn writes(&self) -> Vec<(Param, i128)> {
        let mut c = Config::default();
        c.set_servo(self);
        let mut w: Vec<(Param, i128)> = Self::PARAMS.iter().map(|&p| (p, c.get(p))).collect();
        w.sort_by_key(|(p, _)| p.settable() != snapgen_spec::Settable::Disabled);
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a host writes for a controller configuration, replayed through CONFIGURE's
    /// setter, is that configuration: every field has its parameter, and only one.
    #[test]
    fn servo_writes_round_trip_through_configure() {
        let want = ServoConfig {
            servo_period: 3,
            kp: 11,
            ki: 12,
            kd: 13,
            kv: 14,
            ka: 15,
            integral_limit: 16,
            output_limit: 17,
            following_limit: 18,
            d_filter: 4,
        };
        let mut c = Config::default();
        let writes = want.writes();
        for &(p, v) in &writes {
            c.set(p, v);
        }
        assert_eq!(c.servo(), want);
        let mut params: Vec<u8> = writes.iter().map(|(p, _)| *p as u8).collect();
        params.sort_unstable();
        params.dedup();
        assert_eq!(params.len(), writes.len());
        assert_eq!(writes[0].0.settable(), snapgen_spec::Settable::Disabled);
    }

    #[test]
    fn reset_values_are_the_lists() {
        let c = Config::after_reset(1249, 5);
        assert_eq!(c.tick_divider, 1249);
        assert_eq!(c.input_polarity, 5);
        assert_eq!(c.watchdog_ms, 1000);
        assert_eq!(c.output_limit, 32_767);
        assert_eq!(c.kp, 0);
    }
}
