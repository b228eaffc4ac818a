//! What an exposing bridge lets through: which devices, which commands, and whether
//! requests that change a device pass.

use limber_interfaces::InterfaceKind;
use limber_services::DeviceName;
use thiserror::Error;

/// The allow-list of an exposing bridge. The default lets everything through.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Allow {
    /// Device patterns (`robot/interface/index`, each part a name or `*`); empty: every
    /// device.
    pub devices: Vec<DevicePattern>,
    /// The commands that pass; `None`: every command (unless `requests` is a list: then
    /// none).
    pub commands: Option<Vec<CommandKind>>,
    /// The requests that change a device (power, brakes, speed, ...) that pass; `None`:
    /// every one (unless `commands` is a list: then none). Read-only requests (geometry,
    /// reach) always pass.
    pub requests: Option<Vec<RequestKind>>,
    /// Refuse every command and every request that changes a device (power, brakes,
    /// speed, ...); reading the state and read-only requests (geometry) pass.
    pub read_only: bool,
}

impl Allow {
    /// Whether `device` is exposed.
    pub fn device(&self, device: &DeviceName) -> bool {
        self.devices.is_empty() || self.devices.iter().any(|p| p.matches(device))
    }

    /// Whether the bridge lets through only what its lists name (`--allow-command`,
    /// `--allow-request`): then neither leases nor anything unlisted pass.
    pub fn filtered(&self) -> bool {
        self.commands.is_some() || self.requests.is_some()
    }

    /// Whether a command of `kind` to a device of `interface` passes.
    pub fn command(&self, interface: InterfaceKind, kind: u32) -> bool {
        !self.read_only
            && (!self.filtered()
                || self.commands.as_ref().is_some_and(|list| {
                    list.iter()
                        .any(|c| c.interface == interface && c.kind == kind)
                }))
    }

    /// Whether a request of `kind` to a device of `interface` passes: a read-only one
    /// (`read_only`: geometry, reach) always; one that changes the device by the same rule
    /// as a command, from the list of requests.
    pub fn request(&self, interface: InterfaceKind, kind: u32, read_only: bool) -> bool {
        read_only
            || (!self.read_only
                && (!self.filtered()
                    || self.requests.as_ref().is_some_and(|list| {
                        list.iter()
                            .any(|r| r.0.interface == interface && r.0.kind == kind)
                    })))
    }
}

/// A device pattern: `robot/interface/index`, each part a name or `*`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DevicePattern {
    parts: [String; 3],
}

impl DevicePattern {
    /// Whether `device` matches.
    pub fn matches(&self, device: &DeviceName) -> bool {
        let name = [
            device.robot().to_string(),
            device.interface().name().to_string(),
            device.index().to_string(),
        ];
        self.parts
            .iter()
            .zip(name.iter())
            .all(|(p, n)| p == "*" || p == n)
    }
}

/// A pattern or command name could not be parsed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum AllowError {
    /// A device pattern is not three parts.
    #[error("invalid device pattern {0:?}: use robot/interface/index, each part a name or *")]
    Pattern(String),
    /// A command is not `interface:kind`, or names no command of that interface.
    #[error("unknown command {given:?}: use interface:kind, one of {known}")]
    Command {
        /// What was given.
        given: String,
        /// The commands there are.
        known: String,
    },
    /// A request is not `interface:kind`, or names no request of that interface.
    #[error("unknown request {given:?}: use interface:kind, one of {known}")]
    Request {
        /// What was given.
        given: String,
        /// The requests there are.
        known: String,
    },
}

impl std::str::FromStr for DevicePattern {
    type Err = AllowError;
    fn from_str(s: &str) -> Result<Self, AllowError> {
        let parts: Vec<&str> = s.split('/').collect();
        let [robot, interface, index] = parts[..] else {
            return Err(AllowError::Pattern(s.to_string()));
        };
        let ok = |p: &str| !p.is_empty();
        if !(ok(robot) && ok(index))
            || !(interface == "*" || InterfaceKind::from_name(interface).is_some())
        {
            return Err(AllowError::Pattern(s.to_string()));
        }
        Ok(DevicePattern {
            parts: [robot.to_string(), interface.to_string(), index.to_string()],
        })
    }
}

/// A command of one interface (a `*_CMD` kind code of the layout manifest).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommandKind {
    /// The interface.
    pub interface: InterfaceKind,
    /// The kind code.
    pub kind: u32,
}

/// A request of one interface that changes the device (a `*_REQ` kind code of the layout
/// manifest), for `--allow-request`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RequestKind(pub CommandKind);

