//! Typed client → robot commands.

use super::codec::{EncodeError, Frame, PayloadBuilder};
use super::vendor_conventions as vc;
use thiserror::Error;

/// Command numbers (payload byte 0, client → robot).
pub mod num {
    /// SYNC0, also PULSE (keep-alive).
    pub const SYNC0: u8 = 0;
    /// PULSE: keep-alive, the same number as SYNC0.
    pub const PULSE: u8 = 0;
    /// SYNC1, also OPEN (start the controller's servers).
    pub const SYNC1: u8 = 1;
    /// OPEN: same number as SYNC1.
    pub const OPEN: u8 = 1;
    /// SYNC2, also CLOSE.
    pub const SYNC2: u8 = 2;
    /// CLOSE: same number as SYNC2.
    pub const CLOSE: u8 = 2;
    /// ENABLE: base motors on/off.
    pub const ENABLE: u8 = 4;
    /// CONFIG (no argument): the controller sends one CONFIGpac (0x20).
    pub const CONFIG: u8 = 18;
    /// SONAR: sonar on/off.
    pub const SONAR: u8 = 28;
    /// STOP: stop the base.
    pub const STOP: u8 = 29;
    /// GRIPPER: body gripper and lift sub-command.
    pub const GRIPPER: u8 = 33;
    /// GRIPPERVAL: value for GRIPpress / LIFTcarry.
    pub const GRIPPERVAL: u8 = 36;
    /// GRIPPERPACREQUEST (ARIA): 0xE0 gripper packet stream.
    pub const GRIPPERPACREQUEST: u8 = super::vc::GRIPPER_PACKET_REQUEST;
    /// ARM_INFO: request one ARMINFOpac.
    pub const ARM_INFO: u8 = 70;
    /// ARM_STATUS: 0 stop, 1 one ARMpac, 2 ARMpac every cycle.
    pub const ARM_STATUS: u8 = 71;
    /// ARM_INIT: (re)initialise the arm controller.
    pub const ARM_INIT: u8 = 72;
    /// ARM_CHECK: check the arm is alive.
    pub const ARM_CHECK: u8 = 73;
    /// ARM_POWER: arm servo power.
    pub const ARM_POWER: u8 = 74;
    /// ARM_HOME: home one joint or all.
    pub const ARM_HOME: u8 = 75;
    /// ARM_PARK: home then power off.
    pub const ARM_PARK: u8 = 76;
    /// ARM_POS: LSB target tick, MSB joint.
    pub const ARM_POS: u8 = 77;
    /// ARM_SPEED: LSB ms per step, MSB joint.
    pub const ARM_SPEED: u8 = 78;
    /// ARM_STOP: stop one joint or all.
    pub const ARM_STOP: u8 = 79;
    /// ARM_AUTOPARK: seconds of inactivity before parking (0 disables).
    pub const ARM_AUTOPARK: u8 = 80;
    /// ARM_GRIPPARK: seconds before a closed arm gripper is parked.
    pub const ARM_GRIPPARK: u8 = 81;
}

/// A P2OS arm joint number, 1..=6 (6 = the arm gripper).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ArmJoint(u8);

/// A joint number outside 1..=6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("arm joint number {0} is not in 1..=6")]
pub struct BadJoint(pub u8);

impl ArmJoint {
    /// The arm gripper servo (joint 6).
    pub const GRIPPER: ArmJoint = ArmJoint(6);

    /// A 1-based P2OS joint number (1..=6).
    pub fn new(number: u8) -> Result<ArmJoint, BadJoint> {
        if (1..=6).contains(&number) {
            Ok(ArmJoint(number))
        } else {
            Err(BadJoint(number))
        }
    }

    /// From a 0-based joint index (0..=5).
    pub fn from_index(index: usize) -> Result<ArmJoint, BadJoint> {
        if index < 6 {
            Ok(ArmJoint(index as u8 + 1))
        } else {
            Err(BadJoint(index.min(255) as u8))
        }
    }

    /// The 1-based P2OS number.
    pub fn number(self) -> u8 {
        self.0
    }

    /// The 0-based index.
    pub fn index(self) -> usize {
        usize::from(self.0 - 1)
    }

    /// All six joints in order.
    pub fn all() -> impl Iterator<Item = ArmJoint> {
        (1..=6).map(ArmJoint)
    }
}

