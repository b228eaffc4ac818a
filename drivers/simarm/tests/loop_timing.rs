//! simarm's loop keeps the timing of its timer cycles as every driver does
//! (`limber_services::loop_stats`): what the benchmark's `many` scenario reads of its loop
//! period. Counts only; nothing asserts speed.

use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::{SimArm, SimArmOptions};

#[test]
fn every_tick_of_the_loop_is_counted_and_every_period_between_two_kept() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "simarm").expect("context");
    let mut arm =
        SimArm::new(&ctx, Chain::default_6dof(), SimArmOptions::default()).expect("simarm");
    assert_eq!(arm.tick_stats().cycles, 0);
    // No client: every wake-up is a tick, and `stop` is asked once after each.
    let mut wakes = 0;
    arm.run(|| {
        wakes += 1;
        wakes == 6
    })
    .expect("simarm runs");
    let t = arm.tick_stats();
    assert_eq!(t.cycles, 6);
    // The loop's first tick has no period before it.
    assert_eq!(t.period.samples().len(), 5);
    assert_eq!(t.jitter.samples().len(), 5);
    assert!(t.period.samples().iter().all(|p| *p > 0));
}
