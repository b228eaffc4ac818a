//! Issue 13, the driver against the vendor's protocol: it reads the ARMpac status bytes in
//! the configured layout (the vendor's manuals by default, ARIA's as an option) and notices
//! a robot that uses the other one; it serves the body gripper and lift only when the robot
//! has them. The driver runs in this process so its counters can be read.

use std::time::{Duration, Instant};

use limber_emulator::{ArmpacLayout, Emulator, EmulatorConfig};
use limber_pioneer::{PioneerConfig, PioneerDriver, RunOptions};
use limber_services::prelude::*;
use limber_services::{Domain, Role};

const T: Duration = Duration::from_secs(10);

/// Runs the driver until `done` holds of it and the emulator, or `T` passes; whether it held.
fn run_until_seen(
    driver: &mut PioneerDriver,
    emu: &Emulator,
    mut done: impl FnMut(&PioneerDriver, &Emulator) -> bool,
) -> bool {
    let deadline = Instant::now() + T;
    while Instant::now() < deadline {
        let slice = Instant::now() + Duration::from_millis(100);
        driver
            .run_until(RunOptions::default(), || Instant::now() > slice)
            .unwrap();
        if done(driver, emu) {
            return true;
        }
    }
    false
}

#[test]
fn the_driver_reads_the_configured_layout_and_warns_of_the_other() {
    for (robot, configured) in [
        (ArmpacLayout::Manual, ArmpacLayout::Manual),
        (ArmpacLayout::Aria, ArmpacLayout::Aria),
        (ArmpacLayout::Aria, ArmpacLayout::Manual),
        (ArmpacLayout::Manual, ArmpacLayout::Aria),
    ] {
        let case = format!("robot {robot}, driver configured {configured}");
        let mut ecfg = EmulatorConfig::default();
        ecfg.model.armpac_layout = robot;
        let emu = Emulator::start_pty(ecfg).unwrap();
        let domain = Domain::unique_for_test();
        let ctx = Context::new(&domain, Role::Driver, "pioneer").unwrap();
        let cfg = PioneerConfig {
            armpac_layout: configured,
            ..PioneerConfig::default()
        };
        let mut driver = PioneerDriver::start(&ctx, cfg, emu.link_target()).unwrap();
        assert!(
            driver.hardware().arm,
            "{case}: no arm found; {:?}",
            emu.state()
        );
        if robot == configured {
            // Read the right way, the arm is powered and idle, and nothing is amiss.
            let mut first = None;
            let done = run_until_seen(&mut driver, &emu, |d, e| {
                let n = e.state().stats.arm_packets_out;
                let f = *first.get_or_insert(n);
                n >= f + 3 && d.arm_status() == Some((true, 0))
            });
            assert!(done, "{case}: {:?}", driver.arm_status());
            assert_eq!(driver.armpac_layout_mismatches(), 0, "{case}");
        } else {
            // The driver powers the arm at start: its packets give the layout away.
            let seen = run_until_seen(&mut driver, &emu, |d, _| d.armpac_layout_mismatches() > 0);
            assert!(seen, "{case}: no mismatch noticed");
        }
        driver.shutdown();
        emu.stop().unwrap();
    }
}

/// Issue 13 item 4: `body_gripper = false` serves neither the body gripper nor the lift,
/// whatever the robot's CONFIGpac says (here: a gripper), so no gripper or lift command
/// can reach the robot (`what_the_robot_has.rs` has the CONFIGpac's own cases).
#[test]
fn body_gripper_false_serves_neither_gripper_nor_lift() {
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "pioneer").unwrap();
    let cfg = PioneerConfig::from_toml("body_gripper = false").unwrap();
    let mut driver = PioneerDriver::start(&ctx, cfg, emu.link_target()).unwrap();
    assert!(!driver.hardware().gripper);
    assert!(driver.hardware().arm);
    assert!(
        matches!(&driver.hardware().config, limber_p2os::ConfigProbe::Answered(c) if c.has_gripper()),
        "{:?}",
        driver.hardware().config
    );
    assert!(
        driver.hardware().gripper_note.contains("although"),
        "{}",
        driver.hardware().gripper_note
    );
    let mut names: Vec<String> = limber_services::list_devices(&domain)
        .unwrap()
        .iter()
        .map(|d| d.name.to_string())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["pioneer/actarray/0", "pioneer/gripper/1", "pioneer/limb/0"]
    );
    driver.shutdown();
    emu.stop().unwrap();
}
