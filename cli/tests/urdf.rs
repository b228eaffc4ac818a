//! URDF in and out (issue 30 item 4): `limber simarm --urdf FILE` simulates the arm of a
//! URDF the test writes and reaches a pose with its numeric IK; a malformed URDF is refused
//! with a clear error; `limber layout --urdf DEVICE` prints the URDF limber uses.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::{Bg, limber, output, stderr, stdout};
use limber_services::Domain;
use serde_json::Value;

/// A 6-joint arm with a spherical wrist, a fixed base offset and flange, and a hand with two
/// prismatic fingers (a branch: the chain ends at the hand).
const ARM: &str = r#"<?xml version="1.0"?>
<robot name="testarm">
  <link name="world"/>
  <link name="base"/>
  <link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/>
  <link name="l6"/>
  <link name="hand"/>
  <link name="finger_left"/><link name="finger_right"/>
  <joint name="mount" type="fixed">
    <parent link="world"/><child link="base"/><origin xyz="0 0 0.1" rpy="0 0 0"/>
  </joint>
  <joint name="waist" type="revolute">
    <parent link="base"/><child link="l1"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="shoulder" type="revolute">
    <parent link="l1"/><child link="l2"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="l2"/><child link="l3"/><origin xyz="0 0 0.4"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="wrist_roll" type="revolute">
    <parent link="l3"/><child link="l4"/><origin xyz="0 0 0.35"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="wrist_pitch" type="revolute">
    <parent link="l4"/><child link="l5"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="wrist_yaw" type="revolute">
    <parent link="l5"/><child link="l6"/><origin xyz="0 0 0.08"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="l6"/><child link="hand"/><origin xyz="0 0 0.05" rpy="0 1.5707963267948966 0"/>
  </joint>
  <joint name="left" type="prismatic">
    <parent link="hand"/><child link="finger_left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" velocity="0.1" effort="10"/>
  </joint>
  <joint name="right" type="prismatic">
    <parent link="hand"/><child link="finger_right"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" velocity="0.1" effort="10"/>
  </joint>
</robot>
"#;

fn write(name: &str, text: &str) -> String {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("urdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Simulates the arm of URDF `file` and moves its limb to the pose its forward kinematics
/// gives for `q` (a configuration within its limits): the numeric IK finds it.
fn reaches_a_pose(file: &str, q: &[f64]) {
    let d = Domain::unique_for_test();
    let chain = limber_record::urdf_in::chain_from_urdf_file(Path::new(file)).unwrap();
    assert_eq!(chain.dof(), q.len());
    let pose = chain.fk(q).unwrap();
    let (p, a, o) = (pose.position, pose.approach(), pose.orientation());

    let mut sim = Bg::spawn(d.name(), &["simarm", "--urdf", file, "--time-scale", "4"]);
    sim.line(|l| l.ends_with("ready"));
    let n = |v: f64| format!("{v:.6}");
    let args: Vec<String> = ["limb", "simarm/limb/0", "setpose"]
        .into_iter()
        .map(String::from)
        .chain([p.x, p.y, p.z].map(n))
        .chain(["--approach".to_string()])
        .chain([a.x, a.y, a.z].map(n))
        .chain(["--orient".to_string()])
        .chain([o.x, o.y, o.z].map(n))
        .collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = limber(d.name(), &args);
    assert!(out.status.success(), "{}{}", stdout(&out), stderr(&out));

    // The limb gets there.
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let o = limber(
            d.name(),
            &["echo", "simarm/limb/0", "--json", "--count", "1"],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let v: Value = serde_json::from_str(stdout(&o).lines().next().unwrap()).unwrap();
        let at = &v["position"];
        let err = ((at["x"].as_f64().unwrap() - p.x).powi(2)
            + (at["y"].as_f64().unwrap() - p.y).powi(2)
            + (at["z"].as_f64().unwrap() - p.z).powi(2))
        .sqrt();
        if err < 1e-3 && v["state_name"] == "idle" {
            break;
        }
        assert!(Instant::now() < deadline, "the limb is {err} m away: {v}");
    }
    assert_eq!(sim.term(), Some(0));
}

#[test]
fn simarm_simulates_a_urdf_arm_and_reaches_a_pose_with_its_ik() {
    let file = write("testarm.urdf", ARM);
    reaches_a_pose(&file, &[0.3, 0.5, 0.7, 0.2, 0.6, 0.1]);
}

/// The Panda of the PyPI package example-robot-data (which `.ci/run` installs in its venv,
/// `LIMBER_PYTHON`): a real arm's URDF, 7 joints, fixed joints and a two-finger hand.
#[test]
fn simarm_simulates_the_panda_of_a_urdf_package() {
    let py = std::env::var_os("LIMBER_PYTHON").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/py-venv/bin/python"),
        PathBuf::from,
    );
    let found = output(Command::new(&py).args([
        "-c",
        "import importlib.metadata as m; print([str(f.locate()) for f in m.files('example-robot-data') if str(f).endswith('panda_description/urdf/panda.urdf')][0])",
    ]));
    if !found.status.success() {
        let reason = format!("no example-robot-data in {py:?}: {}", stderr(&found));
        assert!(std::env::var("CI").as_deref() != Ok("true"), "{reason}");
        eprintln!("skipped: {reason}");
        return;
    }
    let file = stdout(&found).trim().to_string();
    reaches_a_pose(&file, &[0.2, -0.3, 0.1, -1.8, 0.2, 1.6, 0.5]);
}

#[test]
fn a_malformed_urdf_is_refused_with_a_clear_error() {
    let d = Domain::unique_for_test();
    for (name, text, says) in [
        ("cut.urdf", &ARM[..ARM.len() / 2], "not well-formed XML"),
        (
            "floating.urdf",
            "<robot name='r'><link name='a'/><link name='b'/><joint name='free' type='floating'><parent link='a'/><child link='b'/></joint></robot>",
            "joint \"free\": type \"floating\" is not supported",
        ),
        (
            "nolimit.urdf",
            "<robot name='r'><link name='a'/><link name='b'/><joint name='j1' type='revolute'><parent link='a'/><child link='b'/></joint></robot>",
            "needs <limit lower upper>",
        ),
    ] {
        let file = write(name, text);
        let o = limber(d.name(), &["simarm", "--urdf", &file]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(name), "{name}: {}", stderr(&o));
    }
    let o = limber(d.name(), &["simarm", "--urdf", "/nonexistent/arm.urdf"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cannot read"), "{}", stderr(&o));
}

#[test]
fn layout_prints_the_urdf_limber_uses_and_simarm_runs_it() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["layout", "--urdf", "pioneer/actarray/0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let urdf = stdout(&o);
    assert!(urdf.starts_with("<?xml"), "{urdf}");
    assert_eq!(urdf.matches("type=\"revolute\"").count(), 5);
    // What limber writes, limber reads: the Pioneer arm's chain as a simulated arm.
    let file = write("pioneer.urdf", &urdf);
    let mut sim = Bg::spawn(d.name(), &["simarm", "--urdf", &file]);
    sim.line(|l| l.ends_with("ready"));
    assert_eq!(sim.term(), Some(0));
    let o = limber(d.name(), &["layout", "--urdf", "pioneer/gripper/0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("no URDF for pioneer/gripper/0"),
        "{}",
        stderr(&o)
    );
}
