//! Group mode (docs/guide/security.md): two accounts of a Unix group share the arm, a third
//! outside the group can neither read nor command it.
//!
//! The tests create the group `limber-arm` and the users `limber-arm-a`, `limber-arm-b` (in
//! it) and `limber-arm-x` (not in it) with groupadd/useradd when they are missing; they need
//! root, and are skipped with the reason otherwise. Each runs the real `limber` command line
//! as those users (setpriv), in a domain and runtime directory of its own.

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use limber_bounded_run::output_within;
use limber_services::Domain;
use limber_services::domain_dir::euid;
use limber_tests::Proc;

const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
const GROUP: &str = "limber-arm";
const A: &str = "limber-arm-a";
const B: &str = "limber-arm-b";
const OUTSIDER: &str = "limber-arm-x";
const LIMIT: Duration = Duration::from_secs(30);

fn run(c: &mut Command) -> Output {
    output_within(c, LIMIT)
}

/// Creates the group and the users if needed; None (with the reason printed) when not root.
fn users() -> Option<u32> {
    if euid() != 0 {
        eprintln!(
            "SKIPPED: creating a Unix group and users needs root (these tests run as root in CI)"
        );
        return None;
    }
    // Tests run in parallel processes: groupadd/useradd may meet another's lock or find the
    // group or user made meanwhile. Bounded retries.
    let has_group = || {
        run(Command::new("getent").args(["group", GROUP]))
            .status
            .success()
    };
    let in_group = |u: &str| {
        let out = run(Command::new("id").args(["-nG", u]));
        out.status.success()
            && String::from_utf8_lossy(&out.stdout)
                .split_whitespace()
                .any(|g| g == GROUP)
    };
    let exists = |u: &str| run(Command::new("id").args(["-u", u])).status.success();
    for _ in 0..50 {
        let ready =
            has_group() && in_group(A) && in_group(B) && exists(OUTSIDER) && !in_group(OUTSIDER);
        if ready {
            let out = run(Command::new("getent").args(["group", GROUP]));
            let text = String::from_utf8_lossy(&out.stdout).into_owned();
            return Some(text.split(':').nth(2).unwrap().trim().parse().unwrap());
        }
        if !has_group() {
            let _ = run(Command::new("groupadd").args(["-r", GROUP]));
        }
        for u in [A, B, OUTSIDER] {
            if !exists(u) {
                let _ =
                    run(Command::new("useradd").args(["-M", "-r", "-s", "/usr/sbin/nologin", u]));
            }
        }
        for u in [A, B] {
            if exists(u) && has_group() && !in_group(u) {
                let _ = run(Command::new("usermod").args(["-aG", GROUP, u]));
            }
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("cannot create the group {GROUP} and its users");
}

/// A directory everybody may enter (the users' working directory, the runtime directory
/// inside it), removed at the end.
struct Scratch {
    dir: PathBuf,
    cli: String,
}

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("limber-grp-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o1777)).unwrap();
        // A copy of the CLI the users can run (the build directory may be private).
        let to = dir.join("limber");
        std::fs::copy(CLI, &to).unwrap();
        std::fs::set_permissions(&to, std::fs::Permissions::from_mode(0o755)).unwrap();
        Scratch {
            cli: to.to_string_lossy().into_owned(),
            dir,
        }
    }

    fn runtime(&self) -> PathBuf {
        self.dir.join("rt")
    }

    /// `limber <args>` as `user` in `domain`, in group mode when `group` (the runtime
    /// directory is this scratch's `rt`).
    fn limber(&self, user: &str, domain: &Domain, group: bool, args: &[&str]) -> Command {
        let mut c = Command::new("setpriv");
        c.args(["--reuid", user, "--regid", user, "--init-groups", "--"])
            .arg(&self.cli)
            .args(args)
            .current_dir(&self.dir)
            .env("LIMBER_DOMAIN", domain.name())
            .env("LIMBER_RUNTIME_DIR", self.runtime())
            .env_remove("LIMBER_GROUP");
        if group {
            c.env("LIMBER_GROUP", GROUP);
        }
        c
    }

    /// `sh -c script` as `user`.
    fn sh(&self, user: &str, script: &str) -> Output {
        run(Command::new("setpriv")
            .args([
                "--reuid",
                user,
                "--regid",
                user,
                "--init-groups",
                "--",
                "sh",
                "-c",
                script,
            ])
            .current_dir(&self.dir))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The driver (`limber pioneer --emulated`) as user A, in group mode; returns once it
/// serves.
fn start_driver(s: &Scratch, domain: &Domain) -> Proc {
    let c = s.limber(A, domain, true, &["pioneer", "--emulated"]);
    let mut d = spawn(c);
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "the driver did not start"
    );
    d
}

/// Spawns a prepared command as a [`Proc`] (stdout read line by line).
fn spawn(c: Command) -> Proc {
    Proc::spawn_command(c)
}

/// The position of joint `j` in a `limber echo --json` line.
fn position(line: &str, j: usize) -> Option<f64> {
    let after = line.split("\"position\":").nth(j + 1)?;
    after.split([',', '}']).next()?.trim().parse().ok()
}

/// The domain's files in /dev/shm.
fn shm_files(prefix: &str) -> Vec<PathBuf> {
    std::fs::read_dir("/dev/shm")
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
        .map(|e| e.path())
        .collect()
}

/// Every entry under `dir`, recursively.
fn tree(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.filter_map(Result::ok) {
            let p = e.path();
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                out.extend(tree(&p));
            }
            out.push(p);
        }
    }
    out
}

