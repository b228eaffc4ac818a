//! The brakes of the chain's joints (the BRAKES request of the actuator array and of the
//! limb, one set of brakes): on, every chain joint stops and is BRAKED, the limb is
//! BRAKED, and a command that would move a chain joint is refused with
//! [`Status::Braked`] until they are released. Stopping is never refused; the gripper
//! has no brakes.

use limber_interfaces::prelude::*;

use super::ArmModel;

impl ArmModel {
    /// True while the brakes are on.
    pub fn braked(&self) -> bool {
        self.brakes
    }

    /// The BRAKES request: on stops every chain joint (a VECMOVE and a current mode end)
    /// and holds them; off releases them. Unsupported when the chain's joints have no
    /// brakes ([`SimArmOptions::brakes`](super::SimArmOptions::brakes)).
    pub(super) fn set_brakes(&mut self, on: bool) -> Result<(), Status> {
        if !self.options.brakes {
            return Err(Status::Unsupported);
        }
        if on {
            self.stop_all_joints();
            self.abort_trajectory(Status::Braked);
        }
        self.brakes = on;
        Ok(())
    }

    /// Refuses an actuator-array command that would move a braked joint (an index
    /// beyond the chain is left to the command's own validation).
    pub(super) fn arm_unbraked(&self, cmd: &ActArrayCommand) -> Result<(), Status> {
        if !self.brakes {
            return Ok(());
        }
        let n = self.n;
        let joint = |j: u16| (j as usize) < n;
        let moves = match *cmd {
            ActArrayCommand::Position { joint: j, .. } => joint(j),
            ActArrayCommand::Speed { joint: j, speed } => joint(j) && speed != 0.0,
            ActArrayCommand::MultiPosition(v) | ActArrayCommand::MultiCurrent(v) => {
                v.len().min(n) > 0
            }
            ActArrayCommand::MultiSpeed(v) => v.as_slice().iter().take(n).any(|s| *s != 0.0),
            // TRAJ checks the brakes against the joints it names when it starts.
            ActArrayCommand::TrajChunk(_)
            | ActArrayCommand::Traj(_)
            | ActArrayCommand::TrajScale(_) => false,
            ActArrayCommand::Home(JointSel::All)
            | ActArrayCommand::Current {
                joint: JointSel::All,
                ..
            } => true,
            ActArrayCommand::Home(JointSel::One(j))
            | ActArrayCommand::Current {
                joint: JointSel::One(j),
                ..
            } => joint(j),
        };
        if moves { Err(Status::Braked) } else { Ok(()) }
    }

    /// Refuses a limb command that would move the limb (all but STOP) while braked.
    pub(super) fn limb_unbraked(&self, cmd: &LimbCommand) -> Result<(), Status> {
        if self.brakes && !matches!(cmd, LimbCommand::Stop) {
            Err(Status::Braked)
        } else {
            Ok(())
        }
    }
}
