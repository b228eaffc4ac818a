//! What the robot has, and which devices the driver serves for it.

use limber_interfaces::diagnostics::hardware;
use limber_interfaces::prelude::*;
use limber_p2os::{ConfigProbe, RobotIdentity};

use crate::config::BodyGripper;

/// What the robot turned out to have.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Hardware {
    /// The robot's identity (SYNC2).
    pub identity: RobotIdentity,
    /// ARM_INFO was answered.
    pub arm: bool,
    /// The body gripper and lift are served: the robot's CONFIGpac said so, or the
    /// configuration's `body_gripper = true` ([`gripper_decision`]).
    pub gripper: bool,
    /// Why the body gripper and lift are (not) served, in a sentence for the log.
    pub gripper_note: String,
    /// What the CONFIG probe at start found.
    pub config: ConfigProbe,
}

/// Whether to serve the body gripper and its lift, from the configuration's
/// `body_gripper` and the CONFIG probe, with the sentence that says why (`robot`: the
/// robot name in device names). Safe by default: `auto` serves them only when the robot's
/// CONFIGpac says a gripper is fitted; `true` serves them whatever the robot says (the
/// user knows the robot; a CONFIGpac saying "none" is warned of, and the commands then
/// reach a controller that ignores them); `false` never does.
pub fn gripper_decision(setting: BodyGripper, probe: &ConfigProbe, robot: &str) -> (bool, String) {
    let devices = format!("{robot}/gripper/0 (body gripper) and {robot}/actarray/1 (lift)");
    let says = match probe {
        ConfigProbe::Answered(c) => Some(c.has_gripper()),
        _ => None,
    };
    let unanswered = match probe {
        ConfigProbe::Unanswered { attempts } => {
            format!("the robot did not answer CONFIG (18) ({attempts} attempts)")
        }
        ConfigProbe::Malformed(e) => format!("the robot's CONFIGpac is unreadable ({e})"),
        ConfigProbe::NotAsked => "CONFIG (18) was not asked".into(),
        ConfigProbe::Answered(_) => String::new(),
    };
    match (setting, says) {
        (BodyGripper::Auto, Some(true)) => (
            true,
            format!("the robot's CONFIGpac says a gripper is fitted: serving {devices}"),
        ),
        (BodyGripper::Auto, Some(false)) => (
            false,
            format!("the robot's CONFIGpac says no gripper is fitted: not serving {devices}"),
        ),
        (BodyGripper::Auto, None) => (
            false,
            format!(
                "{unanswered}: not serving {devices}; if the robot has the body gripper, set \
                 body_gripper = true in the configuration (false to silence this warning)"
            ),
        ),
        (BodyGripper::Fitted, Some(false)) => (
            true,
            format!(
                "body_gripper = true: serving {devices} although the robot's CONFIGpac says no \
                 gripper is fitted; its commands are sent to the robot, which may ignore them"
            ),
        ),
        (BodyGripper::Fitted, _) => (true, format!("body_gripper = true: serving {devices}")),
        (BodyGripper::Absent, Some(true)) => (
            false,
            format!(
                "body_gripper = false: not serving {devices} although the robot's CONFIGpac \
                 says a gripper is fitted"
            ),
        ),
        (BodyGripper::Absent, _) => (
            false,
            format!("body_gripper = false: not serving {devices}"),
        ),
    }
}

/// The devices of the arm: `actarray/0`, `limb/0` and the arm gripper `gripper/1`. They
/// move the same actuators (the limb moves the joints; the arm's gripper is its joint 6):
/// they share one lease ([`DeviceSet::share_lease`](limber_services::DeviceSet::share_lease)).
///
/// The body gripper `gripper/0` and its lift `actarray/1` (the [`BODY_DEVICES`]) are left
/// out, each with a lease of its own: the paddles and the lift are motors of their own,
/// and no command of one moves the other (the gripper's STORE and RETRIEVE, which would
/// move both, are refused as unsupported), nor any of the arm's.
pub(super) const ARM_DEVICES: [(InterfaceKind, u16); 3] = [
    (InterfaceKind::ActArray, 0),
    (InterfaceKind::Limb, 0),
    (InterfaceKind::Gripper, 1),
];

/// [`DriverStats::hardware`]: what the robot has, and what the driver looked for and
/// found missing (`NO_*`, shown by `limber list` and the CLI's "no driver" message).
/// The devices of the body gripper: `gripper/0` and its lift `actarray/1`.
pub(super) const BODY_DEVICES: [(InterfaceKind, u16); 2] =
    [(InterfaceKind::Gripper, 0), (InterfaceKind::ActArray, 1)];

/// [`DriverStats::hardware`](limber_interfaces::diagnostics::DriverStats::hardware): what
/// the robot has, and what the driver looked for and found missing.
pub(super) fn hardware_bits(hw: &Hardware) -> u32 {
    let arm = if hw.arm {
        hardware::ARM
    } else {
        hardware::NO_ARM
    };
    let body = if hw.gripper {
        hardware::GRIPPER | hardware::LIFT
    } else {
        hardware::NO_GRIPPER | hardware::NO_LIFT
    };
    arm | body
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gripper_is_served_when_the_robot_says_so_or_the_user_forces_it() {
        let says = |g: u16| {
            ConfigProbe::Answered(Box::new(limber_p2os::ConfigPacket {
                gripper: g,
                ..Default::default()
            }))
        };
        let silent = ConfigProbe::Unanswered { attempts: 3 };
        let bad = ConfigProbe::Malformed(limber_p2os::ConfigPacketError::Empty);
        for (setting, probe, served, note) in [
            (BodyGripper::Auto, says(1), true, "says a gripper is fitted"),
            (BodyGripper::Auto, says(0), false, "says no gripper"),
            (
                BodyGripper::Auto,
                silent.clone(),
                false,
                "set body_gripper = true",
            ),
            (BodyGripper::Auto, bad, false, "unreadable"),
            (BodyGripper::Fitted, says(0), true, "although"),
            (
                BodyGripper::Fitted,
                silent.clone(),
                true,
                "body_gripper = true",
            ),
            (BodyGripper::Absent, says(1), false, "although"),
            (BodyGripper::Absent, silent, false, "body_gripper = false"),
        ] {
            let (s, n) = gripper_decision(setting, &probe, "kim");
            assert_eq!(s, served, "{setting:?} {probe:?}: {n}");
            assert!(n.contains(note), "{setting:?} {probe:?}: {n}");
            assert!(
                n.contains("kim/gripper/0") && n.contains("kim/actarray/1"),
                "{n}"
            );
        }
    }
}
