//! Shared by the CLI tests: a test driver on a thread of the test process.

#![allow(dead_code)]

use std::process::{Command, Output};
use std::sync::mpsc;
use std::time::Duration;

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

/// `limber pioneer --emulated` in `domain`, killed when dropped.
pub struct Pioneer(std::process::Child);

impl Drop for Pioneer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `limber pioneer --emulated` in `domain` and waits (bounded) for its "ready".
pub fn pioneer_emulated(domain: &str) -> Pioneer {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let mut child = Command::new(LIMBER)
        .args(["pioneer", "--emulated"])
        .env("LIMBER_DOMAIN", domain)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let out = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(out).lines() {
            let Ok(line) = line else { break };
            if line.ends_with("ready") && tx.send(()).is_err() {
                break;
            }
        }
    });
    let p = Pioneer(child);
    rx.recv_timeout(Duration::from_secs(15))
        .expect("the Pioneer driver is ready");
    p
}
