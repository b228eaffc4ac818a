//! A process killed while iceoryx2 was making one of its segments leaves it half made: an
//! empty file nobody may read. iceoryx2 0.10's cleanup after that dead process opens the
//! segment and, run as root, tries again every millisecond for ever (root may open it; its
//! size is zero, and that case never reaches the timeout). That hung a test's teardown
//! (`limber-cli::view`, its driver and viewer SIGKILLed at the end) for its whole 180 s
//! and then `limber clean`, until the file was removed by hand. The domain's cleanup now
//! removes such files before iceoryx2 looks.

use std::os::unix::fs::PermissionsExt;
use std::sync::mpsc;
use std::time::Duration;

use limber_interfaces::prelude::*;
use limber_services::prelude::*;

const CHILD_ENV: &str = "LIMBER_TEST_HALF_MADE_DOMAIN";
const DEVICE: &str = "half/actarray/0";

/// Run by `a_segment_left_half_made_does_not_hang_the_cleanup` as a process of its own (a
/// no-op otherwise): a driver and a client of its device, connected, then waits to be killed.
#[test]
fn half_made_child() {
    let Ok(name) = std::env::var(CHILD_ENV) else {
        return;
    };
    let domain = Domain::new(&name).unwrap();
    let dctx = Context::new(&domain, Role::Driver, "half-driver").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&dctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.publish().unwrap();
    let cctx = Context::new(&domain, Role::Client, "half-client").unwrap();
    let mut client =
        ActArrayClient::connect_timeout(&cctx, DEVICE, Duration::from_secs(10)).unwrap();
    host.publish().unwrap();
    client.wait_state(Duration::from_secs(10)).unwrap();
    println!("READY");
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
}

/// Joins `domain` as a client named `name` (which cleans up after its dead processes), in a
/// thread of its own: a join that hangs fails the test after a minute instead of hanging it.
fn join_within_a_minute(domain: &Domain, name: &'static str) {
    let (tx, rx) = mpsc::channel();
    let d = domain.clone();
    std::thread::spawn(move || {
        let r = Context::new(&d, Role::Client, name).map(|_| ());
        let _ = tx.send(r.map_err(|e| e.to_string()));
    });
    rx.recv_timeout(Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{name} hung joining the domain"))
        .unwrap();
}

/// Starts `half_made_child` in `domain` and kills it once ready (SIGKILL).
fn killed_child(domain: &Domain) {
    let mut child = limber_services::testing::TestProcess::start(
        "half_made_child",
        CHILD_ENV,
        domain.name(),
        "READY",
    )
    .child;
    child.kill().unwrap();
    child.wait().unwrap();
}

/// Starts `half_made_child` in `domain`, kills it once ready, and spoils each of its
/// connections as a kill between iceoryx2's create and its sizing leaves them: empty and
/// write-only. Returns each spoiled file with its path (at least one).
fn killed_leaving_half_made(domain: &Domain) -> Vec<(std::path::PathBuf, std::fs::File)> {
    let prefix = domain.prefix().unwrap().to_string();
    killed_child(domain);
    let mut spoiled = Vec::new();
    for e in std::fs::read_dir("/dev/shm").unwrap().flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with(&prefix) && name.ends_with(".connection") {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(e.path())
                .unwrap();
            f.set_len(0).unwrap();
            f.set_permissions(std::fs::Permissions::from_mode(0o200))
                .unwrap();
            spoiled.push((e.path(), f));
        }
    }
    assert!(!spoiled.is_empty(), "the child left no connection to spoil");
    spoiled
}

#[test]
fn a_segment_left_half_made_does_not_hang_the_cleanup() {
    let domain = Domain::unique_for_test();
    let prefix = domain.prefix().unwrap().to_string();
    let half_made = killed_leaving_half_made(&domain).len();

    // Old code, as root: the cleanup never returns.
    let (tx, rx) = mpsc::channel();
    let cleaner = domain.clone();
    std::thread::spawn(move || {
        let _ = tx.send(cleaner.remove_files().map_err(|e| e.to_string()));
    });
    let removed = rx
        .recv_timeout(Duration::from_secs(60))
        .expect("the domain's cleanup hung on a half-made segment")
        .unwrap();
    assert!(removed.files >= half_made, "{removed:?}");
    let left: Vec<String> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with(&prefix))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Run by `a_driver_does_not_hang_on_what_a_killed_client_left_half_made` as a process of
/// its own (a no-op otherwise): a client of the parent's device, then waits to be killed.
#[test]
fn half_made_client() {
    let Ok(name) = std::env::var(CLIENT_ENV) else {
        return;
    };
    let domain = Domain::new(&name).unwrap();
    let cctx = Context::new(&domain, Role::Client, "half-client").unwrap();
    let mut client =
        ActArrayClient::connect_timeout(&cctx, DEVICE, Duration::from_secs(10)).unwrap();
    println!("CONNECTED");
    client.wait_state(Duration::from_secs(10)).unwrap();
    println!("READY");
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
}

