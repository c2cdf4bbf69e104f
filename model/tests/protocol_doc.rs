//! docs/PROTOCOL.md against the protocol's one table (`snapgen_model::protocol`): every code,
//! length, parameter default and maximum, state, error, flag and payload layout the page gives
//! is the table's, and every hex example is a frame the model encodes, byte for byte, whose
//! CRC a second (table-driven) CRC implementation confirms.

use snapgen_model::io::executor::Config;
use snapgen_model::protocol::*;
use snapgen_model::stop::StopLimits;
use snapgen_model::{Segment, DEFAULT_FORMAT};

fn doc() -> String {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/PROTOCOL.md");
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The rows of the first Markdown table whose header is `header` (cells trimmed).
fn table(doc: &str, header: &str) -> Vec<Vec<String>> {
    let mut lines = doc.lines().skip_while(|l| l.trim() != header);
    assert!(lines.next().is_some(), "no table with header {header:?}");
    lines
        .skip(1) // |---|
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().trim_matches('`').to_string())
                .collect()
        })
        .collect()
}

/// The rows of the table with `header` that follows the heading `heading`.
fn table_after(doc: &str, heading: &str, header: &str) -> Vec<Vec<String>> {
    let at = doc
        .find(heading)
        .unwrap_or_else(|| panic!("no heading {heading:?}"));
    table(&doc[at..], header)
}

fn hex_u8(s: &str) -> u8 {
    u8::from_str_radix(s.trim_start_matches("0x"), 16).unwrap_or_else(|_| panic!("{s:?}"))
}

#[test]
fn the_command_table_is_the_protocols() {
    let rows = table(
        &doc(),
        "| code | command | LEN | payload | changes state | reply |",
    );
    assert_eq!(rows.len(), COMMANDS.len());
    for (row, c) in rows.iter().zip(COMMANDS) {
        assert_eq!(hex_u8(&row[0]), c.code, "{row:?}");
        assert_eq!(row[1], c.name);
        assert_eq!(row[2].parse::<u8>().unwrap(), c.len, "{}", c.name);
        assert_eq!(row[4] == "yes", c.effect, "{}", c.name);
        let reply = match c.reply {
            code::ACK => "ACK",
            code::IDENTITY => "IDENTITY",
            code::STATUS => "STATUS",
            code::STATE => "STATE",
            code::CONFIG => "CONFIG",
            other => panic!("reply code {other:#x}"),
        };
        assert_eq!(row[5], reply, "{}", c.name);
    }
}

#[test]
fn the_reply_table_is_the_protocols() {
    let rows = table(&doc(), "| code | reply | LEN | payload |");
    let want = [
        (code::IDENTITY, "IDENTITY", Identity::BYTES),
        (code::STATUS, "STATUS", Status::BYTES),
        (code::STATE, "STATE", StateReply::BYTES),
        (code::CONFIG, "CONFIG", payload_bytes(&CONFIG_FIELDS)),
        (code::ACK, "ACK", 1),
        (code::NAK, "NAK", 2),
        (code::TELEMETRY, "TELEMETRY", Status::BYTES),
    ];
    assert_eq!(rows.len(), want.len());
    for (row, (c, name, len)) in rows.iter().zip(want) {
        assert_eq!(
            (
                hex_u8(&row[0]),
                row[1].as_str(),
                row[2].parse::<usize>().unwrap()
            ),
            (c, name, len)
        );
    }
    // The frame is the device's, with its maximum payload.
    assert!(doc().contains(&format!("A device takes at most **{DEVICE_MAX_PAYLOAD}**")));
    assert!(doc().contains(&format!("up to **{REPLY_QUEUE}** replies")));
    assert!(doc().contains(&format!("protocol, version {PROTOCOL_VERSION}")));
}

#[test]
fn reasons_states_errors_and_flags_are_the_protocols() {
    let d = doc();
    let check = |header: &str, want: Vec<(u64, &str)>| {
        let rows = table(&d, header);
        let got: Vec<(u64, String)> = rows
            .iter()
            .map(|r| (r[0].parse().unwrap(), r[1].clone()))
            .collect();
        let want: Vec<(u64, String)> = want.into_iter().map(|(v, n)| (v, n.to_string())).collect();
        assert_eq!(got, want, "{header}");
    };
    check(
        "| value | reason | meaning |",
        REASONS.iter().map(|(r, n)| (*r as u64, *n)).collect(),
    );
    check(
        "| value | state | meaning |",
        STATES.iter().map(|(s, n)| (*s as u64, *n)).collect(),
    );
    check(
        "| value | error | cause |",
        ERRORS.iter().map(|(e, n)| (*e as u64, *n)).collect(),
    );
    check(
        "| bit | flag | meaning |",
        flag::ALL
            .iter()
            .map(|(b, n)| (u64::from(b.trailing_zeros()), *n))
            .collect(),
    );
}