fn text(o: &Output) -> String {
    format!(
        "status {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The token (prefix) of the domain, read as root from the runtime directory.
fn prefix(s: &Scratch, domain: &Domain) -> String {
    let token = std::fs::read_to_string(s.runtime().join(format!("{}.token", domain.name())))
        .expect("the domain's token");
    format!("limber_{}_", token.trim())
}

#[test]
fn two_members_share_the_arm_and_an_outsider_is_locked_out() {
    let Some(gid) = users() else { return };
    let s = Scratch::new("share");
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&s, &domain);

    // The runtime directory is the group's: 2770, group limber-arm.
    let md = std::fs::metadata(s.runtime()).unwrap();
    assert_eq!((md.mode() & 0o7777, md.gid()), (0o2770, gid));

    // B sees the devices, reads the arm's state, commands joint 1: "ok", and the state
    // follows.
    let out = run(&mut s.limber(B, &domain, true, &["list"]));
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("pioneer/actarray/0"),
        "{}",
        text(&out)
    );
    let out = run(&mut s.limber(
        B,
        &domain,
        true,
        &["echo", "pioneer/actarray/0", "--json", "--count", "1"],
    ));
    assert!(out.status.success(), "{}", text(&out));
    let before = position(&String::from_utf8_lossy(&out.stdout), 1).expect("joint 1's position");
    let target = if before > 0.0 {
        before - 0.4
    } else {
        before + 0.4
    };
    let out = run(&mut s.limber(
        B,
        &domain,
        true,
        &[
            "actarray",
            "pioneer/actarray/0",
            "pos",
            "1",
            &format!("{target:.3}"),
        ],
    ));
    assert!(out.status.success(), "{}", text(&out));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "ok",
        "{}",
        text(&out)
    );
    let mut echo = spawn(s.limber(
        B,
        &domain,
        true,
        &["echo", "pioneer/actarray/0", "--json", "--count", "100000"],
    ));
    echo.read_until(|l| position(l, 1).is_some_and(|p| (p - target).abs() < 0.02))
        .expect("joint 1 reaches the target B commanded");

    // Every file of the domain is closed to others; the driver's segments and static
    // files are the group's (files made this instant may still be owner-only).
    let prefix = prefix(&s, &domain);
    let shm = shm_files(&prefix);
    let mut owners = std::collections::BTreeSet::new();
    for f in shm.iter().chain(tree(&s.runtime()).iter()) {
        let Ok(md) = std::fs::symlink_metadata(f) else {
            continue; // removed meanwhile
        };
        let mode = md.mode() & 0o7777;
        assert_eq!(mode & 0o007, 0, "{} is {mode:o}", f.display());
        assert!(
            (md.gid() == gid && mode & 0o060 != 0) || mode & 0o077 == 0,
            "{} is {mode:o}, gid {}",
            f.display(),
            md.gid()
        );
        owners.insert(md.uid());
    }
    assert!(owners.len() >= 2, "files of A and of B: {owners:?}");
    let data = shm
        .iter()
        .find(|p| {
            let md = std::fs::metadata(p).unwrap();
            p.to_string_lossy().ends_with(".data") && md.mode() & 0o777 == 0o660
        })
        .expect("a data segment of the driver open to the group")
        .display()
        .to_string();
    let counter = shm
        .iter()
        .find(|p| p.to_string_lossy().ends_with(".global_mgmt"))
        .expect("the node counter")
        .display()
        .to_string();
    assert_eq!(
        std::fs::metadata(&counter).unwrap().mode() & 0o777,
        0o660,
        "the node counter"
    );

    // The outsider: refused in group mode with the group named, refused the group's
    // runtime directory without it, and can open no file of the domain.
    let out = run(&mut s.limber(OUTSIDER, &domain, true, &["list"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        err.contains(&format!("you (user {OUTSIDER}"))
            && err.contains(&format!("not in group {GROUP}")),
        "{err}"
    );
    let out = run(&mut s.limber(OUTSIDER, &domain, false, &["list"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(err.contains(&format!("belongs to user {A}")), "{err}");
    let rt = s.runtime().display().to_string();
    for script in [
        format!("cat '{data}' > /dev/null"),
        format!("printf 0123456789abcdef > '{data}'"),
        format!("printf 0123456789abcdef > '{counter}'"),
        format!("ls '{rt}'"),
        format!("cat '{rt}/{}.token'", domain.name()),
    ] {
        let out = s.sh(OUTSIDER, &script);
        assert!(!out.status.success(), "`{script}` succeeded as {OUTSIDER}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("Permission denied"),
            "`{script}`: {}",
            text(&out)
        );
    }

    // A client of B dies (SIGKILL): the driver and `limber list` go on, and B commands
    // again.
    echo.signal(libc::SIGKILL);
    assert_eq!(echo.wait_timeout(LIMIT), None, "killed");
    let out = run(&mut s.limber(B, &domain, true, &["list"]));
    assert!(out.status.success(), "{}", text(&out));
    let out = run(&mut s.limber(
        B,
        &domain,
        true,
        &[
            "actarray",
            "pioneer/actarray/0",
            "pos",
            "1",
            &format!("{before:.3}"),
        ],
    ));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "ok",
        "{}",
        text(&out)
    );

    // The driver ends cleanly (as A, the signal through its process).
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(LIMIT), Some(0), "the driver's exit");
    remove_leftovers(&prefix);
}

/// Removes (as root) what the members' processes of a test domain left in /dev/shm: the
/// connections one member made and another closed (docs/guide/security.md), which only their
/// owner's next process in the domain would remove.
fn remove_leftovers(prefix: &str) {
    for f in shm_files(prefix) {
        let _ = std::fs::remove_file(f);
    }
}

#[test]
fn a_member_waits_a_bounded_time_for_files_not_yet_open_to_the_group() {
    let Some(gid) = users() else { return };
    let s = Scratch::new("wait");
    let domain = Domain::unique_for_test();
    let driver = start_driver(&s, &domain);
    let services = s.runtime().join("iceoryx2").join("services");
    let statics: Vec<PathBuf> = tree(&services)
        .into_iter()
        .filter(|p| p.to_string_lossy().ends_with(".service"))
        .collect();
    assert!(!statics.is_empty());
    // What a member's file is in the instant before its owner widens it: owner-only, of
    // another user (root here, so that the driver's watcher leaves it alone).
    let a_uid = std::fs::metadata(&statics[0]).unwrap().uid();
    let close = |closed: bool| {
        let (uid, g, mode) = if closed {
            (0, 0, 0o400)
        } else {
            (a_uid, gid, 0o440)
        };
        for f in &statics {
            std::os::unix::fs::chown(f, Some(uid), Some(g)).unwrap();
            std::fs::set_permissions(f, std::fs::Permissions::from_mode(mode)).unwrap();
        }
    };
    close(true);

    // Still closed after the wait: a clear error naming the group mode.
    let out = run(&mut s.limber(
        B,
        &domain,
        true,
        &["actarray", "pioneer/actarray/0", "geom", "--timeout", "0.5"],
    ));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        err.contains("not open to you") && err.contains(&format!("LIMBER_GROUP={GROUP}")),
        "{err}"
    );

    // Opened while the member waits: it connects, and its command is carried out.
    let mut c = s.limber(
        B,
        &domain,
        true,
        &[
            "-v",
            "actarray",
            "pioneer/actarray/0",
            "pos",
            "1",
            "0.1",
            "--timeout",
            "20",
        ],
    );
    c.env("NO_COLOR", "1");
    let mut cmd = spawn_with_stderr(c);
    cmd.read_until(|l| l.contains("not open to the group yet; trying again"))
        .expect("B waits");
    close(false);
    cmd.read_until(|l| l == "ok")
        .expect("B's command is carried out");
    assert_eq!(cmd.wait_timeout(LIMIT), Some(0));
    let prefix = prefix(&s, &domain);
    drop(driver);
    remove_leftovers(&prefix);
}

/// [`spawn`], with stderr merged into stdout.
fn spawn_with_stderr(c: Command) -> Proc {
    let mut sh = Command::new("sh");
    sh.arg("-c")
        .arg("exec \"$@\" 2>&1")
        .arg("sh")
        .arg(c.get_program())
        .args(c.get_args())
        .current_dir(c.get_current_dir().unwrap());
    for (k, v) in c.get_envs() {
        match v {
            Some(v) => sh.env(k, v),
            None => sh.env_remove(k),
        };
    }
    spawn(sh)
}

#[test]
fn a_runtime_directory_that_is_not_the_groups_is_refused_with_its_owner_named() {
    let Some(_) = users() else { return };
    let s = Scratch::new("planted");
    let domain = Domain::unique_for_test();
    // The outsider plants the runtime directory first, with the right mode but its own
    // group.
    let out = s.sh(OUTSIDER, "mkdir rt && chmod 2770 rt");
    assert!(out.status.success(), "{}", text(&out));
    let out = run(&mut s.limber(A, &domain, true, &["list"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        err.contains(&format!("owner user {OUTSIDER}"))
            && err.contains(&format!("is not {GROUP}"))
            && err.contains("LIMBER_RUNTIME_DIR"),
        "{err}"
    );
}

#[test]
fn an_unknown_group_is_refused_with_what_to_do() {
    // No root needed: the group does not exist, whoever asks.
    let out = run(Command::new(CLI)
        .arg("list")
        .env("LIMBER_DOMAIN", Domain::unique_for_test().name())
        .env("LIMBER_GROUP", "limber-no-such-group"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        err.contains("limber-no-such-group")
            && err.contains("does not exist")
            && err.contains("groupadd"),
        "{err}"
    );
}

#[test]
fn a_members_crashed_driver_is_cleaned_up_by_its_user_then_another_member_restarts_it() {
    let Some(_) = users() else { return };
    let s = Scratch::new("crash");
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&s, &domain);
    let out = run(&mut s.limber(
        B,
        &domain,
        true,
        &["actarray", "pioneer/actarray/0", "pos", "1", "0.2"],
    ));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "ok",
        "{}",
        text(&out)
    );
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(LIMIT), None, "killed");

    // B's tools see the driver dead and go on; B may not clean up after A's process (that
    // would leave A's services marked for destruction with files only A can remove), so
    // B's driver is refused, naming A and what to do.
    let out = run(&mut s.limber(B, &domain, true, &["list"]));
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("dead"),
        "{}",
        text(&out)
    );
    let out = run(&mut s.limber(B, &domain, true, &["pioneer", "--emulated"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        err.contains(&format!("a process of user {A}")) && err.contains("limber list"),
        "{err}"
    );

    // A's next limber command cleans up; then B's driver serves and A commands it.
    let out = run(&mut s.limber(A, &domain, true, &["list"]));
    assert!(out.status.success(), "{}", text(&out));
    let mut c = s.limber(B, &domain, true, &["pioneer", "--emulated"]);
    c.env("LIMBER_GROUP", GROUP);
    let mut driver = spawn(c);
    assert!(
        driver.read_until(|l| l.ends_with("ready")).is_some(),
        "B's driver did not start"
    );
    let out = run(&mut s.limber(
        A,
        &domain,
        true,
        &["actarray", "pioneer/actarray/0", "pos", "1", "0.1"],
    ));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "ok",
        "{}",
        text(&out)
    );
    let prefix = prefix(&s, &domain);
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(LIMIT), Some(0), "B's driver's exit");
    remove_leftovers(&prefix);
}

