//! Shared by the CLI tests: a test driver on a thread of the test process.

#![allow(dead_code)]

use std::io::Read;
use std::process::{Command, Output, Stdio};
use std::sync::mpsc;
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
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("limber runs");
    let drain = |mut r: Box<dyn Read + Send>| {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut v = Vec::new();
            let _ = r.read_to_end(&mut v);
            let _ = tx.send(v);
        });
        rx
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let deadline = Instant::now() + VERB_TIMEOUT;
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for limber") {
            break status;
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{cmd:?} still running after {VERB_TIMEOUT:?}: killed");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    // A process it left behind could hold the pipes open: bounded too.
    let rest = |rx: mpsc::Receiver<Vec<u8>>| {
        rx.recv_timeout(deadline.saturating_duration_since(Instant::now()))
            .unwrap_or_else(|_| panic!("{cmd:?}: output still open after {VERB_TIMEOUT:?}"))
    };
    Output {
        status,
        stdout: rest(out),
        stderr: rest(err),
    }
}

/// Stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// Stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}
