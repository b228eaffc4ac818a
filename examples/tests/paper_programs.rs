//! Both programs end to end against the test driver (instant joints) on a thread of this
//! process. The same programs run against the Pioneer driver and simarm in tests/.

use std::sync::mpsc;
use std::time::Duration;

use limber_examples::pick_block::{self, Devices, Event, PickParams, Step};
use limber_examples::random_moves::{self, RandomParams};
use limber_services::prelude::*;
use limber_services::testing::TestDriver;
use limber_services::{Domain, Role};

fn driver(domain: &str) -> mpsc::Sender<()> {
    let (tx, rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.to_string();
    std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "testdriver").unwrap();
        let mut d = TestDriver::new(&ctx, "ex", 6).unwrap();
        ready_tx.send(()).unwrap();
        let _ = d.run(Duration::from_millis(10), || {
            !matches!(rx.try_recv(), Err(mpsc::TryRecvError::Empty))
        });
    });
    ready_rx.recv_timeout(Duration::from_secs(10)).unwrap();
    tx
}

#[test]
fn pick_block_runs_every_step() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let ctx = Context::new(&d, Role::Client, "ex").unwrap();
    let mut dev =
        Devices::connect(&ctx, "ex/limb/0", "ex/gripper/0", Duration::from_secs(2)).unwrap();
    let mut started = Vec::new();
    let s = pick_block::run(&mut dev, &PickParams::default(), &mut |e| {
        if let Event::Start(step) = e {
            started.push(step)
        }
    })
    .unwrap();
    assert_eq!(s.steps, 11);
    assert_eq!(started.first(), Some(&Step::Home));
    assert_eq!(started.last(), Some(&Step::HomeAgain));
    assert!(started.contains(&Step::Grip));
    assert!((s.released_at[1] - PickParams::default().drop[1]).abs() < 1e-9);
}

#[test]
fn pick_block_stops_when_out_of_reach() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let ctx = Context::new(&d, Role::Client, "ex").unwrap();
    let mut dev =
        Devices::connect(&ctx, "ex/limb/0", "ex/gripper/0", Duration::from_secs(2)).unwrap();
    let p = PickParams {
        block: [3.0, 0.0],
        ..PickParams::default()
    };
    let err = pick_block::run(&mut dev, &p, &mut |_| {}).unwrap_err();
    assert!(
        matches!(
            err,
            pick_block::PickError::OutOfReach {
                step: Step::Approach(_)
            }
        ),
        "{err}"
    );
}

#[test]
fn random_moves_stay_within_limits() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let ctx = Context::new(&d, Role::Client, "ex").unwrap();
    let mut arm = ActArrayClient::connect(&ctx, "ex/actarray/0").unwrap();
    let mut moves = 0;
    let q = random_moves::run(&mut arm, &RandomParams::default(), &mut |m, _| {
        if let Some(m) = m {
            assert!(m.target > m.limits.0 && m.target < m.limits.1);
            moves += 1;
        }
    })
    .unwrap();
    assert_eq!(moves, 18);
    assert_eq!(q.len(), 6);
}
