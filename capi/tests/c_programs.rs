//! C and C++ programs against liblimber, built the way a user builds them: cargo has built
//! `liblimber.so` and `liblimber.a` for this test (in the directory of the test's own
//! executable); `capi/install.sh` installs them with the headers and `limber.pc`; gcc and
//! g++ compile the examples with their Makefiles (pkg-config), the README's clients with
//! the README's own command lines, and the programs of `tests/c/` against the header and
//! the library directly. Each runs against the Pioneer driver on the emulator (the code
//! of `limber pioneer --emulated`, on a thread of this process), each test in a domain of
//! its own; every run is bounded. The examples (the paper's Listing 2) are in
//! `listing2.rs`; what both share in `common/`.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_interfaces::prelude::ActArrayData;
use limber_services::Role;
use limber_services::prelude::*;

mod common;
use common::*;

/// The fenced block of `lang` in README.md's "C and C++" section.
fn readme_block(readme: &str, lang: &str) -> String {
    fenced(
        &readme[readme.find("## C and C++").expect("the section")..],
        lang,
    )
}

#[test]
fn the_readme_clients_compile_and_run_as_written() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let dir = scratch("readme");
    let prefix = install(&dir);
    std::fs::write(dir.join("client.c"), readme_block(&readme, "c")).unwrap();
    std::fs::write(dir.join("client.cpp"), readme_block(&readme, "cpp")).unwrap();
    // The README's own compile lines (the build and install lines before them are what
    // cargo and `install` above did, with this test's library and prefix).
    let sh = readme_block(&readme, "sh");
    let lines: Vec<&str> = sh
        .lines()
        .filter(|l| l.starts_with("cc ") || l.starts_with("c++ "))
        .collect();
    assert_eq!(lines.len(), 2, "{sh}");
    assert!(sh.contains("cargo build --release -p limber-c"));
    assert!(sh.contains("capi/install.sh"));
    for line in lines {
        let mut cmd = Command::new("sh");
        cmd.arg("-c")
            .arg(line)
            .current_dir(&*dir)
            .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"));
        run_ok(cmd, line);
    }
    let p = Pioneer::start();
    for (exe, target) in [("client", "0.3"), ("client_cpp", "-0.3")] {
        let o = run_in(&p, &dir.join(exe), &[]);
        let out = text(&o.stdout);
        assert!(o.status.success(), "{exe}: {out}\n{}", text(&o.stderr));
        assert!(out.starts_with("joint 0 at "), "{exe}: {out}");
        assert!(out.contains("move: ok"), "{exe}: {out}");
        // The arm took the command: joint 0 heads for the target.
        let ctx = Context::new(&p.domain, Role::Client, "capi-test").unwrap();
        let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
        let target: f64 = target.parse().unwrap();
        let deadline = Instant::now() + Duration::from_secs(20);
        while (arm.current(T).unwrap().actuators[0].position - target).abs() > 0.02 {
            assert!(
                Instant::now() < deadline,
                "{exe}: joint 0 never reached {target}"
            );
            arm.wait_state(T).unwrap();
        }
    }
}

#[test]
fn a_client_written_from_the_header_reads_the_joints_and_moves_one() {
    let dir = scratch("joints");
    let shared = dir.join("joints");
    let stat = dir.join("joints_static");
    compile("joints.c", &shared, &[]);
    // The same program linked with the static library.
    let a = lib_dir().join("liblimber.a");
    compile(
        "joints.c",
        &stat,
        &[
            a.to_str().unwrap(),
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-ldl",
        ],
    );
    let p = Pioneer::start();
    for exe in [&shared, &stat] {
        let o = run_in(&p, exe, &[]);
        let out = text(&o.stdout);
        assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
        assert!(out.starts_with("6 joints:"), "{out}");
        assert!(out.contains("moved joint 1 from"), "{out}");
        assert!(out.contains("driver alive"), "{out}");
    }
}

