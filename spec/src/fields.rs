//! The byte layout of every payload, each written once as a list of fields (name, Rust type,
//! bytes, signedness, meaning). [`payload!`] turns each list into its field table (what the
//! docs, the C header, the JSON and the fabric's Verilog read) and a plain struct with its
//! little-endian codec (what the model and the host read), so a field's offset and size exist
//! in one place.
//!
//! Meanings may name a constant as `{NAME}`; [`crate::text::expand`] writes its value.

use crate::widths::{POSITION_BYTES, WIDE_BYTES};

/// One field of a payload: name, first byte, size (little-endian), signedness and meaning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Name, as in docs/PROTOCOL.md.
    pub name: &'static str,
    /// First byte.
    pub offset: usize,
    /// Bytes.
    pub bytes: usize,
    /// Two's complement (sign-extended when read).
    pub signed: bool,
    /// What it holds (may name constants as `{NAME}`).
    pub meaning: &'static str,
}

/// The fields of `spec` (name, bytes, signed, meaning) laid out one after the other.
pub const fn layout<const N: usize>(
    spec: [(&'static str, usize, bool, &'static str); N],
) -> [Field; N] {
    let mut out = [Field {
        name: "",
        offset: 0,
        bytes: 0,
        signed: false,
        meaning: "",
    }; N];
    let mut at = 0;
    let mut k = 0;
    while k < N {
        out[k] = Field {
            name: spec[k].0,
            offset: at,
            bytes: spec[k].1,
            signed: spec[k].2,
            meaning: spec[k].3,
        };
        at += spec[k].1;
        k += 1;
    }
    out
}

/// Bytes of a payload laid out by `fields` (0 for none).
pub const fn payload_bytes(fields: &[Field]) -> usize {
    match fields.last() {
        Some(f) => f.offset + f.bytes,
        None => 0,
    }
}

/// The field called `name` in `table` (a compile-time lookup: an unknown name stops the
/// build).
pub const fn field(table: &[Field], name: &str) -> Field {
    let mut k = 0;
    while k < table.len() {
        let a = table[k].name.as_bytes();
        let b = name.as_bytes();
        if a.len() == b.len() {
            let mut i = 0;
            while i < a.len() && a[i] == b[i] {
                i += 1;
            }
            if i == a.len() {
                return table[k];
            }
        }
        k += 1;
    }
    panic!("no field of that name in the layout")
}

/// Writes `value` (two's complement, little-endian, truncated to the field) into `field` of
/// `out`.
pub fn put(out: &mut [u8], field: &Field, value: i128) {
    out[field.offset..field.offset + field.bytes]
        .copy_from_slice(&value.to_le_bytes()[..field.bytes]);
}

/// Reads `field` of `p`, sign-extended when the field is signed.
pub fn get(p: &[u8], field: &Field) -> i128 {
    let mut wide = [0u8; 16];
    wide[..field.bytes].copy_from_slice(&p[field.offset..field.offset + field.bytes]);
    if field.signed && p[field.offset + field.bytes - 1] & 0x80 != 0 {
        wide[field.bytes..].fill(0xff);
    }
    i128::from_le_bytes(wide)
}

#[doc(hidden)]
#[macro_export]
macro_rules! __signed {
    (signed) => {
        true
    };
    (unsigned) => {
        false
    };
}

