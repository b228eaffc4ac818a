//! simarm publishes its driver statistics on `<robot>/driver/0` as the Pioneer driver does
//! (`limber_services::diagnostics`): what `limber echo <robot>/driver`, `limber monitor`
//! and `list_drivers` read. Its name, the robot name, the loop's mode and timer cycles and
//! the clients' counters are filled; a real robot's fields stay empty. Counts only; nothing
//! asserts speed.

use std::time::{Duration, Instant};

use limber_interfaces::diagnostics::{DriverStats, get_text, loop_mode};
use limber_kinematics::chain::Chain;
use limber_services::diagnostics::{StatsReader, list_drivers};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::{SimArmOptions, SimArmThread};

/// How long any wait of this test may take.
const TIMEOUT: Duration = Duration::from_secs(20);

/// Reads statistics until one satisfies `want` (each wait bounded, all of them too).
fn stats_until(reader: &mut StatsReader, want: impl Fn(&DriverStats) -> bool) -> DriverStats {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        let s = *reader
            .wait(TIMEOUT)
            .expect("simarm publishes its statistics");
        if want(&s) {
            return s;
        }
        assert!(
            Instant::now() < deadline,
            "no statistics as wanted within {TIMEOUT:?}; the last: {s:?}"
        );
    }
}

#[test]
fn simarm_publishes_its_name_its_loop_s_ticks_and_its_clients_counters() {
    let domain = Domain::unique_for_test();
    let options = SimArmOptions {
        robot: "statsarm".to_string(),
        ..SimArmOptions::default()
    };
    let _sim = SimArmThread::start(domain.name(), Chain::default_6dof(), options, TIMEOUT)
        .expect("simarm starts");
    let ctx = Context::new(&domain, Role::Client, "stats-test").expect("context");
    assert_eq!(
        list_drivers(&domain).expect("drivers listed"),
        vec!["statsarm".to_string()]
    );

    // The first publication, from the start (the channel's history keeps it).
    let mut reader = StatsReader::open(&ctx, "statsarm").expect("simarm offers its statistics");
    let first = *reader.wait(TIMEOUT).expect("the statistics of the start");
    assert_eq!(get_text(&first.driver).expect("text"), "simarm");
    assert_eq!(get_text(&first.robot_name).expect("text"), "statsarm");
    assert_eq!(first.loop_mode, loop_mode::EVENT);
    assert_eq!(
        first.header.flags,
        device_flag::SIMULATED | device_flag::LINK_UP
    );
    // No real robot: no class, no hardware, no link.
    assert_eq!(get_text(&first.robot_class).expect("text"), "");
    assert_eq!(get_text(&first.robot_subclass).expect("text"), "");
    assert_eq!(first.hardware, 0);
    assert_eq!(
        (first.bytes_in, first.bytes_out, first.packets_in),
        (0, 0, 0)
    );
    assert_eq!(first.sips_per_s, 0.0);

    // Two commands, one refused: counted in the next publications.
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "statsarm/actarray/0", TIMEOUT).expect("the arm");
    let t = arm.move_to(0, 0.1).expect("sent");
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    // 6 joints + the gripper: actuators 0..=6.
    let t = arm.move_to(8, 0.0).expect("sent");
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::UnknownJoint));

    // Published again while the loop runs, with its timer cycles.
    let later = stats_until(&mut reader, |s| {
        s.cycles >= 2 && s.period_p50_ns > 0 && s.commands >= 2
    });
    assert!(later.header.seq > first.header.seq);
    assert_eq!(get_text(&later.driver).expect("text"), "simarm");
    assert_eq!(later.loop_mode, loop_mode::EVENT);
    assert!(later.period_p99_ns >= later.period_p50_ns);
    assert!(later.period_max_ns >= later.period_p99_ns);
    assert_eq!((later.commands, later.refused), (2, 1));
    assert_eq!(later.cmd_overflows, 0);
}
