//! The `snapgen` binary: JSON fields, trace and plot files, and exit codes for bad input.

use std::path::PathBuf;

mod common;
use common::{assert_ok, snapgen};

fn tmp(name: &str) -> PathBuf {
    common::tmp("cli-test", name)
}

const ORDER4: &[&str] = &[
    "--distance",
    "0.5",
    "--vmax",
    "1",
    "--amax",
    "5",
    "--jmax",
    "50",
    "--dmax",
    "1000",
];

#[test]
fn plan_json_has_every_field() {
    let mut args = vec!["plan", "--json"];
    args.extend_from_slice(ORDER4);
    let out = snapgen(&args);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "order",
        "ts",
        "ticks_total",
        "duration_s",
        "phase_ticks",
        "segments",
        "peak",
        "final",
        "target",
        "final_position_error",
        "position_lsb",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["order"], 4);
    assert_eq!(v["ticks_total"], 85_000);
    assert_eq!(
        v["phase_ticks"],
        serde_json::json!({"d": 5000, "j": 5000, "a": 5000, "v": 15000})
    );
    assert_eq!(v["final"]["x"], 0.5);
    assert_eq!(v["final"]["v"], 0.0);
    assert_eq!(v["final_error_lsb"], 0);
    assert_eq!(v["segments"].as_array().unwrap().len(), 15);
    let ticks: u64 = v["segments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["ticks"].as_u64().unwrap())
        .sum();
    assert_eq!(ticks, 85_000);
    assert!(v["peak"]["v"].as_f64().unwrap() <= 1.0);
    assert!(v["peak"]["d"].as_f64().unwrap() <= 1000.0);
}

#[test]
fn seed001_json_reproduces_table_1() {
    let out = snapgen(&[
        "plan",
        "--json",
        "--distance",
        "37.69911184307752",
        "--duration",
        "1.8",
        "--gamma",
        "0.4",
        "--phi",
        "0.25",
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t4 = |k: &str| (v[k].as_f64().unwrap() * 1e4).trunc() / 1e4;
    assert_eq!(t4("velocity"), 34.9065);
    assert_eq!(t4("acceleration"), 64.6418);
    assert_eq!(t4("jerk"), 359.1212);
    assert_eq!(t4("t_acc"), 0.72);
    assert_eq!(t4("t_jerk"), 0.18);
    assert_eq!(
        v["phase_ticks"],
        serde_json::json!({"j": 18000, "a": 36000, "v": 36000})
    );
}

#[test]
fn trace_writes_one_row_per_tick() {
    let csv = tmp("trace.csv");
    let out = snapgen(&[
        "trace",
        "--order",
        "2",
        "--distance",
        "-0.001",
        "--vmax",
        "1",
        "--amax",
        "100",
        "--ts",
        "1e-3",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "tick,time_s,segment,x,v,a,j,d,x_raw,v_raw,a_raw,j_raw,d_raw"
    );
    let last: Vec<&str> = lines.last().unwrap().split(',').collect();
    // Ends at rest, one LSB-exact millimetre back.
    assert_eq!(last[9..12], ["0", "0", "0"]);
    let x: f64 = last[3].parse().unwrap();
    assert!((x + 0.001).abs() < 1e-9, "{x}");
    let ticks: usize = last[0].parse().unwrap();
    assert_eq!(lines.len(), ticks + 2);
}

#[test]
fn plot_writes_an_svg() {
    let svg = tmp("plot.svg");
    let mut args = vec!["plot", "--svg", svg.to_str().unwrap()];
    args.extend_from_slice(ORDER4);
    let out = snapgen(&args);
    assert_ok(&out);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"));
    for label in ["position", "velocity", "acceleration", "jerk", "snap"] {
        assert!(text.contains(label), "no {label} panel");
    }
}

#[test]
fn bad_input_exits_2_with_a_message() {
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "plan",
                "--distance",
                "nan",
                "--vmax",
                "1",
                "--amax",
                "1",
                "--jmax",
                "1",
                "--dmax",
                "1",
            ],
            "distance = NaN is not a finite number",
        ),
        (
            &[
                "plan",
                "--distance",
                "1",
                "--vmax",
                "inf",
                "--amax",
                "1",
                "--jmax",
                "1",
                "--dmax",
                "1",
            ],
            "vmax = inf is not a finite number",
        ),
        (
            &[
                "plan",
                "--distance",
                "1",
                "--vmax",
                "-1",
                "--amax",
                "1",
                "--jmax",
                "1",
                "--dmax",
                "1",
            ],
            "vmax = -1 must be greater than 0",
        ),
        (
            &[
                "plan",
                "--distance",
                "1",
                "--vmax",
                "1",
                "--amax",
                "1",
                "--jmax",
                "1",
                "--dmax",
                "1",
                "--ts",
                "0",
            ],
            "Ts = 0 s is invalid",
        ),
        (
            &[
                "plan",
                "--distance",
                "1",
                "--vmax",
                "1",
                "--amax",
                "1",
                "--jmax",
                "1",
            ],
            "order 4 needs --dmax",
        ),
        (
            &[
                "plan",
                "--order",
                "2",
                "--distance",
                "1",
                "--vmax",
                "1",
                "--amax",
                "1",
                "--jmax",
                "1",
            ],
            "--jmax is not used by order 2",
        ),
        (
            &[
                "plan",
                "--distance",
                "1",
                "--duration",
                "1",
                "--gamma",
                "0.6",
                "--phi",
                "0.2",
            ],
            "gamma = 0.6 is outside its range",
        ),
        (
            &[
                "plan",
                "--distance",
                "1e9",
                "--vmax",
                "1",
                "--amax",
                "1",
                "--jmax",
                "1",
                "--dmax",
                "1",
            ],
            "outside the format's position range",
        ),
        (
            &[
                "plan",
                "--order",
                "2",
                "--distance",
                "1000",
                "--vmax",
                "1e-3",
                "--amax",
                "1",
            ],
            "more than the format allows",
        ),
        (
            &["plan", "--order", "5", "--distance", "1"],
            "5 is not in 2..=4",
        ),
    ];
    for (args, msg) in cases {
        let out = snapgen(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(msg), "{args:?}: {err:?} lacks {msg:?}");
    }
}

