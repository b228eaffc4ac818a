//! The simulated world from the command line (drivers/world/README.md, as written): a world
//! file, the laser's geometry and scans through `limber ranger`, `limber echo` and the
//! monitor, and the world's flags refused when they are wrong.

use limber_services::Domain;

mod common;
use common::{Bg, limber, stderr, stdout};

const TABLE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../drivers/world/examples/table.toml"
);

/// The closest range of `limber ranger ... scan`'s last line: `... closest R m at B deg`.
fn closest(out: &str) -> (f64, f64) {
    let last = out.lines().last().expect("a summary line");
    let rest = &last[last.find("closest ").expect("the closest range") + 8..];
    let v: Vec<&str> = rest.split(' ').collect();
    (v[0].parse().unwrap(), v[3].parse().unwrap())
}

#[test]
fn a_world_file_is_scanned_by_the_laser_as_the_readme_says() {
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(
        d.name(),
        &["simarm", "--world", TABLE, "--laser-noise", "0"],
    );
    let ready = sim.line(|l| l.ends_with("ready"));
    assert!(
        ready.contains("simarm/ranger/0 (laser; 2 blocks at (0.400, 0.080), (0.900, -0.300))"),
        "{ready}"
    );
    let o = limber(d.name(), &["ranger", "simarm/ranger/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stdout(&o).trim_end(),
        "pose (0.1600, 0.0000, 0.2000) m yaw 0.00 deg; size 0.155 x 0.156 x 0.185 m; 181 ranges over -90.0..+90.0 deg every 1.00 deg; range 0.000 to 8.000 m (resolution 0.001 m); 10.0 Hz"
    );
    let o = limber(d.name(), &["ranger", "simarm/ranger/0", "scan"]);
    let out = stdout(&o);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(out.lines().count(), 182, "{out}");
    // The block at (0.40, 0.08): 0.2332 m to its centre from the laser, minus its radius.
    let (r, deg) = closest(&out);
    assert!((r - ((0.24f64).hypot(0.08) - 0.02)).abs() < 0.002, "{out}");
    assert!((deg - 18.0).abs() <= 1.0, "{out}");
    // Straight ahead, the wall 1.5 m ahead (its face at 1.45 m, 1.29 m from the laser).
    assert!(
        out.lines()
            .any(|l| l.starts_with(" 90   +0.00 deg 1.290 m")),
        "{out}"
    );
    let o = limber(d.name(), &["ranger", "simarm/ranger/0", "scan", "--json"]);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("JSON");
    assert_eq!(v["ranges_count"], 181);
    assert_eq!(v["ranges"].as_array().map(Vec::len), Some(181));
    let o = limber(d.name(), &["echo", "simarm/ranger/0", "--count", "1"]);
    assert!(
        stdout(&o).contains("181 ranges over -90.0..+90.0 deg closest"),
        "{}",
        stdout(&o)
    );
    let o = limber(d.name(), &["monitor", "--once"]);
    assert!(
        stdout(&o).contains("simarm/ranger/0 · ranger · world"),
        "{}",
        stdout(&o)
    );
    assert_eq!(sim.term(), Some(0));
}

#[test]
fn a_bad_world_is_a_usage_error_with_the_reason() {
    let d = Domain::unique_for_test();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let bad = dir.join(format!("bad-world-{}.toml", std::process::id()));
    std::fs::write(&bad, "[[block]]\nx = 0.4\ny = 0.1\nsize = -1\n").unwrap();
    let o = limber(d.name(), &["simarm", "--world", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("block 0: coordinates must be finite and sizes > 0"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(&bad).unwrap();
    let o = limber(d.name(), &["simarm", "--world", "/nonexistent/world.toml"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("cannot read the world file"),
        "{}",
        stderr(&o)
    );
    let o = limber(
        d.name(),
        &["ranger", "simarm/ranger/0", "scan", "--timeout", "0.2"],
    );
    assert_eq!(o.status.code(), Some(3), "no driver: {}", stderr(&o));
}

/// Waits (bounded) until the limb shows a command of another client than `before` (the
/// CLI's, a process of its own) and has stopped moving; its state then.
fn settled(
    limb: &mut limber_services::LimbClient,
    before: u64,
) -> limber_interfaces::prelude::LimbData {
    use limber_interfaces::prelude::LimbState;
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    loop {
        let s = *limb
            .wait_state(std::time::Duration::from_secs(5))
            .expect("a state");
        if s.header.last_cmd.client_id != before && s.limb_state() != Ok(LimbState::Moving) {
            return s;
        }
        assert!(std::time::Instant::now() < deadline, "not settled: {s:?}");
    }
}

/// The paper's COLL state on `limber simarm`: a pose below the floor is carried out until
/// the arm meets the floor, where it stops in COLLISION; the next command moves it on.
#[test]
fn simarm_stops_at_the_floor_in_collision_until_the_next_command() {
    use limber_interfaces::prelude::LimbState;
    use limber_services::{Context, LimbClient, Role};
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(d.name(), &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    let ctx = Context::new(&d, Role::Client, "world-test").unwrap();
    let mut limb =
        LimbClient::connect_timeout(&ctx, "simarm/limb/0", std::time::Duration::from_secs(5))
            .unwrap();
    let o = limber(
        d.name(),
        &[
            "limb",
            "simarm/limb/0",
            "setposition",
            "0.45",
            "0.1",
            "-0.1",
        ],
    );
    assert_eq!(stdout(&o).trim(), "ok", "{}", stderr(&o));
    let s = settled(&mut limb, 0);
    assert_eq!(s.limb_state(), Ok(LimbState::Collision), "{s:?}");
    assert!(s.position.z < 0.0 && s.position.z > -0.03, "{s:?}");
    let o = limber(d.name(), &["echo", "simarm/limb/0", "--count", "1"]);
    assert!(stdout(&o).contains(" collision "), "{}", stdout(&o));
    let o = limber(
        d.name(),
        &["limb", "simarm/limb/0", "setposition", "0.45", "0.1", "0.1"],
    );
    assert_eq!(stdout(&o).trim(), "ok", "{}", stderr(&o));
    let s = settled(&mut limb, s.header.last_cmd.client_id);
    assert_eq!(s.limb_state(), Ok(LimbState::Idle), "{s:?}");
    assert!((s.position.z - 0.1).abs() < 0.002, "{s:?}");
    assert_eq!(sim.term(), Some(0));
}
