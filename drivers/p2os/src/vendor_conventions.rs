//! Every place where Player's p2os driver and the vendor's SDK (ARIA) read the
//! protocol differently, and the reading limber follows: **the vendor's**.
//!
//! Both the decoder in [`crate::p2os`] and the emulator in the emulator (`limber-emulator`)
//! take their bit layouts and magic numbers from here, so a change of mind is
//! one edit. Each item says what Player does instead (see the reference,
//! `player-reference.md` sections 3.3, 3.7, 3.8, 3.9 and 6).

/// ARM_HOME / ARM_STOP argument meaning "all joints".
///
/// ARIA sends `0xFF`; Player sends `7` for HOME. Firmware that follows ARIA
/// treats 7 as an invalid joint, so limber sends `0xFF`.
pub const ARM_ALL_JOINTS: u8 = 0xFF;

/// ARMpac status byte order: byte 1 of the payload (after the type byte) is
/// the **low** byte of a 16-bit little-endian status word (ARIA).
///
/// ARIA: low byte bits 0..5 = joint 1..6 moving; high byte bit 0 = arm good
/// (communicating), bit 1 = initialised, bit 2 = powered, bit 3 = homing.
/// Player swaps the two bytes (it reads byte 1 bit 0 as "power" and byte 2 as
/// the moving bits).
pub const ARMPAC_STATUS_LOW_BYTE_FIRST: bool = true;

/// ARMpac status, low byte: bit `j` (0..5) set = joint `j + 1` moving.
pub const ARM_STATUS_MOVING_MASK: u16 = 0x003F;
/// ARMpac status, high byte bit 0: the arm controller is alive and communicating.
pub const ARM_STATUS_GOOD: u16 = 0x0100;
/// ARMpac status, high byte bit 1: the arm controller is initialised.
pub const ARM_STATUS_INITED: u16 = 0x0200;
/// ARMpac status, high byte bit 2: the arm servos are powered.
pub const ARM_STATUS_POWERED: u16 = 0x0400;
/// ARMpac status, high byte bit 3: the arm is homing.
pub const ARM_STATUS_HOMING: u16 = 0x0800;

/// Gripper switch byte (General-I/O gripper: high byte of the SIP "timer"
/// field, and byte 2 of the 0xE0 gripper packet), ARIA's **active-low**
/// reading. Player 3 instead reads bit0 = open, bit1 = closed, bit2 = moving
/// (active-high), and its breakbeam test is always 0.
///
/// Bit 0 **clear** = the paddles are fully open (inner limit switch).
pub const GRIP_SW_OPEN_LIMIT_N: u8 = 0x01;
/// Bit 1 **clear** = the lift is at a limit (top or bottom; which one is
/// known from the last lift command).
pub const GRIP_SW_LIFT_LIMIT_N: u8 = 0x02;
/// Bit 2 set = the outer breakbeam is broken.
pub const GRIP_SW_OUTER_BEAM: u8 = 0x04;
/// Bit 3 set = the inner breakbeam is broken.
pub const GRIP_SW_INNER_BEAM: u8 = 0x08;
/// Bit 4 **clear** = the left paddle touches something (closed on an object
/// or on the other paddle).
pub const GRIP_SW_LEFT_CONTACT_N: u8 = 0x10;
/// Bit 5 **clear** = the right paddle touches something.
pub const GRIP_SW_RIGHT_CONTACT_N: u8 = 0x20;
/// Bit 6 set = the lift is moving.
pub const GRIP_SW_LIFT_MOVING: u8 = 0x40;
/// Bit 7 set = the paddles are moving (General-I/O gripper).
pub const GRIP_SW_PADDLES_MOVING: u8 = 0x80;

/// Lift relative moves (GRIPPERVAL after LIFTcarry) with a negative value
/// (downwards) are sent as `ARGNINT` with the magnitude, as ARIA does.
/// Player sends the 16-bit two's complement as `ARGINT`.
pub const LIFT_CARRY_NEGATIVE_AS_ARGNINT: bool = true;

/// ARIA's arm speed range: the "ms per step" byte is 1..=255 (ARIA: 0 is the
/// fastest, 255 the slowest). Player clamps to 1..=127. limber clamps
/// rad/s → ms/step conversions to `[ARM_SPEED_MS_MIN, ARM_SPEED_MS_MAX]`
/// (0 is avoided: its meaning differs between firmware versions).
pub const ARM_SPEED_MS_MIN: u8 = 1;
/// Upper clamp of the "ms per step" byte (ARIA: 255 is the slowest).
pub const ARM_SPEED_MS_MAX: u8 = 255;

/// Tick → angle sign per joint index 0..5 (ARIA and Player agree): joints 0, 1
/// and 2 are negated.
pub const JOINT_SIGN: [f64; 6] = [-1.0, -1.0, -1.0, 1.0, 1.0, 1.0];

/// ARIA treats joint 6 (the gripper servo) as raw ticks; Player converts it
/// to an angle like the others. limber's [`crate::ArmCalibration`]
/// offers both (`ticks_to_radians` for any joint, raw ticks via
/// [`crate::JointCalibration`]); drivers should command the gripper
/// joint in raw ticks (open = max, close = min).
pub const GRIPPER_JOINT_RAW_TICKS: bool = true;

/// Command number of ARIA's gripper packet request (37): ARGINT 2 starts a
/// 0xE0 gripper packet every cycle, 0 stops it. Player never sends it.
pub const GRIPPER_PACKET_REQUEST: u8 = 37;
