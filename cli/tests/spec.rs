//! `snapgen spec --emit`: the files for users' firmware and tools. The C header compiles
//! without a warning and, in C, checks every worked example frame of docs/PROTOCOL.md with
//! its own CRC and lengths (a corrupted frame is caught); the JSON description decodes a
//! CONFIG reply as a tool would, by its layout alone.

use std::path::{Path, PathBuf};
use std::process::Command;

use snapgen_spec::codes::{COMMANDS, REPLIES};
use snapgen_spec::emit::{examples, FILE_NAMES};

mod common;
use common::snapgen_ok;

fn emit() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snapgen-spec-test-{}", std::process::id()));
    snapgen_ok(&["spec", "--emit", dir.to_str().unwrap()]);
    for name in FILE_NAMES {
        assert!(dir.join(name).is_file(), "{name} not written");
    }
    dir
}

/// A C program over the header: every example frame checked (start byte, length against the
/// command's or reply's, CRC), the CRC's check value, the layouts' sizes against the lengths.
fn c_program(frames: &[(String, Vec<u8>)]) -> String {
    let mut s = String::from(
        "#include <stdio.h>\n#include \"snapgen_protocol.h\"\n\n\
         _Static_assert(SNAPGEN_STATUS_BYTES == SNAPGEN_REPLY_STATUS_LEN, \"status\");\n\
         _Static_assert(SNAPGEN_IDENTITY_BYTES == SNAPGEN_REPLY_IDENTITY_LEN, \"identity\");\n\
         _Static_assert(SNAPGEN_STATE_BYTES == SNAPGEN_REPLY_STATE_LEN, \"state\");\n\
         _Static_assert(SNAPGEN_CONFIG_BYTES == SNAPGEN_REPLY_CONFIG_LEN, \"config\");\n\
         _Static_assert(SNAPGEN_LOAD_SEGMENT_BYTES == SNAPGEN_CMD_LOAD_SEGMENT_LEN, \"segment\");\n\n\
         static int expected_len(unsigned code)\n{\n    switch (code) {\n",
    );
    for c in COMMANDS {
        s.push_str(&format!(
            "    case SNAPGEN_CMD_{0}: return SNAPGEN_CMD_{0}_LEN;\n",
            c.name
        ));
    }
    for r in REPLIES {
        s.push_str(&format!(
            "    case SNAPGEN_REPLY_{0}: return SNAPGEN_REPLY_{0}_LEN;\n",
            r.name
        ));
    }
    s.push_str("    default: return -1;\n    }\n}\n\n");
    s.push_str(
        "static int check(const char *name, const uint8_t *f, size_t n)\n{\n\
         \x20   if (n < SNAPGEN_FRAME_OVERHEAD || f[0] != SNAPGEN_FRAME_START) { printf(\"%s: start\\n\", name); return 1; }\n\
         \x20   if ((size_t)f[1] + SNAPGEN_FRAME_OVERHEAD != n) { printf(\"%s: length\\n\", name); return 1; }\n\
         \x20   if (expected_len(f[2]) != f[1]) { printf(\"%s: payload length\\n\", name); return 1; }\n\
         \x20   uint16_t crc = snapgen_crc16(f + 1, n - 3);\n\
         \x20   if (f[n - 2] != (crc & 0xFFu) || f[n - 1] != (crc >> 8)) { printf(\"%s: crc\\n\", name); return 1; }\n\
         \x20   return 0;\n}\n\nint main(void)\n{\n    int bad = 0;\n\
         \x20   if (snapgen_crc16((const uint8_t *)\"123456789\", 9) != SNAPGEN_CRC_CHECK) { puts(\"crc check\"); bad++; }\n",
    );
    for (k, (name, bytes)) in frames.iter().enumerate() {
        let list: Vec<String> = bytes.iter().map(|b| format!("0x{b:02X}")).collect();
        s.push_str(&format!(
            "    {{ static const uint8_t f{k}[] = {{{}}}; bad += check(\"{name}\", f{k}, sizeof f{k}); }}\n",
            list.join(", ")
        ));
    }
    s.push_str("    return bad != 0;\n}\n");
    s
}