/// A payload: its field table `$table` and a struct `$name` with one field each, with
/// `to_payload` and `from_payload` (which checks the length).
#[macro_export]
macro_rules! payload {
    (
        $(#[$meta:meta])*
        $name:ident, $table:ident {
            $( $field:ident : $ty:ty = $bytes:expr, $sign:ident, $meaning:literal; )*
        }
    ) => {
        $crate::payload! { $(#[$meta])* $name, $table $( $field : $ty = $bytes, $sign, $meaning; )* }
    };
    (
        $(#[$meta:meta])*
        $name:ident, $table:ident
            $( $field:ident : $ty:ty = $bytes:expr, $sign:ident, $meaning:literal; )*
    ) => {
        #[doc = concat!("The layout of [`", stringify!($name), "`].")]
        pub const $table: [$crate::fields::Field; [$(stringify!($field)),*].len()] =
            $crate::fields::layout([$( (stringify!($field), $bytes, $crate::__signed!($sign), $meaning) ),*]);

        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct $name {
            $( #[doc = $meaning] pub $field: $ty, )*
        }

        impl $name {
            /// Payload bytes.
            pub const BYTES: usize = $crate::fields::payload_bytes(&$table);

            /// The payload.
            pub fn to_payload(&self) -> Vec<u8> {
                let mut p = vec![0u8; Self::BYTES];
                self.write_payload(&mut p);
                p
            }

            /// The payload written into `p` (at least [`Self::BYTES`] bytes, zeroed), without
            /// an allocation.
            #[allow(clippy::unnecessary_cast)]
            pub fn write_payload(&self, p: &mut [u8]) {
                let mut fields = $table.iter();
                $( $crate::fields::put(p, fields.next().expect("one field each"), self.$field as i128); )*
            }

            /// From a payload of exactly [`Self::BYTES`] bytes.
            #[allow(clippy::unnecessary_cast)]
            pub fn from_payload(p: &[u8]) -> Option<Self> {
                if p.len() != Self::BYTES {
                    return None;
                }
                let mut fields = $table.iter();
                Some($name {
                    $( $field: $crate::fields::get(p, fields.next().expect("one field each")) as $ty, )*
                })
            }
        }
    };
}

/// Calls `$callback! { $($extra)* $( field: RustType = bytes, signed|unsigned, "meaning"; )* }`
/// with the status block's fields, in order: the one list of them (the fabric's status block
/// takes one input per field).
#[macro_export]
macro_rules! with_status_fields {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)*
        state: u8 = 1, unsigned, "axis state (above)";
        error: u8 = 1, unsigned, "error identifier (above)";
        flags: u16 = 2, unsigned, "flag bits (below)";
        tick_count: u32 = 4, unsigned, "ticks since the last START or program swap, counted while a program plays or a stop runs; START, a swap and reset clear it";
        position: i32 = 4, signed, "the reference position in output LSBs: the position register shifted right by {FRAC_BITS} (rounded toward −∞), low 32 bits, signed";
        velocity: i32 = 4, signed, "the velocity register's top 32 bits (signed): physical velocity ≈ velocity · 2^{VELOCITY_SHIFT} · L / Ts";
        encoder: i32 = 4, signed, "the quadrature count (×4 decoding), signed: where the motor is, against `position`, where it should be";
        bad_crc: u16 = 2, unsigned, "frames dropped for a bad CRC (wraps)";
        bad_frames: u16 = 2, unsigned, "frames with a bad length or an unknown command, cut short by the inter-byte timeout or by a UART framing error (wraps)";
        following_peak: u32 = 4, unsigned, "the largest magnitude of the following error at a controller sample since the last START or reset, counts · 2^-{E_FRAC} (saturates at 2^31)";
        duty: i16 = 2, signed, "the controller's duty now, PWM clocks, signed (its sign is the direction)";
        }
    };
}

with_status_fields!(payload! {
    /// The status block (STATUS, TELEMETRY).
    Status, STATUS_FIELDS
});

payload! {
    /// What a device says about itself (IDENTITY, the reply to PING).
    Identity, IDENTITY_FIELDS {
        protocol: u8 = 1, unsigned, "protocol version ({PROTOCOL_VERSION})";
        design_hash: u32 = 4, unsigned, "FNV-1a (32 bits) of the design's two files, snapgen_core.v then snapgen_io.v generated with this field 0 (docs/HDL.md)";
        clock_hz: u32 = 4, unsigned, "fabric clock, Hz";
        baud: u32 = 4, unsigned, "the UART's rate: clock / clocks-per-bit, rounded (115 207 for 115 200 at 125 MHz)";
        tick_divider: u32 = 4, unsigned, "clocks per tick − 1, now (Ts = (tick_divider + 1) / clock_hz)";
        x_bits: u8 = 1, unsigned, "position register width";
        v_bits: u8 = 1, unsigned, "velocity register width";
        a_bits: u8 = 1, unsigned, "acceleration register width";
        j_bits: u8 = 1, unsigned, "jerk register width";
        d_bits: u8 = 1, unsigned, "snap width";
        frac_bits: u8 = 1, unsigned, "fractional position bits below the output LSB";
        tick_bits: u8 = 1, unsigned, "width of a segment's tick count";
        max_segments: u8 = 1, unsigned, "segments per program";
        snap_bytes: u8 = 1, unsigned, "bytes of a snap in LOAD_SEGMENT";
        stop_jerk: i128 = WIDE_BYTES, signed, "STOP_JERK, now";
        stop_accel: i128 = WIDE_BYTES, signed, "STOP_ACCEL, now";
    }
}

payload! {
    /// The chain's registers and the tick they belong to (STATE, the reply to READ_STATE).
    StateReply, STATE_FIELDS {
        ticks: u64 = 8, unsigned, "ticks since reset (the board's time base; never reset by a move)";
        x: i128 = POSITION_BYTES, signed, "position register ({X_BITS} bits, {FRAC_BITS} fractional bits below the output LSB)";
        v: i128 = WIDE_BYTES, signed, "velocity register ({V_BITS} bits)";
        a: i128 = WIDE_BYTES, signed, "acceleration register";
        j: i128 = WIDE_BYTES, signed, "jerk register";
    }
}

payload! {
    /// A parameter's value (CONFIG, the reply to READ_CONFIG; also CONFIGURE's payload).
    ConfigValue, CONFIG_FIELDS {
        param: u8 = 1, unsigned, "the parameter";
        value: i128 = WIDE_BYTES, signed, "its value (signed {D_BITS}-bit, ≥ 0)";
    }
}

payload! {
    /// LOAD_SEGMENT's payload: one segment of the standby program.
    LoadSegmentArgs, LOAD_SEGMENT_FIELDS {
        index: u8 = 1, unsigned, "0–{LAST_SEGMENT}";
        ticks: u32 = 4, unsigned, "≥ 1";
        snap: i128 = WIDE_BYTES, signed, "signed {D_BITS}-bit";
    }
}

payload! {
    /// COMMIT's payload.
    CommitArgs, COMMIT_FIELDS {
        count: u8 = 1, unsigned, "0–{MAX_SEGMENTS}";
    }
}

payload! {
    /// READ_CONFIG's payload.
    ReadConfigArgs, READ_CONFIG_FIELDS {
        param: u8 = 1, unsigned, "the parameter";
    }
}

payload! {
    /// POWER's payload.
    PowerArgs, POWER_FIELDS {
        on: u8 = 1, unsigned, "0 or 1";
    }
}

payload! {
    /// SWAP_AT's payload.
    SwapAtArgs, SWAP_AT_FIELDS {
        tick: u64 = 8, unsigned, "a value of the time base, `ticks` in STATE";
    }
}

payload! {
    /// ACK's payload.
    AckPayload, ACK_FIELDS {
        cmd: u8 = 1, unsigned, "the acknowledged command's code";
    }
}

payload! {
    /// NAK's payload.
    NakPayload, NAK_FIELDS {
        cmd: u8 = 1, unsigned, "the rejected command's code (0 if unknown)";
        reason: u8 = 1, unsigned, "reason";
    }
}

impl Identity {
    /// The tick period it reports (s): `(tick_divider + 1) / clock_hz`.
    pub fn ts(&self) -> f64 {
        (f64::from(self.tick_divider) + 1.0) / f64::from(self.clock_hz)
    }
}

/// Payloads with no field (PING, START, …).
pub const NO_FIELDS: [Field; 0] = [];

/// Bits of the status block as the fabric holds it (byte 0 in bits 7:0).
pub const STATUS_BITS: usize = 8 * Status::BYTES;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_are_contiguous() {
        for t in [
            &STATUS_FIELDS[..],
            &IDENTITY_FIELDS,
            &STATE_FIELDS,
            &CONFIG_FIELDS,
        ] {
            let mut at = 0;
            for f in t {
                assert_eq!(f.offset, at, "{}", f.name);
                at += f.bytes;
            }
        }
        assert_eq!(Status::BYTES, 30);
        assert_eq!(Identity::BYTES, 52);
        assert_eq!(StateReply::BYTES, 61);
        assert_eq!(ConfigValue::BYTES, 14);
        assert_eq!(LoadSegmentArgs::BYTES, 18);
    }

    #[test]
    fn codecs_round_trip_and_sign_extend() {
        let s = Status {
            state: 2,
            error: 0,
            flags: 0x2021,
            tick_count: 40_000,
            position: -235_702,
            velocity: i32::MIN,
            encoder: 7,
            bad_crc: 1,
            bad_frames: 65_535,
            following_peak: u32::MAX,
            duty: -40,
        };
        let p = s.to_payload();
        assert_eq!(p.len(), Status::BYTES);
        assert_eq!(Status::from_payload(&p), Some(s));
        assert_eq!(Status::from_payload(&p[1..]), None);
        let r = StateReply {
            ticks: u64::MAX,
            x: -(1i128 << 111),
            v: (1i128 << 103) - 1,
            a: -1,
            j: 0,
        };
        assert_eq!(StateReply::from_payload(&r.to_payload()), Some(r));
        // By hand: −40 as i16 little-endian is D8 FF.
        assert_eq!(&p[28..30], &[0xD8, 0xFF]);
    }
}
