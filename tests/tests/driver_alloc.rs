//! The Pioneer driver's loop allocates nothing of its own in steady state: counted on the
//! driver's thread while the emulator streams SIPs and ARMpacs and a client (on another
//! thread) commands the arm. iceoryx2 0.10 itself allocates one small `Rc` per sample
//! published and per response sent (an outcome on its client's stream: see `alloc.rs`) and two small buffers (16 and 24 bytes) per WaitSet
//! wake-up (`wait_and_process_once_with_timeout`, `handle_all_attachments`), so the count
//! may not exceed samples published plus twice the wake-ups (plus the one-time set-up of
//! the wait set when the measured run starts). Traced with backtraces: no
//! allocation comes from limber's own code.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_emulator::{Emulator, EmulatorConfig};
use limber_pioneer::{PioneerConfig, PioneerDriver, RunOptions};
use limber_services::prelude::*;
use limber_services::{Domain, Role};

#[global_allocator]
static GLOBAL: limber_counting_alloc::Counting = limber_counting_alloc::Counting;

fn allocs() -> u64 {
    limber_counting_alloc::allocations()
}

struct Measured {
    allocations: u64,
    published: u64,
    wakeups: u64,
}

#[test]
fn driver_loop_allocates_only_iceoryx2_internals() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let target = emu.link_target();
    let (tx, rx) = mpsc::channel::<Measured>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let d = domain.clone();
    let t = std::thread::spawn(move || {
        let ctx = Context::new(&d, Role::Driver, "pioneer").unwrap();
        let mut driver = PioneerDriver::start(&ctx, PioneerConfig::default(), target).unwrap();
        ready_tx.send(()).unwrap();
        // Warm up: connections, first commands, lazily created resources.
        let until = Instant::now() + Duration::from_millis(1500);
        driver
            .run_until(RunOptions::default(), || Instant::now() > until)
            .unwrap();
        let (a0, p0, w0) = (allocs(), driver.samples_published(), driver.wakeups());
        let until = Instant::now() + Duration::from_secs(3);
        driver
            .run_until(RunOptions::default(), || Instant::now() > until)
            .unwrap();
        let m = Measured {
            allocations: allocs() - a0,
            published: driver.samples_published() - p0,
            wakeups: driver.wakeups() - w0,
        };
        driver.shutdown();
        tx.send(m).unwrap();
    });
    ready_rx.recv_timeout(Duration::from_secs(20)).unwrap();
    // A client commands the arm back and forth meanwhile.
    let ctx = Context::new(&domain, Role::Client, "alloc").unwrap();
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(5))
            .unwrap();
    // ... until the driver has finished measuring (warm-up and measured run alike).
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut i = 0;
    let m = loop {
        match rx.try_recv() {
            Ok(m) => break m,
            Err(mpsc::TryRecvError::Empty) => {}
            Err(mpsc::TryRecvError::Disconnected) => panic!("the driver thread failed"),
        }
        assert!(
            Instant::now() < deadline,
            "the driver never finished measuring"
        );
        let _ = arm.move_to(0, if i % 2 == 0 { 0.3 } else { -0.3 });
        i += 1;
        // Paces the commands.
        std::thread::sleep(Duration::from_millis(50));
    };
    t.join().unwrap();
    eprintln!(
        "driver thread, 3 s of steady state: {} allocations, {} samples published, {} wake-ups, {} commands sent",
        m.allocations, m.published, m.wakeups, i
    );
    assert!(
        m.published > 50 && m.wakeups > 100,
        "the driver was not busy"
    );
    assert!(
        // + the one-time set-up of the wait set when the measured run starts.
        m.allocations <= m.published + 2 * m.wakeups + 32,
        "{} allocations > {} samples + 2 x {} wake-ups: the driver allocates on its own",
        m.allocations,
        m.published,
        m.wakeups
    );
}