#[test]
fn the_refusal_table_is_the_protocols() {
    let rows = table(&doc(), "| command | refused with | when |");
    assert_eq!(rows.len(), REFUSALS.len());
    for (row, r) in rows.iter().zip(REFUSALS) {
        let reasons: Vec<&str> = r.reasons.iter().map(|x| x.name()).collect();
        assert_eq!(
            (row[0].as_str(), row[1].as_str(), row[2].replace('`', "")),
            (
                r.command,
                reasons.join(", ").as_str(),
                r.when.replace('`', "")
            ),
        );
    }
}

#[test]
fn parameters_defaults_and_maxima_are_the_protocols() {
    let rows = table(
        &doc(),
        "| param | name | default | maximum | set | meaning |",
    );
    assert_eq!(rows.len(), PARAMS.len());
    // The defaults after reset, for a design generated with tick divider 1249.
    let reset = Config::after_reset(1249, 0);
    for (row, (p, name)) in rows.iter().zip(PARAMS) {
        assert_eq!(row[0].parse::<u8>().unwrap(), p as u8, "{row:?}");
        assert_eq!(row[1], name);
        let default = if row[2] == "the design's" {
            assert!(
                matches!(p, Param::TickDivider | Param::InputPolarity),
                "{name}"
            );
            reset.get(p)
        } else {
            row[2].parse::<i128>().unwrap()
        };
        let set = match p.settable() {
            Settable::Always => "any time",
            Settable::AtRest => "at rest",
            Settable::Disabled => "Disabled",
        };
        assert_eq!(row[4], set, "{name}");
        assert_eq!(default, reset.get(p), "{name}");
        let max = match row[3]
            .strip_prefix("2^")
            .and_then(|r| r.strip_suffix(" − 1"))
        {
            Some(k) => (1i128 << k.parse::<u32>().unwrap()) - 1,
            None => row[3].parse().unwrap(),
        };
        assert_eq!(max, p.max(), "{name}");
    }
}

#[test]
fn payload_layouts_are_the_protocols() {
    let d = doc();
    let header = "| offset | bytes | field | meaning |";
    for (heading, fields) in [
        ("### Identity", &IDENTITY_FIELDS[..]),
        ("### Status block", &STATUS_FIELDS[..]),
        ("### Registers", &STATE_FIELDS[..]),
        ("### Parameter value", &CONFIG_FIELDS[..]),
    ] {
        let rows = table_after(&d, heading, header);
        let got: Vec<(usize, usize, &str)> = rows
            .iter()
            .map(|r| (r[0].parse().unwrap(), r[1].parse().unwrap(), r[2].as_str()))
            .collect();
        let want: Vec<(usize, usize, &str)> =
            fields.iter().map(|f| (f.offset, f.bytes, f.name)).collect();
        assert_eq!(got, want, "{heading}");
    }
}

/// CRC-16/CCITT-FALSE, table-driven (a second implementation beside the model's bitwise one).
fn crc_table_driven(data: &[u8]) -> u16 {
    let mut table = [0u16; 256];
    for (i, t) in table.iter_mut().enumerate() {
        let mut c = (i as u16) << 8;
        for _ in 0..8 {
            c = if c & 0x8000 != 0 {
                (c << 1) ^ 0x1021
            } else {
                c << 1
            };
        }
        *t = c;
    }
    data.iter().fold(0xFFFF, |crc: u16, &b| {
        (crc << 8) ^ table[usize::from((crc >> 8) as u8 ^ b)]
    })
}

