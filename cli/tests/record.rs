//! `limber record` and `limber replay` against the emulated Pioneer (issue 30): the file
//! opens with an independent MCAP reader (the Python `mcap` package) whose counts and
//! decoded messages agree with the driver's sequence numbers, and a replayed file drives
//! `limber echo` and a Rust client with the recorded states.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::{Bg, limber, output, pioneer_emulated, stderr, stdout};
use limber_interfaces::Describe;
use limber_interfaces::prelude::*;
use limber_record::mcap::{McapReader, Record};
use limber_services::{Client, Context, Domain, Role};
use serde_json::Value;
use zerocopy::FromBytes;

/// A Python with the `mcap` package: `LIMBER_PYTHON`, else the venv `.ci/run` makes. In CI
/// (`CI=true`) a missing one fails the test; elsewhere the test is skipped, saying why.
fn python() -> Option<PathBuf> {
    let py = std::env::var_os("LIMBER_PYTHON").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/py-venv/bin/python"),
        PathBuf::from,
    );
    let ok = py.is_file()
        && output(Command::new(&py).args(["-c", "import mcap"]))
            .status
            .success();
    if ok {
        return Some(py);
    }
    let reason = format!("no Python with the mcap package at {py:?} (set LIMBER_PYTHON)");
    assert!(std::env::var("CI").as_deref() != Ok("true"), "{reason}");
    eprintln!("skipped: {reason}");
    None
}

/// A file in a directory of this test under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("record-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{name}.mcap"))
}

/// Waits (at most 30 s) for `p` to exit; its exit code.
fn exit_of(p: &mut Bg) -> Option<i32> {
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        if let Some(s) = p.0.try_wait().unwrap() {
            return s.code();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    panic!("the process did not end within 30 s");
}

/// Records the emulated Pioneer of domain `d` for `seconds`, moving arm joint 0 meanwhile.
fn record_pioneer(d: &Domain, file: &Path, seconds: &str) {
    let mut rec = Bg::spawn(
        d.name(),
        &[
            "record",
            "-o",
            file.to_str().unwrap(),
            "--duration",
            seconds,
        ],
    );
    rec.line(|l| l == "recording pioneer/actarray/0");
    let moved = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.2"],
    );
    assert!(moved.status.success(), "{}", stderr(&moved));
    let done = rec.line(|l| l.starts_with("recorded "));
    assert!(done.ends_with(", 0 dropped, 0 missed"), "{done}");
    assert_eq!(exit_of(&mut rec), Some(0));
}

/// The per-topic message counts `limber record --info` prints.
fn info_counts(d: &Domain, file: &Path) -> BTreeMap<String, u64> {
    let o = limber(d.name(), &["record", "--info", file.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
        .lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            let topic = w.next()?.strip_prefix('/')?;
            let n = w.next()?.parse().ok()?;
            Some((format!("/{topic}"), n))
        })
        .collect()
}