const CLIENT_ENV: &str = "LIMBER_TEST_HALF_MADE_CLIENT";

/// A live driver cleans up after its dead clients (its 1 Hz housekeeping): a client killed
/// while iceoryx2 made one of its connections does not hang the driver's loop. Such a file
/// names a port of the dead client: the driver removes it at once, young as it is, and
/// cleans up.
#[test]
fn a_driver_does_not_hang_on_what_a_killed_client_left_half_made() {
    let domain = Domain::unique_for_test();
    let prefix = domain.prefix().unwrap().to_string();
    let ctx = Context::new(&domain, Role::Driver, "half-driver").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.publish().unwrap();
    let limber_services::testing::TestProcess {
        child: mut client,
        mut out,
    } = limber_services::testing::TestProcess::start(
        "half_made_client",
        CLIENT_ENV,
        domain.name(),
        "CONNECTED",
    );
    // A state for the client: the driver connects to it as it publishes.
    host.publish().unwrap();
    let mut line = String::new();
    std::io::BufRead::read_line(&mut out, &mut line).unwrap();
    assert!(line.starts_with("READY"), "the client said {line:?}");
    client.kill().unwrap();
    client.wait().unwrap();
    // Each connection file made anew, empty and write-only (the driver keeps its mapping
    // of the old one): what a kill between iceoryx2's create and its sizing leaves.
    let mut spoiled = Vec::new();
    for e in std::fs::read_dir("/dev/shm").unwrap().flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with(&prefix) && name.ends_with(".connection") {
            std::fs::remove_file(e.path()).unwrap();
            let f = std::fs::File::create(e.path()).unwrap();
            f.set_permissions(std::fs::Permissions::from_mode(0o200))
                .unwrap();
            spoiled.push((e.path(), f));
        }
    }
    assert!(
        !spoiled.is_empty(),
        "the client left no connection to spoil"
    );
    // Young, and of the dead client's ports: removed, and the cleanup goes on (old code,
    // as root: never returns).
    host.cleanup_dead();
    assert!(spoiled.iter().all(|(p, _)| !p.exists()));
    assert_eq!(
        dead_nodes(&domain),
        0,
        "the dead client is cleaned up after"
    );
    host.publish().unwrap();
}

/// The processes of `domain` that iceoryx2 lists dead (not cleaned up after yet).
fn dead_nodes(domain: &Domain) -> usize {
    use iceoryx2::prelude::{CallbackProgression, Node, NodeState, ipc};
    let mut n = 0;
    Node::<ipc::Service>::list(domain.config().unwrap(), |s| {
        if matches!(s, NodeState::Dead(_)) {
            n += 1;
        }
        CallbackProgression::Continue
    })
    .unwrap();
    n
}

/// Plants in `/dev/shm`, next to the connection `like` of the domain with `prefix`, a
/// connection between two ports that no process has, empty and write-only: what a live
/// process's connection looks like in the instant iceoryx2 makes it. Returns its path and
/// the open file.
fn plant_stray(prefix: &str, like: &std::path::Path) -> (std::path::PathBuf, std::fs::File) {
    let name = like.file_name().unwrap().to_string_lossy().to_string();
    let hash = name
        .strip_prefix(prefix)
        .and_then(|r| r.split('_').next())
        .expect("a connection of the domain");
    let path = like.with_file_name(format!("{prefix}{hash}_11_22.connection"));
    let f = std::fs::File::create(&path).unwrap();
    f.set_permissions(std::fs::Permissions::from_mode(0o200))
        .unwrap();
    (path, f)
}

/// A process joining the domain cleans up after its dead processes (iceoryx2 did that on
/// every node's creation, and, as root, never returned on a segment a killed process left
/// half made: a client or driver started after such a kill hung in `Context::new`). The
/// join removes the segments the dead left half made, whatever their age, and cleans up
/// after them at once (it used to put the whole cleanup off while they were young: a
/// member's crashed driver stayed dead after its user's next `limber list`,
/// tests/tests/group.rs). A young half-made segment of ports that are not the dead's (its
/// maker may be making it still) puts the cleanup off; once old, it is removed and the
/// cleanup goes on.
#[test]
fn a_process_joining_does_not_hang_on_what_a_killed_one_left_half_made() {
    let domain = Domain::unique_for_test();
    let prefix = domain.prefix().unwrap().to_string();
    let spoiled = killed_leaving_half_made(&domain);
    assert!(dead_nodes(&domain) > 0, "the killed child is listed dead");
    let join = |name: &'static str| join_within_a_minute(&domain, name);
    // Young, of the dead's ports: removed, and the cleanup goes on at once (old code: put
    // off; as root before that: never returned).
    join("late-client");
    let left: Vec<_> = spoiled.iter().filter(|(p, _)| p.exists()).collect();
    assert!(left.is_empty(), "left half made: {left:?}");
    assert_eq!(
        dead_nodes(&domain),
        0,
        "the killed child is cleaned up after"
    );

    // A young one of ports nobody has, and a dead process again: the cleanup is put off.
    let again = killed_leaving_half_made(&domain);
    let stray = plant_stray(&prefix, &again[0].0);
    join("next-client");
    assert!(
        stray.0.exists(),
        "a young segment of unknown ports is left alone"
    );
    assert!(
        again.iter().all(|(p, _)| !p.exists()),
        "the dead's are removed"
    );
    assert!(dead_nodes(&domain) > 0, "the cleanup is put off");
    // Old: removed, and the cleanup goes on.
    stray
        .1
        .set_modified(std::time::SystemTime::now() - Duration::from_secs(60))
        .unwrap();
    join("later-client");
    assert!(!stray.0.exists());
    assert_eq!(
        dead_nodes(&domain),
        0,
        "the killed child is cleaned up after"
    );
}

