//! What the tests of C and C++ programs share: the library cargo built, scratch
//! directories, bounded runs, compiling, and the robots the programs run against (the
//! Pioneer driver on the emulator, simarm, each with its world on a thread of this
//! process).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError, mpsc};
use std::thread::JoinHandle;
use std::time::Duration;

use limber_emulator::{Emulator, EmulatorConfig};
use limber_pioneer::{PioneerConfig, PioneerDriver, RunOptions};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_world::{Block, LaserConfig, World, WorldDriver, WorldOptions};

/// How long one program may run before the test fails.
pub const RUN_LIMIT: Duration = Duration::from_secs(120);
pub const T: Duration = Duration::from_secs(5);

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace root")
        .to_path_buf()
}

/// The Pioneer driver on the emulator, on a thread of this process, until dropped.
pub struct Pioneer {
    /// The world (its laser, its blocks), when the test asked for one: dropped first.
    pub world: Option<SimWorld>,
    pub domain: Domain,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    pub emulator: Emulator,
}

impl Pioneer {
    /// Starts the emulator and the driver and sets the fastest joint speeds (so that the
    /// programs' motions take fractions of a second).
    pub fn start() -> Pioneer {
        let domain = Domain::unique_for_test();
        let emulator = Emulator::start_pty(EmulatorConfig::default()).expect("the emulator");
        let target = emulator.link_target();
        let stop = Arc::new(AtomicBool::new(false));
        let (ready_tx, ready_rx) = mpsc::channel();
        let (d, s) = (domain.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let ctx = Context::new(&d, Role::Driver, "pioneer").expect("the driver's context");
            let mut driver = PioneerDriver::start(&ctx, PioneerConfig::default(), target)
                .expect("the driver starts");
            ready_tx.send(()).expect("the test waits");
            let r = driver.run_until(RunOptions::default(), || s.load(Ordering::Relaxed));
            driver.shutdown();
            r.expect("the driver runs");
        });
        ready_rx
            .recv_timeout(Duration::from_secs(30))
            .expect("the driver is ready");
        let ctx = Context::new(&domain, Role::Client, "capi-test").unwrap();
        let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
        for j in 0..6 {
            arm.set_speed_config(j, 20.0).unwrap();
        }
        Pioneer {
            world: None,
            domain,
            stop,
            thread: Some(thread),
            emulator,
        }
    }

    /// The Pioneer, and its world with a block at each of `blocks` (the laser
    /// `pioneer/ranger/0`, noiseless).
    pub fn with_world(blocks: &[[f64; 2]]) -> Pioneer {
        let mut p = Pioneer::start();
        p.world = Some(SimWorld::start(
            &p.domain,
            "pioneer",
            "pioneer/gripper/1",
            blocks,
        ));
        p
    }
}

/// A robot in a domain of its own, where programs run.
pub trait InDomain {
    /// The domain's name.
    fn name(&self) -> &str;
}

impl InDomain for Pioneer {
    fn name(&self) -> &str {
        self.domain.name()
    }
}

impl Drop for Pioneer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take()
            && t.join().is_err()
            && !std::thread::panicking()
        {
            panic!("the driver thread failed");
        }
    }
}

/// Where cargo put `liblimber.so` and `liblimber.a` for this test: beside its executable.
pub fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's executable");
    let dir = exe.parent().expect("its directory").to_path_buf();
    assert!(
        dir.join("liblimber.so").is_file() && dir.join("liblimber.a").is_file(),
        "liblimber.so and liblimber.a are not in {}",
        dir.display()
    );
    dir
}

/// A fresh scratch directory for one test, removed when dropped (it holds copies of the
/// library: hundreds of MB in a debug build).
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if let Err(e) = std::fs::remove_dir_all(&self.0) {
            eprintln!("cannot remove {}: {e}", self.0.display());
        }
    }
}

