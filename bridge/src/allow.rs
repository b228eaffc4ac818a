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
    /// The commands that pass; `None`: every command.
    pub commands: Option<Vec<CommandKind>>,
    /// Refuse every command and every request that changes a device (power, brakes,
    /// speed, ...); reading the state and read-only requests (geometry) pass.
    pub read_only: bool,
}

impl Allow {
    /// Whether `device` is exposed.
    pub fn device(&self, device: &DeviceName) -> bool {
        self.devices.is_empty() || self.devices.iter().any(|p| p.matches(device))
    }

    /// Whether a command of `kind` to a device of `interface` passes.
    pub fn command(&self, interface: InterfaceKind, kind: u32) -> bool {
        !self.read_only
            && self.commands.as_ref().is_none_or(|list| {
                list.iter()
                    .any(|c| c.interface == interface && c.kind == kind)
            })
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

/// The command kinds of `interface`: (lower-case name, code), from the layout manifest.
fn kinds(interface: InterfaceKind) -> Vec<(String, u32)> {
    let group = format!("{}_CMD", interface.name().to_ascii_uppercase());
    limber_interfaces::manifest()
        .constants
        .iter()
        .filter(|g| g.name == group)
        .flat_map(|g| g.constants.iter())
        .filter_map(|c| Some((c.name.to_ascii_lowercase(), u32::try_from(c.value).ok()?)))
        .collect()
}

impl std::str::FromStr for CommandKind {
    type Err = AllowError;
    /// `interface:kind`, e.g. `actarray:pos`, `gripper:open` (the names of the layout
    /// manifest's `*_CMD` constants, any case).
    fn from_str(s: &str) -> Result<Self, AllowError> {
        let unknown = || AllowError::Command {
            given: s.to_string(),
            known: InterfaceKind::ALL
                .iter()
                .flat_map(|i| kinds(*i).into_iter().map(move |(n, _)| format!("{i}:{n}")))
                .collect::<Vec<_>>()
                .join(", "),
        };
        let (interface, kind) = s.split_once(':').ok_or_else(unknown)?;
        let interface = InterfaceKind::from_name(interface).ok_or_else(unknown)?;
        let kind = kind.to_ascii_lowercase();
        kinds(interface)
            .into_iter()
            .find(|(n, _)| *n == kind)
            .map(|(_, code)| CommandKind {
                interface,
                kind: code,
            })
            .ok_or_else(unknown)
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
            read_only: false,
        };
        assert!(allow.device(&arm) && !allow.device(&lift));
        assert!(allow.command(InterfaceKind::ActArray, 1));
        assert!(!allow.command(InterfaceKind::ActArray, 5));
        assert!(
            !Allow {
                read_only: true,
                ..Allow::default()
            }
            .command(InterfaceKind::ActArray, 1)
        );
    }
}
