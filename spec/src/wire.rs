//! The frame on the wire (docs/PROTOCOL.md, "Frame"):
//!
//! ```text
//! +------+-----+-----+-----+-------------+---------+
//! | 0xA5 | LEN | CMD | SEQ | PAYLOAD     | CRC16   |
//! +------+-----+-----+-----+-------------+---------+
//!    1      1     1     1    LEN bytes     2 (LE)
//! ```
//!
//! `CRC16` is CRC-16/CCITT-FALSE (polynomial [`CRC_POLY`], initial value [`CRC_INIT`], no
//! reflection, no final XOR; check value [`CRC_CHECK`] for "123456789") over
//! `LEN CMD SEQ PAYLOAD`, sent low byte first. Multi-byte fields are little-endian; signed
//! fields are two's complement.

/// Start-of-frame byte.
pub const START: u8 = 0xA5;
/// Bytes around the payload: start, length, command, sequence, two CRC bytes.
pub const OVERHEAD: usize = 6;
/// Bytes before the payload: start, length, command, sequence.
pub const HEADER: usize = 4;
/// Protocol version reported by PING.
pub const PROTOCOL_VERSION: u8 = 4;
/// The CRC polynomial (CRC-16/CCITT-FALSE).
pub const CRC_POLY: u16 = 0x1021;
/// The CRC's initial value.
pub const CRC_INIT: u16 = 0xFFFF;
/// The CRC of the ASCII bytes "123456789" (the catalogue's check value).
pub const CRC_CHECK: u16 = 0x29B1;
/// The longest payload a device accepts: a start byte followed by a longer `LEN` is noise,
/// not a frame start.
pub const DEVICE_MAX_PAYLOAD: usize = 32;
/// A device drops a partial frame when no byte follows for this long (seconds).
pub const FRAME_TIMEOUT_S: f64 = 0.02;
/// The sequence number of frames a device sends on its own (TELEMETRY) and of NAKs of frames
/// whose sequence is untrusted; hosts use 1–255.
pub const DEVICE_SEQ: u8 = 0;

/// CRC-16/CCITT-FALSE of `crc` followed by `byte`.
#[inline]
pub const fn crc16_step(crc: u16, byte: u8) -> u16 {
    let mut crc = crc ^ ((byte as u16) << 8);
    let mut k = 0;
    while k < 8 {
        crc = if crc & 0x8000 != 0 {
            (crc << 1) ^ CRC_POLY
        } else {
            crc << 1
        };
        k += 1;
    }
    crc
}

/// CRC-16/CCITT-FALSE of `data`.
pub const fn crc16(data: &[u8]) -> u16 {
    let mut crc = CRC_INIT;
    let mut k = 0;
    while k < data.len() {
        crc = crc16_step(crc, data[k]);
        k += 1;
    }
    crc
}

const _: () = assert!(crc16(b"123456789") == CRC_CHECK);

/// The bytes of a frame: start byte, length, code, sequence, payload, CRC (low byte first).
///
/// # Panics
/// If the payload is longer than 255 bytes (no frame can carry it).
pub fn frame_bytes(cmd: u8, seq: u8, payload: &[u8]) -> Vec<u8> {
    let len = u8::try_from(payload.len()).expect("a payload of at most 255 bytes");
    let mut v = Vec::with_capacity(payload.len() + OVERHEAD);
    v.extend_from_slice(&[START, len, cmd, seq]);
    v.extend_from_slice(payload);
    let crc = crc16(&v[1..]);
    v.extend_from_slice(&crc.to_le_bytes());
    v
}