pub fn scratch(name: &str) -> Scratch {
    let d =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("capi-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("a scratch directory");
    Scratch(d)
}

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Runs `cmd` to completion within [`RUN_LIMIT`]; fails the test unless it succeeds.
pub fn run_ok(cmd: Command, what: &str) -> Output {
    let o = limber_bounded_run::output_within(cmd, RUN_LIMIT);
    assert!(
        o.status.success(),
        "{what} failed ({}):\nstdout:\n{}\nstderr:\n{}",
        o.status,
        text(&o.stdout),
        text(&o.stderr)
    );
    o
}

/// Runs `exe args` in the driver's domain within [`RUN_LIMIT`]. Without cargo's
/// `LD_LIBRARY_PATH` (which names target/debug, where an older liblimber.so may lie): the
/// library is found by the run path linked into the program, as on a user's machine.
pub fn run_in(p: &impl InDomain, exe: &Path, args: &[&str]) -> Output {
    let mut cmd = Command::new(exe);
    cmd.args(args);
    run_in_cmd(p, cmd)
}

/// Runs `cmd` in the driver's domain within [`RUN_LIMIT`] (as [`run_in`]).
pub fn run_in_cmd(p: &impl InDomain, mut cmd: Command) -> Output {
    cmd.env("LIMBER_DOMAIN", p.name())
        .env_remove("LD_LIBRARY_PATH");
    limber_bounded_run::output_within(cmd, RUN_LIMIT)
}

/// `capi/install.sh PREFIX BUILD_DIR` with the library of this test; returns PREFIX.
pub fn install(dir: &Path) -> PathBuf {
    let prefix = dir.join("prefix");
    let mut cmd = Command::new("sh");
    cmd.arg(root().join("capi/install.sh"))
        .arg(&prefix)
        .arg(lib_dir());
    let o = run_ok(cmd, "capi/install.sh");
    assert!(text(&o.stdout).contains("installed liblimber"));
    for f in [
        "lib/liblimber.so",
        "lib/liblimber.a",
        "lib/pkgconfig/limber.pc",
        "include/limber/limber.h",
        "include/limber/limber_client.h",
        "include/limber/limber.hpp",
    ] {
        assert!(prefix.join(f).is_file(), "{f} not installed");
    }
    prefix
}

/// Compiles one C (`.c`) or C++ (`.cpp`) source of `tests/c/` against the headers of the
/// source tree and this test's library.
pub fn compile(src: &str, exe: &Path, extra: &[&str]) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/c")
        .join(src);
    let cpp = src.extension().is_some_and(|e| e == "cpp");
    let lib = lib_dir();
    let mut cmd = Command::new(if cpp { "g++" } else { "gcc" });
    cmd.arg(if cpp { "-std=c++17" } else { "-std=c11" })
        .args(["-Wall", "-Wextra", "-Werror", "-O1"])
        .arg("-I")
        .arg(root().join("capi/include"))
        .arg("-I")
        .arg(root().join("interfaces/include"))
        .arg(&src)
        .arg("-o")
        .arg(exe)
        .args(extra);
    if !extra.iter().any(|a| a.ends_with("liblimber.a")) {
        cmd.arg("-L")
            .arg(&lib)
            .arg("-llimber")
            .arg(format!("-Wl,-rpath,{}", lib.display()));
    }
    cmd.arg("-lm");
    run_ok(cmd, &format!("compiling {}", src.display()));
}

/// The `(x, y, z)` of a line `<step>: limb at (x, y, z)` of the C example.
pub fn position_at(out: &str, step: &str) -> [f64; 3] {
    let prefix = format!("{step}: limb at (");
    let line = out
        .lines()
        .find(|l| l.starts_with(&prefix))
        .unwrap_or_else(|| panic!("no line {prefix:?} in:\n{out}"));
    let v: Vec<f64> = line[prefix.len()..line.len() - 1]
        .split(", ")
        .map(|x| x.parse().expect("a number"))
        .collect();
    [v[0], v[1], v[2]]
}

pub fn near(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
}

/// Runs the build lines of the `sh` block of an example's README as written, from the
/// workspace root, in a shell: `capi/install.sh "$HOME/..."`, `export PKG_CONFIG_PATH=...`,
/// `make -C examples/...`. HOME is the scratch directory `dir`, the library that
/// install.sh takes from `$CARGO_TARGET_DIR/release` is this test's, and `OUT` (which the
/// Makefiles honour) puts the binary in `dir`. Not run: the `cargo build` line (cargo built
/// the library for this test), `limber pioneer --emulated &` (the driver runs on a thread
/// here), and the program itself (run by the test with its domain).
pub fn run_readme_build_lines(readme: &str, dir: &Path) {
    let readme = std::fs::read_to_string(root().join(readme)).unwrap();
    let sh = fenced(&readme, "sh");
    let script: Vec<&str> = sh
        .lines()
        .filter(|l| {
            l.starts_with("capi/install.sh") || l.starts_with("export ") || l.starts_with("make ")
        })
        .collect();
    assert_eq!(script.len(), 3, "{sh}");
    assert!(
        sh.starts_with("cargo build --release -p limber-c\n"),
        "{sh}"
    );
    let target = dir.join("target");
    std::fs::create_dir_all(&target).unwrap();
    std::os::unix::fs::symlink(lib_dir(), target.join("release")).unwrap();
    let mut cmd = Command::new("sh");
    cmd.arg("-ec")
        .arg(script.join("\n"))
        .current_dir(root())
        .env("HOME", dir)
        .env("CARGO_TARGET_DIR", &target)
        .env("OUT", dir)
        .env_remove("PKG_CONFIG_PATH");
    run_ok(cmd, &script.join("; "));
    assert!(dir.join(".local/limber/lib/pkgconfig/limber.pc").is_file());
}

