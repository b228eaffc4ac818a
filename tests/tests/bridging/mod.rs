//! What the bridge tests share (`bridge.rs`, `bridge_access.rs`): the driver, a mirrored
//! arm, a free port, user/password configurations.
#![allow(dead_code)] // each test file uses a part of it

use std::time::Duration;

use limber_services::prelude::*;
use limber_tests::{Proc, usrpwd_config};

/// The CLI under test.
pub const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");

/// A TCP port on loopback that was free a moment ago.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free loopback port")
}

/// `limber pioneer --emulated` in `a`, ready.
pub fn start_driver(a: &Domain) -> Proc {
    let mut d = Proc::spawn(CLI, a.name(), &["pioneer", "--emulated"]);
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "the driver did not start"
    );
    d
}

/// Waits (bounded) until mirror `m` hosts the arm.
pub fn wait_mirrored(m: &mut Proc) {
    assert!(
        m.read_until(|l| l == "mirrored pioneer/actarray/0 as pioneer/actarray/0")
            .is_some(),
        "mirror did not host the arm"
    );
}

/// The mirrored arm, from a client in `b`.
pub fn arm_in(b: &Domain) -> ActArrayClient {
    let ctx = Context::new(b, Role::Client, "bridge-test").expect("join domain B");
    ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(10))
        .expect("the mirrored arm")
}

/// A scratch directory with Zenoh user/password configurations: the robot's (user `robot`,
/// with the dictionary), the operator's with the right password, and one with a wrong one.
pub fn usrpwd_configs(name: &str) -> (std::path::PathBuf, String, String, String) {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("bridge-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    let users = dir.join("users.txt");
    std::fs::write(&users, "robot:a long secret\n").expect("write the users");
    let robot = usrpwd_config(&dir, "robot.json5", "robot", "a long secret", Some(&users));
    let good = usrpwd_config(&dir, "good.json5", "robot", "a long secret", None);
    let bad = usrpwd_config(&dir, "bad.json5", "robot", "a guess", None);
    (dir, robot, good, bad)
}

/// `bridge expose ARGS` in `a`, once it exposed the arm.
pub fn expose_with(a: &Domain, args: &[&str]) -> Proc {
    let mut e = Proc::spawn(CLI, a.name(), &[&["bridge", "expose"], args].concat());
    assert!(
        e.read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some(),
        "expose did not expose the arm"
    );
    e
}

/// `bridge mirror ARGS` in `b`, once it started (it may mirror nothing: see
/// [`mirrored_nothing`]).
pub fn mirror_with(b: &Domain, args: &[&str]) -> Proc {
    let mut m = Proc::spawn(CLI, b.name(), &[&["bridge", "mirror"], args].concat());
    assert!(
        m.read_until(|l| l.starts_with("mirroring into")).is_some(),
        "the mirror did not start"
    );
    m
}

/// Ends mirror `m` (SIGTERM) and checks it mirrored nothing in its whole life.
pub fn mirrored_nothing(mut m: Proc) {
    m.signal(libc::SIGTERM);
    m.wait_timeout(Duration::from_secs(30));
    let rest = m.rest_of_stdout();
    assert!(!rest.contains("mirrored"), "{rest}");
}
