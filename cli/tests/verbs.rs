//! Every device verb of `limber` against a running driver, with its exit codes.

use limber_services::Domain;

mod common;
use common::{driver, limber, stderr, stdout};

#[test]
fn actarray_verbs() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let dom = d.name();
    let ok = |args: &[&str]| {
        let o = limber(dom, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        stdout(&o)
    };
    assert!(ok(&["actarray", "cli/actarray/0", "pos", "2", "0.5"]).contains("ok"));
    assert!(ok(&["actarray", "cli/actarray/0", "pos", "2", "-0.5"]).contains("ok"));
    assert!(
        ok(&[
            "actarray",
            "cli/actarray/0",
            "multipos",
            "0.1",
            "0.2",
            "-0.3"
        ])
        .contains("ok")
    );
    assert!(ok(&["actarray", "cli/actarray/0", "home"]).contains("ok"));
    assert!(ok(&["actarray", "cli/actarray/0", "home", "3"]).contains("ok"));
    assert!(ok(&["actarray", "cli/actarray/0", "power", "on"]).contains("ok"));
    assert!(ok(&["actarray", "cli/actarray/0", "speedcfg", "1", "0.5"]).contains("ok"));
    // Issue "Nobody moves the arm who may not", item 8: beyond the joint's limit, clamped and
    // said so.
    let out = ok(&["actarray", "cli/actarray/0", "speedcfg", "1", "1e308"]);
    assert!(out.contains("ok") && out.contains("clamped"), "{out}");
    assert!(ok(&["actarray", "cli/actarray/0", "pos", "1", "0.2", "--no-wait"]).contains("sent"));
    let geom = ok(&["actarray", "cli/actarray/0", "geom"]);
    assert_eq!(
        geom.lines().filter(|l| l.contains("rotary")).count(),
        6,
        "{geom}"
    );
    // Refusals: exit 5 with the reason.
    let o = limber(dom, &["actarray", "cli/actarray/0", "pos", "9", "0.1"]);
    assert_eq!(o.status.code(), Some(5));
    assert!(stderr(&o).contains("unknown joint"), "{}", stderr(&o));
    let o = limber(dom, &["actarray", "cli/actarray/0", "pos", "1", "7"]);
    assert_eq!(o.status.code(), Some(5));
    assert!(stderr(&o).contains("beyond the joint limits"));
    let o = limber(dom, &["actarray", "cli/actarray/0", "brakes", "on"]);
    assert_eq!(o.status.code(), Some(5));
    assert!(stderr(&o).contains("unsupported"));
    let o = limber(
        dom,
        &["actarray", "cli/actarray/0", "current", "all", "0.1"],
    );
    assert_eq!(o.status.code(), Some(5));
    // Bad input never reaches the driver.
    let o = limber(dom, &["actarray", "cli/actarray/0", "pos", "1", "nan"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not finite"), "{}", stderr(&o));
    let o = limber(dom, &["actarray", "cli/actarray/0", "pos", "x", "1"]);
    assert_eq!(o.status.code(), Some(2));
    // No driver: exit 3.
    let o = limber(dom, &["actarray", "nobody/actarray/0", "pos", "1", "0.1"]);
    assert_eq!(o.status.code(), Some(3));
    assert!(stderr(&o).contains("no driver offers nobody/actarray/0"));
    let o = limber(dom, &["actarray", "cli/arm/0", "pos", "1", "0.1"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn limb_and_gripper_verbs() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let dom = d.name();
    let o = limber(
        dom,
        &[
            "limb",
            "cli/limb/0",
            "setpose",
            "0.3",
            "0",
            "0.2",
            "--approach",
            "0",
            "0",
            "-1",
            "--orient",
            "1",
            "0",
            "0",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(
        dom,
        &["limb", "cli/limb/0", "setposition", "0.3", "0.1", "-0.2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(
        dom,
        &["limb", "cli/limb/0", "vecmove", "0", "0", "1", "0.05"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(dom, &["limb", "cli/limb/0", "setpose", "2", "0", "0"]);
    assert_eq!(o.status.code(), Some(5));
    assert!(stderr(&o).contains("out of reach"));
    for v in [
        &["home"][..],
        &["stop"],
        &["power", "off"],
        &["speed", "0.1"],
        &["geom"],
    ] {
        let mut args = vec!["limb", "cli/limb/0"];
        args.extend_from_slice(v);
        let o = limber(dom, &args);
        assert!(o.status.success(), "{v:?}: {}", stderr(&o));
    }
    let o = limber(dom, &["limb", "cli/limb/0", "setpose", "0.3", "0"]);
    assert_eq!(o.status.code(), Some(2));
    for v in ["open", "close", "stop", "geom"] {
        let o = limber(dom, &["gripper", "cli/gripper/0", v]);
        assert!(o.status.success(), "{v}: {}", stderr(&o));
    }
    let o = limber(dom, &["gripper", "cli/gripper/0", "store"]);
    assert_eq!(o.status.code(), Some(5));
}

#[test]
fn echo_prints_states_as_text_and_json() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let dom = d.name();
    let o = limber(dom, &["echo", "cli/actarray/0", "--count", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert_eq!(text.lines().count(), 3);
    assert!(text.contains("j5"), "{text}");
    let o = limber(dom, &["echo", "cli/limb/0", "--json", "--count", "2"]);
    assert!(o.status.success());
    for line in stdout(&o).lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert_eq!(v["device"], "cli/limb/0");
        assert!(v["header"]["seq"].as_u64().unwrap() > 0);
        assert_eq!(v["state_name"], "idle");
        assert!(v["position"]["x"].is_f64(), "a limber_vec3: {v}");
    }
    let o = limber(dom, &["echo", "cli/gripper/0", "--json", "--count", "1"]);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(v["state_name"], "open");
    assert_eq!(
        v["state"],
        limber_services::prelude::GripperState::Open as u32,
        "the code, as in limber_gripper_data"
    );
    let o = limber(dom, &["echo", "nobody/gripper/0", "--count", "1"]);
    assert_eq!(o.status.code(), Some(3));
}
