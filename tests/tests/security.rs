//! Another local user can neither read, command nor deny a domain (docs/guide/security.md).
//!
//! The hostile actions run as a second Unix user, `limber-hostile`, which the tests create
//! (idempotently) with `useradd`; they need root, and are skipped with the reason otherwise.

use std::os::unix::fs::MetadataExt;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

use limber_bounded_run::output_within;
use limber_services::domain_dir::{DomainError, euid};
use limber_services::prelude::*;
use limber_services::{ContextError, Domain, Role};
use limber_tests::Proc;

mod hostile;
use hostile::{LIMIT, Scratch, as_user, hostile_user};

const DRIVER: &str = env!("CARGO_BIN_EXE_limber-test-driver");
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");

fn start_driver(domain: &Domain) -> Proc {
    let mut d = Proc::spawn(DRIVER, domain.name(), &[]);
    assert!(
        d.read_until(|l| l == "ready").is_some(),
        "driver did not start"
    );
    d
}

/// A client of ours connects, commands and sees the state.
fn client_works(domain: &Domain) {
    let ctx = Context::new(domain, Role::Client, "owner").expect("the owner joins");
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", Duration::from_secs(5))
        .expect("the owner connects");
    arm.power(true).expect("power");
    let t = arm.move_to(1, 0.25).expect("move");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );
}

fn shm_files(prefix: &str) -> Vec<PathBuf> {
    std::fs::read_dir("/dev/shm")
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
        .map(|e| e.path())
        .collect()
}

