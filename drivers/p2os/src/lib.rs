#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

//! ## The library
//!
//! The P2OS/AROS/ARCOS protocol of the Pioneer controller.
//!
//! * [`codec`]: framing, checksum, the streaming [`Decoder`] (resynchronises
//!   on garbage, drops and counts bad checksums, never allocates or panics).
//! * [`Command`]: typed client → robot commands (connection, arm, gripper,
//!   lift), and [`ReceivedCommand`] for the robot side.
//! * [`RobotPacket`]: typed robot → client packets (SIP, ARMpac, ARMINFOpac,
//!   the 0xE0 gripper packet, sync replies); [`ConfigPacket`]: the CONFIGpac
//!   (0x20), what the robot has.
//! * [`ArmCalibration`]: tick ↔ radian and speed conversions from ARMINFOpac.
//! * [`Link`]: a serial device, pty or TCP connection with counters and a
//!   raw fd for epoll; [`Connection`]: the handshake state machine.
//! * [`vendor_conventions`]: where Player, ARIA and the vendor's manuals
//!   disagree, the reading limber follows (the manuals'; ARIA's where an
//!   option says so, e.g. [`ArmpacLayout`], [`GripperByteLayout`]).
//!
//! ```
//! use limber_p2os::{Command, Decoder, RobotPacket};
//! let frame = Command::Sync0.encode().unwrap();
//! assert_eq!(frame.as_bytes(), &[0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00]);
//! let mut d = Decoder::new();
//! d.feed(frame.as_bytes());
//! let p = d.next_packet().unwrap();
//! assert!(matches!(RobotPacket::parse(p), Ok(RobotPacket::Sync { step: 0, .. })));
//! ```

pub mod codec;
mod command;
mod configpac;
mod connection;
mod convert;
mod gripper_byte;
mod link;
mod packet;
pub mod sys;
pub mod vendor_conventions;

pub use codec::{
    ARGINT, ARGNINT, ARGSTR, Decoder, DecoderStats, EncodeError, Frame, MAX_FRAME, MAX_PAYLOAD,
    PayloadBuilder, checksum,
};
pub use command::{
    Argument, ArmJoint, ArmStatusMode, BadJoint, Command, GripperCommand, JointSelection,
    ReceivedCommand, num,
};
pub use configpac::{ConfigPacket, ConfigPacketError, ConfigWorking};
pub use connection::{
    BAUD_RATES, CloseError, ConfigProbe, ConnectError, ConnectOptions, Connection,
};
pub use convert::{ArmCalibration, ConversionError, TickTarget};
pub use gripper_byte::{
    GripperByteLayout, GripperReading, GripperSwitchFacts, GripperSwitches, LiftState, PaddleState,
};
pub use link::{DEFAULT_TCP_PORT, Link, LinkError, LinkStats, LinkTarget, OpenError};
pub use packet::{
    ArmInfo, ArmPacket, ArmStatus, ArmpacLayout, GripperPacket, JointCalibration, MAX_SONAR,
    MAX_VERSION, PacketError, RobotIdentity, RobotPacket, Sip, SonarReading, ptype,
};
