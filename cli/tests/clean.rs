//! `limber clean`: a domain's files removed once no live process uses it, refused (exit 5,
//! naming the processes) while one does.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use limber_services::{Context, Domain, Role};

mod common;
use common::{LIMBER, output, pioneer_emulated, stderr, stdout};

/// Every file and directory whose name contains `needle`, under `dir` (recursively).
fn named_with(dir: &Path, needle: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(rd) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in rd.map(Result::unwrap) {
        let path = e.path();
        if e.file_type().unwrap().is_dir() {
            out.extend(named_with(&path, needle));
        }
        if e.file_name().to_string_lossy().contains(needle) {
            out.push(path);
        }
    }
    out.sort();
    out
}

/// Every file of `domain` in its runtime directory and in /dev/shm (the token names it; the
/// token is in every other name), and the node directories that hold its nodes' files.
fn files_of(domain: &Domain) -> Vec<PathBuf> {
    let token = domain.prefix().unwrap().trim_end_matches('_').to_string();
    let runtime = limber_services::domain_dir::runtime_dir();
    let mut v = named_with(&runtime, &token);
    v.extend(named_with(Path::new("/dev/shm"), &token));
    v.extend(named_with(&runtime, domain.name()));
    let nodes = runtime.join("iceoryx2").join("nodes");
    let dirs: Vec<PathBuf> = v
        .iter()
        .filter_map(|p| p.parent())
        .filter(|d| d.parent() == Some(nodes.as_path()))
        .map(PathBuf::from)
        .collect();
    v.extend(dirs);
    v.sort();
    v.dedup();
    v
}

fn clean(domain: &str, args: &[&str]) -> std::process::Output {
    output(
        Command::new(LIMBER)
            .arg("clean")
            .args(args)
            .env("LIMBER_DOMAIN", domain),
    )
}

#[test]
fn clean_refuses_while_a_driver_lives_and_removes_a_sigkilled_drivers_files() {
    let domain = Domain::unique_for_test();
    let name = domain.name();
    let mut driver = pioneer_emulated(name);
    let pid = driver.0.id();

    let o = clean(name, &[]);
    assert_eq!(o.status.code(), Some(5), "{o:?}");
    let err = stderr(&o);
    assert!(
        err.contains(&format!("domain {name} is in use"))
            && err.contains(&format!("limber-driver:pioneer (pid {pid})")),
        "{err}"
    );
    let kept = files_of(&domain);
    assert!(kept.iter().any(|p| p.starts_with("/dev/shm")), "{kept:?}");
    assert!(kept.iter().all(|p| p.exists()), "nothing removed: {kept:?}");

    driver.signal(libc::SIGKILL);
    let deadline = Instant::now() + Duration::from_secs(10);
    while driver.0.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "the driver survived SIGKILL");
        std::thread::sleep(Duration::from_millis(10));
    }
    let left = files_of(&domain);
    let runtime = limber_services::domain_dir::runtime_dir();
    let nodes = runtime.join("iceoryx2").join("nodes");
    assert!(
        left.iter()
            .any(|p| p.starts_with("/dev/shm") && !p.to_string_lossy().ends_with(".global_mgmt")),
        "a SIGKILLed driver leaves its segments: {left:?}"
    );
    assert!(
        left.iter().any(|p| p.parent() == Some(nodes.as_path())),
        "and its node directory: {left:?}"
    );
    assert!(
        left.iter().any(|p| p.ends_with(format!("{name}.token"))),
        "{left:?}"
    );

    let o = clean(name, &[]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    // iceoryx2 cleans up after the dead driver, then limber removes the rest. The process
    // had two nodes (the Pioneer driver's and its world's); iceoryx2 counts one or two
    // dead processes for them (seen both ways), so either count is right.
    let out = stdout(&o);
    let prefix = format!("domain {name}: removed the files of ");
    assert!(
        out.starts_with(&prefix)
            && ["1 dead process, then ", "2 dead processes, then "]
                .iter()
                .any(|n| out[prefix.len()..].starts_with(n)),
        "{}",
        stdout(&o)
    );
    let still: Vec<_> = left.iter().filter(|p| p.exists()).collect();
    assert!(still.is_empty(), "left behind: {still:?}");

    // Nothing left to do: said so, exit 0.
    let o = clean(name, &[]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    assert_eq!(stdout(&o), format!("domain {name}: no files\n"));
}

#[test]
fn clean_all_with_a_prefix_removes_the_idle_domains_and_names_the_busy_ones() {
    let busy = Domain::unique_for_test();
    let idle = Domain::for_test(&format!("{}_idle", busy.name())).unwrap();
    let client = Context::new(&busy, Role::Client, "holder").unwrap();
    drop(Context::new(&idle, Role::Client, "gone").unwrap());
    let idle_files = files_of(&idle);
    assert!(!idle_files.is_empty(), "a domain that was used has files");

    let o = clean("limber", &["--all", "--prefix", busy.name()]);
    assert_eq!(o.status.code(), Some(5), "{o:?}");
    assert!(
        stdout(&o).contains(&format!("domain {}: removed ", idle.name())),
        "{}",
        stdout(&o)
    );
    let err = stderr(&o);
    assert!(
        err.contains(&format!("domain {} is in use", busy.name()))
            && err.contains("limber-client:holder (pid "),
        "{err}"
    );
    let still: Vec<_> = idle_files.iter().filter(|p| p.exists()).collect();
    assert!(still.is_empty(), "left behind: {still:?}");
    assert!(files_of(&busy).iter().all(|p| p.exists()), "kept");
    drop(client);
}

#[test]
fn a_prefix_without_all_is_a_usage_error() {
    let d = Domain::unique_for_test();
    let o = clean(d.name(), &["--prefix", "x"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
}
