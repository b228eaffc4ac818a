//! The executor against a perfect device (actual = desired) and a pushed one: reached within
//! the goal tolerance, a path tolerance violation holds, replacement from the start time,
//! scaling pauses and resumes, STOP decelerates, refusals with their cause, and a tick that
//! allocates nothing.

use limber_counting_alloc::{Counting, allocations_in};
use limber_interfaces::prelude::*;
use limber_trajectory::{Config, Executor, JointLimit, Refusal, Tick};

#[global_allocator]
static GLOBAL: Counting = Counting;

const MS: u64 = 1_000_000;

fn config() -> Config {
    let mut c = Config::new(3);
    for l in c.limits.iter_mut().take(3) {
        *l = JointLimit {
            min: -2.0,
            max: 2.0,
            max_velocity: 2.0,
            max_deceleration: 4.0,
        };
    }
    c
}

/// Joints 0 and 1 from 0 to (1, -0.5) through a midpoint, positions only, in 1 s.
fn line(goal_tol: f64, path_tol: f64) -> Box<JointTrajectory> {
    let mut t = JointTrajectory::new(&[0, 1]).unwrap();
    t.push(0.5, &[0.5, -0.25], None, None).unwrap();
    t.push(1.0, &[1.0, -0.5], None, None).unwrap();
    t.set_goal_tolerance(&[goal_tol; 2]).unwrap();
    t.set_path_tolerance(&[path_tol; 2]).unwrap();
    t
}

/// Ticks a perfect device (it is where it was told) every 10 ms until the executor ends or
/// `until` ns; returns the end and the time.
fn follow(
    x: &mut Executor,
    pos: &mut [f64; 3],
    from: u64,
    until: u64,
) -> (Option<MotionResult>, u64) {
    let mut now = from;
    while now <= until {
        let tick = x.tick(now, pos);
        for (j, p) in pos.iter_mut().enumerate() {
            if x.driven() & (1 << j) != 0 {
                *p = x.desired(j);
            }
        }
        if let Tick::Ended(r) = tick {
            return (Some(r), now);
        }
        now += 10 * MS;
    }
    (None, now)
}

#[test]
fn a_trajectory_is_followed_and_reached() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    x.accept(&line(0.01, 0.1), 1000 * MS, &pos).unwrap();
    assert_eq!(x.running(), 0b11);
    // Half-way the desired positions are the midpoint.
    let (end, _) = follow(&mut x, &mut pos, 1000 * MS, 1500 * MS);
    assert_eq!(end, None);
    assert!(
        (pos[0] - 0.5).abs() < 1e-9 && (pos[1] + 0.25).abs() < 1e-9,
        "{pos:?}"
    );
    let (end, at) = follow(&mut x, &mut pos, 1510 * MS, 3000 * MS);
    assert_eq!(end, Some(MotionResult::Reached));
    assert_eq!(at, 2000 * MS);
    let p = x.progress(0);
    assert_eq!(p.end, Some((MotionResult::Reached, Status::Ok)));
    // The device is one tick behind: within the tolerance.
    assert!(
        p.error.abs() <= 0.01 + 1e-12 && p.tolerance == 0.01,
        "{p:?}"
    );
    assert_eq!(
        x.progress(2).end,
        Some((MotionResult::Preempted, Status::Ok))
    );
}

#[test]
fn a_push_off_the_path_holds_with_the_path_result() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    x.accept(&line(0.01, 0.05), 0, &pos).unwrap();
    follow(&mut x, &mut pos, 0, 300 * MS);
    // Something holds joint 1 back: it stays while the trajectory moves on.
    let stuck = pos[1];
    let mut now = 310 * MS;
    let end = loop {
        let mut actual = pos;
        actual[1] = stuck;
        if let Tick::Ended(r) = x.tick(now, &actual) {
            break r;
        }
        assert!(now < 2000 * MS);
        now += 10 * MS;
    };
    assert_eq!(end, MotionResult::PathToleranceViolated);
    // It holds where the joints are.
    assert_eq!(x.desired(1), stuck);
    assert_eq!(x.tick(now + 100 * MS, &pos), Tick::Running);
    assert_eq!(x.desired(1), stuck);
    assert_eq!(
        x.progress(1).end,
        Some((MotionResult::PathToleranceViolated, Status::Ok))
    );
}

#[test]
fn not_reaching_the_goal_in_time_is_a_goal_violation() {
    let mut x = Executor::new(config());
    let pos = [0.0; 3];
    let mut t = line(0.01, 0.0);
    t.set_goal_time_tolerance(0.2).unwrap();
    x.accept(&t, 0, &pos).unwrap();
    // The device never moves.
    let mut now = 0;
    let end = loop {
        if let Tick::Ended(r) = x.tick(now, &pos) {
            break r;
        }
        now += 10 * MS;
        assert!(now < 3000 * MS);
    };
    assert_eq!(end, MotionResult::GoalToleranceViolated);
    assert!(now >= 1200 * MS, "ended at {now}");
}

#[test]
fn scaling_zero_pauses_and_one_resumes() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    x.accept(&line(0.01, 0.1), 0, &pos).unwrap();
    follow(&mut x, &mut pos, 0, 250 * MS);
    assert_eq!(x.set_scale(0.0), Status::Ok);
    let held = pos;
    let (end, _) = follow(&mut x, &mut pos, 260 * MS, 5000 * MS);
    assert_eq!(end, None);
    assert_eq!(pos, held);
    assert_eq!(x.set_scale(1.0), Status::Ok);
    let (end, at) = follow(&mut x, &mut pos, 5010 * MS, 9000 * MS);
    assert_eq!(end, Some(MotionResult::Reached));
    assert!(at > 5700 * MS);
    assert_eq!(x.set_scale(3.0), Status::Clamped);
    assert_eq!(x.set_scale(-1.0), Status::BeyondLimits);
    assert_eq!(x.scale(), 1.0);
}