/// The kinds of `interface` in its manifest group `<INTERFACE>_<suffix>`: (lower-case name,
/// code).
fn kinds_of(interface: InterfaceKind, suffix: &str) -> Vec<(String, u32)> {
    let group = format!("{}_{suffix}", interface.name().to_ascii_uppercase());
    limber_interfaces::manifest()
        .constants
        .iter()
        .filter(|g| g.name == group)
        .flat_map(|g| g.constants.iter())
        .filter_map(|c| Some((c.name.to_ascii_lowercase(), u32::try_from(c.value).ok()?)))
        .collect()
}

/// `interface:kind` of the manifest's `<INTERFACE>_<suffix>` group (`CMD`, `REQ`): the
/// kind, or the list of every `interface:kind` there is (for the error).
fn parse_kind(s: &str, suffix: &str) -> Result<CommandKind, String> {
    let unknown = || {
        InterfaceKind::ALL
            .iter()
            .flat_map(|i| {
                kinds_of(*i, suffix)
                    .into_iter()
                    .map(move |(n, _)| format!("{i}:{n}"))
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (interface, kind) = s.split_once(':').ok_or_else(unknown)?;
    let interface = InterfaceKind::from_name(interface).ok_or_else(unknown)?;
    let kind = kind.to_ascii_lowercase();
    kinds_of(interface, suffix)
        .into_iter()
        .find(|(n, _)| *n == kind)
        .map(|(_, code)| CommandKind {
            interface,
            kind: code,
        })
        .ok_or_else(unknown)
}

impl std::str::FromStr for RequestKind {
    type Err = AllowError;
    /// `interface:kind`, e.g. `actarray:power`, `limb:speed` (the names of the layout
    /// manifest's `*_REQ` constants, any case).
    fn from_str(s: &str) -> Result<Self, AllowError> {
        parse_kind(s, "REQ")
            .map(RequestKind)
            .map_err(|known| AllowError::Request {
                given: s.to_string(),
                known,
            })
    }
}

impl std::str::FromStr for CommandKind {
    type Err = AllowError;
    /// `interface:kind`, e.g. `actarray:pos`, `gripper:open` (the names of the layout
    /// manifest's `*_CMD` constants, any case).
    fn from_str(s: &str) -> Result<Self, AllowError> {
        parse_kind(s, "CMD").map_err(|known| AllowError::Command {
            given: s.to_string(),
            known,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_and_commands_parse_and_match() {
        let arm: DeviceName = "pioneer/actarray/0".parse().unwrap();
        let lift: DeviceName = "pioneer/actarray/1".parse().unwrap();
        let p: DevicePattern = "pioneer/actarray/0".parse().unwrap();
        assert!(p.matches(&arm) && !p.matches(&lift));
        let p: DevicePattern = "*/actarray/*".parse().unwrap();
        assert!(p.matches(&arm) && p.matches(&lift));
        assert!("pioneer/arm/0".parse::<DevicePattern>().is_err());
        assert!("pioneer/actarray".parse::<DevicePattern>().is_err());

        let pos: CommandKind = "actarray:POS".parse().unwrap();
        assert_eq!(pos.interface, InterfaceKind::ActArray);
        assert_eq!(pos.kind, 1);
        let e = "actarray:fly".parse::<CommandKind>().unwrap_err();
        assert!(e.to_string().contains("gripper:open"), "{e}");

        let allow = Allow {
            devices: vec!["*/actarray/0".parse().unwrap()],
            commands: Some(vec![pos]),
            requests: None,
            read_only: false,
        };
        assert!(allow.device(&arm) && !allow.device(&lift));
        assert!(allow.command(InterfaceKind::ActArray, 1));
        assert!(!allow.command(InterfaceKind::ActArray, 5));
        // A bridge that lets POS alone through lets no request that changes the arm
        // through (POWER, SPEED): only read-only ones.
        let power: RequestKind = "actarray:power".parse().unwrap();
        assert!(!allow.request(InterfaceKind::ActArray, power.0.kind, false));
        assert!(allow.request(InterfaceKind::ActArray, power.0.kind, true));
        let with_power = Allow {
            requests: Some(vec![power]),
            ..allow.clone()
        };
        assert!(with_power.request(InterfaceKind::ActArray, power.0.kind, false));
        let e = "actarray:fly".parse::<RequestKind>().unwrap_err();
        assert!(e.to_string().contains("actarray:power"), "{e}");
        // A list of requests alone lets no command through.
        let requests_only = Allow {
            commands: None,
            requests: Some(vec![power]),
            ..Allow::default()
        };
        assert!(!requests_only.command(InterfaceKind::ActArray, 1));
        assert!(Allow::default().request(InterfaceKind::ActArray, power.0.kind, false));
        assert!(
            !Allow {
                read_only: true,
                ..Allow::default()
            }
            .command(InterfaceKind::ActArray, 1)
        );
    }
}
