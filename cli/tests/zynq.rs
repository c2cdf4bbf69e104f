//! The Zynq build (`snapgen build --host ps`, issue 23 item 3). Vivado is not here, so its
//! scripts run under a stand-in that records Vivado's commands (`vivado_standin.tcl`, in
//! tclsh), and the names they use are checked against the generated Verilog, the constraints
//! and the C header: every command is one Vivado has, every pin of the station the block
//! design names is a port of `snapgen_axi`, every input of the station is driven, every
//! external port is constrained and every constraint names an external port, the IP's
//! registers sit where the header says. Each of the scripts' own guards is shown to fire. The
//! overlay compiles with `dtc` (installed by the test command) and reads back as the
//! Zynq-7000's facts say; the Makefile's steps are valid (`make -n`); the Verilog lints clean.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{assert_ok, lint_clean, snapgen};

const TOP: &str = "snapgen_zybo_z7_10_ps";

/// The Vivado Tcl commands (UG835) the scripts may call: a call outside this list is a typo
/// or a command Vivado does not have.
const VIVADO_COMMANDS: [&str; 58] = [
    "add_files",
    "apply_bd_automation",
    "assign_bd_address",
    "close_project",
    "connect_bd_intf_net",
    "connect_bd_net",
    "create_bd_cell",
    "create_bd_design",
    "create_bd_port",
    "create_project",
    "current_fileset",
    "current_project",
    "generate_target",
    "get_bd_addr_segs",
    "get_bd_addr_spaces",
    "get_bd_cells",
    "get_bd_intf_pins",
    "get_bd_pins",
    "get_bd_ports",
    "get_board_parts",
    "get_files",
    "get_ports",
    "get_property",
    "get_runs",
    "get_timing_paths",
    "ipx::add_address_block",
    "ipx::add_bus_parameter",
    "ipx::add_memory_map",
    "ipx::add_register",
    "ipx::add_register_parameter",
    "ipx::associate_bus_interfaces",
    "ipx::check_integrity",
    "ipx::create_xgui_files",
    "ipx::current_core",
    "ipx::get_address_blocks",
    "ipx::get_bus_interfaces",
    "ipx::get_bus_parameters",
    "ipx::get_memory_maps",
    "ipx::get_register_parameters",
    "ipx::infer_bus_interface",
    "ipx::package_project",
    "ipx::remove_all_bus_interface",
    "ipx::remove_memory_map",
    "ipx::save_core",
    "ipx::update_checksums",
    "launch_runs",
    "make_wrapper",
    "open_run",
    "report_timing_summary",
    "report_utilization",
    "save_bd_design",
    "set_property",
    "update_compile_order",
    "update_ip_catalog",
    "validate_bd_design",
    "wait_on_run",
    "write_bitstream",
    "write_hw_platform",
];

fn tmp(name: &str) -> PathBuf {
    common::tmp("zynq", name)
}

