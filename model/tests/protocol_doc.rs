//! docs/PROTOCOL.md (and BOARDS.md's pin table) against the contract (`snapgen_spec`): every
//! table and the worked examples on the page are generated between markers, and the page must
//! be what the generator writes (`SNAPGEN_BLESS=1 cargo test -p snapgen-model --test protocol_doc`
//! rewrites it; `snapgen spec --update-docs` does the same). The examples' CRCs are checked with
//! a second, table-driven CRC, and the numbers the prose states are the contract's.

use snapgen_spec::emit::markdown;
use snapgen_spec::rules::REPLY_QUEUE;
use snapgen_spec::wire::{DEVICE_MAX_PAYLOAD, PROTOCOL_VERSION};

fn path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs")
        .join(name)
}

fn doc() -> String {
    let p = path("PROTOCOL.md");
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

/// Each page with generated blocks is what the contract writes into it; the protocol page
/// holds every block but the board's pins, which BOARDS.md holds.
#[test]
fn the_pages_are_what_the_contract_generates() {
    for name in markdown::PAGES {
        let page = std::fs::read_to_string(path(name)).unwrap();
        let want = markdown::update(&page, &snapgen_model::spec_facts())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        if std::env::var_os("SNAPGEN_BLESS").is_some() {
            std::fs::write(path(name), &want).unwrap();
            continue;
        }
        if page != want {
            let line = page
                .lines()
                .zip(want.lines())
                .position(|(a, b)| a != b)
                .unwrap_or(page.lines().count().min(want.lines().count()));
            panic!(
                "docs/{name} differs from the contract from line {}: regenerate it with \
                 `snapgen spec --update-docs` (or SNAPGEN_BLESS=1)\n page: {:?}\n want: {:?}",
                line + 1,
                page.lines().nth(line),
                want.lines().nth(line)
            );
        }
    }
    let protocol = doc();
    let boards = std::fs::read_to_string(path("BOARDS.md")).unwrap();
    let axi = std::fs::read_to_string(path("AXI.md")).unwrap();
    for b in markdown::BLOCKS {
        let marker = format!("<!-- spec:{b} -->");
        let page = match b {
            "board_pins" => &boards,
            "axi_registers" => &axi,
            _ => &protocol,
        };
        assert!(page.contains(&marker), "no {b} block");
    }
}

#[test]
fn the_numbers_in_the_prose_are_the_contracts() {
    let d = doc();
    assert!(d.contains(&format!("A device takes at most **{DEVICE_MAX_PAYLOAD}**")));
    assert!(d.contains(&format!("up to **{REPLY_QUEUE}** replies")));
    assert!(d.contains(&format!("protocol, version {PROTOCOL_VERSION}")));
}

/// A CRC-16/CCITT-FALSE computed another way (a 256-entry table).
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

#[test]
fn every_worked_example_has_its_length_and_a_good_crc() {
    let frames = snapgen_spec::emit::examples::frames();
    assert!(frames.len() > 20);
    for (label, f) in frames {
        let n = f.len();
        assert_eq!(f[0], 0xA5, "{label}");
        assert_eq!(usize::from(f[1]), n - 6, "LEN of {label}");
        assert_eq!(
            u16::from_le_bytes([f[n - 2], f[n - 1]]),
            crc_table_driven(&f[1..n - 2]),
            "{label}"
        );
    }
    assert_eq!(crc_table_driven(b"123456789"), 0x29B1);
    // Two frames by hand (the page reads them byte by byte).
    let d = doc();
    assert!(d.contains("PING, seq 1                                    A5 00 01 01 8C EF"));
    assert!(d.contains("A5 12 02 07 02 88 13 00 00 4E 43 0F 40 01 F5 FF FF FF FF FF FF FF 15 3C"));
}

/// The stop unit's timing the page states is the microprogram's.
#[test]
fn the_stop_timing_on_the_page_is_the_stop_units() {
    let d = doc();
    let c = snapgen_model::stop::phase_clocks();
    let tens = |n: u32| (f64::from(n) / 10.0).round() as u32 * 10;
    assert!(
        d.contains(&format!(
            "about {} clocks from the request, while the move plays on",
            tens(c.prep)
        )),
        "prep {}",
        c.prep
    );
    assert!(
        d.contains(&format!(
            "about {} clocks compute where the law begins",
            tens(c.init)
        )),
        "init {}",
        c.init
    );
    assert!(
        d.contains(&format!(
            "at most about {} clocks after the tick that took the stop",
            tens(c.init + c.decide)
        )),
        "init + decide {}",
        c.init + c.decide
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