#[test]
fn zero_distance_is_fine() {
    let out = snapgen(&[
        "plan",
        "--json",
        "--distance",
        "0",
        "--vmax",
        "1",
        "--amax",
        "1",
        "--jmax",
        "1",
        "--dmax",
        "1",
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["ticks_total"], 0);
    assert_eq!(v["segments"], serde_json::json!([]));
}

#[test]
fn cosim_bench_prints_medians_and_the_ratio() {
    let out = snapgen(&[
        "cosim",
        "--moves",
        "12",
        "--seed",
        "3",
        "--sessions",
        "1",
        "--bench",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    assert!(stdout.contains(", 0 mismatches"), "{stdout}");
    // "... 5 runs: median A, best B M ticks/s ...": positive, best at least the median.
    let numbers = |prefix: &str| -> (f64, f64) {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no line {prefix:?} in {stdout}"));
        let after = |key: &str| -> f64 {
            let rest = &line[line.find(key).unwrap() + key.len()..];
            rest.split([',', ' ']).next().unwrap().parse().unwrap()
        };
        (after("median "), after("best "))
    };
    for prefix in ["bench, co-simulation, 5 runs", "bench, model alone"] {
        let (median, best) = numbers(prefix);
        assert!(median > 0.0 && best >= median, "{prefix}: {stdout}");
    }
    assert!(
        stdout.contains("bench, co-sim / model throughput ratio (medians): "),
        "{stdout}"
    );
}

#[test]
fn cosim_bench_refuses_waves() {
    let out = snapgen(&["cosim", "--moves", "1", "--bench", "--vcd", "x.vcd"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--vcd"));
}

/// `experiment seed001 --json` (on the fast loop: the fabric's run is the demo's and
/// `sim/tests/closed_loop.rs`'): stdout is one JSON object with a figure set per profile, the
/// plots are written, and the figures are the motor's, not the plan's: the trapezoid's shaft
/// reaches about its 32 rad/s, the S-curve's its higher peak, the loop tracks within a few
/// counts, and every reference lands exactly.
#[test]
fn experiment_json_reports_every_profile() {
    let dir = tmp("seed001");
    let out = snapgen(&[
        "experiment",
        "seed001",
        "--board",
        "fast",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON only");
    assert!(v["mismatches"].is_null(), "the fast loop has no fabric");
    let profiles = v["profiles"].as_array().unwrap();
    let names: Vec<&str> = profiles
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["scurve", "trapezoid", "order4", "return"]);
    let num = |p: &serde_json::Value, k: &str| p[k].as_f64().unwrap_or_else(|| panic!("{k}"));
    for p in profiles {
        assert_eq!(p["landed_exactly"], true, "{p}");
        assert!(p["settle_s"].is_number() || p["settle_s"].is_null());
        // Within 0.05 rad all the way (64 counts), and a control effort below the supply.
        assert!(num(p, "peak_error_rad") < 0.05, "{p}");
        assert!(num(p, "error_at_t_rad").abs() <= num(p, "peak_error_rad"));
        assert!((0.5..48.0).contains(&num(p, "peak_effort")), "{p}");
    }
    let trapezoid = num(&profiles[1], "peak_velocity");
    assert!((31.0..34.0).contains(&trapezoid), "{trapezoid}");
    // The S-curve of Table 1 peaks at 12π/1.8/(1 − γ) = 34.9 rad/s.
    assert!(num(&profiles[0], "peak_velocity") > trapezoid);
    assert_eq!(
        v["loops"].as_array().unwrap().len(),
        3,
        "fabric rate and the 5 ms host loop"
    );
    for svg in [
        "fig12-scurve.svg",
        "fig10-trapezoid.svg",
        "order4.svg",
        "fig15-return.svg",
    ] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(text.starts_with("<svg") && text.contains("</svg>"), "{svg}");
    }
}

/// `experiment seed001 --mismatch` (fast loop): the nominal plant first, then the cases given,
/// two profiles each, with the shaft's error and the trip flag; a bad case is refused (exit 2)
/// with what to change.
#[test]
fn experiment_mismatch_reports_each_case() {
    let out = snapgen(&[
        "experiment",
        "seed001",
        "--board",
        "fast",
        "--json",
        "--short",
        "--mismatch",
        "r=1.4,friction=2",
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON only");
    let cases = v["cases"].as_array().unwrap();
    let names: Vec<&str> = cases.iter().map(|c| c["case"].as_str().unwrap()).collect();
    assert_eq!(names, ["nominal", "R +40 %, friction ×2"]);
    for c in cases {
        for p in c["profiles"].as_array().unwrap() {
            assert_eq!(
                (&p["tripped"], &p["landed_exactly"]),
                (&false.into(), &true.into()),
                "{p}"
            );
            // The shaft's own error is reported beside the encoder's.
            assert!(p["shaft_error_at_t_rad"].is_number(), "{p}");
            assert!(p["rms_error_rad"].as_f64().unwrap() <= p["peak_error_rad"].as_f64().unwrap());
        }
    }
    let bad = snapgen(&[
        "experiment",
        "seed001",
        "--board",
        "fast",
        "--mismatch",
        "r=-1",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("give a factor from 0.1 to 10"));
}

/// `gains` prints the CONFIGURE values derived from the plant, and refuses a bad design or a
/// broken plant file with exit 2 and what to change.
#[test]
fn gains_prints_configure_values_and_refuses_bad_designs() {
    let out = snapgen(&["gains", "--json"]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let c = &v["configure"];
    for k in [
        "SERVO_PERIOD",
        "KP",
        "KI",
        "KD",
        "KV",
        "KA",
        "INTEGRAL_LIMIT",
        "OUTPUT_LIMIT",
        "FOLLOWING_LIMIT",
        "D_FILTER",
        "PWM_PERIOD",
    ] {
        assert!(c[k].is_u64(), "{k}: {c}");
    }
    // Kv = 1/K V per rad/s: K is the data sheet's 158 rpm/V in rad/s.
    let k = v["plant"]["k_rad_per_s_per_v"].as_f64().unwrap();
    assert!((k / (158.0 * 2.0 * std::f64::consts::PI / 60.0) - 1.0).abs() < 1e-9);
    assert!((v["volts"]["kv"].as_f64().unwrap() * k - 1.0).abs() < 1e-12);
    let out = snapgen(&["gains", "--damping", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("damping"));
    let broken = tmp("broken-motor.toml");
    std::fs::write(&broken, "[motor]\nname = \"x\"\n").unwrap();
    let out = snapgen(&["gains", "--motor", broken.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken-motor.toml"));
}

const SCRIPT: &str = r#"
order = 3
[[event]]
at_ms = 0
kind = "move_absolute"
position = 3.0
velocity = 100.0
acceleration = 4000.0
deceleration = 3000.0
jerk = 500000.0
[[event]]
at_ms = 0
kind = "move_absolute"
position = 5.0
velocity = 60.0
acceleration = 4000.0
deceleration = 3000.0
jerk = 500000.0
buffer_mode = "blending_low"
[[event]]
at_ms = 20
override = 0.5
"#;

#[test]
fn online_plays_a_script_and_reports_every_field() {
    let script = tmp("script.toml");
    std::fs::write(&script, SCRIPT).unwrap();
    let (csv, svg) = (tmp("online.csv"), tmp("online.svg"));
    let out = snapgen(&[
        "online",
        "--script",
        script.to_str().unwrap(),
        "--baud",
        "3000000",
        "--json",
        "--csv",
        csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let outcomes: Vec<&str> = j["commands"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["outcome"].as_str().unwrap())
        .collect();
    assert_eq!(outcomes, ["Done", "Done"]);
    // The override: taken, with its latency (at 3 Mbaud its own upload, and here the one it
    // waited for: the blend's, still on the wire).
    let overrides = j["overrides"].as_array().unwrap();
    assert_eq!(overrides.len(), 1);
    assert_eq!(overrides[0]["event"], 2);
    assert_eq!(overrides[0]["factor"], 0.5);
    assert!(overrides[0]["error_id"].is_null());
    let ms = overrides[0]["latency_ms"].as_f64().unwrap();
    assert!(ms > 0.0 && ms < 10.0, "override latency {ms} ms");
    // Its due tick and the tick of the swap that realised it: the latency between them.
    let (due, swap) = (
        overrides[0]["due_tick"].as_u64().unwrap(),
        overrides[0]["swap_tick"].as_u64().unwrap(),
    );
    assert!(swap > due);
    let ts = j["ts"].as_f64().unwrap();
    assert!(((swap - due) as f64 * ts * 1e3 - ms).abs() < 1e-9);
    assert!(j["refused_overrides"].as_array().unwrap().is_empty());
    assert!(j["replans"].as_u64().unwrap() >= 1);
    assert_eq!(j["final_lsb"], j["target_lsb"]);
    assert_eq!(j["target_lsb"].as_i64(), Some(5_000_000));
    assert_eq!(j["final_raw"]["v"], "0");
    assert!(j["mismatches"].is_null(), "the model board has no fabric");
    // One row per tick from the script's first state to the last one read, and the last row
    // is the final register.
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows[0], "tick,x,v,a,j,position_lsb");
    let first: Vec<&str> = rows[1].split(',').collect();
    let last: Vec<&str> = rows.last().unwrap().split(',').collect();
    let span = last[0].parse::<u64>().unwrap() - first[0].parse::<u64>().unwrap();
    assert_eq!(
        Some(span),
        j["ticks"].as_u64(),
        "{} .. {}",
        rows[1],
        rows.last().unwrap()
    );
    assert_eq!(rows.len() as u64, span + 2);
    assert_eq!(last[1], j["final_raw"]["x"].as_str().unwrap());
    assert!(std::fs::metadata(&svg).unwrap().len() > 1000);
}

#[test]
fn online_refuses_a_bad_script_with_exit_2() {
    let script = tmp("bad.toml");
    std::fs::write(
        &script,
        "[[event]]\nat_ms = 5\nkind = \"move_absolute\"\nposition = 1.0\n",
    )
    .unwrap();
    let out = snapgen(&["online", "--script", script.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a valid script"));
    std::fs::write(&script, "order = 5\n[[event]]\nat_ms = 0\noverride = 1.0\n").unwrap();
    let out = snapgen(&["online", "--script", script.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("order = 5"));
}

/// The X, Y, Z (mm) of every row of `snapgen path --csv`.
fn path_rows(csv: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|r| r.split(',').skip(2).map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// `snapgen path`: the example part is played, passes its independent check and ends where it
/// began; a program with an unsupported word is refused with its line (exit 2) before anything
/// moves.
#[test]
fn path_plays_the_example_part_and_refuses_bad_gcode() {
    let part = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/part.ngc");
    let csv = tmp("part.csv");
    let svg = tmp("part.svg");
    let out = snapgen(&[
        "path",
        "--gcode",
        part,
        "--csv",
        csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("9 blocks"), "{text}");
    assert!(
        text.contains("within every axis's limits on every tick"),
        "{text}"
    );
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.contains("path, XY plane") && picture.contains("jerk (mm/s^3)"));
    // The part's Z moves: its ZX and YZ views too.
    assert!(picture.contains("path, XZ plane") && picture.contains("path, YZ plane"));
    assert!(picture.contains("distance from the programmed path"));
    assert!(text.contains("farthest from the programmed path"), "{text}");
    let xyz = path_rows(&csv).pop().unwrap();
    assert!(
        xyz.len() == 3 && xyz.iter().all(|v| v.abs() < 1e-9),
        "{xyz:?}"
    );
    let out = snapgen(&["path", "--gcode", part, "--json"]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["checked"], true);
    assert_eq!(v["blocks"].as_array().unwrap().len(), 9);
    assert_eq!(v["blocks"][0]["kind"], "rapid");
    let bad = tmp("bad.ngc");
    std::fs::write(&bad, "G21 F600\nG1 X1\nM3 S1000\nM30\n").unwrap();
    let out = snapgen(&["path", "--gcode", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 3: M3 is not supported"), "{err}");
    // A path longer than its length register holds (1073.7 mm at 1 nm), with its block.
    let long = tmp("long.ngc");
    std::fs::write(&long, "G21 F6000\nG1 X600\nG1 X1200\nM30\n").unwrap();
    let out = snapgen(&["path", "--gcode", long.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 3: the path reaches 1200.000"), "{err}");
}

/// `snapgen path --scenario seed002`: the line and its tangent arc at the seed's three jerks,
/// every event taken, the arc entered at speed, the check passed, the durations docs/PATH.md
/// gives; the arc enters on the first tick the trace (`--csv`) is 300 mm along; a G-code part
/// under overrides too; a malformed override is refused.
#[test]
fn path_plays_seed002_as_a_path_and_the_part_under_overrides() {
    let csv = tmp("seed002_path.csv");
    for (jerk, duration) in [("5000", 4.9177), ("50000", 4.7611), ("500000", 4.7042)] {
        let out = snapgen(&[
            "path",
            "--scenario",
            "seed002",
            "--jerk",
            jerk,
            "--json",
            "--csv",
            csv.to_str().unwrap(),
        ]);
        assert_ok(&out);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["checked"], true, "{v}");
        assert!(
            (v["duration_s"].as_f64().unwrap() - duration).abs() < 1e-9,
            "{v}"
        );
        let blocks = v["blocks"].as_array().unwrap();
        assert_eq!(blocks.len(), 2);
        let entry = blocks[1]["entry"].as_f64().unwrap();
        assert!(entry > 100.0 && entry <= 140.0, "{entry}");
        let events = v["events"].as_array().unwrap();
        assert_eq!(events.len(), 7);
        assert!(events
            .iter()
            .all(|e| e["tick"].is_u64() && e["refused"].is_null()));
        // The arc enters on the first tick X (the path length, on the line) is 300 mm along.
        let reached = path_rows(&csv)
            .iter()
            .position(|p| p[0] >= 300.0 - 0.5e-6)
            .unwrap();
        assert_eq!(events[5]["tick"].as_u64(), Some(reached as u64), "{jerk}");
    }
    let part = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/part.ngc");
    let out = snapgen(&[
        "path",
        "--gcode",
        part,
        "--override",
        "1.8@300",
        "--override",
        "0.3@2500",
        "--json",
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["checked"], true, "{v}");
    assert!(
        v["blocks"][2]["entry"].as_f64().unwrap() > 0.0,
        "the tangent arc at speed"
    );
    let out = snapgen(&["path", "--gcode", part, "--override", "3@10"]);
    assert_eq!(out.status.code(), Some(2));
}

/// `snapgen path --board model`: a line, a tangent arc and a line with the path length
/// integrated by the virtual board (its Ts read from it: 10 µs), the host interpolating: the
/// check passes, the tangent arc is entered at speed, and the end is the program's; `--ts`
/// with a board is refused.
#[test]
fn path_runs_its_length_on_a_virtual_board() {
    let small = tmp("small.ngc");
    std::fs::write(&small, "G21 G90 F1200\nG1 X2\nG3 X4 Y2 J2\nG1 Y3\nM30\n").unwrap();
    let csv = tmp("small.csv");
    let out = snapgen(&[
        "path",
        "--gcode",
        small.to_str().unwrap(),
        "--board",
        "model",
        "--json",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["checked"], true, "{v}");
    assert_eq!(v["ts"].as_f64(), Some(1e-5));
    assert!(v["blocks"][1]["entry"].as_f64().unwrap() > 0.5, "{v}");
    let last = path_rows(&csv).pop().unwrap();
    assert!(
        (last[0] - 4.0).abs() < 1e-6 && (last[1] - 3.0).abs() < 1e-6,
        "{last:?}"
    );
    let out = snapgen(&[
        "path",
        "--gcode",
        small.to_str().unwrap(),
        "--board",
        "model",
        "--ts",
        "1e-4",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// `snapgen path --board path-core`: a path longer than the ring the board writes before the
/// run, or with elements too short for its tick, is refused (exit 2) before anything moves,
/// saying why.
#[test]
fn path_core_board_refuses_a_path_longer_than_its_ring() {
    let long = tmp("ring.ngc");
    let mut g = String::from("G21 G90 F600\n");
    for k in 1..=70 {
        g.push_str(&format!("G1 X{} Y{}\n", k % 2, k));
    }
    g.push_str("M30\n");
    std::fs::write(&long, g).unwrap();
    let out = snapgen(&[
        "path",
        "--gcode",
        long.to_str().unwrap(),
        "--board",
        "path-core",
        "--lsb",
        "1e-3",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the path has 70 segments") && err.contains("holds 62"),
        "{err}"
    );
    // Three elements shorter together than a tick's advance: a tick could cross more
    // segments than the board's tick has room for.
    let short = tmp("short.ngc");
    std::fs::write(
        &short,
        "G21 G90 F600\nG1 X0.001\nG1 X0.002\nG1 X0.003\nG1 X5\nM30\n",
    )
    .unwrap();
    let out = snapgen(&[
        "path",
        "--gcode",
        short.to_str().unwrap(),
        "--board",
        "path-core",
        "--lsb",
        "1e-3",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("segments 0 to 2 are 3.0 LSB long together"),
        "{err}"
    );
}

/// `snapgen cosim-path-core` runs the path core in lockstep and reports its runs; a fault
/// injected into an output exits 1 naming the port and clock.
#[test]
fn cosim_path_core_reports_and_fails_on_a_fault() {
    let out = snapgen(&["cosim-path-core", "--axes", "2", "--clocks", "300000"]);
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("300000 clocks compared") && text.contains(", 0 mismatches"),
        "{text}"
    );
    assert!(text.contains("no violation"), "{text}");
    let out = snapgen(&[
        "cosim-path-core",
        "--axes",
        "2",
        "--clocks",
        "300000",
        "--inject-fault",
        "12345:step:1",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("step") && text.contains("12345"), "{text}");
}

/// `--uio`: a device that is not there, or that is no station's register map, is refused with
/// what to check (exit 1); `--port` and `--uio` together are a usage error (exit 2).
#[test]
fn uio_links_refuse_what_is_no_station() {
    let out = snapgen(&["stop", "--uio", "/dev/snapgen-no-such-uio"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot open the UIO device"), "{err}");
    let out = snapgen(&["stop", "--uio", "/dev/null"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot map its registers"), "{err}");
    let out = snapgen(&["stop", "--uio", "/dev/null", "--port", "/dev/null"]);
    assert_eq!(out.status.code(), Some(2));
    let mut send = vec!["send", "--uio", "/dev/snapgen-no-such-uio"];
    send.extend_from_slice(ORDER4);
    let out = snapgen(&send);
    assert_eq!(out.status.code(), Some(1));
}

/// `identify` refuses bad bounds and cases before anything moves (exit 2), and a virtual
/// board's motor cannot be given with a real board.
#[test]
fn identify_refuses_bad_input() {
    for (args, says) in [
        (&["--travel=0"][..], "--travel 0: give a positive number"),
        (&["--mismatch", "r=0"][..], "give a factor from 0.1 to 10"),
        (
            &["--port", "/dev/null", "--mismatch", "r=2"][..],
            "cannot be used with",
        ),
    ] {
        let mut all = vec!["identify", "--board", "model"];
        all.extend_from_slice(args);
        let out = snapgen(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(says),
            "{args:?}"
        );
    }
}
