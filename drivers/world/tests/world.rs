//! The world without a transport: the file format, the seeded placement, the laser's
//! ray-casting and noise, and blocks carried by the gripper.

use limber_interfaces::prelude::*;
use limber_world::{Block, Carrier, Laser, LaserConfig, World, WorldError};

fn quiet() -> LaserConfig {
    LaserConfig {
        noise: 0.0,
        ..LaserConfig::lms200()
    }
}

fn scan(world: &World, config: LaserConfig) -> RangerData {
    let mut laser = Laser::new(config, 7).expect("a valid laser");
    let mut s = RangerData::default();
    laser.scan(world, &mut s);
    s
}

/// The index of the shortest range (the paper's Listing 2, lines 16-22).
fn closest(s: &RangerData) -> usize {
    let r = s.ranges();
    (1..r.len()).fold(0, |m, i| if r[i] < r[m] { i } else { m })
}

#[test]
fn the_lms200_has_181_beams_over_180_degrees_to_8_m() {
    let c = LaserConfig::lms200();
    let s = scan(&World::default(), quiet());
    assert_eq!(s.ranges().len(), 181);
    assert!((s.min_angle + 90f64.to_radians()).abs() < 1e-12);
    assert!((s.max_angle - 90f64.to_radians()).abs() < 1e-12);
    assert!(
        s.ranges().iter().all(|r| *r == 8.0),
        "an empty world reads the max range"
    );
    let g = c.geometry();
    assert_eq!(g.ranges_count, 181);
    assert_eq!(g.pose.position.to_array(), [0.16, 0.0, 0.20]);
    assert_eq!(
        LaserConfig::lms200_half_degree().geometry().ranges_count,
        361
    );
}

#[test]
fn a_block_straight_ahead_is_at_its_distance_minus_its_radius() {
    let w = World {
        blocks: vec![Block::at(0.5, 0.0)],
        ..World::default()
    };
    let s = scan(&w, quiet());
    let i = closest(&s);
    assert_eq!(i, 90, "the beam straight ahead");
    assert!((s.ranges()[i] - (0.5 - 0.16 - 0.02)).abs() < 1e-9);
}

#[test]
fn listing_2_finds_the_centre_of_a_block_from_the_closest_point() {
    for (x, y) in [(0.38, 0.10), (0.45, -0.12), (0.30, 0.0), (0.42, 0.15)] {
        let w = World {
            blocks: vec![Block::at(x, y)],
            ..World::default()
        };
        let s = scan(&w, quiet());
        let i = closest(&s);
        let pre = s.ranges()[i] + 0.02;
        let b = s.bearing(i);
        let (cx, cy) = (pre * b.cos() + 0.16, pre * b.sin());
        let err = (cx - x).hypot(cy - y);
        assert!(
            err < 0.005,
            "block at ({x}, {y}) found at ({cx}, {cy}): {err} m off"
        );
    }
}

#[test]
fn noise_moves_the_ranges_and_zero_noise_does_not() {
    let w = World {
        blocks: vec![Block::at(0.5, 0.0)],
        ..World::default()
    };
    let a = scan(&w, quiet());
    let b = scan(&w, quiet());
    assert_eq!(a.ranges(), b.ranges());
    let n = scan(&w, LaserConfig::lms200());
    let hit: Vec<usize> = (0..181).filter(|&i| a.ranges()[i] < 8.0).collect();
    assert!(!hit.is_empty());
    assert!(hit.iter().any(|&i| n.ranges()[i] != a.ranges()[i]));
    assert!(
        hit.iter()
            .all(|&i| (n.ranges()[i] - a.ranges()[i]).abs() < 0.02)
    );
}

#[test]
fn an_obstacle_in_front_hides_what_is_behind_it() {
    let w = World::from_toml(
        "[[block]]\nx = 1.5\ny = 0.0\n\n[[obstacle]]\nx = 1.0\ny = 0.0\nlength = 0.2\nwidth = 1.0\n",
    )
    .expect("a world");
    let s = scan(&w, quiet());
    assert!((s.ranges()[90] - (0.9 - 0.16)).abs() < 1e-9);
}

