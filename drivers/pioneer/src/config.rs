//! The Pioneer driver's configuration (TOML). Every field has a default that fits a
//! Pioneer 3 with the 5-DOF arm, the body gripper and its lift.

use std::path::Path;
use std::time::Duration;

use limber_p2os::{ArmpacLayout, GripperByteLayout};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A configuration could not be loaded.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The TOML is malformed or has unknown keys.
    #[error("invalid configuration: {0}")]
    Parse(#[source] toml::de::Error),
    /// A value is out of range.
    #[error("invalid configuration: {0}")]
    Invalid(String),
}

/// Geometry of a gripper as reported by GET_GEOM.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GripperGeometry {
    /// Pose in the robot frame: x, y, z (m), roll, pitch, yaw (rad).
    pub pose: [f64; 6],
    /// Outer size: width, length, height (m).
    pub outer: [f64; 3],
    /// Space between the open fingers: width, length, height (m).
    pub inner: [f64; 3],
}

/// The driver's configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PioneerConfig {
    /// The link: a serial device (`/dev/ttyS0`), a pty, or `tcp://host:port` (a
    /// simulator or an ethernet-serial bridge; 8101 is the simulator port).
    pub port: String,
    /// Serial baud rate, one of the P2OS rates (9600, 19200, 38400, 57600, 115200); unset:
    /// try 9600, 38400, 19200, 115200, 57600 in turn.
    pub baud: Option<u32>,
    /// The robot name in device names (`<robot>/actarray/0`, ...).
    pub robot: String,
    /// Arm base position in the robot frame, m.
    pub arm_base: [f64; 3],
    /// Arm link lengths L1, L2, L4, L5 of Gan et al. (m).
    pub arm_links: [f64; 4],
    /// Angular calibration offsets of joints 0..4, rad.
    pub limb_offsets: [f64; 5],
    /// Link lengths reported per actuator in the arm geometry (m), joints 0..5.
    pub arm_geometry_lengths: [f64; 6],
    /// The body gripper's geometry.
    pub gripper: GripperGeometry,
    /// The arm gripper's geometry (pose relative to the end effector).
    pub arm_gripper: GripperGeometry,
    /// Lift stroke (m): position 0 = down, this = up.
    pub lift_stroke: f64,
    /// Lift speed (m/s); a full stroke takes stroke/speed.
    pub lift_speed: f64,
    /// Loop tick, ms: housekeeping, motion streaming and state estimates.
    pub tick_ms: u64,
    /// No packet from the robot for this long means the link is down, ms.
    pub link_timeout_ms: u64,
    /// No packet from the robot for this long (or `link_timeout_ms`, if shorter) and a
    /// client's command is refused "link down" instead of being written to a robot that
    /// may carry it out late or never, ms. A robot sends a SIP every 100 ms.
    pub command_silence_ms: u64,
    /// Pause between reconnection attempts, ms.
    pub reconnect_interval_ms: u64,
    /// How long each ARM_INFO may go unanswered, ms. The handshake asks 3 times before
    /// the robot counts as armless; the loop then keeps asking in the background, the wait
    /// doubling from this value up to 30 s (an arm found so late needs a driver restart to
    /// be served; after a reconnect, the arm's ARMpac stream is restarted). Also how long
    /// each CONFIG (the body-gripper probe at start) may go unanswered: asked 3 times with
    /// `body_gripper = "auto"`, once when it is true or false. At least 100 (one controller
    /// cycle).
    pub arm_info_timeout_ms: u64,
    /// Send PULSE when nothing was sent for this long, ms; at least 100 (one controller
    /// cycle: shorter floods the link).
    pub pulse_interval_ms: u64,
    /// A joint that stays short of its target for this long, not moving, is stalled, ms.
    pub stall_timeout_ms: u64,
    /// End-effector speed for limb motions until a limb SPEED request changes it, m/s.
    pub limb_speed: f64,
    /// Largest deviation from the straight line allowed in VECMOVE, m.
    pub vecmove_deviation: f64,
    /// SETPOSE (and the limb's REACH request): how far from the requested position the
    /// end effector may end, m. The solver meets the position exactly whenever the arm
    /// can; this admits poses at the edge of the reach and near a singularity. The
    /// joints' resolution (one tick, about 1°) adds its own few millimetres.
    pub setpose_position_tolerance: f64,
    /// SETPOSE: how far from the requested approach vector the gripper may point,
    /// degrees (also how far from perpendicular to the approach the orientation vector
    /// may be). The orientation itself is turned to the nearest one the five joints can
    /// hold, and the outcome says so (ADJUSTED).
    pub setpose_approach_tolerance_deg: f64,
    /// How the two ARMpac status bytes are read: `"manual"` (the vendor's manuals: byte A
    /// servo power and arm connection, byte B the joints' moving bits; the default) or
    /// `"aria"` (ARIA's ArP2Arm: one little-endian word, moving bits first). The driver
    /// warns when the robot's packets only make sense in the other layout.
    #[serde(with = "layout_name")]
    pub armpac_layout: ArmpacLayout,
    /// How the body gripper's state byte (in the SIP) is read: `"manual"` (the Pioneer
    /// Gripper manual's Table 4: active-high bits paddles open / closed / moving /
    /// error, lift up / down / moving / error, the breakbeams in DIGIN; the default) or
    /// `"aria"` (ARIA's General-I/O switches, active low, the beams in the byte).
    #[serde(with = "gripper_byte_name")]
    pub gripper_byte: GripperByteLayout,
    /// Whether the robot has the body gripper and its lift (`<robot>/gripper/0` and
    /// `<robot>/actarray/1`): `"auto"` (the default) asks the robot at connect (CONFIG;
    /// served if its CONFIGpac says a gripper is fitted, not served if it says none or
    /// does not answer); `true` or `false` decide for a controller that does not answer
    /// CONFIG. Without them no gripper or lift command is ever sent to the robot.
    #[serde(with = "body_gripper_value")]
    pub body_gripper: BodyGripper,
    /// The arm's autopark watchdog (AUTOPARK, P2OS command 80), s: when no command
    /// (PULSE included) reaches the robot for this long, the arm homes and powers off by
    /// itself, so a driver killed with SIGKILL does not leave it moving. Sent at every
    /// connection; 0 disables the watchdog. Must exceed the keep-alive interval.
    pub autopark_s: u16,
    /// Event mode: how long, µs, the loop keeps polling its clients after a command or
    /// request before it sleeps again, so that a client's next command in a tight loop
    /// needs no wake-up (`event_loop::linger`; at most 1 ms of CPU per burst). 0: sleep at
    /// once. Chosen by measurement (`limber bench --only command`, the `event-*` rows).
    pub linger_us: u32,
    /// Clients each device admits at once (`limber pioneer --max-clients N`; 1 to
    /// `limber_services::qos::MAX_CLIENTS_LIMIT`): a full device refuses one more with a
    /// sentence naming the limit. A few more slots are kept for priority clients (the
    /// robot's control program: `LIMBER_PRIORITY=1`). Every slot costs a little on every
    /// publish: size it to the programs of the robot PC.
    pub max_clients: usize,
}

