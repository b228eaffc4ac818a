//! Device addresses: limber's `robot/interface/index` to Player's `interface:index`.
//!
//! By default a device keeps its limber index (`pioneer/actarray/0` is `actarray:0`, the
//! arm; `pioneer/gripper/0` is `gripper:0`, the body gripper; the lift
//! `pioneer/actarray/1` is `actarray:1`); when two robots of a domain have the same
//! interface and index, the device whose name sorts later takes the lowest index still
//! free. `--map DEVICE=interface:index` ([`MapEntry`]) fixes a device's address first, e.g.
//! `--map pioneer/actarray/1=actarray:0` for playerjoy, which moves the lift as
//! `actarray:0` joint 0 (the arm then moves to the lowest free index, `actarray:1`).
//! A ranger is Player's `laser` (`pioneer/ranger/0` is `laser:0`;
//! `--map simarm/ranger/0=laser:1`).

use std::collections::BTreeSet;
use std::str::FromStr;

use limber_interfaces::InterfaceKind;
use limber_services::{DeviceInfo, DeviceName};
use thiserror::Error;

use crate::translate::{player_code, player_name};

/// A `--map` entry could not be read.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MapError {
    /// Not `DEVICE=interface:index`.
    #[error("{0:?}: expected DEVICE=interface:index, e.g. pioneer/actarray/1=actarray:0")]
    Syntax(String),
    /// The device name is not `robot/interface/index`.
    #[error("{entry:?}: {source}")]
    Device {
        /// The entry.
        entry: String,
        /// Why.
        #[source]
        source: limber_services::NameError,
    },
    /// The Player interface is not the device's.
    #[error("{entry:?}: a {device} device is Player's {expected} interface, not {player}")]
    Interface {
        /// The entry.
        entry: String,
        /// The device's interface.
        device: InterfaceKind,
        /// The Player interface it is shown as.
        expected: &'static str,
        /// The Player interface named.
        player: String,
    },
}

/// One fixed address: `DEVICE=interface:index`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MapEntry {
    /// The limber device.
    pub device: DeviceName,
    /// Its Player index.
    pub index: u16,
}

impl FromStr for MapEntry {
    type Err = MapError;
    fn from_str(s: &str) -> Result<Self, MapError> {
        let syntax = || MapError::Syntax(s.to_string());
        let (dev, addr) = s.split_once('=').ok_or_else(syntax)?;
        let (iface, index) = addr.split_once(':').ok_or_else(syntax)?;
        let index: u16 = index.parse().map_err(|_| syntax())?;
        let device: DeviceName = dev.parse().map_err(|e| MapError::Device {
            entry: s.to_string(),
            source: e,
        })?;
        if player_name(device.interface()) != iface {
            return Err(MapError::Interface {
                entry: s.to_string(),
                device: device.interface(),
                expected: player_name(device.interface()),
                player: iface.to_string(),
            });
        }
        Ok(MapEntry { device, index })
    }
}

/// A device with its Player index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mapped {
    /// The device.
    pub info: DeviceInfo,
    /// Player's index of it.
    pub index: u16,
}

impl Mapped {
    /// Player's interface code.
    pub fn interf(&self) -> u16 {
        player_code(self.info.interface())
    }
}

/// Gives every device of `devices` (sorted by name, as discovery lists them) its Player
/// index: the fixed entries first, then each device its own index when free, else the
/// lowest free one. Devices whose interface `served` refuses are left out.
pub fn assign(
    devices: &[DeviceInfo],
    fixed: &[MapEntry],
    served: impl Fn(InterfaceKind) -> bool,
) -> Vec<Mapped> {
    let mut taken: BTreeSet<(u16, u16)> = BTreeSet::new();
    let mut out: Vec<Mapped> = Vec::new();
    let candidates: Vec<&DeviceInfo> = devices
        .iter()
        .filter(|d| d.alive && served(d.interface()))
        .collect();
    let mut rest = Vec::new();
    for d in &candidates {
        let code = player_code(d.interface());
        match fixed.iter().find(|e| e.device == d.name) {
            Some(e) if taken.insert((code, e.index)) => out.push(Mapped {
                info: (*d).clone(),
                index: e.index,
            }),
            _ => rest.push(*d),
        }
    }
    for d in rest {
        let code = player_code(d.interface());
        let own = d.name.index();
        let index = if !taken.contains(&(code, own)) {
            own
        } else {
            (0..=u16::MAX)
                .find(|i| !taken.contains(&(code, *i)))
                .unwrap_or(u16::MAX)
        };
        taken.insert((code, index));
        out.push(Mapped {
            info: d.clone(),
            index,
        });
    }
    out.sort_by_key(|m| (m.interf(), m.index));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dev(name: &str) -> DeviceInfo {
        DeviceInfo {
            name: name.parse().expect("a name"),
            driver: "pioneer".into(),
            layout: String::new(),
            alive: true,
            nodes: 1,
        }
    }

    fn find(m: &[Mapped], name: &str) -> u16 {
        m.iter()
            .find(|x| x.info.name.to_string() == name)
            .map(|x| x.index)
            .expect("mapped")
    }

    #[test]
    fn devices_keep_their_index_and_collisions_take_the_next_free_one() {
        let devices = [
            dev("pioneer/actarray/0"),
            dev("pioneer/actarray/1"),
            dev("pioneer/gripper/0"),
            dev("simarm/actarray/0"),
        ];
        let m = assign(&devices, &[], |_| true);
        assert_eq!(find(&m, "pioneer/actarray/0"), 0);
        assert_eq!(find(&m, "pioneer/actarray/1"), 1);
        assert_eq!(find(&m, "pioneer/gripper/0"), 0);
        assert_eq!(find(&m, "simarm/actarray/0"), 2);
    }

    #[test]
    fn a_fixed_entry_goes_first() {
        let devices = [dev("pioneer/actarray/0"), dev("pioneer/actarray/1")];
        let e: MapEntry = "pioneer/actarray/1=actarray:0".parse().expect("an entry");
        let m = assign(&devices, &[e], |_| true);
        assert_eq!(find(&m, "pioneer/actarray/1"), 0);
        assert_eq!(find(&m, "pioneer/actarray/0"), 1);
    }

    #[test]
    fn a_ranger_is_players_laser() {
        let devices = [dev("pioneer/ranger/0"), dev("simarm/ranger/0")];
        let e: MapEntry = "simarm/ranger/0=laser:0".parse().expect("an entry");
        let m = assign(&devices, &[e], |_| true);
        assert_eq!(find(&m, "simarm/ranger/0"), 0);
        assert_eq!(find(&m, "pioneer/ranger/0"), 1);
        assert!(m.iter().all(|x| x.interf() == 6));
        assert!(matches!(
            "pioneer/ranger/0=ranger:0".parse::<MapEntry>(),
            Err(MapError::Interface {
                expected: "laser",
                ..
            })
        ));
    }

    #[test]
    fn bad_entries_are_refused() {
        assert!(matches!(
            "pioneer/actarray/1".parse::<MapEntry>(),
            Err(MapError::Syntax(_))
        ));
        assert!(matches!(
            "pioneer/actarray/1=gripper:0".parse::<MapEntry>(),
            Err(MapError::Interface { .. })
        ));
        assert!(matches!(
            "nonsense=actarray:0".parse::<MapEntry>(),
            Err(MapError::Device { .. })
        ));
    }
}