#[test]
fn the_world_file_refuses_what_it_does_not_know() {
    let w = World::from_toml("[[block]]\nx = 0.4\ny = 0.1\nsize = 0.05\n").expect("a world");
    assert_eq!(w.blocks[0].size, 0.05);
    assert!(matches!(
        World::from_toml("[[block]]\nx = 0.4\n"),
        Err(WorldError::Parse(_))
    ));
    assert!(matches!(
        World::from_toml("[[block]]\nx = 0.4\ny = 0.1\ncolour = 3\n"),
        Err(WorldError::Parse(_))
    ));
    assert!(matches!(
        World::from_toml("[[block]]\nx = 0.4\ny = 0.1\nsize = -1.0\n"),
        Err(WorldError::Value {
            what: "block",
            index: 0
        })
    ));
    assert!(matches!(
        World::load(std::path::Path::new("/nonexistent/world.toml")),
        Err(WorldError::Read { .. })
    ));
}

#[test]
fn a_seed_places_the_block_in_the_same_place_within_the_region() {
    let a = World::random_block(42, [0.34, 0.40], [0.04, 0.12]);
    let b = World::random_block(42, [0.34, 0.40], [0.04, 0.12]);
    let c = World::random_block(43, [0.34, 0.40], [0.04, 0.12]);
    assert_eq!(a, b);
    assert_ne!(a, c);
    for s in 0..50 {
        let p = World::random_block(s, [0.34, 0.40], [0.04, 0.12]);
        assert!((0.34..0.40).contains(&p.x) && (0.04..0.12).contains(&p.y));
    }
}

#[test]
fn a_block_is_carried_when_the_gripper_closes_on_it_and_put_down_where_it_opens() {
    let mut w = World {
        blocks: vec![Block::at(0.38, 0.10)],
        ..World::default()
    };
    let mut c = Carrier::default();
    // Closing away from the block grips nothing.
    c.update(&mut w, [0.30, 0.0, 0.17], true);
    assert_eq!(c.held(), None);
    c.update(&mut w, [0.30, 0.0, 0.17], false);
    // Open above it, then close around it.
    c.update(&mut w, [0.381, 0.10, 0.17], false);
    assert_eq!(c.between_fingers(&w, [0.381, 0.10, 0.17]), Some(0));
    c.update(&mut w, [0.381, 0.10, 0.17], true);
    assert_eq!(c.held(), Some(0));
    // Lifted and carried.
    c.update(&mut w, [0.381, 0.10, 0.22], true);
    assert!((w.blocks[0].lifted - 0.05).abs() < 1e-9);
    c.update(&mut w, [0.381, -0.10, 0.17], true);
    // Released.
    c.update(&mut w, [0.381, -0.10, 0.17], false);
    assert_eq!(c.held(), None);
    assert!((w.blocks[0].x - 0.38).abs() < 1e-9 && (w.blocks[0].y + 0.10).abs() < 1e-9);
    assert_eq!(w.blocks[0].lifted, 0.0);
    // Moving the closed gripper through a block does not pick it up.
    c.update(&mut w, [0.2, 0.2, 0.17], true);
    c.update(&mut w, [0.38, -0.10, 0.17], true);
    assert_eq!(c.held(), None);
}

/// With the default noise (2 mm) the paper's closest-point rule still lands within the
/// gripper's capture radius (2 cm) of the block's centre, for blocks anywhere in the
/// region `--seed` draws from and many noise draws: the demo's default can pick the block.
#[test]
fn with_the_default_noise_listing_2_lands_within_the_capture_radius() {
    let mut worst: f64 = 0.0;
    for seed in 0..200 {
        let b = World::random_block(seed, [0.37, 0.42], [0.04, 0.12]);
        let w = World {
            blocks: vec![b],
            ..World::default()
        };
        let mut laser = Laser::new(LaserConfig::lms200(), seed).expect("a laser");
        let mut s = RangerData::default();
        laser.scan(&w, &mut s);
        let i = closest(&s);
        let pre = s.ranges()[i] + b.radius();
        let (cx, cy) = (pre * s.bearing(i).cos() + 0.16, pre * s.bearing(i).sin());
        worst = worst.max((cx - b.x).hypot(cy - b.y));
    }
    assert!(worst < Carrier::default().capture_radius, "worst {worst} m");
}