/// `body_gripper`: whether the robot has the body gripper and its lift.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BodyGripper {
    /// `"auto"`: ask the robot at connect (CONFIG, 18) and trust its CONFIGpac; a robot
    /// that does not answer gets neither device (a warning says how to force it).
    #[default]
    Auto,
    /// `true`: fitted, served whatever the robot says (the robot is asked all the same, and
    /// a CONFIGpac saying "no gripper" is warned of).
    Fitted,
    /// `false`: not fitted, never served.
    Absent,
}

/// `body_gripper` in TOML: `"auto"`, `true` or `false`.
mod body_gripper_value {
    use super::BodyGripper;
    use serde::de::{self, Visitor};
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &BodyGripper, s: S) -> Result<S::Ok, S::Error> {
        match v {
            BodyGripper::Auto => s.serialize_str("auto"),
            BodyGripper::Fitted => s.serialize_bool(true),
            BodyGripper::Absent => s.serialize_bool(false),
        }
    }

    struct V;

    impl Visitor<'_> for V {
        type Value = BodyGripper;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("true, false or \"auto\"")
        }

        fn visit_bool<E: de::Error>(self, b: bool) -> Result<BodyGripper, E> {
            Ok(if b {
                BodyGripper::Fitted
            } else {
                BodyGripper::Absent
            })
        }

        fn visit_str<E: de::Error>(self, v: &str) -> Result<BodyGripper, E> {
            match v {
                "auto" => Ok(BodyGripper::Auto),
                _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
            }
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BodyGripper, D::Error> {
        d.deserialize_any(V)
    }
}

