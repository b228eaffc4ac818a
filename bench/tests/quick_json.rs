//! End to end: the quick mode of cheap scenarios (floor, ik, and `loop` through the
//! emulator over a pty) with small counts, through the real binary and its child
//! processes; checks the structure of the JSON report and of the SVG plot. Asserts
//! structure, never speed.

use std::process::Command;
use std::time::Duration;

use serde_json::Value;

#[test]
fn quick_run_writes_a_well_formed_report() {
    let dir = std::env::temp_dir().join(format!("limber-bench-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let svg = dir.join("report.svg");
    let out = limber_bounded_run::output_within(
        Command::new(env!("CARGO_BIN_EXE_limber-bench"))
            .args(["--quick", "--scale", "0.1", "--no-progress", "--only"])
            .arg("floor,ik,loop")
            .arg("--json")
            .arg(&json)
            .arg("--plot")
            .arg(&svg),
        Duration::from_secs(600),
    );
    assert!(
        out.status.success(),
        "limber-bench failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("machine:"), "{table}");
    assert!(
        table.contains("command → state, through the emulator"),
        "{table}"
    );

    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let machine = &v["machine"];
    for k in ["cpu", "cores", "kernel", "load_avg", "pinning", "build"] {
        assert!(!machine[k].is_null(), "machine.{k} missing: {machine}");
    }
    assert_eq!(v["jitter_definition"], "jitter = p99 - p50");

    let scenarios = v["scenarios"].as_array().unwrap();
    let status = |name: &str| {
        scenarios
            .iter()
            .find(|s| s["name"] == name)
            .map(|s| s["status"].as_str().unwrap().to_string())
    };
    assert_eq!(status("floor").as_deref(), Some("ok"));
    assert_eq!(status("ik").as_deref(), Some("ok"));
    assert_eq!(status("loop").as_deref(), Some("ok"));

    let ms = v["measurements"].as_array().unwrap();
    let ids: Vec<&str> = ms.iter().map(|m| m["id"].as_str().unwrap()).collect();
    for id in [
        "floor.spin.rtt",
        "floor.spin.oneway",
        "floor.spin2.rtt",
        "floor.spin2.oneway",
        "floor.spin2.back",
        "floor.event.rtt",
        "floor.event.oneway",
        "floor.futex.rtt",
        "floor.futex.oneway",
        "floor.cacheline.rtt",
        "floor.cacheline.oneway",
        "ik.pioneer.pose",
        "ik.chain6.pose",
        "loop.to_robot",
        "loop.driver",
        "loop.driver_send",
        "loop.driver_work",
        "loop.spin.driver",
        "loop.spin.driver_work",
        "loop.spin.pty_write",
        "loop.to_client",
        "loop.total",
    ] {
        assert!(ids.contains(&id), "{id} missing from {ids:?}");
    }
    for m in ms {
        for k in ["scenario", "label", "strategy", "metric"] {
            assert!(m[k].is_string(), "{k} in {m}");
        }
        let s = &m["summary"];
        let get = |k: &str| s[k].as_u64().unwrap_or_else(|| panic!("{k} in {s}"));
        assert!(get("count") > 0, "{m}");
        assert!(get("p50_ns") <= get("p90_ns"));
        assert!(get("p90_ns") <= get("p99_ns"));
        assert!(get("p99_ns") <= get("p999_ns"));
        assert!(get("p999_ns") <= get("max_ns"));
        assert_eq!(get("jitter_ns"), get("p99_ns") - get("p50_ns"));
        assert!(!m["curve"].as_array().unwrap().is_empty());
    }
    let strategies: Vec<&str> = ms.iter().map(|m| m["strategy"].as_str().unwrap()).collect();
    assert!(strategies.contains(&"spin"));
    assert!(strategies.contains(&"blocking"));
    assert!(strategies.contains(&"compute"));
    // The floor-only ratio is computed in the same run.
    assert!(
        v["ratios"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| r["num"] == "floor.event.rtt")
    );

    // The goals in time: each with the value of its series in this run and a verdict.
    let goals = v["time_goals"].as_array().unwrap();
    let six = goals
        .iter()
        .find(|g| g["id"] == "ik.chain6.pose" && g["pct"] == "p50")
        .expect("the 6-joint pose goal");
    assert_eq!(
        six["ns"].as_u64().unwrap(),
        ms.iter().find(|m| m["id"] == "ik.chain6.pose").unwrap()["summary"]["p50_ns"]
            .as_u64()
            .unwrap()
    );
    assert_eq!(six["at_most_ns"], 10_000);
    assert!(six["floor"].is_null());
    // The spinning driver's goal names its floor, the bare pty write, as measured.
    let driver = goals
        .iter()
        .find(|g| g["id"] == "loop.spin.driver")
        .expect("the spinning driver's goal");
    assert_eq!(driver["floor"]["id"], "loop.spin.pty_write");
    assert_eq!(
        driver["floor"]["ns"].as_u64().unwrap(),
        ms.iter()
            .find(|m| m["id"] == "loop.spin.pty_write")
            .unwrap()["summary"]["p50_ns"]
            .as_u64()
            .unwrap()
    );
    assert_eq!(
        six["met"].as_bool().unwrap(),
        six["ns"].as_u64().unwrap() <= 10_000
    );

    // Blocking rows are compared with the futex floor, spinning rows with the cache line.
    let row = |id: &str| ms.iter().find(|m| m["id"] == id).unwrap();
    assert_eq!(row("floor.event.rtt")["phys_id"], "floor.futex.rtt");
    assert_eq!(
        row("floor.spin.oneway")["phys_id"],
        "floor.cacheline.oneway"
    );
    assert!(row("floor.event.rtt")["x_phys_p50"].as_f64().unwrap() > 0.0);
    assert!(row("floor.futex.rtt")["phys_id"].is_null());
    assert!(
        v["ratios"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| r["den"] == "floor.futex.rtt" && r["num"] == "floor.event.rtt")
    );

    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.starts_with("<svg"), "not an SVG");
    assert!(svg_text.contains("polyline") || svg_text.contains("path"));
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

#[test]
fn unknown_scenario_is_an_error_not_a_panic() {
    let out = limber_bounded_run::output_within(
        Command::new(env!("CARGO_BIN_EXE_limber-bench")).args(["--only", "nosuch"]),
        Duration::from_secs(60),
    );
    assert_eq!(out.status.code(), Some(2), "a usage error");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown scenario"), "{err}");
    assert!(err.contains("the scenarios are floor, "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn an_output_that_cannot_be_written_is_refused_before_the_run() {
    let dir = std::env::temp_dir().join(format!("limber-bench-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("no-such-dir").join("x.json");
    for (flag, path) in [("--json", &missing), ("--plot", &dir)] {
        let out = limber_bounded_run::output_within(
            Command::new(env!("CARGO_BIN_EXE_limber-bench"))
                .args(["--only", "floor", "--quick", "--no-progress", flag])
                .arg(path),
            Duration::from_secs(60),
        );
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("{flag} {}", path.display())), "{err}");
        assert!(err.contains("cannot write it"), "{err}");
        // Refused before the run: no table was printed.
        assert!(
            out.stdout.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
    assert!(!missing.exists());
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only lang`: the Rust, C and Python clients' state reads and command round trips; a
/// language that cannot run here is skipped with the reason (in CI, `CI=true`, with the
/// venv of `.ci/run` in `LIMBER_PYTHON`, all three must run, Python's package installed by pip
/// with its compiled state copy). And without a Python, the Python client is skipped with
/// the reason while the others run.
#[test]
fn lang_measures_rust_c_and_python_or_says_why_not() {
    let dir = std::env::temp_dir().join(format!("limber-bench-lang-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |json: &std::path::Path, python: Option<&str>| {
        let (s, ids, _, stderr) = run_only("lang", json, python.map(|p| ("LIMBER_PYTHON", p)));
        (ids, s["detail"].as_str().unwrap().to_string(), stderr)
    };
    let ci = std::env::var("CI").as_deref() == Ok("true");
    let (ids, detail, _) = run(&dir.join("lang.json"), None);
    for lang in ["rust", "c", "python"] {
        let measured = ids.contains(&format!("lang.{lang}.state"))
            && ids.contains(&format!("lang.{lang}.rtt"));
        let name = match lang {
            "rust" => "Rust",
            "c" => "C",
            _ => "Python",
        };
        if lang == "rust" || ci {
            assert!(measured, "{lang} not measured: {ids:?} ({detail})");
        } else {
            assert!(
                measured || detail.contains(&format!("{name} skipped: ")),
                "{ids:?} ({detail})"
            );
        }
    }
    // One placement for every language (the driver on a core of its own) where there are
    // two cores: unpinned, the ratios between languages measured where each process landed.
    if std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2) {
        assert!(
            detail.contains("lang pinned whatever --pin says (one placement for every client)"),
            "{detail}"
        );
    }
    // The package as pip installs it: in CI (a C compiler and Python's headers), with the
    // state copy in C.
    if ci {
        assert!(
            detail.contains("Python: states copied by the package's compiled limber._fast"),
            "{detail}"
        );
    }
    // No Python: skipped, with the reason on stderr and in the report.
    let (ids, detail, stderr) = run(&dir.join("nopy.json"), Some("/nonexistent/python3"));
    assert!(ids.contains(&"lang.rust.rtt".to_string()), "{ids:?}");
    assert!(!ids.iter().any(|i| i.starts_with("lang.python")), "{ids:?}");
    assert!(
        detail.contains("Python skipped: cannot start \"/nonexistent/python3\""),
        "{detail}"
    );
    assert!(stderr.contains("lang: Python skipped: "), "{stderr}");
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only bridge`: the command round trip through a `limber bridge expose` + `mirror` pair
/// over TCP loopback, and the same client direct; without a `limber` that runs `bridge`
/// (here: `LIMBER_BIN` naming none), skipped with the reason. In CI (`CI=true`) the
/// workspace's `limber` is built beside `limber-bench`, and both rows must be there.
#[test]
fn bridge_measures_through_a_bridge_pair_or_says_why_not() {
    let dir = std::env::temp_dir().join(format!("limber-bench-bridge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |json: &std::path::Path, limber: Option<&str>| {
        let (s, ids, v, stderr) = run_only("bridge", json, limber.map(|p| ("LIMBER_BIN", p)));
        for m in v["measurements"].as_array().unwrap() {
            assert_eq!(m["strategy"], "blocking", "{m}");
        }
        let ratios = v["ratios"].as_array().unwrap();
        let ratio = ratios
            .iter()
            .any(|r| r["num"] == "bridge.zenoh.rtt" && r["den"] == "bridge.direct.rtt")
            // The goal against the raw Zenoh floor of the same run, at p50 and p99.
            && ["p50", "p99"].iter().all(|pct| {
                ratios.iter().any(|r| {
                    r["num"] == "bridge.zenoh.rtt"
                        && r["den"] == "bridge.raw.put.rtt"
                        && r["pct"] == *pct
                        && r["goal"]["at_most"] == 1.3
                })
            })
            // The idle bridge pair's CPU, each with its goal.
            && ["bridge expose", "bridge mirror"].iter().all(|p| {
                v["cpu"].as_array().unwrap().iter().any(|c| {
                    c["process"] == *p && c["load"] == "idle" && c["at_most_percent"] == 1.0
                })
            });
        (
            ids,
            ratio,
            s["detail"].as_str().unwrap().to_string(),
            stderr,
        )
    };
    let ci = std::env::var("CI").as_deref() == Ok("true");
    let (ids, ratio, detail, _) = run(&dir.join("bridge.json"), None);
    let measured = ids.contains(&"bridge.direct.rtt".to_string())
        && ids.contains(&"bridge.zenoh.rtt".to_string())
        && ids.contains(&"bridge.raw.put.rtt".to_string())
        && ids.contains(&"bridge.raw.get.rtt".to_string());
    if ci {
        assert!(measured, "the bridge rows are missing: {ids:?} ({detail})");
    } else {
        assert!(
            measured || detail.contains("bridge skipped: "),
            "{ids:?} ({detail})"
        );
    }
    if measured {
        assert!(ratio, "no bridge/direct ratio");
    }
    // No limber: skipped, with the reason on stderr and in the report.
    let (ids, _, detail, stderr) = run(&dir.join("nolimber.json"), Some("/nonexistent/limber"));
    assert!(ids.is_empty(), "{ids:?}");
    assert!(
        detail.contains("bridge skipped: no limber executable with `bridge`"),
        "{detail}"
    );
    assert!(stderr.contains("bridge skipped: "), "{stderr}");
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only bridge` with `LIMBER_BENCH_ZENOH_CONFIG` naming the project's LowLatency
/// configuration (`bridge/zenoh-lowlatency.json5`): both bridges start with it
/// (`--zenoh-config`), as docs/guide/bridge.md has them, and relay the commands; the raw
/// Zenoh floor starts from it too; the report says so. In CI the rows must be there.
#[test]
fn bridge_runs_the_pair_and_its_floor_on_a_given_zenoh_configuration() {
    let dir = std::env::temp_dir().join(format!("limber-bench-zcfg-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../bridge/zenoh-lowlatency.json5")
        .canonicalize()
        .expect("bridge/zenoh-lowlatency.json5");
    let (s, ids, _, _) = run_only(
        "bridge",
        &dir.join("bridge.json"),
        Some(("LIMBER_BENCH_ZENOH_CONFIG", file.to_str().unwrap())),
    );
    let detail = s["detail"].as_str().unwrap().to_string();
    let measured = [
        "bridge.zenoh.rtt",
        "bridge.raw.put.rtt",
        "bridge.raw.get.rtt",
    ]
    .iter()
    .all(|id| ids.contains(&id.to_string()));
    if std::env::var("CI").as_deref() == Ok("true") || measured {
        assert!(measured, "the bridge rows are missing: {ids:?} ({detail})");
        assert!(
            detail.contains(
                "the bridges and the raw Zenoh floor started from the Zenoh configuration"
            ) && detail.contains("zenoh-lowlatency.json5"),
            "{detail}"
        );
    } else {
        assert!(detail.contains("bridge skipped: "), "{ids:?} ({detail})");
    }
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only gateway`: a GET_GEOM's round trip through the Player gateway, with its ratio to
/// the direct request and Player's own figure in the notes.
#[test]
fn gateway_measures_a_request_through_the_player_gateway() {
    let dir = std::env::temp_dir().join(format!("limber-bench-gateway-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (s, ids, _, _) = run_only("gateway", &dir.join("gateway.json"), None);
    assert_eq!(ids, ["gateway.player.rtt"]);
    assert!(s["detail"].as_str().unwrap().contains("162 ms p50"), "{s}");
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only state`: the fan-outs at 1 kHz beside their floors paced at the same rate (a futex
/// wake and a raw iceoryx2 event wake; raw iceoryx2's and the kernel's own fan-outs), and
/// the goals stated against them in the ratios.
#[test]
fn state_measures_the_fanouts_beside_floors_paced_at_their_rate() {
    let dir = std::env::temp_dir().join(format!("limber-bench-state-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (_, ids, v, text) = run_only("state", &dir.join("state.json"), None);
    for id in [
        "state.paced.futex.oneway",
        "state.paced.event.oneway",
        "state.1.oneway",
        "state.4.oneway",
        "state.16.oneway",
        "state.raw.1.oneway",
        "state.raw.4.oneway",
        "state.raw.16.oneway",
        "state.futex.1.oneway",
        "state.futex.4.oneway",
        "state.futex.16.oneway",
    ] {
        assert!(ids.iter().any(|i| i == id), "{id} missing from {ids:?}");
    }
    let ratios = v["ratios"].as_array().unwrap();
    let goal = |num: &str, den: &str, pct: &str| {
        let r = ratios
            .iter()
            .find(|r| r["num"] == num && r["den"] == den && r["pct"] == pct)
            .unwrap_or_else(|| panic!("no ratio {num} / {den} ({pct}) in {ratios:?}"));
        let at_most = r["goal"]["at_most"].as_f64().expect("a goal");
        let value = r["value"].as_f64().unwrap();
        assert_eq!(r["met"].as_bool().unwrap(), value <= at_most, "{r}");
        at_most
    };
    assert_eq!(
        goal("state.1.oneway", "state.paced.event.oneway", "p50"),
        1.3
    );
    assert_eq!(
        goal("state.1.oneway", "state.paced.event.oneway", "p99"),
        2.0
    );
    assert_eq!(goal("state.16.oneway", "state.1.oneway", "p50"), 2.0);
    // The fan-out's goal carries its floor: the kernel's own 16 / 1 of the same run (one
    // futex wake of 16 waiters: limber's state waiters sleep on a futex), and the text says
    // the goal is below it exactly when that ratio alone exceeds the goal.
    let find = |num: &str, den: &str| {
        ratios
            .iter()
            .find(|r| r["num"] == num && r["den"] == den && r["pct"] == "p50")
            .unwrap_or_else(|| panic!("no ratio {num} / {den} in {ratios:?}"))
    };
    let raw = find("state.futex.16.oneway", "state.futex.1.oneway")["value"]
        .as_f64()
        .unwrap();
    let fan = find("state.16.oneway", "state.1.oneway");
    assert_eq!(fan["floor"][0].as_f64(), Some(raw), "{fan}");
    assert!(
        fan["floor"][1]
            .as_str()
            .unwrap()
            .contains("futex broadcast")
    );
    // Raw iceoryx2's own fan-out stays beside it.
    find("state.raw.16.oneway", "state.raw.1.oneway");
    let line = text
        .lines()
        .find(|l| l.contains("state → 16 subscribers / state → 1 subscriber"))
        .unwrap_or_else(|| panic!("no fan-out ratio line in {text}"));
    assert_eq!(
        line.contains("the goal is below its floor"),
        raw > 2.0,
        "{line}"
    );
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only command`: the spinning pair back to back and at a control loop's rate (1 kHz)
/// beside raw iceoryx2 in the command path's shape at that rate, both measured in alternate
/// turns and each merged into one series; the paced goals are stated against that floor.
#[test]
fn command_measures_the_spinning_pair_at_1_khz_beside_its_floor_in_turns() {
    let dir = std::env::temp_dir().join(format!("limber-bench-command-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (_, ids, v, _) = run_only("command", &dir.join("command.json"), None);
    let ms = v["measurements"].as_array().unwrap();
    for id in [
        "command.spin.oneway",
        "command.paced.spin.rtt",
        "command.paced.spin.oneway",
        "command.paced.spin.back",
        "command.paced.spin2.rtt",
        "command.paced.spin2.oneway",
        "command.paced.spin2.back",
    ] {
        // One series of every turn's samples (a turn has at least 10; there are 3).
        assert_eq!(
            ids.iter().filter(|i| *i == id).count(),
            1,
            "{id} in {ids:?}"
        );
        let m = ms.iter().find(|m| m["id"] == id).unwrap();
        if id.contains("paced") {
            assert!(m["summary"]["count"].as_u64().unwrap() >= 30, "{m}");
            assert!(m["label"].as_str().unwrap().ends_with(", 1 kHz"), "{m}");
        }
    }
    let ratios = v["ratios"].as_array().unwrap();
    for (num, den, pct, at_most) in [
        (
            "command.paced.spin.oneway",
            "command.paced.spin2.oneway",
            "p50",
            1.5,
        ),
        (
            "command.paced.spin.oneway",
            "command.paced.spin2.oneway",
            "p99",
            2.0,
        ),
        (
            "command.paced.spin.rtt",
            "command.paced.spin2.rtt",
            "p50",
            1.2,
        ),
    ] {
        let r = ratios
            .iter()
            .find(|r| r["num"] == num && r["den"] == den && r["pct"] == pct)
            .unwrap_or_else(|| panic!("no ratio {num} / {den} ({pct}) in {ratios:?}"));
        assert_eq!(r["goal"]["at_most"].as_f64(), Some(at_most), "{r}");
        let value = r["value"].as_f64().unwrap();
        assert_eq!(r["met"].as_bool().unwrap(), value <= at_most, "{r}");
    }
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--results DIR`: the run as `DIR/latest.md` (the machine, the exact command, the table,
/// the goals missed) and `DIR/latest.json`.
#[test]
fn results_writes_the_run_with_its_machine_and_command() {
    let dir = std::env::temp_dir().join(format!("limber-bench-results-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = limber_bounded_run::output_within(
        Command::new(env!("CARGO_BIN_EXE_limber-bench"))
            .args(["--quick", "--scale", "0.1", "--no-progress", "--only", "ik"])
            .arg("--results")
            .arg(&dir),
        Duration::from_secs(300),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let md = std::fs::read_to_string(dir.join("latest.md")).unwrap();
    for part in [
        "| CPU |",
        "| cores | ",
        "| kernel |",
        "| load average",
        "| build |",
    ] {
        assert!(md.contains(part), "{part} missing from {md}");
    }
    assert!(
        md.contains("--quick --scale 0.1 --no-progress --only ik --results"),
        "{md}"
    );
    assert!(md.contains("numeric IK, 6 joints, pose (p50)"), "{md}");
    assert!(
        md.contains("Goals **not met** in this run")
            || md.contains("Every goal of this run was met"),
        "{md}"
    );
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("latest.json")).unwrap()).unwrap();
    assert_eq!(v["scenarios"][0]["name"], "ik");
    // A directory that does not exist is refused before the run.
    let out = limber_bounded_run::output_within(
        Command::new(env!("CARGO_BIN_EXE_limber-bench"))
            .args(["--quick", "--only", "ik", "--results"])
            .arg(dir.join("missing")),
        Duration::from_secs(60),
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--results"));
    assert!(out.stdout.is_empty());
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only many` (quick: 1 simarm, 1 emulated Pioneer, then 4 drivers of both kinds; 16
/// clients): listing the domain, a command's round trip to simarm and its floor beside the
/// same drivers, each kind's loop period and the floor's, for each pass; the goals at 16
/// drivers are not in a quick run; the memory per driver of each kind and per client in
/// the notes.
#[test]
fn many_measures_listing_round_trips_loop_periods_and_memory_per_number_of_drivers() {
    let dir = std::env::temp_dir().join(format!("limber-bench-many-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (s, ids, _, _) = run_only("many", &dir.join("many.json"), None);
    let mut want = Vec::new();
    for tag in ["1", "1p", "4"] {
        want.push(format!("many.{tag}.list"));
        want.push(format!("many.{tag}.list.raw"));
        want.push(format!("many.{tag}.ticker.period"));
        for what in ["rtt", "oneway", "back"] {
            want.push(format!("many.{tag}.paced.event.{what}"));
        }
    }
    for tag in ["1", "4"] {
        want.push(format!("many.{tag}.rtt"));
        want.push(format!("many.{tag}.simarm.period"));
    }
    for tag in ["1p", "4"] {
        want.push(format!("many.{tag}.pioneer.period"));
    }
    for id in &want {
        assert!(ids.contains(id), "{id} missing from {ids:?}");
    }
    // Nothing else: no round trip through the Pioneer alone, no simarm there.
    assert_eq!(ids.len(), want.len(), "{ids:?}");
    let detail = s["detail"].as_str().unwrap();
    for pass in [
        "1 driver (simarm), 16 clients: per simarm RSS ",
        "1 driver (an emulated Pioneer), 16 clients: per emulated Pioneer RSS ",
        "4 drivers, 16 clients: per simarm RSS ",
    ] {
        assert!(detail.contains(pass), "{pass} missing: {detail}");
    }
    assert!(detail.contains("per emulated Pioneer RSS "), "{detail}");
    assert!(detail.contains("per client "), "{detail}");
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// `--only cpu`: the driver's and the client's CPU per second, idle and at 1 kHz of
/// commands, for each mode that runs here, beside the round trip at that load; the idle
/// event-driven driver carries its goal.
#[test]
fn cpu_reports_what_each_mode_costs_beside_its_latency() {
    let dir = std::env::temp_dir().join(format!("limber-bench-cpu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (_, ids, v, _) = run_only("cpu", &dir.join("cpu.json"), None);
    let cpu = v["cpu"].as_array().unwrap();
    for mode in ["event", "linger"] {
        assert!(ids.contains(&format!("cpu.{mode}.rtt")), "{ids:?}");
        for load in ["idle", "1khz"] {
            for process in ["driver", "client"] {
                let id = format!("cpu.{mode}.{load}.{process}");
                let c = cpu
                    .iter()
                    .find(|c| c["id"] == id.as_str())
                    .unwrap_or_else(|| panic!("{id} missing from {cpu:?}"));
                assert!(c["percent"].as_f64().unwrap() >= 0.0, "{c}");
                assert!(c["window_s"].as_f64().unwrap() > 0.0, "{c}");
                if load == "1khz" {
                    assert_eq!(c["latency_id"], format!("cpu.{mode}.rtt"), "{c}");
                }
            }
        }
    }
    let idle = cpu
        .iter()
        .find(|c| c["id"] == "cpu.event.idle.driver")
        .unwrap();
    assert_eq!(idle["at_most_percent"], 1.0);
    std::fs::remove_dir_all(&dir).expect("remove the test's directory");
}

/// What a `--quick --scale 0.2 --only <scenario>` run gave: its one scenario's status
/// entry, the ids of its measurements (each checked to have samples), the whole report,
/// and what it printed (stdout, then stderr). `env`, if given, is set for the run.
fn run_only(
    scenario: &str,
    json: &std::path::Path,
    env: Option<(&str, &str)>,
) -> (Value, Vec<String>, Value, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_limber-bench"));
    cmd.args([
        "--quick",
        "--scale",
        "0.2",
        "--no-progress",
        "--only",
        scenario,
    ])
    .arg("--json")
    .arg(json);
    if let Some((k, v)) = env {
        cmd.env(k, v);
    }
    let out = limber_bounded_run::output_within(cmd, Duration::from_secs(300));
    assert!(
        out.status.success(),
        "limber-bench failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let s = v["scenarios"][0].clone();
    assert_eq!(s["name"], scenario);
    assert_eq!(s["status"], "ok", "{s}");
    let ids: Vec<String> = v["measurements"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            assert!(m["summary"]["count"].as_u64().unwrap() > 0, "{m}");
            m["id"].as_str().unwrap().to_string()
        })
        .collect();
    // What it printed: the table (stdout), then its notes (stderr).
    let printed = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (s, ids, v, printed)
}
