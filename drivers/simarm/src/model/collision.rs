//! The limb's collisions (the paper's COLL state): the arm's joint frames and its tool
//! point against the floor and the obstacles of [`SimArmOptions::obstacles`]. A motion that
//! brings one of them below the floor or into an obstacle is stopped there (within one
//! step of the simulation), and the limb's state is COLLISION until the next limb command
//! (a limb command that starts in contact may move until the arm is clear).
//!
//! Points, not link volumes: the origin of every joint frame after the first (the first
//! sits on the base) and the tool point.

use super::ArmModel;
#[allow(unused_imports)]
use super::SimArmOptions;

/// An obstacle the arm may hit: a box, axis-aligned in the robot frame (m) (the
/// kinematics' [`Box3`](limber_kinematics::path::Box3): the rule is the path checks').
pub use limber_kinematics::path::Box3 as SimObstacle;
/// What the arm touched.
pub use limber_kinematics::path::Contact;
/// What the arm can collide with (default: nothing): the kinematics'
/// [`Scene`](limber_kinematics::path::Scene), which the path checks use too.
pub use limber_kinematics::path::Scene as Obstacles;

impl ArmModel {
    /// The first contact of the arm (a joint frame after the first, or the tool point)
    /// with the floor or an obstacle, in its current configuration.
    pub fn contact(&self) -> Option<Contact> {
        self.options.obstacles.contact(&self.chain, &self.q())
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