/// `armpac_layout` as its name in TOML.
mod layout_name {
    use limber_p2os::ArmpacLayout;
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(l: &ArmpacLayout, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(l.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<ArmpacLayout, D::Error> {
        let name = String::deserialize(d)?;
        ArmpacLayout::from_name(&name).ok_or_else(|| {
            D::Error::custom(format!(
                "armpac_layout {name:?}: expected \"manual\" or \"aria\""
            ))
        })
    }
}

/// `gripper_byte` as its name in TOML.
mod gripper_byte_name {
    use limber_p2os::GripperByteLayout;
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(l: &GripperByteLayout, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(l.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<GripperByteLayout, D::Error> {
        let name = String::deserialize(d)?;
        GripperByteLayout::from_name(&name).ok_or_else(|| {
            D::Error::custom(format!(
                "gripper_byte {name:?}: expected \"manual\" or \"aria\""
            ))
        })
    }
}

impl Default for PioneerConfig {
    fn default() -> Self {
        PioneerConfig {
            port: "/dev/ttyS0".into(),
            baud: None,
            robot: "pioneer".into(),
            arm_base: [0.105, 0.0, 0.3185],
            arm_links: [0.06875, 0.16, 0.13775, 0.11321],
            limb_offsets: [0.0; 5],
            arm_geometry_lengths: [0.06875, 0.16, 0.0, 0.13775, 0.11321, 0.0],
            gripper: GripperGeometry {
                pose: [0.2, 0.0, 0.05, 0.0, 0.0, 0.0],
                outer: [0.315, 0.195, 0.035],
                inner: [0.205, 0.095, 0.035],
            },
            arm_gripper: GripperGeometry {
                pose: [0.0; 6],
                outer: [0.09, 0.09, 0.041],
                inner: [0.054, 0.025, 0.041],
            },
            lift_stroke: 0.07,
            lift_speed: 0.02,
            tick_ms: 10,
            link_timeout_ms: 1000,
            command_silence_ms: 250,
            reconnect_interval_ms: 500,
            arm_info_timeout_ms: 1000,
            pulse_interval_ms: 1000,
            stall_timeout_ms: 2000,
            limb_speed: 0.1,
            vecmove_deviation: 0.002,
            setpose_position_tolerance: 0.001,
            setpose_approach_tolerance_deg: 1.0,
            armpac_layout: ArmpacLayout::default(),
            gripper_byte: GripperByteLayout::default(),
            body_gripper: BodyGripper::Auto,
            // The link timeout (1 s) and a reconnection or two, with room to spare.
            autopark_s: 10,
            linger_us: limber_services::qos::DRIVER_LINGER.as_micros() as u32,
            max_clients: limber_services::qos::DEFAULT_MAX_CLIENTS,
        }
    }
}

impl PioneerConfig {
    /// Loads a TOML file; absent keys take their defaults, unknown keys are an error.
    pub fn from_file(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml(&text)
    }

    /// Parses TOML text.
    pub fn from_toml(text: &str) -> Result<Self, ConfigError> {
        let c: PioneerConfig = toml::from_str(text).map_err(ConfigError::Parse)?;
        c.validate()?;
        Ok(c)
    }

    /// The configuration as TOML (what `limber pioneer --print-config` shows), with a
    /// comment on the keys whose meaning is not obvious from their name or value.
    pub fn to_toml(&self) -> String {
        format!(
            "# autopark_s: seconds without any command (PULSE included) after which the arm\n\
             # homes and powers off by itself (AUTOPARK, sent at every connection); 0 disables.\n{}",
            toml::to_string_pretty(self)
                .unwrap_or_default()
                .replacen(
                    "setpose_position_tolerance =",
                    "# SETPOSE: position (m) and approach (degrees) within these; the orientation is the\n# nearest one the five joints can hold (outcome ADJUSTED, the limb state says by how much)\nsetpose_position_tolerance =",
                    1,
                )
                .replacen(
                    "max_clients =",
                    "# max_clients: clients each device admits at once (a few more slots are kept for\n# priority clients, LIMBER_PRIORITY=1); every slot costs a little on every publish\nmax_clients =",
                    1,
                )
                .replacen(
                    "linger_us =",
                    "# linger_us: after a command, keep polling the clients this long (µs) before sleeping; 0: sleep at once\nlinger_us =",
                    1,
                )
                .replacen(
                    "body_gripper =",
                    "# body_gripper: \"auto\" asks the robot (CONFIG) at connect; true/false decide for a\n# controller that does not answer (false: gripper/0 and actarray/1 never served)\nbody_gripper =",
                    1,
                )
                .replacen(
                    "gripper_byte =",
                    "# body gripper state byte: \"manual\" (the Pioneer Gripper manual, active high, beams in DIGIN) or \"aria\" (ARIA's active-low switches)\ngripper_byte =",
                    1,
                )
                .replacen(
                    "armpac_layout =",
                    "# ARMpac status bytes: \"manual\" (the vendor's manuals, Player) or \"aria\" (ARIA's ArP2Arm)\narmpac_layout =",
                    1,
                )
        )
    }

    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |m: &str| Err(ConfigError::Invalid(m.to_string()));
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !finite(&self.arm_base)
            || !finite(&self.arm_links)
            || !finite(&self.limb_offsets)
            || !finite(&self.arm_geometry_lengths)
        {
            return bad("arm values must be finite");
        }
        if self.arm_links.iter().any(|l| *l < 0.0)
            || self.arm_links[1] <= 0.0
            || self.arm_links[2] <= 0.0
        {
            return bad("arm_links must be >= 0 (L2 and L4 > 0)");
        }
        if let Err(e) = limber_services::qos::Capacity::new(self.max_clients) {
            return bad(&e.to_string());
        }
        if !(self.lift_stroke > 0.0 && self.lift_stroke.is_finite()) {
            return bad("lift_stroke must be > 0");
        }
        if !(self.lift_speed > 0.0 && self.lift_speed.is_finite()) {
            return bad("lift_speed must be > 0");
        }
        if !(self.limb_speed > 0.0 && self.limb_speed.is_finite()) {
            return bad("limb_speed must be > 0");
        }
        if !(self.vecmove_deviation > 0.0 && self.vecmove_deviation.is_finite()) {
            return bad("vecmove_deviation must be > 0");
        }
        if !(self.setpose_position_tolerance > 0.0 && self.setpose_position_tolerance <= 0.05) {
            return bad("setpose_position_tolerance must be in (0, 0.05] m");
        }
        if !(self.setpose_approach_tolerance_deg > 0.0
            && self.setpose_approach_tolerance_deg <= 10.0)
        {
            return bad("setpose_approach_tolerance_deg must be in (0, 10] degrees");
        }
        if let Some(b) = self.baud
            && !limber_p2os::BAUD_RATES.contains(&b)
        {
            return Err(ConfigError::Invalid(format!(
                "baud {b} is not a rate a P2OS controller speaks: one of 9600, 19200, 38400, 57600, 115200, or unset to try them all"
            )));
        }
        if self.tick_ms == 0 || self.tick_ms > 1000 {
            return bad("tick_ms must be 1..=1000");
        }
        if self.pulse_interval_ms < 100 {
            return bad(
                "pulse_interval_ms must be >= 100: the keep-alive PULSE goes out when nothing was sent for this long, and a shorter interval floods the link (0 would send one at every tick)",
            );
        }
        if self.arm_info_timeout_ms < 100 {
            return bad(
                "arm_info_timeout_ms must be >= 100: the robot answers ARM_INFO and CONFIG within its 100 ms cycle, and a shorter wait gives up before the answer (0 would serve neither the arm nor the gripper)",
            );
        }
        if self.autopark_s != 0 && u64::from(self.autopark_s) * 1000 <= self.pulse_interval_ms {
            return bad(
                "autopark_s must be 0 (disabled) or longer than pulse_interval_ms, or a live driver's arm parks",
            );
        }
        if self.linger_us > 10_000 {
            return bad("linger_us must be 0..=10000 (µs of polling after activity)");
        }
        if self.command_silence_ms < 150 {
            return bad("command_silence_ms must be >= 150 (a robot sends a SIP every 100 ms)");
        }
        if self.link_timeout_ms < 200 {
            return bad("link_timeout_ms must be >= 200 (a robot sends a SIP every 100 ms)");
        }
        if self.robot.is_empty()
            || !self
                .robot
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
        {
            return bad("robot must be [A-Za-z0-9_-]+");
        }
        Ok(())
    }

    /// How long the robot may have been silent when a client's command comes:
    /// `command_silence_ms`, or `link_timeout_ms` if shorter.
    pub fn command_silence(&self) -> Duration {
        Duration::from_millis(self.command_silence_ms.min(self.link_timeout_ms))
    }

    /// The loop tick.
    pub fn tick(&self) -> Duration {
        Duration::from_millis(self.tick_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linger_defaults_to_the_measured_budget_and_is_bounded() {
        let c = PioneerConfig::default();
        assert_eq!(
            u128::from(c.linger_us),
            limber_services::qos::DRIVER_LINGER.as_micros()
        );
        assert!(c.to_toml().contains("# linger_us:"));
        assert_eq!(
            PioneerConfig::from_toml("linger_us = 0").unwrap().linger_us,
            0
        );
        assert!(PioneerConfig::from_toml("linger_us = 20000").is_err());
    }

    #[test]
    fn body_gripper_is_auto_by_default_true_false_or_auto_and_nothing_else() {
        let c = PioneerConfig::default();
        assert_eq!(c.body_gripper, BodyGripper::Auto);
        let text = c.to_toml();
        assert!(text.contains("body_gripper = \"auto\""), "{text}");
        assert!(text.contains("# body_gripper:"), "{text}");
        assert_eq!(PioneerConfig::from_toml(&text).unwrap(), c);
        for (toml, want) in [
            ("body_gripper = true", BodyGripper::Fitted),
            ("body_gripper = false", BodyGripper::Absent),
            ("body_gripper = \"auto\"", BodyGripper::Auto),
        ] {
            let c = PioneerConfig::from_toml(toml).unwrap();
            assert_eq!(c.body_gripper, want, "{toml}");
            assert_eq!(PioneerConfig::from_toml(&c.to_toml()).unwrap(), c, "{toml}");
        }
        for bad in ["body_gripper = \"yes\"", "body_gripper = 1"] {
            let e = PioneerConfig::from_toml(bad).unwrap_err();
            assert!(e.to_string().contains("auto"), "{bad}: {e}");
        }
    }

    #[test]
    fn autopark_defaults_to_ten_seconds_and_is_printed_with_its_meaning() {
        let c = PioneerConfig::default();
        assert_eq!(c.autopark_s, 10);
        let text = c.to_toml();
        assert!(text.contains("autopark_s = 10"), "{text}");
        assert!(text.contains("# autopark_s:"), "{text}");
        assert_eq!(PioneerConfig::from_toml(&text).unwrap(), c);
    }

    #[test]
    fn autopark_must_be_off_or_longer_than_the_keep_alive() {
        assert_eq!(
            PioneerConfig::from_toml("autopark_s = 0")
                .unwrap()
                .autopark_s,
            0
        );
        let e = PioneerConfig::from_toml("autopark_s = 1\npulse_interval_ms = 1000").unwrap_err();
        assert!(e.to_string().contains("autopark_s"), "{e}");
        assert!(PioneerConfig::from_toml("autopark_s = 70000").is_err());
    }

    #[test]
    fn a_zero_keep_alive_or_arm_info_wait_is_refused_with_its_reason() {
        for (bad, key) in [
            ("pulse_interval_ms = 0", "pulse_interval_ms"),
            ("pulse_interval_ms = 99", "pulse_interval_ms"),
            ("arm_info_timeout_ms = 0", "arm_info_timeout_ms"),
            ("arm_info_timeout_ms = 50", "arm_info_timeout_ms"),
        ] {
            let e = PioneerConfig::from_toml(bad).unwrap_err();
            assert!(e.to_string().contains(key), "{bad}: {e}");
            assert!(e.to_string().contains(">= 100"), "{bad}: {e}");
        }
        let c = PioneerConfig::from_toml("pulse_interval_ms = 100\narm_info_timeout_ms = 100");
        assert!(c.is_ok(), "{c:?}");
    }

    #[test]
    fn setpose_tolerances_default_to_a_millimetre_and_a_degree_and_are_checked() {
        let c = PioneerConfig::default();
        assert_eq!(c.setpose_position_tolerance, 0.001);
        assert_eq!(c.setpose_approach_tolerance_deg, 1.0);
        let text = c.to_toml();
        assert!(text.contains("# SETPOSE: position"), "{text}");
        let c = PioneerConfig::from_toml(
            "setpose_position_tolerance = 0.0005\nsetpose_approach_tolerance_deg = 0.5",
        )
        .unwrap();
        assert_eq!(c.setpose_position_tolerance, 0.0005);
        for bad in [
            "setpose_position_tolerance = 0.0",
            "setpose_position_tolerance = nan",
            "setpose_approach_tolerance_deg = -1.0",
            "setpose_approach_tolerance_deg = 45.0",
        ] {
            let e = PioneerConfig::from_toml(bad).unwrap_err();
            assert!(e.to_string().contains("setpose_"), "{bad}: {e}");
        }
    }
}