#[test]
fn a_recorded_run_reads_with_the_reference_reader_and_agrees_with_the_driver() {
    let Some(py) = python() else { return };
    let d = Domain::unique_for_test();
    let _pioneer = pioneer_emulated(d.name());
    let file = scratch("pioneer");
    record_pioneer(&d, &file, "3");

    let o = output(
        Command::new(&py)
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/record/check_mcap.py"))
            .arg(&file),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let topics = v["topics"].as_object().unwrap();

    // Python's counts are limber's (--info) and the summary's.
    let counts = info_counts(&d, &file);
    let total: u64 = counts.values().sum();
    assert_eq!(v["message_count"].as_u64(), Some(total));
    for (topic, n) in &counts {
        let py_n = topics
            .get(topic)
            .map_or(0, |t| t["count"].as_u64().unwrap());
        assert_eq!(py_n, *n, "{topic}");
    }

    // Every state the driver published while recording is in the file: the sequence
    // numbers, decoded from the schema alone, have no gap.
    for device in [
        "pioneer/actarray/0",
        "pioneer/actarray/1",
        "pioneer/limb/0",
        "pioneer/gripper/0",
        "pioneer/gripper/1",
    ] {
        let t = &topics[&format!("/{device}/state")];
        let seqs: Vec<u64> = t["seqs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_u64().unwrap())
            .collect();
        assert!(seqs.len() >= 10, "{device}: {seqs:?}");
        assert_eq!(t["count"].as_u64(), Some(seqs.len() as u64));
        assert!(
            seqs.windows(2).all(|w| w[1] == w[0] + 1),
            "{device}: a gap in {seqs:?}"
        );
        let version = limber_interfaces::LAYOUT_VERSION;
        assert_eq!(
            t["schema"],
            format!("limber.v{version}.{}", schema_of(device))
        );
    }

    // Foxglove's joint states carry the same positions as the limber states.
    let arm = &topics["/pioneer/actarray/0/state"]["decoded"];
    let joints = &topics["/pioneer/actarray/0/joint_states"]["decoded"];
    assert_eq!(
        joints.as_array().unwrap().len(),
        arm.as_array().unwrap().len()
    );
    for (j, a) in joints
        .as_array()
        .unwrap()
        .iter()
        .zip(arm.as_array().unwrap())
    {
        let from_json: Vec<f64> = j["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j["position"].as_f64().unwrap())
            .collect();
        let from_wire: Vec<f64> = a
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p.as_f64().unwrap())
            .collect();
        assert_eq!(from_json, from_wire);
    }
    // The arm moved joint 0 to 0.2 rad while recording: its last state says so...
    let last = arm.as_array().unwrap().last().unwrap()[0].as_f64().unwrap();
    assert!((last - 0.2).abs() < 0.05, "joint 0 at {last}");
    // ...and the command's outcome (OK) is recorded.
    let outcomes = &topics["/pioneer/actarray/0/outcome"]["decoded"];
    assert!(
        outcomes.as_array().unwrap().iter().any(|s| s == 0),
        "{outcomes}"
    );
    // The driver's statistics, decoded: the driver's name.
    let stats = &topics["/pioneer/driver"]["decoded"];
    assert!(
        stats.as_array().unwrap().iter().all(|s| s == "pioneer"),
        "{stats}"
    );
    assert!(!stats.as_array().unwrap().is_empty());
}

fn schema_of(device: &str) -> &'static str {
    match device.split('/').nth(1) {
        Some("actarray") => "ActArrayData",
        Some("limb") => "LimbData",
        _ => "GripperData",
    }
}

/// The recorded states of `topic`, in order, read with limber's reader.
fn recorded_states(file: &Path, topic: &str) -> Vec<ActArrayData> {
    let mut r = McapReader::new(std::fs::File::open(file).unwrap()).unwrap();
    let mut channel = None;
    let mut out = Vec::new();
    while let Some(rec) = r.next_record().unwrap() {
        match rec {
            Record::Channel(c) if c.topic == topic => channel = Some(c.id),
            Record::Message {
                channel: c, data, ..
            } if Some(c) == channel => {
                out.push(ActArrayData::read_from_bytes(&data).unwrap());
            }
            _ => {}
        }
    }
    out
}

/// A state's JSON as `limber echo --json` prints it and this test reads it back (serde_json's
/// parsing of a printed float may differ from the float in its last bit).
fn as_printed(v: Value) -> Value {
    serde_json::from_str(&v.to_string()).unwrap()
}

/// A state's JSON without its stamp (a replay stamps states when it publishes them).
fn unstamped(mut v: Value) -> Value {
    v["header"]["stamp_ns"] = Value::Null;
    if let Some(o) = v.as_object_mut() {
        o.remove("device");
    }
    v
}

#[test]
fn a_replayed_run_drives_echo_and_a_client_with_the_recorded_states() {
    let d = Domain::unique_for_test();
    let file = scratch("replay");
    let _pioneer = pioneer_emulated(d.name());
    record_pioneer(&d, &file, "2");
    let recorded = recorded_states(&file, "/pioneer/actarray/0/state");
    assert!(recorded.len() >= 5, "{} states", recorded.len());
    let index_of = |seq: u64| {
        recorded
            .iter()
            .position(|s| s.header.seq == seq)
            .unwrap_or_else(|| panic!("seq {seq} was never recorded"))
    };

    // Replayed into a domain of its own, looping, so that clients that come late still
    // see whole passes.
    let r = Domain::unique_for_test();
    let mut replay = Bg::spawn(
        r.name(),
        &["replay", file.to_str().unwrap(), "--loop", "--rate", "2"],
    );
    replay.line(|l| l == "hosting pioneer/actarray/0");

    // A Rust client takes every state: a whole pass, in order, equal to the recording.
    let ctx = Context::new(&r, Role::Client, "replay-test").unwrap();
    let mut c =
        Client::<ActArray>::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(10))
            .unwrap();
    let wake = c.relay_listener().unwrap();
    let mut seen: Vec<ActArrayData> = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(60);
    // From the first recorded state on (the next pass), one full pass.
    let mut started = false;
    while seen.len() < recorded.len() {
        assert!(Instant::now() < deadline, "no full pass within 60 s");
        wake.timed_wait(|_| {}, Duration::from_millis(100)).unwrap();
        c.relay_states(|s| {
            started |= s.header.seq == recorded[0].header.seq;
            if started {
                seen.push(*s);
            }
        })
        .unwrap();
    }
    for (s, want) in seen.iter().zip(&recorded) {
        assert_eq!(s.header.seq, want.header.seq);
        assert_eq!(unstamped(s.json()), unstamped(want.json()));
    }

    // `limber echo --json` prints recorded states, in the recorded order.
    let o = limber(
        r.name(),
        &["echo", "pioneer/actarray/0", "--json", "--count", "8"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut last: Option<usize> = None;
    let mut wrapped = false;
    for line in stdout(&o).lines() {
        let v: Value = serde_json::from_str(line).unwrap();
        let i = index_of(v["header"]["seq"].as_u64().unwrap());
        assert_eq!(
            unstamped(v.clone()),
            unstamped(as_printed(recorded[i].json()))
        );
        if let Some(l) = last
            && i <= l
        {
            assert!(!wrapped, "out of the recorded order: {i} after {l}");
            wrapped = true;
        }
        last = Some(i);
    }
    assert_eq!(stdout(&o).lines().count(), 8);
    // `limber list`, the recorded geometry and the monitor see the replayed device as live.
    let o = limber(r.name(), &["list"]);
    assert!(stdout(&o).contains("pioneer/actarray/0"), "{}", stdout(&o));
    let live = limber(d.name(), &["actarray", "pioneer/actarray/0", "geom"]);
    let replayed = limber(r.name(), &["actarray", "pioneer/actarray/0", "geom"]);
    assert!(replayed.status.success(), "{}", stderr(&replayed));
    assert_eq!(stdout(&replayed), stdout(&live));
    let o = limber(r.name(), &["monitor", "--once"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("pioneer/actarray/0"), "{}", stdout(&o));
    // Commands are refused at once: nothing moves in a recording.
    let o = limber(
        r.name(),
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.5"],
    );
    assert_eq!(o.status.code(), Some(5), "{}{}", stdout(&o), stderr(&o));
    assert!(stderr(&o).contains("unsupported"), "{}", stderr(&o));
    assert_eq!(replay.term(), Some(0));
}

#[test]
fn a_split_recording_is_a_series_of_whole_files_without_a_gap_between_them() {
    let Some(py) = python() else { return };
    let d = Domain::unique_for_test();
    let _pioneer = pioneer_emulated(d.name());
    let base = scratch("split");
    let mut rec = Bg::spawn(
        d.name(),
        &[
            "record",
            "pioneer/actarray/0",
            "-o",
            base.to_str().unwrap(),
            "--duration",
            "3.5",
            "--split-time",
            "1",
        ],
    );
    let done = rec.line(|l| l.starts_with("recorded "));
    assert!(done.ends_with(", 0 dropped, 0 missed"), "{done}");
    assert_eq!(exit_of(&mut rec), Some(0));
    assert!(!base.exists(), "a series has no file of the name given");
    let mut seqs = Vec::new();
    let mut files = 0;
    for i in 0.. {
        let file = limber_record::files::series_path(&base, i);
        if !file.exists() {
            break;
        }
        files += 1;
        let o = output(
            Command::new(&py)
                .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/record/check_mcap.py"))
                .arg(&file),
        );
        assert!(o.status.success(), "{}: {}", file.display(), stderr(&o));
        let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
        // Each file is whole: its channels declared again, its geometry only in the first.
        let t = &v["topics"]["/pioneer/actarray/0/state"];
        seqs.extend(
            t["seqs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_u64().unwrap()),
        );
    }
    assert!((3..=5).contains(&files), "{files} files");
    assert!(seqs.len() >= 10, "{seqs:?}");
    assert!(
        seqs.windows(2).all(|w| w[1] == w[0] + 1),
        "a gap between the files: {seqs:?}"
    );
}