/// A client killed while iceoryx2 made one of its connections, before the driver
/// connected to it: the driver's next publication connects to the new client, and
/// iceoryx2 0.10, as root, waited on the half-made file for ever there (the loop froze in
/// `publish`). The host removes the half-made segments of a client that is gone before
/// its ports connect, whatever their age.
#[test]
fn a_driver_does_not_hang_connecting_to_a_client_killed_mid_connection() {
    let domain = Domain::unique_for_test();
    let prefix = domain.prefix().unwrap().to_string();
    let ctx = Context::new(&domain, Role::Driver, "half-driver").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.publish().unwrap();
    let shm = || -> std::collections::HashSet<std::path::PathBuf> {
        std::fs::read_dir("/dev/shm")
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                let n = p.file_name().unwrap().to_string_lossy();
                n.starts_with(&prefix) && n.ends_with(".connection")
            })
            .collect()
    };
    let before = shm();
    let mut client = limber_services::testing::TestProcess::start(
        "half_made_client",
        CLIENT_ENV,
        domain.name(),
        "CONNECTED",
    )
    .child;
    client.kill().unwrap();
    client.wait().unwrap();
    // The client's connections, made anew empty and write-only: what a kill between
    // iceoryx2's create and its sizing leaves (the driver has not opened them yet).
    let spoiled: Vec<_> = shm().difference(&before).cloned().collect();
    assert!(!spoiled.is_empty(), "the client made no connection");
    for p in &spoiled {
        std::fs::remove_file(p).unwrap();
        let f = std::fs::File::create(p).unwrap();
        f.set_permissions(std::fs::Permissions::from_mode(0o200))
            .unwrap();
    }
    // Old code, as root: `publish` never returns; the test ends in an abort.
    let (done, watch) = mpsc::channel::<()>();
    std::thread::spawn(move || {
        if watch.recv_timeout(Duration::from_secs(60)) == Err(mpsc::RecvTimeoutError::Timeout) {
            eprintln!("the driver hung connecting to a client killed mid-connection");
            std::process::abort();
        }
    });
    host.publish().unwrap();
    host.cleanup_dead();
    host.publish().unwrap();
    let _ = done.send(());
    // None is left half made (iceoryx2 made what it needed anew).
    for p in &spoiled {
        if let Ok(md) = std::fs::metadata(p) {
            assert!(md.len() > 0, "{} is still half made", p.display());
        }
    }
}

/// A process killed while iceoryx2 wrote one of its port or service tags leaves the tag
/// unfinished (mode 0600, iceoryx2's mode while it writes a static storage): iceoryx2 does
/// not list it, and with an unfinished service tag its cleanup after that process failed:
/// the process stayed listed dead for good (seen after a driver SIGKILLed mid-connection,
/// tests/tests/group.rs; an unfinished port tag did no harm, checked too). Nobody will
/// finish a tag: the cleanup after the dead removes the tags they left unfinished, and the
/// dead process is gone from the list.
#[test]
fn a_tag_a_killed_process_left_unfinished_does_not_keep_it_listed_dead() {
    for kind in [".port_tag", ".service_tag"] {
        let domain = Domain::unique_for_test();
        let prefix = domain.prefix().unwrap().to_string();
        killed_child(&domain);
        let nodes = domain.root().unwrap().join("nodes");
        let mut files = Vec::new();
        for node in std::fs::read_dir(&nodes).unwrap().flatten() {
            if !node.path().is_dir() {
                continue;
            }
            for e in std::fs::read_dir(node.path()).unwrap().flatten() {
                let name = e.file_name().to_string_lossy().to_string();
                if name.starts_with(&prefix) && name.ends_with(kind) {
                    files.push(e.path());
                }
            }
        }
        let file = files
            .first()
            .unwrap_or_else(|| panic!("no {kind} of the killed child"));
        std::fs::set_permissions(file, std::fs::Permissions::from_mode(0o600)).unwrap();
        assert!(dead_nodes(&domain) > 0, "the killed child is listed dead");
        // A process joining the domain cleans up after the dead.
        join_within_a_minute(&domain, "after-unfinished");
        assert_eq!(
            dead_nodes(&domain),
            0,
            "{kind} left unfinished: the killed child stays listed dead"
        );
        assert!(!file.exists(), "the unfinished {} stayed", file.display());
    }
}
