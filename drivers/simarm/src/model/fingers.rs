//! The seam between the gripper and the objects of the simulated world: what is between
//! the fingers, taken out of the world (STORE) or put back between them (RETRIEVE). The
//! model knows one optional object ([`SimObject`]); a world of many objects replaces
//! these functions (and [`ArmModel::object_between_fingers`]) and nothing else.

use super::gripper::GripperCmd;
use super::{ArmModel, SimObject};

impl ArmModel {
    /// Takes the object between the fingers (held or not) out of the world: `None` when
    /// nothing is between them. The fingers stay where they are, no longer on it.
    pub(super) fn take_from_fingers(&mut self) -> Option<SimObject> {
        if !self.object_between_fingers() {
            return None;
        }
        let o = self.object.take()?;
        self.held = false;
        self.gripper.stalled = false;
        Some(o)
    }

    /// Puts `o` back into the world between the fingers, held: the fingers closed on its
    /// width (CLOSED). Gives it back when there is no room for it (something is between
    /// the fingers already, or the world has its one object).
    pub(super) fn put_between_fingers(&mut self, mut o: SimObject) -> Result<(), SimObject> {
        if self.object.is_some() {
            return Err(o);
        }
        let p = self.tool_pose().position;
        o.position = [p.x, p.y, p.z];
        self.object = Some(o);
        self.held = true;
        self.gripper.stop();
        self.gripper.pos = o.width.clamp(0.0, self.gripper_stroke);
        self.gripper.target = self.gripper.pos;
        self.gripper.stalled = true;
        self.gripper_cmd = GripperCmd::Close;
        Ok(())
    }
}