/// The first fenced block of `lang` in `text`.
pub fn fenced(text: &str, lang: &str) -> String {
    let fence = format!("```{lang}\n");
    let start = text.find(&fence).expect("the block") + fence.len();
    let len = text[start..].find("```").expect("its end");
    text[start..start + len].to_string()
}

/// A robot's world on a thread of this process: its laser (`<robot>/ranger/0`, noiseless)
/// and its blocks, carried by `<robot>/limb/0` and `gripper`; stopped when dropped.
pub struct SimWorld {
    laser: Mutex<RangerClient>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    world: Arc<Mutex<World>>,
}

impl SimWorld {
    /// Starts the world with a block at each of `blocks` and waits for its first scan.
    pub fn start(domain: &Domain, robot: &str, gripper: &str, blocks: &[[f64; 2]]) -> SimWorld {
        let world = World {
            blocks: blocks.iter().map(|b| Block::at(b[0], b[1])).collect(),
            ..World::default()
        };
        let options = WorldOptions {
            laser: LaserConfig {
                noise: 0.0,
                ..LaserConfig::lms200()
            },
            ..WorldOptions::new(robot, &format!("{robot}/limb/0"), gripper)
        };
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let (d, s) = (domain.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let mut w = WorldDriver::new(&d, world, options).expect("the world starts");
            tx.send(w.world()).expect("the test waits");
            w.run(|| s.load(Ordering::Relaxed)).expect("the world runs");
        });
        let world = rx
            .recv_timeout(Duration::from_secs(30))
            .expect("the world is ready");
        let ctx = Context::new(domain, Role::Client, "capi-test-world").expect("a context");
        let laser = RangerClient::connect_timeout(&ctx, &format!("{robot}/ranger/0"), T)
            .expect("the laser");
        SimWorld {
            laser: Mutex::new(laser),
            stop,
            thread: Some(thread),
            world,
        }
    }

    /// The first block, where it is now.
    pub fn block(&self) -> Block {
        self.world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .blocks[0]
    }

    /// Moves the first block to `x`, `y` (on the floor) and waits (bounded) for a scan
    /// that sees it there: the closest range is the block's, straight from the laser.
    pub fn place(&self, x: f64, y: f64) {
        let b = Block::at(x, y);
        self.world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .blocks[0] = b;
        let mut laser = self.laser.lock().unwrap_or_else(PoisonError::into_inner);
        let g = laser
            .geometry()
            .expect("the laser's geometry")
            .pose
            .position;
        let want = (x - g.x).hypot(y - g.y) - b.radius();
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        loop {
            let s = laser.wait_state(T).expect("a scan");
            let closest = s.ranges().iter().copied().fold(f64::INFINITY, f64::min);
            if (closest - want.min(s.max_range)).abs() < 0.01 {
                return;
            }
            assert!(
                std::time::Instant::now() < deadline,
                "the laser does not see the block at ({x}, {y})"
            );
        }
    }
}

impl Drop for SimWorld {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take()
            && t.join().is_err()
            && !std::thread::panicking()
        {
            panic!("the world's thread failed");
        }
    }
}

/// simarm (the built-in 6-joint arm) on a thread of this process, with its world: a
/// block at `block`, which its fingers close on at the paper's HandleHeight (0.17 m).
pub struct SimArmRun {
    /// The world: dropped first.
    pub world: SimWorld,
    domain: Domain,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl SimArmRun {
    /// Starts simarm and its world.
    pub fn start(block: [f64; 2]) -> SimArmRun {
        use limber_simarm::{SimArm, SimArmOptions, SimObject};
        let domain = Domain::unique_for_test();
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let (d, s) = (domain.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let ctx = Context::new(&d, Role::Driver, "simarm").expect("the driver's context");
            let options = SimArmOptions {
                object: Some(SimObject::block([block[0], block[1], 0.17], 0.04)),
                ..SimArmOptions::default()
            };
            let chain = limber_kinematics::chain::Chain::default_6dof();
            let mut arm = SimArm::new(&ctx, chain, options).expect("simarm starts");
            tx.send(()).expect("the test waits");
            arm.run(|| s.load(Ordering::Relaxed)).expect("simarm runs");
        });
        rx.recv_timeout(Duration::from_secs(30))
            .expect("simarm is ready");
        let world = SimWorld::start(&domain, "simarm", "simarm/gripper/0", &[block]);
        SimArmRun {
            world,
            domain,
            stop,
            thread: Some(thread),
        }
    }
}

impl InDomain for SimArmRun {
    fn name(&self) -> &str {
        self.domain.name()
    }
}

impl Drop for SimArmRun {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take()
            && t.join().is_err()
            && !std::thread::panicking()
        {
            panic!("the simarm thread failed");
        }
    }
}
