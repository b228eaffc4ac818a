//! Signals and the long-running verbs: simarm, the emulator and the demo ignore the
//! signals that would end a process by default and are no request to end (SIGALRM,
//! SIGUSR1, ...) and end cleanly on SIGQUIT; a client stopped and continued in a blocking
//! wait resumes it.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::testing::TestDriver;
use limber_services::{Domain, Role};

mod common;
use common::{Bg, limber, stderr};

const IGNORED: [i32; 6] = [
    libc::SIGALRM,
    libc::SIGUSR1,
    libc::SIGUSR2,
    libc::SIGIO,
    libc::SIGVTALRM,
    libc::SIGXFSZ,
];

#[test]
fn simarm_and_emulator_ignore_sigalrm_and_sigusr1_and_end_on_sigquit() {
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(d.name(), &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    let mut emu = Bg::spawn(d.name(), &["emulator", "--pty", "--ignore-stdin"]);
    let pty = emu.line(|l| l.starts_with("/dev/"));
    for sig in IGNORED {
        sim.signal(sig);
        emu.signal(sig);
        // simarm still serves: a request is answered after each.
        let o = limber(d.name(), &["actarray", "simarm/actarray/0", "geom"]);
        assert!(o.status.success(), "after signal {sig}: {}", stderr(&o));
    }
    let o = limber(
        d.name(),
        &["actarray", "simarm/actarray/0", "pos", "1", "0.2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(matches!(sim.0.try_wait(), Ok(None)), "simarm ended");
    // The emulator still plays the robot on its pty: a driver connects to it and serves.
    let mut drv = Bg::spawn(d.name(), &["pioneer", "--port", &pty]);
    drv.line(|l| l.ends_with("ready"));
    let o = limber(d.name(), &["actarray", "pioneer/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(drv.term(), Some(0));
    assert!(matches!(emu.0.try_wait(), Ok(None)), "the emulator ended");
    assert_eq!(sim.end_with(libc::SIGQUIT), Some(0));
    assert_eq!(emu.end_with(libc::SIGQUIT), Some(0));
}

#[test]
fn the_demo_ignores_sigalrm_and_sigusr1() {
    let d = Domain::unique_for_test();
    let mut demo = Bg::spawn(d.name(), &["demo", "--fast"]);
    demo.line(|l| l.starts_with("[ 1/11]"));
    for sig in IGNORED {
        demo.signal(sig);
    }
    demo.line(|l| l.trim_end().ends_with("done."));
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Ok(Some(s)) = demo.0.try_wait() {
            break s;
        }
        assert!(Instant::now() < deadline, "the demo did not end");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(0), "{status:?}");
}

/// The state of the main thread of process `pid` (`S` sleeping, `T` stopped, ...).
fn proc_state(pid: u32) -> Option<char> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // "pid (comm) S ...": the command may hold spaces and parentheses.
    stat.rsplit_once(')')?.1.trim_start().chars().next()
}

/// Waits (bounded) until process `pid`'s main thread is in state `want`.
fn wait_proc_state(pid: u32, want: char) {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let s = proc_state(pid);
        if s == Some(want) {
            return;
        }
        assert!(
            !matches!(s, None | Some('Z')),
            "process {pid} ended while waiting for state {want}"
        );
        assert!(
            Instant::now() < deadline,
            "process {pid} in state {s:?}, not {want}, after 10 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// A test driver on a thread of this process that publishes only when commanded (its
/// period is an hour), so that a client waiting for the next state blocks. It ends at its
/// first wake-up after `stop` is sent or dropped, and then says so on `ended`.
struct QuietDriver {
    stop: mpsc::Sender<()>,
    ended: mpsc::Receiver<()>,
}

fn quiet_driver(domain: &str) -> QuietDriver {
    let (stop, rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let (ended_tx, ended) = mpsc::channel();
    let name = domain.to_string();
    std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "quietdriver").unwrap();
        let mut d = TestDriver::new(&ctx, "quiet", 6).unwrap();
        ready_tx.send(()).unwrap();
        d.run(Duration::from_secs(3600), || {
            !matches!(rx.try_recv(), Err(mpsc::TryRecvError::Empty))
        })
        .expect("the quiet driver's loop");
        drop(d);
        drop(ctx);
        // The test may have stopped waiting (it failed): nobody to tell.
        ended_tx.send(()).ok();
    });
    ready_rx.recv_timeout(Duration::from_secs(10)).unwrap();
    QuietDriver { stop, ended }
}

/// Ctrl-Z and `fg` (SIGSTOP, SIGCONT) on a client blocked in a wait for the next state:
/// the wait resumes (no "receiving failed: InterruptSignal"); the client prints the next
/// state when it comes and exits 0.
#[test]
fn a_client_stopped_and_continued_in_a_wait_resumes_it() {
    let d = Domain::unique_for_test();
    let driver = quiet_driver(d.name());
    let ctx = Context::new(&d, Role::Client, "signals-test").unwrap();
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "quiet/actarray/0", Duration::from_secs(5)).unwrap();
    // A first state, for echo to print at once.
    let t = arm.move_to(0, 0.1).unwrap();
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5)).unwrap(),
        Status::Ok
    );
    let mut echo = Bg::spawn(
        d.name(),
        &[
            "echo",
            "quiet/actarray/0",
            "--json",
            "--count",
            "2",
            "--timeout",
            "20",
        ],
    );
    echo.line(|l| l.starts_with('{'));
    let pid = echo.0.id();
    for _ in 0..3 {
        // Blocked in its wait for the next state (nothing else makes it sleep now).
        wait_proc_state(pid, 'S');
        echo.signal(libc::SIGSTOP);
        wait_proc_state(pid, 'T');
        echo.signal(libc::SIGCONT);
    }
    wait_proc_state(pid, 'S');
    assert!(
        matches!(echo.0.try_wait(), Ok(None)),
        "echo ended after a stop and continue"
    );
    let t = arm.move_to(0, 0.2).unwrap();
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5)).unwrap(),
        Status::Ok
    );
    echo.line(|l| l.starts_with('{'));
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Ok(Some(s)) = echo.0.try_wait() {
            break s;
        }
        assert!(Instant::now() < deadline, "echo did not end");
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(status.code(), Some(0), "{status:?}");
    // The driver ends at its next wake-up: a command gives it one.
    drop(driver.stop);
    let _wake = arm.move_to(0, 0.3).unwrap();
    driver
        .ended
        .recv_timeout(Duration::from_secs(10))
        .expect("the quiet driver ended");
}
