//! The limb's COLLISION state (issue 27): a motion into the floor or an obstacle stops at
//! contact, the state says COLLISION until the next limb command, which may move away.

use limber_interfaces::prelude::*;
use limber_kinematics::chain::Chain;
use limber_simarm::{ArmModel, Contact, Obstacles, SimArmOptions, SimObstacle};

fn model(obstacles: Obstacles) -> ArmModel {
    let o = SimArmOptions {
        obstacles,
        ..SimArmOptions::default()
    };
    ArmModel::new(Chain::default_6dof(), o).unwrap()
}

fn limb(m: &ArmModel) -> LimbData {
    let mut s = LimbData::default();
    m.limb_state(&mut s);
    s
}

fn run(m: &mut ArmModel) {
    for _ in 0..100_000 {
        if !m.limb_moving() {
            return;
        }
        m.advance(0.002);
    }
    panic!("still moving");
}

const DOWN: Vec3 = Vec3::new(0.0, 0.0, -1.0);

#[test]
fn a_pose_below_the_floor_stops_at_the_floor_in_collision_until_the_next_command() {
    let mut m = model(Obstacles {
        floor: Some(0.0),
        boxes: vec![],
    });
    let above = LimbCommand::set_position(Vec3::new(0.45, 0.1, 0.10)).unwrap();
    assert_eq!(m.limb_command(&above), Status::Ok);
    run(&mut m);
    assert_eq!(limb(&m).limb_state(), Ok(LimbState::Idle));
    // Straight down through the floor: carried out, stopped at contact.
    let below = LimbCommand::vec_move(DOWN, 0.2).unwrap();
    assert_eq!(m.limb_command(&below), Status::Ok);
    run(&mut m);
    let s = limb(&m);
    assert_eq!(s.limb_state(), Ok(LimbState::Collision));
    assert_eq!(m.collision(), Some(Contact::Floor));
    assert!(
        s.position.z < 0.0 && s.position.z > -0.02,
        "{:?}",
        s.position
    );
    // Still COLLISION while nothing is commanded.
    m.advance(0.1);
    assert_eq!(limb(&m).limb_state(), Ok(LimbState::Collision));
    // The next command clears it and moves away from the floor.
    assert_eq!(m.limb_command(&above), Status::Ok);
    run(&mut m);
    let s = limb(&m);
    assert_eq!(s.limb_state(), Ok(LimbState::Idle));
    assert!((s.position.z - 0.10).abs() < 0.002, "{:?}", s.position);
}

#[test]
fn an_obstacle_in_the_way_stops_the_limb_and_no_obstacle_lets_it_pass() {
    // A wall across the way, its near face at x = 0.40, low enough that the arm's upper
    // frames pass above it.
    let wall = SimObstacle {
        min: [0.40, -1.0, -1.0],
        max: [0.46, 1.0, 0.25],
    };
    for (boxes, want) in [(vec![wall], Some(Contact::Obstacle(0))), (vec![], None)] {
        let mut m = model(Obstacles { floor: None, boxes });
        let start = LimbCommand::set_position(Vec3::new(0.30, 0.1, 0.2)).unwrap();
        assert_eq!(m.limb_command(&start), Status::Ok);
        run(&mut m);
        assert_eq!(m.contact(), None, "clear of the wall at the start");
        let along_x = LimbCommand::vec_move(Vec3::new(1.0, 0.0, 0.0), 0.15).unwrap();
        assert_eq!(m.limb_command(&along_x), Status::Ok);
        run(&mut m);
        assert_eq!(m.collision(), want);
        let x = limb(&m).position.x;
        match want {
            // Stopped on the way, at the latest when the tool reached the wall (a joint
            // frame beside the tool may reach it first).
            Some(_) => assert!(x > 0.31 && x < 0.41, "stopped at x {x}"),
            None => assert!((x - 0.45).abs() < 0.002, "went on to x {x}"),
        }
    }
}