/// A member's driver SIGKILLed while iceoryx2 made one of its connections (a port of its
/// own connecting, as the world's watch of the arm does when the arm answers late) leaves
/// that file empty and write-only. Its user's next command removes it with the rest of the
/// dead driver's files and cleans up at once: it used to put the whole cleanup off while
/// the file was young (under 10 s), so another member's driver was still refused after it
/// (the flaky end of the test above, on a loaded machine).
#[test]
fn a_members_driver_killed_mid_connection_is_cleaned_up_by_its_users_next_command() {
    let Some(_) = users() else { return };
    let s = Scratch::new("midconn");
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&s, &domain);
    let prefix = prefix(&s, &domain);
    // The driver's own ports connect (the world watches the arm) a moment after "ready".
    let a_uid = std::fs::metadata(s.runtime()).unwrap().uid();
    let deadline = std::time::Instant::now() + LIMIT;
    let conn = loop {
        let found = shm_files(&prefix).into_iter().find(|p| {
            p.to_string_lossy().ends_with(".connection")
                && std::fs::metadata(p).is_ok_and(|md| md.uid() == a_uid && md.len() > 0)
        });
        if let Some(p) = found {
            break p;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "the driver made no connection"
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(LIMIT), None, "killed");

    // That connection, as the kill between iceoryx2's creating it and sizing it leaves it:
    // empty, write-only, of its user.
    let md = std::fs::metadata(&conn).unwrap();
    std::fs::remove_file(&conn).unwrap();
    let f = std::fs::File::create(&conn).unwrap();
    f.set_permissions(std::fs::Permissions::from_mode(0o200))
        .unwrap();
    std::os::unix::fs::fchown(&f, Some(md.uid()), Some(md.gid())).unwrap();
    drop(f);

    // A's next limber command cleans up, that file included; then B's driver serves.
    let out = run(&mut s.limber(A, &domain, true, &["list"]));
    assert!(out.status.success(), "{}", text(&out));
    assert!(!conn.exists(), "{} is left", conn.display());
    let mut driver = spawn(s.limber(B, &domain, true, &["pioneer", "--emulated"]));
    assert!(
        driver.read_until(|l| l.ends_with("ready")).is_some(),
        "B's driver did not start"
    );
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(LIMIT), Some(0), "B's driver's exit");
    remove_leftovers(&prefix);
}
