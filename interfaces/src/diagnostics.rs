//! `driver`: what a driver process says about itself (loop timing, link statistics, what
//! the robot reported), like the introspection ros2_control users rely on. Published on
//! `limber/<robot>/driver/0/data`; `limber echo <robot>/driver` shows it.

use crate::common::StateHeader;
use crate::error::DecodeError;
use crate::manifest::{Constant, ConstantGroup};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

/// Length of the text fields of [`DriverStats`].
pub const TEXT_LEN: usize = 32;

wire_struct! {
    /// Loop, link and robot facts of one driver process.
    pub struct DriverStats : "limber.v6.DriverStats", size = 352, align = 8 {
        /// Common header (`flags`: `DEVICE_FLAG_LINK_UP` while the link is up).
        pub header: StateHeader,
        /// The driver's name (NUL-padded ASCII), e.g. "pioneer".
        pub driver: [u8; 32],
        /// The robot's name as it reported it (SYNC2), NUL-padded.
        pub robot_name: [u8; 32],
        /// The robot's class, NUL-padded (e.g. "Pioneer").
        pub robot_class: [u8; 32],
        /// The robot's subclass, NUL-padded (e.g. "p3dx").
        pub robot_subclass: [u8; 32],
        /// `HARDWARE` bits: what the robot has.
        pub hardware: u32,
        /// `LOOP_MODE`: how the loop waits.
        pub loop_mode: u32,
        /// Loop cycles since start.
        pub cycles: u64,
        /// Cycles that started later than one period after the previous one.
        pub overruns: u64,
        /// Period between cycles: median, ns.
        pub period_p50_ns: u64,
        /// Period: 99th percentile, ns.
        pub period_p99_ns: u64,
        /// Period: maximum, ns.
        pub period_max_ns: u64,
        /// Jitter: 99th percentile of |period − nominal|, ns.
        pub jitter_p99_ns: u64,
        /// Command received → bytes written to the link: median, ns.
        pub cmd_to_wire_p50_ns: u64,
        /// Command to wire: 99th percentile, ns.
        pub cmd_to_wire_p99_ns: u64,
        /// Command to wire: maximum, ns.
        pub cmd_to_wire_max_ns: u64,
        /// Standard SIPs received in the last second.
        pub sips_per_s: f64,
        /// Bytes received from the robot.
        pub bytes_in: u64,
        /// Bytes sent to the robot.
        pub bytes_out: u64,
        /// Good packets received.
        pub packets_in: u64,
        /// Packets dropped for a bad checksum.
        pub bad_checksums: u64,
        /// Garbage bytes skipped while resynchronising.
        pub resync_bytes: u64,
        /// Times the link was re-established.
        pub reconnects: u64,
        /// Times the link was found dead (silence, EOF, error).
        pub link_faults: u64,
        /// Commands handled, all devices.
        pub commands: u64,
        /// Commands refused, all devices.
        pub refused: u64,
        /// Requests answered, all devices.
        pub requests: u64,
        /// Commands lost to queue overflow, all devices.
        pub cmd_overflows: u64,
    }
}

/// Bits of [`DriverStats::hardware`].
pub mod hardware {
    /// The robot has the 5-DOF arm (ARMINFO answered).
    pub const ARM: u32 = 1;
    /// The robot has the body gripper.
    pub const GRIPPER: u32 = 2;
    /// The robot has the gripper lift.
    pub const LIFT: u32 = 4;
    /// The driver looked for an arm and the robot has none (ARM_INFO unanswered): its
    /// devices are not served (the driver keeps asking, and serves them if it answers).
    pub const NO_ARM: u32 = 0x100;
    /// The robot has no body gripper: its CONFIGpac says none, it did not answer CONFIG,
    /// or the configuration says so (`body_gripper`). Not served.
    pub const NO_GRIPPER: u32 = 0x200;
    /// The robot has no gripper lift (it comes with the body gripper: see [`NO_GRIPPER`]).
    /// Not served.
    pub const NO_LIFT: u32 = 0x400;

    /// The hardware a device stands for in the Pioneer driver's naming (`actarray/0`,
    /// `limb/0` and `gripper/1`: the arm; `gripper/0`: the body gripper; `actarray/1`:
    /// the lift): its `NO_*` bit and its name. `None` for any other device.
    pub fn of_device(interface: crate::InterfaceKind, index: u16) -> Option<(u32, &'static str)> {
        use crate::InterfaceKind::{ActArray, Gripper, Limb};
        match (interface, index) {
            (ActArray, 0) | (Limb, 0) | (Gripper, 1) => Some((NO_ARM, "arm")),
            (Gripper, 0) => Some((NO_GRIPPER, "gripper")),
            (ActArray, 1) => Some((NO_LIFT, "lift")),
            _ => None,
        }
    }

    /// The names of the hardware `bits` says the robot lacks (`NO_*`), in bit order.
    pub fn lacking(bits: u32) -> Vec<&'static str> {
        [(NO_ARM, "arm"), (NO_GRIPPER, "gripper"), (NO_LIFT, "lift")]
            .into_iter()
            .filter(|&(b, _)| bits & b != 0)
            .map(|(_, n)| n)
            .collect()
    }
}

/// Values of [`DriverStats::loop_mode`].
pub mod loop_mode {
    /// Event-driven (WaitSet on the link, the clients and a timer).
    pub const EVENT: u32 = 1;
    /// Busy-polling.
    pub const SPIN: u32 = 2;
}

/// Copies `s` into a NUL-padded text field (truncating at a char boundary).
pub fn put_text(field: &mut [u8; TEXT_LEN], s: &str) {
    field.fill(0);
    let mut n = s.len().min(TEXT_LEN - 1);
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    field[..n].copy_from_slice(&s.as_bytes()[..n]);
}

/// Reads a NUL-padded text field; non-UTF-8 is an error.
pub fn get_text(field: &[u8; TEXT_LEN]) -> Result<&str, DecodeError> {
    let end = field.iter().position(|&b| b == 0).unwrap_or(TEXT_LEN);
    core::str::from_utf8(&field[..end]).map_err(|_| DecodeError::UnknownCode {
        field: "text",
        value: -1,
    })
}

pub(crate) const GROUPS: &[ConstantGroup] = &[
    ConstantGroup {
        name: "HARDWARE",
        doc: "DriverStats.hardware bits",
        constants: &[
            Constant {
                name: "ARM",
                value: 1,
                doc: "5-DOF arm present",
            },
            Constant {
                name: "GRIPPER",
                value: 2,
                doc: "body gripper present",
            },
            Constant {
                name: "LIFT",
                value: 4,
                doc: "gripper lift present",
            },
            Constant {
                name: "NO_ARM",
                value: 0x100,
                doc: "the driver looked for an arm and the robot has none",
            },
            Constant {
                name: "NO_GRIPPER",
                value: 0x200,
                doc: "no body gripper (robot or configuration)",
            },
            Constant {
                name: "NO_LIFT",
                value: 0x400,
                doc: "no gripper lift (robot or configuration)",
            },
        ],
    },
    ConstantGroup {
        name: "LOOP_MODE",
        doc: "DriverStats.loop_mode",
        constants: &[
            Constant {
                name: "EVENT",
                value: 1,
                doc: "event-driven",
            },
            Constant {
                name: "SPIN",
                value: 2,
                doc: "busy-polling",
            },
        ],
    },
];
