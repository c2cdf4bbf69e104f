//! `snapgen_protocol.json`: the whole contract as one JSON document, for tools written in any
//! language (a protocol client, a decoder in a logic analyser, a test bench).

use serde_json::{json, Value};

use crate::codes::{AxisState, ErrorId, Reason, COMMANDS, FLAGS, REPLIES};
use crate::fields::{
    Field, ACK_FIELDS, COMMIT_FIELDS, CONFIG_FIELDS, IDENTITY_FIELDS, LOAD_SEGMENT_FIELDS,
    NAK_FIELDS, POWER_FIELDS, READ_CONFIG_FIELDS, STATE_FIELDS, STATUS_FIELDS, SWAP_AT_FIELDS,
};
use crate::params::{Reset, PARAMS};
use crate::ports::{Block, IO_TOP, MOTION_CORE};
use crate::refusals::REFUSALS;
use crate::rules::{HOST_REPLY_TIMEOUT_S, HOST_RETRIES, REPLY_QUEUE, SWAP_MIN_LEAD, SWAP_REACH};
use crate::text::{expand, UnknownConstant};
use crate::widths;
use crate::wire::{
    CRC_CHECK, CRC_INIT, CRC_POLY, DEVICE_MAX_PAYLOAD, FRAME_TIMEOUT_S, OVERHEAD, PROTOCOL_VERSION,
    START,
};

fn fields(f: &[Field], extra: &[(&str, String)]) -> Result<Value, UnknownConstant> {
    let mut v = Vec::new();
    for x in f {
        v.push(json!({
            "name": x.name, "offset": x.offset, "bytes": x.bytes, "signed": x.signed,
            "meaning": expand(x.meaning, extra)?,
        }));
    }
    Ok(Value::Array(v))
}

fn block(b: &Block) -> Value {
    json!({
        "clock": b.clock,
        "ports": b.ports.iter().map(|p| json!({
            "name": p.name, "dir": p.dir.verilog(), "bits": p.bits, "section": p.section, "doc": p.doc,
        })).collect::<Vec<_>>(),
    })
}

/// The document (`extra`: facts of the design named in the prose).
pub fn document(extra: &[(&str, String)]) -> Result<Value, UnknownConstant> {
    let x = |s: &str| expand(s, extra);
    let mut commands = Vec::new();
    for c in COMMANDS {
        commands.push(json!({
            "code": c.code, "name": c.name, "len": c.len, "changes_state": c.effect,
            "reply": c.reply, "meaning": x(c.meaning)?, "payload": fields(c.fields, extra)?,
        }));
    }
    let mut replies = Vec::new();
    for r in REPLIES {
        replies.push(json!({
            "code": r.code, "name": r.name, "len": r.len, "meaning": x(r.meaning)?,
            "payload": fields(r.fields, extra)?,
        }));
    }
    let mut params = Vec::new();
    for p in PARAMS {
        params.push(json!({
            "code": p.param as u8, "name": p.name, "register": p.register, "bits": p.bits,
            "signed": p.signed,
            "max": p.max().to_string(),
            "reset": match p.reset { Reset::Value(v) => json!(v.to_string()), Reset::Max => json!(p.max().to_string()), Reset::Design => json!("design") },
            "settable": p.settable.name(), "meaning": x(p.meaning)?,
        }));
    }
    let named = |code: u8, name: &str, meaning: &str| -> Result<Value, UnknownConstant> {
        Ok(json!({"value": code, "name": name, "meaning": x(meaning)?}))
    };
    let mut reasons = Vec::new();
    for r in Reason::ALL {
        reasons.push(named(r as u8, r.name(), r.meaning())?);
    }
    let mut states = Vec::new();
    for s in AxisState::ALL {
        states.push(named(s as u8, s.name(), s.meaning())?);
    }
    let mut errors = Vec::new();
    for e in ErrorId::ALL {
        errors.push(named(e as u8, e.name(), e.meaning())?);
    }
    let mut flags = Vec::new();
    for f in FLAGS {
        flags.push(json!({"bit": f.bit, "name": f.name, "meaning": x(f.meaning)?}));
    }
    let mut refusals = Vec::new();
    for r in REFUSALS {
        refusals.push(json!({
            "command": r.command,
            "reasons": r.reasons.iter().map(|q| q.name()).collect::<Vec<_>>(),
            "when": x(r.when)?,
        }));
    }
    Ok(json!({
        "protocol_version": PROTOCOL_VERSION,
        "frame": {
            "start": START, "overhead": OVERHEAD, "device_max_payload": DEVICE_MAX_PAYLOAD,
            "crc": {"name": "CRC-16/CCITT-FALSE", "poly": CRC_POLY, "init": CRC_INIT, "check": CRC_CHECK},
            "inter_byte_timeout_s": FRAME_TIMEOUT_S,
        },
        "rules": {
            "reply_queue": REPLY_QUEUE, "swap_min_lead": SWAP_MIN_LEAD, "swap_reach": SWAP_REACH,
            "host_reply_timeout_s": HOST_REPLY_TIMEOUT_S, "host_retries": HOST_RETRIES,
        },
        "widths": {
            "x": widths::X_BITS, "v": widths::V_BITS, "a": widths::A_BITS, "j": widths::J_BITS,
            "d": widths::D_BITS, "frac": widths::FRAC_BITS, "tick": widths::TICK_BITS,
            "max_segments": widths::MAX_SEGMENTS,
        },
        "commands": commands,
        "refusals": refusals,
        "replies": replies,
        "reasons": reasons,
        "axis_states": states,
        "errors": errors,
        "flags": flags,
        "params": params,
        "layouts": {
            "status": fields(&STATUS_FIELDS, extra)?, "identity": fields(&IDENTITY_FIELDS, extra)?,
            "state": fields(&STATE_FIELDS, extra)?, "config": fields(&CONFIG_FIELDS, extra)?,
            "load_segment": fields(&LOAD_SEGMENT_FIELDS, extra)?, "commit": fields(&COMMIT_FIELDS, extra)?,
            "read_config": fields(&READ_CONFIG_FIELDS, extra)?, "power": fields(&POWER_FIELDS, extra)?,
            "swap_at": fields(&SWAP_AT_FIELDS, extra)?, "ack": fields(&ACK_FIELDS, extra)?,
            "nak": fields(&NAK_FIELDS, extra)?,
        },
        "blocks": { "snapgen_core": block(&MOTION_CORE), "snapgen_io": block(&IO_TOP) },
    }))
}
