//! The paper's Listing 2 as written ([`pick_block::run`] with a laser) on simarm and its
//! world, both on threads of this process: the laser finds the block where the test put
//! it, the arm picks it up and puts it down, and the world's block is at the drop point.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError, mpsc};
use std::time::Duration;

use limber_examples::pick_block::{self, Devices, Event, PickError, PickParams};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::{SimArm, SimArmOptions, SimObject};
use limber_world::{Block, LaserConfig, World, WorldDriver, WorldOptions};

/// The drivers of a test, on threads of this process: [`Drivers::stop`] ends them and waits
/// for them, so that their ports are closed before the test's domain removes its files (a
/// thread still running when the test returns ends with the process, and leaves the files
/// of a dead process behind).
struct Drivers {
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Drivers {
    fn stop(self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads {
            t.join().expect("a driver thread panicked");
        }
    }
}

/// simarm with a block at `block` (its grasp point at 0.17 m) and the world's laser, each
/// on a thread of its own, until [`Drivers::stop`].
fn start(domain: &Domain, block: [f64; 2]) -> (Drivers, Arc<Mutex<World>>) {
    let stop = Arc::new(AtomicBool::new(false));
    let (arm_tx, arm_rx) = mpsc::channel();
    let (d, s) = (domain.clone(), stop.clone());
    let arm = std::thread::spawn(move || {
        let ctx = Context::new(&d, Role::Driver, "simarm").unwrap();
        let options = SimArmOptions {
            object: Some(SimObject::block([block[0], block[1], 0.17], 0.04)),
            ..SimArmOptions::default()
        };
        let chain = limber_kinematics::chain::Chain::default_6dof();
        let mut arm = SimArm::new(&ctx, chain, options).unwrap();
        arm_tx.send(()).unwrap();
        arm.run(|| s.load(Ordering::Relaxed)).unwrap();
    });
    arm_rx.recv_timeout(Duration::from_secs(30)).unwrap();
    let (tx, rx) = mpsc::channel();
    let (d, s) = (domain.clone(), stop.clone());
    let laser = std::thread::spawn(move || {
        let world = World {
            blocks: vec![Block::at(block[0], block[1])],
            ..World::default()
        };
        let options = WorldOptions {
            laser: LaserConfig {
                noise: 0.0,
                ..LaserConfig::lms200()
            },
            ..WorldOptions::new("simarm", "simarm/limb/0", "simarm/gripper/0")
        };
        let mut world = WorldDriver::new(&d, world, options).unwrap();
        tx.send(world.world()).unwrap();
        world.run(|| s.load(Ordering::Relaxed)).unwrap();
    });
    let world = rx.recv_timeout(Duration::from_secs(30)).unwrap();
    let drivers = Drivers {
        stop,
        threads: vec![arm, laser],
    };
    (drivers, world)
}

#[test]
fn listing_2_finds_the_block_with_the_laser_and_moves_it_on_simarm() {
    let d = Domain::unique_for_test();
    let (drivers, world) = start(&d, [0.40, 0.06]);
    let ctx = Context::new(&d, Role::Client, "ex").unwrap();
    let t = Duration::from_secs(5);
    let mut dev = Devices::connect_with_laser(
        &ctx,
        "simarm/limb/0",
        "simarm/gripper/0",
        "simarm/ranger/0",
        t,
    )
    .unwrap();
    let mut found_first = None;
    let s = pick_block::run(&mut dev, &PickParams::default(), &mut |e| {
        if let Event::Found(f) = e {
            found_first = Some(f);
        }
    })
    .unwrap();
    let f = s.found.expect("found with the laser");
    assert_eq!(found_first, Some(f));
    assert!(
        (f.centre[0] - 0.40).hypot(f.centre[1] - 0.06) < 0.005,
        "{f:?}"
    );
    // The closest point is one block radius short of the centre, on the beam from the
    // laser; the orientation vector joins them.
    let d2 = (f.closest[0] - 0.16).hypot(f.closest[1]);
    let dc = (f.centre[0] - 0.16).hypot(f.centre[1]);
    assert!((dc - d2 - 0.02).abs() < 1e-9, "{f:?}");
    assert!((f.orientation[0].hypot(f.orientation[1]) - 0.02).abs() < 1e-9);
    assert_eq!(s.steps, 11);
    assert!(s.block_seen, "the gripper's beam saw the block");
    let b = world.lock().unwrap_or_else(PoisonError::into_inner).blocks[0];
    assert!((b.x - 0.38).hypot(b.y + 0.10) < 0.03, "{b:?}");
    assert_eq!(b.lifted, 0.0);
    drop(dev);
    drivers.stop();
}

#[test]
fn a_laser_that_sees_nothing_stops_the_program_before_it_moves() {
    let d = Domain::unique_for_test();
    let (drivers, world) = start(&d, [0.40, 0.06]);
    world
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .blocks
        .clear();
    let ctx = Context::new(&d, Role::Client, "ex").unwrap();
    let mut dev = Devices::connect_with_laser(
        &ctx,
        "simarm/limb/0",
        "simarm/gripper/0",
        "simarm/ranger/0",
        Duration::from_secs(5),
    )
    .unwrap();
    // Wait (bounded) for a scan of the empty world.
    let laser = dev.laser.as_mut().unwrap();
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    while laser
        .wait_state(Duration::from_secs(5))
        .unwrap()
        .ranges()
        .iter()
        .any(|r| *r < 8.0)
    {
        assert!(
            std::time::Instant::now() < deadline,
            "the block is still seen"
        );
    }
    let mut started = Vec::new();
    let e = pick_block::run(&mut dev, &PickParams::default(), &mut |e| {
        if let Event::Start(s) = e {
            started.push(s)
        }
    })
    .unwrap_err();
    assert_eq!(e, PickError::NothingSeen);
    // The laser is read before the first step: nothing moved.
    assert!(started.is_empty(), "{started:?}");
    drop(dev);
    drivers.stop();
}