#[test]
fn a_replacement_takes_over_from_its_start_time_without_a_jump() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    x.accept(&line(0.01, 0.1), 0, &pos).unwrap();
    follow(&mut x, &mut pos, 0, 400 * MS);
    // The new one, starting 100 ms ahead, sends joint 0 back to 0 and leaves joint 1.
    let mut back = JointTrajectory::new(&[0]).unwrap();
    back.push(0.5, &[0.0], None, None).unwrap();
    back.set_start_ns(500 * MS);
    x.accept(&back, 410 * MS, &pos).unwrap();
    // Until then the first goes on.
    follow(&mut x, &mut pos, 410 * MS, 490 * MS);
    assert!((pos[0] - 0.49).abs() < 1e-9, "{pos:?}");
    let before = pos;
    let (end, at) = follow(&mut x, &mut pos, 500 * MS, 2000 * MS);
    assert_eq!(end, Some(MotionResult::Reached));
    assert_eq!(at, 1000 * MS);
    assert_eq!(pos[0], 0.0);
    // Joint 1 held where the hand-off found it; its motion was preempted.
    assert!((pos[1] - before[1]).abs() < 0.006, "{pos:?} {before:?}");
    assert_eq!(
        x.progress(1).end,
        Some((MotionResult::Preempted, Status::Ok))
    );
}

#[test]
fn stop_decelerates_within_the_limit() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    x.accept(&line(0.01, 0.1), 0, &pos).unwrap();
    follow(&mut x, &mut pos, 0, 300 * MS);
    let v = x.desired_velocity(0);
    assert!((v - 1.0).abs() < 1e-9);
    x.stop(300 * MS);
    assert_eq!(x.progress(0).end, Some((MotionResult::Stopped, Status::Ok)));
    let p0 = x.desired(0);
    follow(&mut x, &mut pos, 310 * MS, 2000 * MS);
    // v²/2a = 1/8 m further, and not moving any more.
    assert!((pos[0] - (p0 + 0.125)).abs() < 1e-9, "{} {}", pos[0], p0);
    assert_eq!(x.desired_velocity(0), 0.0);
}

#[test]
fn invalid_goals_are_refused_with_their_cause_and_change_nothing() {
    let mut x = Executor::new(config());
    let pos = [0.0; 3];
    let mut t = JointTrajectory::new(&[0, 5]).unwrap();
    t.push(1.0, &[0.1, 0.1], None, None).unwrap();
    let e = x.accept(&t, 0, &pos).unwrap_err();
    assert_eq!(e, Refusal::UnknownJoint { joint: 5, last: 2 });
    assert_eq!(e.status(), Status::UnknownJoint);

    let mut t = JointTrajectory::new(&[1]).unwrap();
    t.push(1.0, &[2.5], None, None).unwrap();
    let e = x.accept(&t, 0, &pos).unwrap_err();
    assert_eq!(e.status(), Status::BeyondLimits);

    let mut t = JointTrajectory::new(&[1]).unwrap();
    t.push(0.5, &[1.5], None, None).unwrap();
    let e = x.accept(&t, 0, &pos).unwrap_err();
    assert_eq!(e.status(), Status::TooFast);
    assert!(
        e.to_string()
            .contains("joint 1 needs 3.0000/s on the way to point 0"),
        "{e}"
    );

    let mut t = JointTrajectory::new(&[1]).unwrap();
    t.push(0.5, &[0.5], None, None).unwrap();
    t.set_start_ns(1000 * MS);
    let e = x.accept(&t, 3000 * MS, &pos).unwrap_err();
    assert_eq!(e.status(), Status::OldTimestamp);

    // A cubic that overshoots the limit between its points.
    let mut t = JointTrajectory::new(&[0]).unwrap();
    t.push(4.0, &[1.9], Some(&[1.9]), None).unwrap();
    t.push(5.0, &[1.9], Some(&[0.0]), None).unwrap();
    let e = x.accept(&t, 0, &pos).unwrap_err();
    assert_eq!(e.status(), Status::BeyondLimits, "{e}");

    assert_eq!(x.running(), 0);
    assert_eq!(x.tick(0, &pos), Tick::Idle);
}

#[test]
fn a_tick_allocates_nothing() {
    let mut x = Executor::new(config());
    let mut pos = [0.0; 3];
    let mut t = JointTrajectory::new(&[0, 1, 2]).unwrap();
    for i in 1..=10 {
        let p = 0.1 * i as f64;
        let v = if i == 10 { 0.0 } else { 0.1 };
        t.push(
            0.1 * i as f64,
            &[p, -p, p / 2.0],
            Some(&[v, -v, v / 2.0]),
            Some(&[0.0; 3]),
        )
        .unwrap();
    }
    x.accept(&t, 0, &pos).unwrap();
    let mut now = 0;
    let n = allocations_in(|| {
        for _ in 0..200 {
            x.tick(now, &pos);
            for (j, p) in pos.iter_mut().enumerate() {
                *p = x.desired(j);
            }
            now += 7 * MS;
        }
    });
    assert_eq!(n, 0);
    assert_eq!(x.progress(0).end, Some((MotionResult::Reached, Status::Ok)));
}
