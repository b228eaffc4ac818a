//! A second local Unix user, `limber-hostile`, for the tests of what another user cannot do
//! (`security.rs`, `bridge_access.rs`): created with `useradd` when needed (root only).
#![allow(dead_code)] // each test file uses a part of it

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use limber_bounded_run::output_within;
use limber_services::domain_dir::euid;

/// The CLI the hostile user runs (or a copy of it).
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
/// The second user's name.
pub const HOSTILE: &str = "limber-hostile";
/// How long one of its commands may take.
pub const LIMIT: Duration = Duration::from_secs(30);

/// Creates the hostile user if needed; None (with the reason printed) when not root.
pub fn hostile_user() -> Option<&'static str> {
    if euid() != 0 {
        eprintln!(
            "SKIPPED: creating a second Unix user needs root (these tests run as root in CI)"
        );
        return None;
    }
    // Tests run in parallel processes: useradd may meet another's lock or find the user
    // made meanwhile. Bounded retries.
    for _ in 0..50 {
        if output_within(Command::new("id").arg("-u").arg(HOSTILE), LIMIT)
            .status
            .success()
        {
            return Some(HOSTILE);
        }
        let _ = output_within(
            Command::new("useradd").args(["-M", "-r", "-s", "/usr/sbin/nologin", HOSTILE]),
            LIMIT,
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("cannot create the user {HOSTILE}");
}

/// Runs `script` with `sh -c` as `user`, in `dir`, with `env`.
pub fn as_user(user: &str, dir: &Path, env: &[(&str, &str)], script: &str) -> Output {
    let mut c = Command::new("runuser");
    c.args(["-u", user, "--", "sh", "-c", script])
        .current_dir(dir);
    for (k, v) in env {
        c.env(k, v);
    }
    output_within(c, LIMIT)
}

/// A directory everybody may enter, for the hostile user's work, removed at the end.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Scratch {
        let p = std::env::temp_dir().join(format!("limber-sec-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o1777)).unwrap();
        Scratch(p)
    }

    /// A copy of the CLI the hostile user can run (the build directory may be private).
    pub fn cli(&self, user: &str) -> String {
        if as_user(user, &self.0, &[], &format!("test -x '{CLI}'"))
            .status
            .success()
        {
            return CLI.to_string();
        }
        let to = self.0.join("limber");
        std::fs::copy(CLI, &to).unwrap();
        to.to_string_lossy().into_owned()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