/// The frames of the worked examples, as the model encodes them.
fn examples() -> Vec<Vec<u8>> {
    let f = DEFAULT_FORMAT;
    let c = |c: Command, s: u8| c.to_frame(s, &f).to_bytes();
    let r = |r: Reply, s: u8| r.to_frame(s).to_bytes();
    let jerk = 120_892_581_961_462_917i128;
    vec![
        c(Command::Ping, 1),
        r(
            Reply::Identity(Identity {
                protocol: PROTOCOL_VERSION,
                design_hash: 0x1234_ABCD,
                clock_hz: 125_000_000,
                baud: 115_207,
                tick_divider: 1249,
                widths: [112, 104, 104, 104, 104],
                frac_bits: 80,
                tick_bits: 32,
                max_segments: 32,
                snap_bytes: 13,
                stop: StopLimits {
                    jerk,
                    accel: 60_446_290_980_731_458_735_309,
                },
            }),
            1,
        ),
        c(
            Command::Configure {
                param: Param::StopJerk,
                value: jerk,
            },
            2,
        ),
        r(
            Reply::Ack {
                cmd: code::CONFIGURE,
            },
            2,
        ),
        c(
            Command::ReadConfig {
                param: Param::StopJerk,
            },
            3,
        ),
        r(
            Reply::Config {
                param: Param::StopJerk,
                value: jerk,
            },
            3,
        ),
        c(Command::Power { on: true }, 4),
        c(
            Command::LoadSegment {
                index: 2,
                segment: Segment {
                    ticks: 5000,
                    snap: -12_089_258_196_146,
                },
            },
            7,
        ),
        c(Command::Commit { count: 15 }, 8),
        c(Command::Start, 9),
        r(Reply::Ack { cmd: code::START }, 9),
        r(
            Reply::Nak {
                cmd: code::START,
                reason: Reason::NoProgram,
            },
            9,
        ),
        c(Command::ReadStatus, 11),
        r(
            Reply::Status(Status {
                state: AxisState::Standstill as u8,
                error: 0,
                flags: flag::DONE | flag::AMPLIFIER,
                tick_count: 85_000,
                position: 500_000,
                velocity: 0,
                encoder: 500_000,
                bad_crc: 0,
                bad_frames: 1,
                following_peak: 3 << 16,
                duty: 12,
            }),
            11,
        ),
        c(Command::Stop, 12),
        c(Command::Halt, 13),
        c(Command::ReadState, 14),
        r(
            Reply::State(StateReply {
                ticks: 1_234_567,
                x: (500_000i128 << 80) + (1i128 << 79),
                v: 0,
                a: 0,
                j: 0,
            }),
            14,
        ),
        c(Command::Reset, 15),
        c(
            Command::Configure {
                param: Param::TickDivider,
                value: 1249,
            },
            16,
        ),
        c(
            Command::Configure {
                param: Param::TelemetryPeriod,
                value: 100,
            },
            17,
        ),
        r(
            Reply::Telemetry(Status {
                state: AxisState::DiscreteMotion as u8,
                error: 0,
                flags: flag::PLAYING | flag::AMPLIFIER,
                tick_count: 40_000,
                position: 235_702,
                velocity: 123_456,
                encoder: 235_700,
                bad_crc: 0,
                bad_frames: 0,
                following_peak: 0x0002_8000,
                duty: -40,
            }),
            0,
        ),
        r(
            Reply::Nak {
                cmd: 0,
                reason: Reason::BadCrc,
            },
            0,
        ),
        c(Command::SwapAt { tick: 1_301_000 }, 18),
        r(Reply::Ack { cmd: code::SWAP_AT }, 18),
        r(
            Reply::Nak {
                cmd: code::SWAP_AT,
                reason: Reason::Late,
            },
            19,
        ),
    ]
}

/// Every frame written in the examples' code block (runs of hex bytes from `A5`).
fn documented_frames(doc: &str) -> Vec<Vec<u8>> {
    let at = doc.find("## Worked examples").expect("the examples");
    let block = doc[at..].split("```").nth(1).expect("a code block");
    block
        .lines()
        .filter_map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            let start = words.iter().position(|w| *w == "A5")?;
            let bytes: Vec<u8> = words[start..]
                .iter()
                .map(|w| u8::from_str_radix(w, 16).unwrap_or_else(|_| panic!("{w:?} in {l:?}")))
                .collect();
            Some(bytes)
        })
        .collect()
}

#[test]
fn every_worked_example_is_the_models_frame_with_a_good_crc() {
    let documented = documented_frames(&doc());
    let want = examples();
    assert_eq!(documented.len(), want.len(), "examples on the page");
    for (got, want) in documented.iter().zip(&want) {
        assert_eq!(got, want);
        let n = got.len();
        assert_eq!(got[1] as usize, n - 6, "LEN");
        assert_eq!(
            u16::from_le_bytes([got[n - 2], got[n - 1]]),
            crc_table_driven(&got[1..n - 2])
        );
    }
    assert_eq!(crc_table_driven(b"123456789"), 0x29B1);
}

/// The stop unit's timing the page states is the microprogram's.
#[test]
fn the_stop_timing_on_the_page_is_the_stop_units() {
    let d = doc();
    let c = snapgen_model::stop::phase_clocks();
    let prep = (f64::from(c.prep) / 10.0).round() as u32 * 10;
    assert!(
        d.contains(&format!("about {prep} clocks while the move plays on")),
        "prep {}",
        c.prep
    );
    assert!(
        d.contains(&format!("(a tick divider below {})", c.decide)),
        "decide {}",
        c.decide
    );
    assert!(d.contains(&format!("in about {} clocks", c.decide + 1)));
}

/// docs/MODEL.md's table of the stop unit's phases is the microprogram's.
#[test]
fn the_stop_phases_in_model_md_are_the_microprograms() {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/MODEL.md");
    let d = std::fs::read_to_string(p).unwrap();
    let rows = table(&d, "| phase | clocks | when |");
    let c = snapgen_model::stop::phase_clocks();
    let got: Vec<(String, u32)> = rows
        .iter()
        .map(|r| (r[0].clone(), r[1].parse().unwrap()))
        .collect();
    assert_eq!(
        got,
        [
            ("Prep".to_string(), c.prep),
            ("Init".to_string(), c.init),
            ("Decide".to_string(), c.decide)
        ]
    );
}
