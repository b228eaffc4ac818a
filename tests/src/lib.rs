#![doc = include_str!("../README.md")]

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// How long [`Proc::read_until`] waits for a line before the test fails.
pub const LINE_TIMEOUT: Duration = Duration::from_secs(30);

/// A child process that is killed when dropped.
#[derive(Debug)]
pub struct Proc {
    /// The child (its stdout is read by a thread of its own: see [`Proc::read_until`]).
    pub child: Child,
    /// The child's stdout, line by line, from the reader thread (disconnected at EOF).
    lines: Receiver<String>,
    /// The child's stdin.
    stdin: Option<ChildStdin>,
    exe: String,
}

impl Proc {
    /// Spawns `exe` with `args` in domain `domain` and waits (bounded) until it prints
    /// `ready`, as every driver of the tests does once it serves.
    pub fn spawn_ready(exe: &str, domain: &str, args: &[&str]) -> Proc {
        let mut d = Proc::spawn(exe, domain, args);
        assert!(
            d.read_until(|l| l == "ready").is_some(),
            "{exe} did not start"
        );
        d
    }

    /// Spawns `exe` with `args` in domain `domain`, stdin and stdout piped.
    pub fn spawn(exe: &str, domain: &str, args: &[&str]) -> Proc {
        let mut c = Command::new(exe);
        c.args(args).env("LIMBER_DOMAIN", domain);
        Proc::spawn_command(c)
    }

    /// Spawns a prepared command (its environment, working directory), stdin and stdout
    /// piped, stderr inherited.
    pub fn spawn_command(mut c: Command) -> Proc {
        let exe = c.get_program().to_string_lossy().into_owned();
        let mut child = c
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {exe}: {e}"));
        let out = child.stdout.take().expect("stdout is piped");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let stdin = child.stdin.take();
        Proc {
            child,
            lines,
            stdin,
            exe,
        }
    }

    /// Writes `line` (and a newline) to the child's stdin.
    pub fn write_line(&mut self, line: &str) {
        let stdin = self.stdin.as_mut().expect("stdin is piped");
        writeln!(stdin, "{line}")
            .and_then(|()| stdin.flush())
            .unwrap_or_else(|e| panic!("cannot write to {}: {e}", self.exe));
    }

    /// Sends a signal (SIGKILL, SIGTERM, ...).
    pub fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child's pid has no memory-safety implications.
        unsafe {
            libc::kill(self.child.id() as i32, sig);
        }
    }

    /// Waits up to `timeout` for the exit; returns the exit code (None: killed by a signal
    /// or still running, in which case it is killed).
    pub fn wait_timeout(&mut self, timeout: Duration) -> Option<i32> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                return status.code();
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Reads stdout lines until one satisfies `pred` and returns it; None if stdout ends
    /// first. Fails the test if no such line comes within [`LINE_TIMEOUT`].
    pub fn read_until(&mut self, pred: impl Fn(&str) -> bool) -> Option<String> {
        self.read_until_within(LINE_TIMEOUT, pred)
    }

    /// [`Proc::read_until`] with its own timeout.
    pub fn read_until_within(
        &mut self,
        timeout: Duration,
        pred: impl Fn(&str) -> bool,
    ) -> Option<String> {
        let deadline = Instant::now() + timeout;
        let mut seen = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if pred(line.trim_end()) => return Some(line.trim_end().to_string()),
                Ok(line) => seen.push(line),
                Err(RecvTimeoutError::Disconnected) => return None,
                Err(RecvTimeoutError::Timeout) => panic!(
                    "{}: no expected line within {timeout:?}; lines seen meanwhile: {seen:?}",
                    self.exe
                ),
            }
        }
    }

    /// All remaining stdout (after the process ended). Fails the test if stdout is still
    /// open after [`LINE_TIMEOUT`] (a grandchild holding it, for example).
    pub fn rest_of_stdout(&mut self) -> String {
        let deadline = Instant::now() + LINE_TIMEOUT;
        let mut s = String::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    s.push_str(&line);
                    s.push('\n');
                }
                Err(RecvTimeoutError::Disconnected) => return s,
                Err(RecvTimeoutError::Timeout) => panic!(
                    "{}: stdout still open {LINE_TIMEOUT:?} after the exit; read so far: {s}",
                    self.exe
                ),
            }
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The keys every multi-process Pioneer test sets: short timeouts, so faults are detected
/// quickly.
const PIONEER_TEST_KEYS: [&str; 4] = [
    "link_timeout_ms = 400",
    "reconnect_interval_ms = 100",
    "arm_info_timeout_ms = 500",
    "stall_timeout_ms = 1500",
];

/// Writes `<dir>/<name>.toml`, a Pioneer driver configuration with the tests' short
/// timeouts and the keys of `extra` (which win over the defaults here); returns its path.
pub fn pioneer_test_config(dir: &std::path::Path, name: &str, extra: &str) -> std::path::PathBuf {
    let mut toml = extra.to_string();
    if !toml.is_empty() && !toml.ends_with('\n') {
        toml.push('\n');
    }
    for line in PIONEER_TEST_KEYS {
        let key = line.split(' ').next().unwrap_or(line);
        if !extra.lines().any(|l| l.trim_start().starts_with(key)) {
            toml += line;
            toml.push('\n');
        }
    }
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, toml).expect("write the test configuration");
    path
}

/// Starts the Pioneer driver binary `bin` in `domain` on the link `port` with the
/// configuration file `cfg`, and waits (bounded) for its "ready" line.
pub fn start_pioneer(bin: &str, domain: &str, port: &str, cfg: &std::path::Path) -> Proc {
    let cfg = cfg.to_str().expect("a UTF-8 configuration path");
    let mut d = Proc::spawn(bin, domain, &["--port", port, "--config", cfg]);
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "driver did not start"
    );
    d
}

/// Writes a Zenoh configuration with user/password authentication to `dir/file` (user
/// `user`, password `password`; with `dictionary`, the file of the users it accepts, as a
/// listening bridge has) and returns its path, for the bridge tests.
pub fn usrpwd_config(
    dir: &std::path::Path,
    file: &str,
    user: &str,
    password: &str,
    dictionary: Option<&std::path::Path>,
) -> String {
    let path = dir.join(file);
    let dict = dictionary
        .map(|d| format!(", dictionary_file: \"{}\"", d.display()))
        .unwrap_or_default();
    let text = format!(
        "{{ transport: {{ auth: {{ usrpwd: {{ user: \"{user}\", password: \"{password}\"{dict} }} }} }} }}\n"
    );
    std::fs::write(&path, text).expect("write a Zenoh configuration");
    path.display().to_string()
}
