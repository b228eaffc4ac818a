#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

use std::io::Read;
use std::process::{Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Runs `cmd` (stdin closed) like [`Command::output`]; panics, after killing it, when it
/// is still running after `limit`, or when its output is still open `limit` after the start.
pub fn output_within(mut cmd: impl std::borrow::BorrowMut<Command>, limit: Duration) -> Output {
    let cmd = cmd.borrow_mut();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    let drain = |mut r: Box<dyn Read + Send>| {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut v = Vec::new();
            // A read error ends the output early; what was read is still reported.
            if let Err(e) = r.read_to_end(&mut v) {
                v.extend_from_slice(format!("\n[reading the output failed: {e}]").as_bytes());
            }
            // The receiver gives up only after its deadline has failed the test, so a
            // failed send has nobody left to tell.
            tx.send(v).unwrap_or_default();
        });
        rx
    };
    let out = drain(Box::new(child.stdout.take().expect("piped stdout")));
    let err = drain(Box::new(child.stderr.take().expect("piped stderr")));
    let deadline = Instant::now() + limit;
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the child") {
            break status;
        }
        if Instant::now() >= deadline {
            let killed = child.kill();
            let reaped = child.wait();
            panic!("{cmd:?} still running after {limit:?}: killed ({killed:?}, {reaped:?})");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let rest = |rx: mpsc::Receiver<Vec<u8>>| {
        rx.recv_timeout(deadline.saturating_duration_since(Instant::now()))
            .unwrap_or_else(|_| panic!("{cmd:?}: output still open after {limit:?}"))
    };
    Output {
        status,
        stdout: rest(out),
        stderr: rest(err),
    }
}