/// Compiles and runs `program` beside the header in `dir`: whether it passed, and its output.
fn compile_and_run(dir: &Path, program: &str, name: &str) -> (bool, String) {
    let src = dir.join(format!("{name}.c"));
    let exe = dir.join(name);
    std::fs::write(&src, program).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args([
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-I",
        ])
        .arg(dir)
        .arg(&src)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("{cc}: {e} (a C compiler is needed, as for linking Rust)"));
    assert!(
        out.status.success(),
        "the header does not compile cleanly:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    (
        run.status.success(),
        String::from_utf8_lossy(&run.stdout).into_owned(),
    )
}

#[test]
fn the_c_header_compiles_and_checks_every_example_frame() {
    let dir = emit();
    let frames = examples::frames();
    assert!(frames.len() >= 10);
    let (ok, out) = compile_and_run(&dir, &c_program(&frames), "frames");
    assert!(ok, "{out}");
    // The same program with one payload bit flipped in one frame fails on its CRC.
    let mut bad = frames.clone();
    let f = bad.iter_mut().find(|(_, b)| b.len() > 8).unwrap();
    f.1[5] ^= 0x10;
    let (ok, out) = compile_and_run(&dir, &c_program(&bad), "frames_bad");
    assert!(!ok && out.contains(": crc"), "{out}");
}

#[test]
fn the_json_decodes_a_config_reply_by_its_layout() {
    let dir = emit();
    let text = std::fs::read_to_string(dir.join("snapgen_protocol.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (label, frame) = examples::frames()
        .into_iter()
        .find(|(l, _)| l.starts_with("CONFIG "))
        .expect("a CONFIG example");
    // The reply by its code, its payload by the layout's offsets and sizes.
    let reply = doc["replies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["code"] == u64::from(frame[2]))
        .expect("the reply's code");
    assert_eq!(reply["name"], "CONFIG");
    assert_eq!(reply["len"], u64::from(frame[1]));
    let payload = &frame[4..frame.len() - 2];
    let field = |name: &str| -> i128 {
        let f = reply["payload"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == name)
            .unwrap_or_else(|| panic!("no field {name}"));
        let (at, n) = (
            f["offset"].as_u64().unwrap() as usize,
            f["bytes"].as_u64().unwrap() as usize,
        );
        let mut v: i128 = 0;
        for k in (0..n).rev() {
            v = (v << 8) | i128::from(payload[at + k]);
        }
        if f["signed"] == true && n < 16 && payload[at + n - 1] & 0x80 != 0 {
            v -= 1i128 << (8 * n);
        }
        v
    };
    let code = field("param");
    let param = doc["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["code"] == code as u64)
        .expect("the parameter's code");
    // The label says "CONFIG NAME VALUE, seq N".
    let mut words = label.split([' ', ',']);
    let (_, name, value) = (words.next(), words.next().unwrap(), words.next().unwrap());
    assert_eq!(param["name"], name);
    assert_eq!(field("value").to_string(), value);
}

/// `--update-docs` rewrites the pages' generated blocks (a table row added by hand is taken
/// out again) and leaves up-to-date pages as they are.
#[test]
fn update_docs_restores_a_generated_table() {
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/PROTOCOL.md");
    let good = std::fs::read_to_string(&page).unwrap();
    let start = good.find("<!-- spec:").expect("a generated block");
    let row = start + good[start..].find("\n|").unwrap() + 1;
    let dir = emit();
    let copy = dir.join("PROTOCOL.md");
    let mut edited = good.clone();
    edited.insert_str(row, "| edited by hand |\n");
    std::fs::write(&copy, &edited).unwrap();
    for other in ["BOARDS.md", "AXI.md"] {
        let page = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../docs")
            .join(other);
        std::fs::copy(&page, dir.join(other)).unwrap();
    }
    let run = || {
        let out = snapgen_ok(&["spec", "--update-docs", "--docs", dir.to_str().unwrap()]);
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let first = run();
    assert!(
        first.contains("updated") && first.contains("PROTOCOL.md"),
        "{first}"
    );
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), good);
    assert_eq!(run().matches("is up to date").count(), 3);
}