#[test]
fn another_user_can_neither_read_nor_write_nor_deny_a_running_domain() {
    let Some(user) = hostile_user() else { return };
    let scratch = Scratch::new("running");
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain);
    client_works(&domain);

    let prefix = domain.prefix().unwrap().to_string();
    let files = shm_files(&prefix);
    let counter: Vec<_> = files
        .iter()
        .filter(|p| p.to_string_lossy().ends_with(".global_mgmt"))
        .collect();
    assert_eq!(counter.len(), 1, "one node counter: {files:?}");
    for f in &files {
        // A file listed a moment ago may be gone: the client above closing its ports, the
        // driver cleaning up after it. A file that no longer exists exposes nothing.
        let mode = match std::fs::metadata(f) {
            Ok(m) => m.mode() & 0o777,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => panic!("{}: {e}", f.display()),
        };
        assert_eq!(mode, 0o600, "{} is {mode:o}", f.display());
    }

    // The hostile user writes 16 bytes into the counter (what used to lock a domain out),
    // reads a segment, lists and reads the owner's runtime directory.
    let counter = counter[0].display().to_string();
    let rt = format!("/tmp/limber-{}", euid());
    let segment = files
        .iter()
        .find(|p| p.to_string_lossy().ends_with(".data"))
        .expect("a data segment")
        .display()
        .to_string();
    for script in [
        format!("printf 0123456789abcdef > '{counter}'"),
        format!("cat '{segment}' > /dev/null"),
        format!("ls '{rt}'"),
        format!("cat '{rt}/{}.token'", domain.name()),
        format!("touch '{rt}/iceoryx2/x'"),
    ] {
        let out = as_user(user, &scratch.0, &[], &script);
        assert!(!out.status.success(), "`{script}` succeeded as {user}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("Permission denied"),
            "`{script}`: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }

    // The hostile user's own `limber list` of the domain sees none of its devices and says
    // whose it is.
    let cli = scratch.cli(user);
    let out = as_user(
        user,
        &scratch.0,
        &[("LIMBER_DOMAIN", domain.name())],
        &format!("'{cli}' list"),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    assert!(text.contains("no devices in domain"), "{text}");
    assert!(
        text.contains(&format!("also exists for user root (uid {})", euid())),
        "{text}"
    );

    // The domain still works, and a restarted driver starts.
    client_works(&domain);
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(LIMIT), Some(0));
    let _driver = start_driver(&domain);
    client_works(&domain);
}

#[test]
fn names_another_user_could_plant_beforehand_do_not_stop_a_new_domain() {
    let Some(user) = hostile_user() else { return };
    let scratch = Scratch::new("plant");
    let domain = Domain::unique_for_test();
    // Where the domain's files used to be (prefix `<domain>_`, root /tmp/iceoryx2): the
    // node counter iceoryx2 0.10 made for that prefix, filled with garbage, planted before
    // anything of the domain exists.
    let planted = format!(
        "/dev/shm/{}_9204dd183d1c4d8e1ff592a30766ffa6765aa8b5_node.0_10_0.global_mgmt",
        domain.name()
    );
    let out = as_user(
        user,
        &scratch.0,
        &[],
        &format!("printf 0123456789abcdef > '{planted}' && chmod 666 '{planted}'"),
    );
    assert!(out.status.success(), "{out:?}");
    let driver = start_driver(&domain);
    client_works(&domain);
    drop(driver);
    let _ = std::fs::remove_file(&planted);
}

#[test]
fn a_runtime_directory_of_another_user_is_refused_with_its_owner_named() {
    let Some(user) = hostile_user() else { return };
    let scratch = Scratch::new("rtdir");
    let rt = scratch.0.join("rt");
    let out = as_user(user, &scratch.0, &[], "mkdir -m 777 rt");
    assert!(out.status.success(), "{out:?}");
    let domain = Domain::unique_for_test();
    let out = output_within(
        Command::new(CLI)
            .arg("list")
            .env("LIMBER_DOMAIN", domain.name())
            .env("LIMBER_RUNTIME_DIR", &rt),
        LIMIT,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{out:?}");
    assert!(
        err.contains(&format!("belongs to user {user}")) && err.contains("LIMBER_RUNTIME_DIR"),
        "{err}"
    );
}

#[test]
fn a_node_counter_of_another_user_is_refused_with_its_owner_named() {
    let Some(user) = hostile_user() else { return };
    let scratch = Scratch::new("counter");
    let domain = Domain::unique_for_test();
    // Suppose the prefix leaked (it is random and kept in the owner's 0700 directory): the
    // hostile user makes the domain's node counter first.
    let prefix = domain.prefix().unwrap().to_string();
    let path = format!("/dev/shm/{prefix}x_node.0_10_0.global_mgmt");
    let out = as_user(
        user,
        &scratch.0,
        &[],
        &format!("printf 0123456789abcdef > '{path}'"),
    );
    assert!(out.status.success(), "{out:?}");
    let fresh = Domain::new(domain.name()).unwrap();
    let err = Context::new(&fresh, Role::Driver, "d").expect_err("a foreign counter is refused");
    let _ = std::fs::remove_file(&path);
    let ContextError::Domain { source, .. } = &err else {
        panic!("unexpected error: {err:?}");
    };
    let DomainError::ForeignOwner { owner, .. } = source.as_ref() else {
        panic!("unexpected error: {err:?}");
    };
    assert!(owner.contains(user), "{owner}");
    assert!(err.to_string().contains(&path), "{err}");
}

#[test]
fn a_damaged_node_counter_is_reported_with_what_to_do() {
    // What another user could do before limber narrowed the counter's mode: 16 bytes of
    // garbage in it. Done here by the owner, so the message can be checked.
    let domain = Domain::unique_for_test();
    drop(Context::new(&domain, Role::Client, "first").unwrap());
    let prefix = domain.prefix().unwrap().to_string();
    let counter = shm_files(&prefix)
        .into_iter()
        .find(|p| p.to_string_lossy().ends_with(".global_mgmt"))
        .expect("the node counter");
    std::fs::write(&counter, b"0123456789abcdef").unwrap();
    let err = Context::new(&domain, Role::Client, "second").expect_err("a damaged counter");
    let _ = std::fs::remove_file(&counter);
    assert!(matches!(err, ContextError::NodeCounter { .. }), "{err:?}");
    let text = err.to_string();
    assert!(
        text.contains(&prefix) && text.contains("remove it"),
        "{text}"
    );
    // Once removed, the domain works again.
    Context::new(&domain, Role::Client, "third").expect("a fresh counter");
}
