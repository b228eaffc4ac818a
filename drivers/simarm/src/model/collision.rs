//! The limb's collisions (the paper's COLL state): the arm's joint frames and its tool
//! point against the floor and the obstacles of [`SimArmOptions::obstacles`]. A motion that
//! brings one of them below the floor or into an obstacle is stopped there (within one
//! step of the simulation), and the limb's state is COLLISION until the next limb command
//! (a limb command that starts in contact may move until the arm is clear).
//!
//! Points, not link volumes: the origin of every joint frame after the first (the first
//! sits on the base) and the tool point.

use limber_kinematics::Pose;
use limber_kinematics::chain::MAX_JOINTS;

use super::ArmModel;
#[allow(unused_imports)]
use super::SimArmOptions;

/// An obstacle the arm may hit: a box, axis-aligned in the robot frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimObstacle {
    /// The corner with the smallest x, y, z.
    pub min: [f64; 3],
    /// The corner with the largest x, y, z.
    pub max: [f64; 3],
}

impl SimObstacle {
    fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|k| p[k] > self.min[k] && p[k] < self.max[k])
    }
}

/// What the arm can collide with (default: nothing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Obstacles {
    /// The floor's height in the robot frame (m); `None`: no floor.
    pub floor: Option<f64>,
    /// The obstacles.
    pub boxes: Vec<SimObstacle>,
}

/// What the arm touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// The floor.
    Floor,
    /// Obstacle `i` of [`Obstacles::boxes`].
    Obstacle(usize),
}

impl ArmModel {
    /// The first contact of the arm (a joint frame after the first, or the tool point)
    /// with the floor or an obstacle, in its current configuration.
    pub fn contact(&self) -> Option<Contact> {
        let o = &self.options.obstacles;
        if o.floor.is_none() && o.boxes.is_empty() {
            return None;
        }
        let q = self.q();
        let mut frames = [Pose::identity(); MAX_JOINTS];
        let tool = self.chain.fk_frames(&q, &mut frames[..self.n]).ok()?;
        let points = frames[1..self.n]
            .iter()
            .chain(core::iter::once(&tool))
            .map(|f| [f.position.x, f.position.y, f.position.z]);
        for p in points {
            if o.floor.is_some_and(|z| p[2] < z) {
                return Some(Contact::Floor);
            }
            if let Some(i) = o.boxes.iter().position(|b| b.contains(p)) {
                return Some(Contact::Obstacle(i));
            }
        }
        None
    }

    /// The contact that stopped the limb, until the next limb command.
    pub fn collision(&self) -> Option<Contact> {
        self.collision
    }

    /// After a step of the simulation: a limb that comes into contact stops where it is
    /// (one that started its command in contact moves freely until it is clear).
    pub(super) fn stop_at_contact(&mut self) {
        if self.collision.is_some() || !self.limb_moving() {
            return;
        }
        let contact = self.contact();
        if self.leaving_contact {
            self.leaving_contact = contact.is_some();
            return;
        }
        if let Some(c) = contact {
            self.stop_all_joints();
            self.collision = Some(c);
            tracing::info!(contact = ?c, "simarm: the limb collided and stopped");
        }
    }
}