/// The stand-in's run of `script` in `dir` with `env`: success, the recorded calls (words),
/// and what it wrote on stderr.
fn standin(dir: &Path, script: &str, env: &[(&str, &str)]) -> (bool, Vec<Vec<String>>, String) {
    let standin = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/vivado_standin.tcl");
    let out = Command::new("tclsh")
        .current_dir(dir)
        .arg(standin)
        .arg(script)
        .env_remove("STANDIN_BOARD_PARTS")
        .env_remove("STANDIN_FCLK_MHZ")
        .env_remove("STANDIN_SETUP_SLACK")
        .env_remove("STANDIN_HOLD_SLACK")
        .env_remove("STANDIN_LATEST_PARTS")
        .env_remove("STANDIN_PROGRESS")
        .envs(env.iter().copied())
        .output()
        .expect("tclsh is installed by the test command");
    let calls = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.strip_prefix("CALL\u{1f}"))
        .map(|l| l.split('\u{1f}').map(str::to_string).collect())
        .collect();
    (
        out.status.success(),
        calls,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The ports of module `name` in `verilog`, with their directions ("input"/"output").
fn module_ports(verilog: &str, name: &str) -> BTreeMap<String, String> {
    let start = verilog
        .find(&format!("module {name}("))
        .expect("module header");
    let body = &verilog[start..verilog[start..].find("endmodule").unwrap() + start];
    body.lines()
        .filter_map(|l| {
            let l = l.trim();
            let dir = ["input", "output"].into_iter().find(|d| l.starts_with(d))?;
            let name = l.trim_end_matches(';').split_whitespace().last()?;
            Some((name.to_string(), dir.to_string()))
        })
        .collect()
}

#[test]
fn the_ps_build_is_whole_and_its_names_agree() {
    let dir = tmp("zybo");
    assert_ok(&ps_build(&dir, &["--board", "zybo-z7-10"]));
    let sources: Vec<String> = ["snapgen_core.v", "snapgen_io.v", "snapgen_axi.v"]
        .map(String::from)
        .to_vec();
    lint_clean(&dir, "snapgen_axi", &sources);
    check(&dir);

    // Each check fails on an injected mistake (one at a time, in a copy of the build).
    let mistakes: [(&str, &str, &str); 8] = [
        // A pin the station does not have.
        (
            "block_design.tcl",
            "get_bd_pins snapgen_0/estop",
            "get_bd_pins snapgen_0/e_stop",
        ),
        // An input left undriven.
        (
            "block_design.tcl",
            "connect_bd_net [get_bd_ports limit_neg] [get_bd_pins snapgen_0/limit_neg]\n",
            "",
        ),
        // The interrupt to the wrong pin of the PS.
        ("block_design.tcl", "ps7/IRQ_F2P", "ps7/FCLK_CLK0"),
        // A constraint for a port the design does not have.
        (
            &format!("{TOP}.xdc"),
            "[get_ports { pwm }]",
            "[get_ports { pwm_out }]",
        ),
        // A command Vivado does not have.
        (
            "package_ip.tcl",
            "ipx::add_register $name",
            "ipx::add_reg $name",
        ),
        // A register where the header does not put it.
        ("package_ip.tcl", "X_0 0x48", "X_0 0x4C"),
        // The SPI numbered as the interrupt ID.
        ("snapgen.dtso", "<0 29 4>", "<0 61 4>"),
        // A timing check that lets negative slack through.
        (
            "build.tcl",
            "$wns < 0 || $whs < 0",
            "$wns < -1 || $whs < -1",
        ),
    ];
    for (k, (file, from, to)) in mistakes.iter().enumerate() {
        let copy = tmp(&format!("mistake{k}"));
        std::fs::create_dir_all(&copy).unwrap();
        for e in std::fs::read_dir(&dir).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), copy.join(e.file_name())).unwrap();
            }
        }
        let text = std::fs::read_to_string(copy.join(file)).unwrap();
        assert!(text.contains(from), "{file} lacks {from:?}");
        std::fs::write(copy.join(file), text.replacen(from, to, 1)).unwrap();
        assert!(
            std::panic::catch_unwind(|| check(&copy)).is_err(),
            "{file}: {from:?} -> {to:?} was not caught"
        );
    }
}