/// One joint or all joints, for ARM_HOME and ARM_STOP.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointSelection {
    /// One joint.
    One(ArmJoint),
    /// All joints (sent as [`vc::ARM_ALL_JOINTS`], the vendor's 0xFF).
    All,
}

impl JointSelection {
    fn wire(self) -> u8 {
        match self {
            JointSelection::One(j) => j.number(),
            JointSelection::All => vc::ARM_ALL_JOINTS,
        }
    }
}

/// ARM_STATUS argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmStatusMode {
    /// Stop the ARMpac stream (0).
    Stop = 0,
    /// Send one ARMpac (1).
    Once = 1,
    /// Send an ARMpac every cycle (2).
    Continuous = 2,
}

/// GRIPPER sub-commands (the LSB of the GRIPPER argument).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GripperCommand {
    /// Open the paddles (1).
    Open = 1,
    /// Close the paddles (2).
    Close = 2,
    /// Stop the paddles (3).
    Stop = 3,
    /// Raise the lift (4).
    LiftUp = 4,
    /// Lower the lift (5).
    LiftDown = 5,
    /// Stop the lift (6).
    LiftStop = 6,
    /// Close the paddles and raise the lift (7).
    Store = 7,
    /// Open the paddles and lower the lift (8).
    Deploy = 8,
    /// Stop paddles and lift (15).
    Halt = 15,
    /// Grip with a pressure/time set by the following GRIPPERVAL (16).
    Press = 16,
    /// Move the lift for the time set by the following GRIPPERVAL (17),
    /// in 20 ms steps; negative = down.
    LiftCarry = 17,
}

impl GripperCommand {
    /// From the wire value.
    pub fn from_u8(v: u8) -> Option<GripperCommand> {
        use GripperCommand::*;
        Some(match v {
            1 => Open,
            2 => Close,
            3 => Stop,
            4 => LiftUp,
            5 => LiftDown,
            6 => LiftStop,
            7 => Store,
            8 => Deploy,
            15 => Halt,
            16 => Press,
            17 => LiftCarry,
            _ => return None,
        })
    }
}

/// A client → robot command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Sync step 0 (same number as PULSE).
    Sync0,
    /// Sync step 1 (same number as OPEN).
    Sync1,
    /// Sync step 2 (same number as CLOSE).
    Sync2,
    /// Keep-alive.
    Pulse,
    /// Start the controller's servers (after the sync).
    Open,
    /// Close the connection.
    Close,
    /// Base motors on/off.
    Enable(bool),
    /// Sonar on/off.
    Sonar(bool),
    /// Ask for one CONFIGpac ([`crate::ConfigPacket`]).
    Config,
    /// Stop the base.
    Stop,
    /// A body-gripper or lift sub-command.
    Gripper(GripperCommand),
    /// Value for the preceding Press or LiftCarry (20 ms units; negative
    /// carry = down, sent per [`vc::LIFT_CARRY_NEGATIVE_AS_ARGNINT`]).
    GripperValue(i16),
    /// 0xE0 gripper packets: 0 stop, 1 one, 2 every cycle (ARIA).
    GripperPacketRequest(u8),
    /// Request one ARMINFOpac.
    ArmInfo,
    /// ARMpac stream control.
    ArmStatus(ArmStatusMode),
    /// (Re)initialise the arm controller.
    ArmInit,
    /// Check the arm controller.
    ArmCheck,
    /// Arm servo power on/off.
    ArmPower(bool),
    /// Home one joint or all.
    ArmHome(JointSelection),
    /// Home then power off.
    ArmPark,
    /// Move a joint to a raw tick.
    ArmPos {
        /// The joint.
        joint: ArmJoint,
        /// Target tick.
        tick: u8,
    },
    /// Set a joint's speed in ms per step.
    ArmSpeed {
        /// The joint.
        joint: ArmJoint,
        /// Milliseconds per tick step.
        ms_per_step: u8,
    },
    /// Stop one joint or all.
    ArmStop(JointSelection),
    /// Seconds of inactivity before the arm parks (0 disables).
    ArmAutoPark(u16),
    /// Seconds before a closed arm gripper is parked.
    ArmGripPark(u16),
    /// Any other command with an optional integer argument.
    Custom {
        /// Command number.
        number: u8,
        /// Integer argument (ARGINT/ARGNINT), or none.
        arg: Option<i32>,
    },
}

