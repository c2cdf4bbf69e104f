//! The `snapgen` binary: JSON fields, trace and plot files, and exit codes for bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn snapgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(args)
        .output()
        .expect("run snapgen")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snapgen-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["ticks_total"], 0);
    assert_eq!(v["segments"], serde_json::json!([]));
}

#[test]
fn demo_runs_and_writes_plots() {
    let dir = tmp("demo");
    let out = snapgen(&["demo", "--out", dir.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("round trip 0 -> 12π -> 0 ends on the start register bit for bit"));
    assert!(stdout.contains(", 0 mismatches"), "{stdout}");
    assert!(stdout.contains(" 0 latches"), "{stdout}");
    for f in [
        "seed001_table1.svg",
        "seed001_table3_return.svg",
        "seed000_all_limits.svg",
    ] {
        assert!(dir.join(f).exists(), "{f} not written");
    }
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
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
