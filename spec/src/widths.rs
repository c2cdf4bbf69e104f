//! Register widths of the generated fabric and the byte sizes they give on the wire.
//!
//! The chain's registers share one LSB per power of the tick (docs/MODEL.md): position
//! [`X_BITS`] bits with [`FRAC_BITS`] fractional bits below the output LSB, velocity,
//! acceleration, jerk and snap [`V_BITS`]. The model's default format, the fabric's widths,
//! the protocol's field sizes and the harness's word layout are all these numbers.

/// Position register width (signed, two's complement).
pub const X_BITS: u32 = 112;
/// Velocity register width.
pub const V_BITS: u32 = 104;
/// Acceleration register width.
pub const A_BITS: u32 = 104;
/// Jerk register width.
pub const J_BITS: u32 = 104;
/// Snap (a segment's value) width.
pub const D_BITS: u32 = 104;
/// Fractional bits of the position register below the output LSB.
pub const FRAC_BITS: u32 = 80;
/// Width of a segment's tick count and of the fabric's tick counter.
pub const TICK_BITS: u32 = 32;
/// Segment address within a program bank.
pub const ADDR_BITS: u32 = 5;
/// Segments per program (the depth of a program bank).
pub const MAX_SEGMENTS: u32 = 1 << ADDR_BITS;
/// Width of a segment index or count (holds 0..=[`MAX_SEGMENTS`]).
pub const INDEX_BITS: u32 = ADDR_BITS + 1;
/// Width of the whole-LSB position output (`x >> FRAC_BITS`, low bits).
pub const POSITION_BITS: u32 = 32;
/// Width of the time base (ticks since reset).
pub const TIME_BITS: u32 = 64;
/// Bits of the time base the core compares for a program swap (SWAP_AT).
pub const SWAP_BITS: u32 = 32;
/// Width of the encoder count.
pub const ENCODER_BITS: u32 = 32;
/// Width of an axis state or error identifier in the fabric.
pub const STATE_BITS: u32 = 3;
/// Width of a controller gain register (signed; its largest value is `2^(GAIN_BITS-1) − 1`).
pub const GAIN_BITS: u32 = 48;
/// Fractional bits of the controller's following error (counts · 2^-E_FRAC).
pub const E_FRAC: u32 = 16;

/// Axes a path design may have at most (issue 22: 1 to 8, chosen at generation).
pub const MAX_AXES: u32 = 8;
/// Width of an axis index in the path interpolator.
pub const AXIS_BITS: u32 = 3;
/// Width of a line's share of the length per axis, an arc's radius growth and the
/// interpolator's sine and cosine (signed, 62 fraction bits: `1.0` is `2^62`).
pub const SHARE_BITS: u32 = 64;
/// Fraction bits of a share, a growth, a sine or a cosine.
pub const SHARE_FRAC: u32 = 62;
/// Width of an arc's angular rate (turns·2^64 per raw unit of the path length, with
/// [`RATE_FRAC`] fraction bits; never negative).
pub const RATE_BITS: u32 = 128;
/// Fraction bits of an arc's angular rate.
pub const RATE_FRAC: u32 = 120;
/// Width of an angle: a full turn is `2^TURN_BITS`.
pub const TURN_BITS: u32 = 64;

/// Width of a path segment's index in the path sequencer (wrapping: a path may have any number
/// of segments; the sequencer compares indices by wrapping differences).
pub const PATH_INDEX_BITS: u32 = 16;
/// Width of a segment's slot in the path sequencer's ring of segments.
pub const PATH_SLOT_BITS: u32 = 6;
/// Segments the path sequencer holds at once (its ring's depth).
pub const PATH_SLOTS: u32 = 1 << PATH_SLOT_BITS;

/// Width of the step/dir generator's step length and its pulse timers (clocks).
pub const STEP_TIMER_BITS: u32 = 16;

/// Bytes that hold `bits` bits.
pub const fn bytes_for(bits: u32) -> usize {
    bits.div_ceil(8) as usize
}

/// Bytes of a wide value on the wire: a snap, velocity, acceleration, jerk, stop limit or a
/// CONFIGURE value (signed, two's complement).
pub const WIDE_BYTES: usize = bytes_for(D_BITS);
/// Bytes of the position register on the wire.
pub const POSITION_BYTES: usize = bytes_for(X_BITS);

const _: () = {
    assert!(V_BITS == A_BITS && A_BITS == J_BITS && J_BITS == D_BITS);
    assert!(X_BITS > V_BITS && X_BITS <= 127 && X_BITS >= FRAC_BITS + POSITION_BITS);
    assert!(bytes_for(V_BITS) == WIDE_BYTES);
    assert!(MAX_AXES == 1 << AXIS_BITS);
    assert!(PATH_SLOT_BITS < PATH_INDEX_BITS - 1 && PATH_INDEX_BITS <= 16);
};

/// The largest value of a register of `bits` bits: two's complement when `signed`.
pub const fn max_of(bits: u32, signed: bool) -> i128 {
    if signed {
        (1i128 << (bits - 1)) - 1
    } else {
        (1i128 << bits) - 1
    }
}