impl Command {
    /// The command number.
    pub fn number(&self) -> u8 {
        use Command::*;
        match self {
            Sync0 | Pulse => num::SYNC0,
            Sync1 | Open => num::SYNC1,
            Sync2 | Close => num::SYNC2,
            Enable(_) => num::ENABLE,
            Sonar(_) => num::SONAR,
            Config => num::CONFIG,
            Stop => num::STOP,
            Gripper(_) => num::GRIPPER,
            GripperValue(_) => num::GRIPPERVAL,
            GripperPacketRequest(_) => num::GRIPPERPACREQUEST,
            ArmInfo => num::ARM_INFO,
            ArmStatus(_) => num::ARM_STATUS,
            ArmInit => num::ARM_INIT,
            ArmCheck => num::ARM_CHECK,
            ArmPower(_) => num::ARM_POWER,
            ArmHome(_) => num::ARM_HOME,
            ArmPark => num::ARM_PARK,
            ArmPos { .. } => num::ARM_POS,
            ArmSpeed { .. } => num::ARM_SPEED,
            ArmStop(_) => num::ARM_STOP,
            ArmAutoPark(_) => num::ARM_AUTOPARK,
            ArmGripPark(_) => num::ARM_GRIPPARK,
            Custom { number, .. } => *number,
        }
    }

    /// The integer argument, if the command has one.
    pub fn argument(&self) -> Option<i32> {
        use Command::*;
        let lsb_msb = |lsb: u8, msb: u8| i32::from(u16::from_le_bytes([lsb, msb]));
        match *self {
            Sync0 | Sync1 | Sync2 | Pulse | Open | Close | Config | Stop | ArmInfo | ArmInit
            | ArmCheck | ArmPark => None,
            Enable(b) | Sonar(b) | ArmPower(b) => Some(i32::from(b)),
            Gripper(g) => Some(g as i32),
            GripperValue(v) => {
                if vc::LIFT_CARRY_NEGATIVE_AS_ARGNINT {
                    Some(i32::from(v))
                } else {
                    Some(i32::from(v as u16))
                }
            }
            GripperPacketRequest(v) => Some(i32::from(v)),
            ArmStatus(m) => Some(m as i32),
            ArmHome(s) | ArmStop(s) => Some(i32::from(s.wire())),
            ArmPos { joint, tick } => Some(lsb_msb(tick, joint.number())),
            ArmSpeed { joint, ms_per_step } => Some(lsb_msb(ms_per_step, joint.number())),
            ArmAutoPark(s) | ArmGripPark(s) => Some(i32::from(s)),
            Custom { arg, .. } => arg,
        }
    }

    /// Encodes the command as a packet.
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        let mut b = PayloadBuilder::new(self.number());
        if let Some(arg) = self.argument() {
            b.int_arg(arg)?;
        }
        b.frame()
    }
}

/// A command as the robot receives it: number and decoded argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReceivedCommand<'a> {
    /// Command number.
    pub number: u8,
    /// The argument.
    pub arg: Argument<'a>,
}

/// A decoded command argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Argument<'a> {
    /// No argument.
    None,
    /// An integer (ARGINT positive, ARGNINT negative).
    Int(i32),
    /// A string (ARGSTR).
    Str(&'a [u8]),
    /// Bytes that are not a well-formed argument.
    Malformed(&'a [u8]),
}

impl<'a> ReceivedCommand<'a> {
    /// Parses a command payload (robot side). Never fails: a payload whose
    /// argument is not well formed gives [`Argument::Malformed`]; an empty
    /// payload gives `None`.
    pub fn parse(payload: &'a [u8]) -> Option<ReceivedCommand<'a>> {
        let (&number, rest) = payload.split_first()?;
        let arg = match rest {
            [] => Argument::None,
            [super::codec::ARGINT, lo, hi] => {
                Argument::Int(i32::from(u16::from_le_bytes([*lo, *hi])))
            }
            [super::codec::ARGNINT, lo, hi] => {
                Argument::Int(-i32::from(u16::from_le_bytes([*lo, *hi])))
            }
            [super::codec::ARGSTR, len, s @ ..] if usize::from(*len) == s.len() => Argument::Str(s),
            // Some clients (Player's SETO) send a type byte alone.
            [super::codec::ARGINT] => Argument::Int(0),
            other => Argument::Malformed(other),
        };
        Some(ReceivedCommand { number, arg })
    }

    /// The integer argument, if any.
    pub fn int(&self) -> Option<i32> {
        match self.arg {
            Argument::Int(v) => Some(v),
            _ => None,
        }
    }
}