/// Every check of a written PS build in `dir` (panics on the first that fails).
fn check(dir: &Path) {
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    let ports = module_ports(&read("snapgen_axi.v"), "snapgen_axi");
    assert!(ports.len() > 20, "{ports:?}");

    // The whole build under the stand-in, to its end.
    let (ok, calls, err) = standin(dir, "build.tcl", &[]);
    assert!(ok, "{err}");
    for c in &calls {
        assert!(
            VIVADO_COMMANDS.contains(&c[0].as_str()),
            "not a Vivado command: {c:?}"
        );
    }
    fn called<'a>(calls: &'a [Vec<String>], cmd: &'a str) -> impl Iterator<Item = &'a Vec<String>> {
        calls.iter().filter(move |c| c[0] == cmd)
    }
    // Every pin of the station the block design names is a port of snapgen_axi.
    for c in called(&calls, "get_bd_pins") {
        for a in &c[1..] {
            if let Some(p) = a
                .strip_prefix("snapgen_0/")
                .filter(|p| *p != "s_axi" && !p.starts_with("s_axi/"))
            {
                assert!(
                    ports.contains_key(p),
                    "snapgen_0/{p} is no port of snapgen_axi"
                );
            }
        }
    }
    // Its AXI ports are the interface's, listed in package_ip.tcl.
    let package = read("package_ip.tcl");
    let busif_line = package
        .lines()
        .find(|l| l.contains("[snapgen_interface $core s_axi {"))
        .expect("the s_axi interface");
    let axi: BTreeSet<&str> = busif_line
        .split(['{', '}'])
        .nth(1)
        .unwrap()
        .split_whitespace()
        .collect();
    let verilog_axi: BTreeSet<&str> = ports
        .keys()
        .map(String::as_str)
        .filter(|p| p.starts_with("s_axi_"))
        .collect();
    assert_eq!(axi, verilog_axi);
    // Every port is connected: the clock to FCLK_CLK0, the reset to the reset block, the
    // interrupt to IRQ_F2P, each pin to the block design's port of its name, the AXI ports
    // through the interface; only the debug status stays open.
    let nets: Vec<&Vec<String>> = called(&calls, "connect_bd_net").collect();
    let net_of = |pin: &str| {
        let end = format!("<get_bd_pins:snapgen_0/{pin}>");
        nets.iter().find(|n| n.contains(&end)).copied()
    };
    for (p, dir) in &ports {
        if p.starts_with("s_axi_") || p == "status" {
            continue;
        }
        let net = net_of(p).unwrap_or_else(|| panic!("{dir} {p} of snapgen_axi is not connected"));
        let other = match p.as_str() {
            "clock" => "<get_bd_pins:ps7/FCLK_CLK0>".to_string(),
            "reset" => "<get_bd_pins:rst_fclk0/peripheral_reset>".to_string(),
            "irq" => "<get_bd_pins:ps7/IRQ_F2P>".to_string(),
            _ => format!("<get_bd_ports:{p}>"),
        };
        assert!(net.contains(&other), "{p}: {net:?}");
    }
    assert!(called(&calls, "connect_bd_intf_net")
        .any(|c| c.contains(&"<get_bd_intf_pins:snapgen_0/s_axi>".to_string())));
    // Each external port is constrained, each constraint names an external port, and the
    // pins are the Zybo Z7-10's (Digilent's master XDC).
    let bd_ports: BTreeSet<String> = called(&calls, "create_bd_port")
        .map(|c| c.last().unwrap().clone())
        .collect();
    let (ok, xdc_calls, err) = standin(dir, &format!("{TOP}.xdc"), &[]);
    assert!(ok, "{err}");
    let constrained: BTreeSet<String> = xdc_calls
        .iter()
        .filter(|c| c[0] == "get_ports")
        .map(|c| c[1].trim().to_string())
        .filter(|p| !p.is_empty())
        .collect();
    assert_eq!(bd_ports, constrained);
    let xdc = read(&format!("{TOP}.xdc"));
    for (pin, port) in [
        ("K18", "btn_reset"),
        ("M14", "led_idle"),
        ("D18", "led_heartbeat"),
        ("V15", "pwm"),
        ("T11", "amplifier"),
        ("T10", "estop"),
        ("T14", "enc_a"),
    ] {
        assert!(
            xdc.contains(&format!(
                "PACKAGE_PIN {pin} IOSTANDARD LVCMOS33 }} [get_ports {{ {port} }}]"
            )),
            "{port} on {pin}: {xdc}"
        );
    }
    // The PS: FCLK_CLK0 at the board file's 100 MHz; the slave at 0x43C00000, one page.
    let ps7 = called(&calls, "set_property")
        .find(|c| c.iter().any(|w| w.contains("CONFIG.PCW_USE_M_AXI_GP0")))
        .expect("the PS7's configuration");
    assert!(
        ps7[2].contains("CONFIG.PCW_FPGA0_PERIPHERAL_FREQMHZ 100 "),
        "{ps7:?}"
    );
    let address = called(&calls, "assign_bd_address")
        .next()
        .expect("an address");
    assert_eq!(address[1..5], ["-offset", "0x43C00000", "-range", "4096"]);
    // The IP's registers sit where the C header puts them.
    let mut ip_regs = BTreeMap::new();
    let mut last = String::new();
    for c in &calls {
        match (c[0].as_str(), c.get(1).map(String::as_str)) {
            ("ipx::add_register", Some(name)) => last = name.to_string(),
            ("set_property", Some("address_offset")) => {
                ip_regs.insert(last.clone(), u32::from_str_radix(&c[2][2..], 16).unwrap());
            }
            _ => {}
        }
    }
    let header = read("snapgen_axi.h");
    let mut in_header = 0;
    for l in header.lines().filter(|l| l.ends_with("/* byte offset */")) {
        let mut w = l.split_whitespace();
        let name = w.nth(1).unwrap().trim_start_matches("SNAPGEN_AXI_");
        let offset = u32::from_str_radix(
            w.next()
                .unwrap()
                .trim_start_matches("0x")
                .trim_end_matches('u'),
            16,
        )
        .unwrap();
        let ip = ip_regs
            .get(name)
            .or_else(|| ip_regs.get(&format!("{name}_0")))
            .unwrap_or_else(|| panic!("{name} is not in the IP's register map"));
        assert_eq!(*ip, offset, "{name}");
        in_header += 1;
    }
    assert_eq!(in_header, 14);
    // The run's bitstream is the build's.
    assert!(dir.join(format!("{TOP}.bit")).exists());

    // Each of the scripts' guards fires on what it guards against, and stops the build.
    let cases: [(&[(&str, &str)], &str); 5] = [
        (
            &[("STANDIN_SETUP_SLACK", "-0.012")],
            "routed timing does not close",
        ),
        (&[("STANDIN_HOLD_SLACK", "-0.004")], "hold slack -0.004"),
        (
            &[("STANDIN_FCLK_MHZ", "111.111115")],
            "FCLK_CLK0 at 111.111115 MHz",
        ),
        (
            &[("STANDIN_BOARD_PARTS", ""), ("STANDIN_LATEST_PARTS", "")],
            "does not know the board part",
        ),
        (&[("STANDIN_PROGRESS", "0%")], "synthesis failed"),
    ];
    for (env, says) in cases {
        let _ = std::fs::remove_file(dir.join(format!("{TOP}.bit")));
        let (ok, calls, err) = standin(dir, "build.tcl", env);
        assert!(!ok && err.contains(says), "{env:?}: {err}");
        assert!(
            !dir.join(format!("{TOP}.bit")).exists()
                && !calls.iter().any(|c| c[0] == "write_hw_platform"),
            "{env:?}: a bitstream or platform was written"
        );
    }
    // Another version of the board's files than the board file names is taken.
    let other = "digilentinc.com:zybo-z7-10:part0:1.0";
    let (ok, calls, err) = standin(
        dir,
        "build.tcl",
        &[("STANDIN_BOARD_PARTS", ""), ("STANDIN_LATEST_PARTS", other)],
    );
    assert!(ok, "{err}");
    assert!(calls
        .iter()
        .any(|c| c[0] == "set_property" && c[1] == "board_part" && c[2] == other));

    // The overlay compiles without a warning and says what the Zynq-7000 needs: the page at
    // the base, IRQ_F2P[0] = interrupt ID 61 (UG585 Table 7-4) = SPI 29, level high.
    let dtc = Command::new("dtc")
        .current_dir(dir)
        .args([
            "-@",
            "-I",
            "dts",
            "-O",
            "dtb",
            "-o",
            "snapgen.dtbo",
            "snapgen.dtso",
        ])
        .output()
        .expect("dtc is installed by the test command");
    assert!(
        dtc.status.success() && dtc.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&dtc.stderr)
    );
    let back = Command::new("dtc")
        .current_dir(dir)
        .args(["-I", "dtb", "-O", "dts", "snapgen.dtbo"])
        .output()
        .unwrap();
    let back = String::from_utf8_lossy(&back.stdout);
    for want in [
        "reg = <0x43c00000 0x1000>;",
        "interrupts = <0x00 0x1d 0x04>;",
        "compatible = \"snapgen,axi-station\\0generic-uio\";",
        &format!("firmware-name = \"{TOP}.bit.bin\";"),
        "fpga_full = \"/fragment@0:target:0\";",
        "amba = \"/fragment@1:target:0\";",
        // FCLK_CLK0 (clkc's clock 15) kept at the design's 100 MHz.
        "compatible = \"xlnx,fclk\";",
        "assigned-clock-rates = <0x5f5e100>;",
        "clkc = \"/fragment@1/__overlay__/snapgen-fclk0:clocks:0",
    ] {
        assert!(back.contains(want), "{want}: {back}");
    }
    assert!(read(&format!("{TOP}.bif")).contains(&format!("\t{TOP}.bit\n")));
    // The Makefile's steps, as make reads them.
    let make = Command::new("make")
        .current_dir(dir)
        .args(["-n", "-B", "all", "VIVADO=true", "BOOTGEN=true"])
        .output()
        .unwrap();
    let steps = String::from_utf8_lossy(&make.stdout);
    assert!(
        make.status.success(),
        "{}",
        String::from_utf8_lossy(&make.stderr)
    );
    for want in [
        "-source build.tcl",
        &format!("-image {TOP}.bif -arch zynq -process_bitstream bin"),
        "dtc -@ -I dts -O dtb -o snapgen.dtbo snapgen.dtso",
    ] {
        assert!(steps.contains(want), "{want}: {steps}");
    }
}

/// `snapgen build --host ps --out OUT` with `args`.
fn ps_build(out: &Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["build", "--host", "ps", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    snapgen(&all)
}

/// `snapgen build --host ps` with `args`, refused with a message containing `says`.
fn refused(args: &[&str], says: &str) {
    let out = ps_build(&tmp("refused"), args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains(says),
        "{args:?}: {err}"
    );
}

#[test]
fn the_ps_build_needs_a_zynq_and_a_clock_it_can_make() {
    refused(&["--board", "ulx3s"], "no processing system");
    // 1000 MHz / 123 MHz is no product of two dividers.
    refused(
        &["--board", "zybo-z7-10", "--clock-hz", "123e6"],
        "two dividers of 1 to 63",
    );
    // 1000 MHz / 125 MHz = 8: the script asks the PS for 125 MHz.
    let dir = tmp("125");
    assert_ok(&ps_build(
        &dir,
        &["--board", "zybo-z7-10", "--clock-hz", "125e6"],
    ));
    let bd = std::fs::read_to_string(dir.join("block_design.tcl")).unwrap();
    assert!(
        bd.contains("CONFIG.PCW_FPGA0_PERIPHERAL_FREQMHZ {125}"),
        "{bd}"
    );
}