#[test]
fn every_error_path_returns_its_code_and_message() {
    let dir = scratch("errors");
    let exe = dir.join("errors");
    compile("errors.c", &exe, &[]);
    let p = Pioneer::start();
    let o = run_in(&p, &exe, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("all error paths ok"), "{out}");
    // The code's message and the detail, as a user sees them.
    assert!(
        out.contains(&format!(
            "ok: unknown device: no driver offers the device: no driver offers pioneer/actarray/7 in domain {}",
            p.name()
        )),
        "{out}"
    );
}

#[test]
fn handles_work_from_threads_of_their_own() {
    let dir = scratch("threads");
    let exe = dir.join("threads");
    compile("threads.c", &exe, &["-pthread"]);
    let p = Pioneer::start();
    let o = run_in(&p, &exe, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert_eq!(out, "threads ok\n");
}

/// A running program whose stdout lines arrive on a channel (disconnected at its end), and
/// whose stdin the test writes.
struct Running {
    child: Child,
    lines: mpsc::Receiver<String>,
}

impl Running {
    fn spawn(p: &Pioneer, mut cmd: Command) -> Running {
        let mut child = cmd
            .env("LIMBER_DOMAIN", p.name())
            .env_remove("LD_LIBRARY_PATH")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("spawn");
        let out = child.stdout.take().expect("its stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Running { child, lines }
    }

    /// The next line, within `limit`.
    fn line(&self, limit: Duration) -> String {
        self.lines
            .recv_timeout(limit)
            .unwrap_or_else(|e| panic!("no line from the program within {limit:?}: {e}"))
    }

    /// Writes `line` and a newline to the program's stdin.
    fn send(&mut self, line: &str) {
        use std::io::Write;
        let stdin = self.child.stdin.as_mut().expect("its stdin");
        writeln!(stdin, "{line}").expect("the program reads its stdin");
        stdin.flush().expect("the program reads its stdin");
    }

    /// Every line until the program closed its stdout, within `limit`.
    fn rest(&mut self, limit: Duration) -> String {
        let deadline = Instant::now() + limit;
        let mut s = String::new();
        loop {
            match self
                .lines
                .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            {
                Ok(l) => {
                    s.push_str(&l);
                    s.push('\n');
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => return s,
                Err(mpsc::RecvTimeoutError::Timeout) => panic!("still running; so far:\n{s}"),
            }
        }
    }

    /// Every remaining line, and the exit status, within `limit`.
    fn finish(&mut self, limit: Duration) -> (String, std::process::ExitStatus) {
        let out = self.rest(limit);
        let deadline = Instant::now() + limit;
        loop {
            if let Some(status) = self.child.try_wait().expect("its status") {
                return (out, status);
            }
            assert!(Instant::now() < deadline, "still running after:\n{out}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A Python (>= 3.9) to run python/limber with: `LIMBER_PYTHON`, else the venv `.ci/run`
/// makes (`target/py-venv`). None, with the reason printed, when there is none on a
/// developer's machine; in CI (`CI=true`) a missing one fails the test. The package is a
/// ctypes binding over liblimber: [`python_cmd`] points it at this build's library.
fn python() -> Option<PathBuf> {
    let candidates: Vec<PathBuf> = match std::env::var_os("LIMBER_PYTHON") {
        Some(p) => vec![PathBuf::from(p)],
        None => vec![root().join("target/py-venv/bin/python")],
    };
    for py in &candidates {
        let mut cmd = Command::new(py);
        cmd.args(["-c", "import sys; assert sys.version_info >= (3, 9)"]);
        if py.is_file()
            && limber_bounded_run::output_within(cmd, RUN_LIMIT)
                .status
                .success()
        {
            return Some(py.clone());
        }
    }
    let reason = format!(
        "no Python >= 3.9 at {candidates:?}: set LIMBER_PYTHON, or run .ci/run once (it makes target/py-venv)"
    );
    assert!(std::env::var("CI").as_deref() != Ok("true"), "{reason}");
    eprintln!("skipped: {reason}");
    None
}

/// `python script` with the package of `package_dir` on `PYTHONPATH`, over this build's
/// liblimber.so (`LIMBER_LIB`).
fn python_cmd(python: &Path, script: &Path, package_dir: &Path) -> Command {
    let mut cmd = Command::new(python);
    cmd.arg(script)
        .env("PYTHONPATH", package_dir)
        .env("LIMBER_LIB", lib_dir().join("liblimber.so"));
    cmd
}

/// The joint positions and gripper state of a `seen:` line, as every client prints them
/// (`%.9f` per joint, then `gripper <state>`).
fn seen_line(arm: &ActArrayData, gripper: &GripperData) -> String {
    let joints: Vec<String> = arm.actuators[..arm.actuators_count as usize]
        .iter()
        .map(|a| format!("{:.9}", a.position))
        .collect();
    format!("seen: {} gripper {}", joints.join(" "), gripper.state)
}

#[test]
fn rust_python_c_and_cpp_clients_work_on_one_driver_at_once() {
    // C commands the arm (joint 0 to 0.35 rad), C++ the arm gripper (close), Python asks
    // for the arm's and the gripper's geometry over and over meanwhile, and Rust (here)
    // reads the states throughout. Then, the arm at rest, each reports the joints and the
    // gripper state it sees: all four agree, and show both commands carried out.
    let Some(python) = python() else { return };
    const JOINT: usize = 0;
    const TARGET: f64 = 0.35;
    let dir = scratch("together");
    let (arm_exe, gripper_exe) = (dir.join("arm"), dir.join("gripper"));
    compile("arm.c", &arm_exe, &[]);
    compile("gripper.cpp", &gripper_exe, &[]);
    let p = Pioneer::start();
    let ctx = Context::new(&p.domain, Role::Client, "capi-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    let mut gripper = GripperClient::connect_timeout(&ctx, "pioneer/gripper/1", T).unwrap();
    let start = arm.current(T).unwrap().actuators[JOINT].position;
    assert!(
        (start - TARGET).abs() > 0.1,
        "joint {JOINT} starts at {start}"
    );

    let mut c = Command::new(&arm_exe);
    c.args([JOINT.to_string(), TARGET.to_string()]);
    let py = python_cmd(
        &python,
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/py/geometry.py"),
        &root().join("python"),
    );
    let mut clients = [
        ("C", Running::spawn(&p, c)),
        ("C++", Running::spawn(&p, Command::new(&gripper_exe))),
        ("Python", Running::spawn(&p, py)),
    ];
    for (name, client) in &mut clients {
        let first = client.line(RUN_LIMIT);
        assert_eq!(first, "ready", "{name}");
    }
    for (_, client) in &mut clients {
        client.send("go");
    }

    // Rust reads while the others work, until C and C++ say their commands are done.
    let (mut lo, mut hi, mut saw_closed) = (f64::MAX, f64::MIN, false);
    let mut said = String::new();
    let mut done = [false, false];
    let deadline = Instant::now() + RUN_LIMIT;
    while done != [true, true] {
        let q = arm.wait_state(T).expect("arm states").actuators[JOINT].position;
        (lo, hi) = (lo.min(q), hi.max(q));
        saw_closed |= gripper.current(T).unwrap().gripper_state() == Ok(GripperState::Closed);
        for (i, (name, client)) in clients.iter_mut().enumerate() {
            while let Ok(l) = client.lines.try_recv() {
                if i < 2 {
                    done[i] |= l.ends_with(": done");
                }
                said += &format!("{name}: {l}\n");
            }
            if let Some(status) = client.child.try_wait().unwrap() {
                let e = p.emulator.state();
                panic!(
                    "{name} ended early ({status}):\n{said}the emulator (running: {}, stage {:?}, armpac mode {}, powered {}, autoparks {}): ticks {:?}, targets {:?}, {} commands, {:?}; arm flags {:x}",
                    p.emulator.is_running(),
                    e.robot.stage,
                    e.robot.arm_status_mode,
                    e.robot.arm_powered,
                    e.robot.autoparks,
                    e.robot.servo_ticks,
                    e.robot.servo_targets,
                    e.robot.commands,
                    e.stats,
                    arm.current(T).unwrap().header.flags
                );
            }
        }
        assert!(
            Instant::now() < deadline,
            "the commands did not finish:\n{said}"
        );
    }
    assert!(said.contains("C: arm: move ok\n"), "{said}");
    assert!(said.contains("C++: gripper: close ok\n"), "{said}");
    assert!(
        lo <= start.min(TARGET) + 0.02 && hi >= start.max(TARGET) - 0.02,
        "Rust did not see joint {JOINT} travel from {start} to {TARGET}: {lo}..{hi}"
    );

    // The arm at rest (every joint idle: the gripper's too), each client reports.
    let deadline = Instant::now() + RUN_LIMIT;
    while !arm.wait_state(T).unwrap().actuators[..6]
        .iter()
        .all(|a| a.flags() == Ok(ActuatorFlags::IDLE))
    {
        assert!(Instant::now() < deadline, "the arm never came to rest");
    }
    for (_, client) in &mut clients {
        client.send("report");
    }
    let ours = seen_line(arm.wait_state(T).unwrap(), gripper.wait_state(T).unwrap());
    let geometry = arm.geometry().unwrap();
    for (name, client) in &mut clients {
        let (out, status) = client.finish(RUN_LIMIT);
        assert!(status.success(), "{name} failed ({status}):\n{out}");
        let seen = out
            .lines()
            .find(|l| l.starts_with("seen: "))
            .unwrap_or_else(|| panic!("{name} reported nothing:\n{out}"));
        assert_eq!(seen, ours, "{name} and Rust disagree");
        if *name == "Python" {
            let a = &geometry.actuators[0];
            let expected = format!(
                "6 actuators, joint 0 in [{:.9}, {:.9}], gripper geometry ok",
                a.min, a.max
            );
            assert!(out.contains(&expected), "{expected:?} not in:\n{out}");
            let requests: u64 = out
                .strip_prefix("geometry: ")
                .and_then(|s| s.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("no request count in:\n{out}"));
            assert!(requests > 0, "{out}");
        }
    }
    // Both commands carried out, as all four saw it.
    let joint: f64 = ours.split(' ').nth(1 + JOINT).unwrap().parse().unwrap();
    assert!((joint - TARGET).abs() < 0.02, "{ours}");
    assert!(saw_closed, "Rust never saw the gripper closed");
    assert!(
        ours.ends_with(&format!(" gripper {}", GripperState::Closed as u32)),
        "{ours}"
    );
}

#[test]
fn a_handle_sees_its_driver_go() {
    // Through the library's Rust face (the same functions C calls): alive while the
    // driver runs, then gone, and waiting for a state says so instead of timing out.
    use limber::*;
    let p = Pioneer::start();
    let domain = std::ffi::CString::new(p.name()).unwrap();
    let mut h: *mut LimberActArray = std::ptr::null_mut();
    let mut live = LimberLiveness::NoData;
    let mut data = ActArrayData::default();
    // SAFETY: valid strings, and pointers to locals that outlive the calls.
    unsafe {
        let c = limber_device_connect_checked(
            c"pioneer/actarray/0".as_ptr(),
            domain.as_ptr(),
            5000,
            limber_interfaces::LAYOUT_VERSION,
            LimberInterface::Actarray as i32,
            size_of::<ActArrayData>(),
            size_of::<limber_interfaces::prelude::ActArrayGeom>(),
            &mut h,
        );
        assert_eq!(c, LimberCode::Ok);
        assert_eq!(
            limber_device_state(h, 5000, (&raw mut data).cast(), size_of::<ActArrayData>()),
            LimberCode::Ok
        );
        assert_eq!(limber_device_liveness(h, 5000, &mut live), LimberCode::Ok);
    }
    assert_eq!(live, LimberLiveness::Alive);
    // The domain outlives the driver: its files go once the handle is disconnected too.
    let _domain = p.domain.clone();
    drop(p);
    // SAFETY: as above; the handle is live until disconnected.
    unsafe {
        // The states published as it stopped, then the news that it is gone.
        let mut c = LimberCode::Ok;
        for _ in 0..100 {
            c = limber_device_wait_state(
                h,
                10_000,
                (&raw mut data).cast(),
                size_of::<ActArrayData>(),
            );
            if c != LimberCode::Ok {
                break;
            }
        }
        assert_eq!(c, LimberCode::DriverGone);
        assert_eq!(limber_device_liveness(h, 0, &mut live), LimberCode::Ok);
        let mut status = LimberDriverStatus::Alive;
        assert_eq!(limber_device_driver_status(h, &mut status), LimberCode::Ok);
        assert_ne!(status, LimberDriverStatus::Alive);
        limber_device_disconnect(h);
    }
    assert_eq!(live, LimberLiveness::Gone);
}

/// What the Pioneer driver answers to each call of `tests/c/commands.c`: carried out, or
/// the cause it names for what the Pioneer cannot do (no current control, no brakes, no
/// acceleration setting, no store/retrieve on the arm gripper).
const PIONEER_VERDICTS: &str = "\
actarray move_to: ok
actarray move_to_multi: ok
actarray move_at_speed: ok
actarray move_at_speed_multi: ok
actarray set_current: unsupported by this device
actarray set_current_multi: unsupported by this device
actarray home: ok
actarray power: ok
actarray brakes: refused: unsupported by this device
actarray set_speed_config: ok
actarray set_accel_config: refused: unsupported by this device
actarray geometry: ok
limb set_pose: ok
limb set_position: ok
limb vec_move: ok
limb stop: ok
limb home: ok
limb power: ok
limb brakes: refused: unsupported by this device
limb set_speed: ok
limb geometry: ok
limb can_reach: ok
limb can_reach adjusted: yes
limb can_reach far: refused: out of reach
gripper open: ok
gripper close: ok
gripper stop: ok
gripper store: unsupported by this device
gripper retrieve: unsupported by this device
gripper geometry: ok
";

#[test]
fn every_command_and_request_reaches_the_driver_as_itself() {
    let dir = scratch("commands");
    let exe = dir.join("commands");
    compile("commands.c", &exe, &[]);
    let p = Pioneer::start();
    let o = run_in(&p, &exe, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(text(&o.stdout), PIONEER_VERDICTS);
}

#[test]
fn a_lease_refuses_the_other_client_by_name_and_preemption_and_the_deadman_are_told() {
    let dir = scratch("lease");
    let (c, cpp) = (dir.join("lease"), dir.join("lease_cpp"));
    compile("lease.c", &c, &[]);
    compile("lease.cpp", &cpp, &[]);
    let p = Pioneer::start();
    let o = run_in(&p, &c, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    for line in [
        "empty name: invalid value; nothing was sent: a lease name has 1 to 31 bytes, not 0",
        "holder: alice",
        "bob's move: held by another client: refused: held by another client (alice, client ",
        "bob's acquire: the driver refused the request: held by another client (alice)",
        "limb held with the arm: alice",
        "bob's move after release: ok",
        "limb holder: lease",
        "gripper lease ok",
        "alice's slow move preempted by bob",
        "alice's renew after the deadman: the lease was lost (heartbeat missed)",
        "all lease steps ok",
    ] {
        assert!(out.contains(line), "{line:?} not in:\n{out}");
    }
    let o = run_in(&p, &cpp, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(
        out.contains(
            "refused: the driver refused the request: held by another client (cpp-holder)"
        ),
        "{out}"
    );
    assert!(out.contains("holder: lease_cpp"), "{out}");
    assert!(out.contains("all C++ lease steps ok"), "{out}");
}

/// The layout manifest with one field moved, as the rules of limber.h have it: the layout
/// version bumped and every type name with it; in `ActArrayData`, `motor_state` now comes
/// before `actuators_count` (each takes the other's offset: the sizes stay the same).
fn manifest_with_a_field_moved() -> limber_interfaces::manifest::Manifest {
    let mut m = limber_interfaces::manifest();
    let (old, new) = (m.layout_version, m.layout_version + 1);
    m.layout_version = new;
    for st in &mut m.structs {
        let renamed = st
            .type_name
            .replace(&format!("limber.v{old}."), &format!("limber.v{new}."));
        assert_ne!(renamed, st.type_name, "a versioned type name");
        st.type_name = Box::leak(renamed.into_boxed_str());
        if st.name == "ActArrayData" {
            let mut fields = st.fields.to_vec();
            let at = |n: &str| fields.iter().position(|f| f.name == n).expect(n);
            let (a, b) = (at("actuators_count"), at("motor_state"));
            let (oa, ob) = (fields[a].offset, fields[b].offset);
            fields.swap(a, b);
            (fields[a].offset, fields[b].offset) = (oa, ob);
            st.fields = Box::leak(fields.into_boxed_slice());
        }
    }
    m
}

#[test]
fn a_field_moved_in_a_message_makes_c_cpp_and_python_refuse_to_connect() {
    // limber.h and _layout.py generated (by the generators of limber.h and _layout.py)
    // from the manifest with a field moved; the C and C++ clients compiled against that
    // header, the Python client run with that _layout.py; the driver and liblimber speak
    // the real layout. Each refuses to connect and says why, instead of misreading.
    let moved = manifest_with_a_field_moved();
    let dir = scratch("moved");
    let include = dir.join("include");
    std::fs::create_dir_all(&include).unwrap();
    let header = limber_interfaces::codegen::c_header(&moved);
    assert!(header.contains("    uint32_t motor_state;\n    uint32_t actuators_count;\n"));
    std::fs::write(include.join("limber.h"), header).unwrap();
    // Python: the package as it is, with the moved _layout.py.
    let package = dir.join("py/limber");
    std::fs::create_dir_all(&package).unwrap();
    for e in std::fs::read_dir(root().join("python/limber")).unwrap() {
        let f = e.unwrap().file_name();
        let f = f.to_str().unwrap();
        if f != "_layout.py" && (f.ends_with(".py") || f == "py.typed") {
            std::fs::copy(root().join("python/limber").join(f), package.join(f)).unwrap();
        }
    }
    std::fs::write(
        package.join("_layout.py"),
        limber_interfaces::codegen::python_module(&moved),
    )
    .unwrap();
    // C (joints.c, the client written from the header) and C++ (README.md's client),
    // their moved limber.h found first.
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let cpp = dir.join("client.cpp");
    std::fs::write(&cpp, readme_block(&readme, "cpp")).unwrap();
    let (c_exe, cpp_exe) = (dir.join("joints"), dir.join("client_cpp"));
    let flag = format!("-I{}", include.display());
    // The same sources against the moved header (the -I before the source tree's).
    for (src, exe, std, cc) in [
        (
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c/joints.c"),
            &c_exe,
            "-std=c11",
            "gcc",
        ),
        (cpp.clone(), &cpp_exe, "-std=c++17", "g++"),
    ] {
        let lib = lib_dir();
        let mut cmd = Command::new(cc);
        cmd.args([std, "-Wall", "-Wextra", "-Werror", &flag, "-I"])
            .arg(root().join("capi/include"))
            .arg("-I")
            .arg(root().join("interfaces/include"))
            .arg(&src)
            .arg("-o")
            .arg(exe)
            .arg("-L")
            .arg(&lib)
            .arg("-llimber")
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .arg("-lm");
        run_ok(
            cmd,
            &format!("compiling {} against the moved limber.h", src.display()),
        );
    }
    let p = Pioneer::start();
    let version = limber_interfaces::LAYOUT_VERSION;
    let detail = format!(
        "this program was compiled against limber.h layout version {} (limber_actarray_data 1376 bytes, \
         limber_actarray_geom 3384 bytes), but this liblimber speaks layout version {version} \
         (1376 and 3384 bytes): rebuild the program against the limber.h installed with this library",
        version + 1
    );
    let o = run_in(&p, &c_exe, &[]);
    let out = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{}\n{out}", text(&o.stdout));
    assert!(o.stdout.is_empty(), "C read something: {}", text(&o.stdout));
    assert_eq!(
        out,
        format!(
            "joints: connect: the device is of another interface or layout version: {detail}\n"
        )
    );
    let o = run_in(&p, &cpp_exe, &[]);
    let out = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{}\n{out}", text(&o.stdout));
    assert!(
        o.stdout.is_empty(),
        "C++ read something: {}",
        text(&o.stdout)
    );
    assert!(out.contains(&detail), "{out}");
    assert!(
        out.ends_with(&format!(
            "(code {})\n",
            limber::LimberCode::Incompatible as i32
        )),
        "{out}"
    );

    let Some(python) = python() else { return };
    let connect = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/py/connect.py");
    let o = run_in_cmd(&p, python_cmd(&python, &connect, &dir.join("py")));
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{out}\n{}", text(&o.stderr));
    assert!(
        out.starts_with("incompatible: pioneer/actarray/0 is incompatible"),
        "{out}"
    );
    assert!(
        out.contains(&format!("layout version {}", version + 1)),
        "{out}"
    );
    // The real package connects (the refusal is the layout's, not the script's).
    let o = run_in_cmd(&p, python_cmd(&python, &connect, &root().join("python")));
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(out.starts_with("connected: joint 0 at "), "{out}");
}

#[test]
fn the_calls_every_interface_shares_work_from_c_and_cpp() {
    let dir = scratch("device");
    let (c, cpp) = (dir.join("device"), dir.join("device_cpp"));
    compile("device.c", &c, &[]);
    compile("device.cpp", &cpp, &[]);
    let p = Pioneer::start();
    let o = run_in(&p, &c, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    for line in [
        "status OUT_OF_REACH CLAMPED UNKNOWN",
        "name pioneer/actarray/0 interface 0",
        "gripper call on the arm: the device is of another interface or layout version: \
         pioneer/actarray/0 is an actarray, not a gripper",
        "wrong size: refused",
        "gripper connect to the arm: the device is of another interface or layout version: \
         pioneer/actarray/0 is an actarray, not a gripper",
        "poll: the arm's state came; move OK",
        "other's move: LEASED by alice (the holder: yes)",
        "other's acquire: the driver refused the request; last holder alice (the holder: yes)",
        "stats: some cycles latest ok",
        "log: 1 warning(s): this program was compiled against limber.h layout version",
        "all device steps ok",
    ] {
        assert!(out.contains(line), "{line:?} not in:\n{out}");
    }
    // C++: run until it is ready, stop the driver, let it see the driver gone.
    let mut child = Command::new(&cpp)
        .env("LIMBER_DOMAIN", p.name())
        .env_remove("LD_LIBRARY_PATH")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("device_cpp runs");
    let stdout = child.stdout.take().expect("its stdout");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut lines = Vec::new();
    let deadline = Instant::now() + RUN_LIMIT;
    while lines.last().is_none_or(|l: &String| l != "ready") {
        match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(l) => lines.push(l),
            Err(_) => {
                let _ = child.kill();
                let o = child.wait_with_output().expect("its output");
                panic!("device_cpp never got ready: {lines:?}\n{}", text(&o.stderr));
            }
        }
    }
    let _domain = p.domain.clone();
    drop(p);
    {
        use std::io::Write as _;
        let mut stdin = child.stdin.take().expect("its stdin");
        writeln!(stdin).expect("a line to device_cpp");
    }
    while let Ok(l) = rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
        lines.push(l);
    }
    let status = child.wait().expect("device_cpp ends");
    let out = lines.join("\n");
    assert!(status.success(), "{out}");
    for line in [
        "move: OK carried out 1 text ok raw 1",
        "no news without an exception: 1",
        "reach: adjusted 1",
        "setpose: ADJUSTED carried out 1",
        "reach far: OUT_OF_REACH",
        "gone: the driver is gone",
    ] {
        assert!(out.contains(line), "{line:?} not in:\n{out}");
    }
    assert!(
        !out.contains("the driver is gone: the driver is gone"),
        "what() repeats itself:\n{out}"
    );
}
