//! Shared by the CLI tests: a test driver on a thread of the test process.

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use limber_services::testing::TestDriver;
use limber_services::{Context, Domain, Role};

/// The binary under test.
pub const LIMBER: &str = env!("CARGO_BIN_EXE_limber");

/// Runs the test driver on a thread of this process until `stop` is dropped.
pub fn driver(domain: &str) -> mpsc::Sender<()> {
    let (tx, rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.to_string();
    std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "testdriver").unwrap();
        let mut d = TestDriver::new(&ctx, "cli", 6).unwrap();
        ready_tx.send(()).unwrap();
        let _ = d.run(Duration::from_millis(10), || {
            !matches!(rx.try_recv(), Err(mpsc::TryRecvError::Empty))
        });
    });
    ready_rx.recv_timeout(Duration::from_secs(10)).unwrap();
    tx
}

/// How long one `limber` verb may take before the test fails.
pub const VERB_TIMEOUT: Duration = Duration::from_secs(60);

/// Runs `limber <args>` in `domain`.
pub fn limber(domain: &str, args: &[&str]) -> Output {
    output(Command::new(LIMBER).args(args).env("LIMBER_DOMAIN", domain))
}

/// `cmd.output()` (stdin closed), but killed and failing the test after [`VERB_TIMEOUT`].
pub fn output(cmd: &mut Command) -> Output {
    limber_bounded_run::output_within(cmd, VERB_TIMEOUT)
}

/// Stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// Stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// A background `limber` process; its stdout lines arrive on a channel.
pub struct Bg(pub Child, pub Receiver<String>);

impl Bg {
    pub fn spawn(domain: &str, args: &[&str]) -> Bg {
        let mut child = Command::new(LIMBER)
            .args(args)
            .env("LIMBER_DOMAIN", domain)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let out = child.stdout.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Bg(child, rx)
    }

    /// The first stdout line satisfying `pred`, within 30 s.
    pub fn line(&mut self, pred: impl Fn(&str) -> bool) -> String {
        let timeout = Duration::from_secs(30);
        let deadline = Instant::now() + timeout;
        let mut seen = Vec::new();
        loop {
            match self
                .1
                .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            {
                Ok(l) if pred(l.trim_end()) => return l.trim_end().to_string(),
                Ok(l) => seen.push(l),
                Err(RecvTimeoutError::Disconnected) => {
                    panic!("process ended before the expected line; it printed {seen:?}")
                }
                Err(RecvTimeoutError::Timeout) => {
                    panic!("no expected line within {timeout:?}; the process printed {seen:?}")
                }
            }
        }
    }

    pub fn term(&mut self) -> Option<i32> {
        self.end_with(libc::SIGTERM)
    }

    /// Sends `sig` (one that does not end the process).
    pub fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child; no memory is involved.
        unsafe { libc::kill(self.0.id() as i32, sig) };
    }

    /// Sends `sig` and waits up to 10 s for the exit; the exit code.
    pub fn end_with(&mut self, sig: i32) -> Option<i32> {
        self.signal(sig);
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Ok(Some(s)) = self.0.try_wait() {
                return s.code();
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        None
    }
}

impl Drop for Bg {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `limber pioneer --emulated` in `domain` and waits (bounded) for its "ready";
/// killed when dropped.
pub fn pioneer_emulated(domain: &str) -> Bg {
    let mut p = Bg::spawn(domain, &["pioneer", "--emulated"]);
    p.line(|l| l.ends_with("ready"));
    p
}
