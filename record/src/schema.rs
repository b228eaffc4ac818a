//! The schemas written with each channel: limber's wire structs described by the layout
//! manifest, and Foxglove's well-known `foxglove.JointStates` (JSON) for actuator arrays.

use core::any::{Any, TypeId};

use limber_interfaces::actarray::ActArrayData;
use limber_interfaces::manifest::StructLayout;
use serde_json::{Value, json};

/// The schema text of wire struct `root`: `{"layout_version", "root", "structs"}` with
/// `root` and every struct its fields use (dependencies first), each as `limber layout
/// --json` prints it.
pub fn layout_schema(root: &StructLayout) -> String {
    let manifest = limber_interfaces::manifest();
    let mut order: Vec<&StructLayout> = Vec::new();
    fn visit<'m>(
        s: &'m StructLayout,
        m: &'m limber_interfaces::Manifest,
        order: &mut Vec<&'m StructLayout>,
    ) {
        if order.iter().any(|o| o.name == s.name) {
            return;
        }
        for f in s.fields {
            if let Some(dep) = m.find(f.ty) {
                visit(dep, m, order);
            }
        }
        order.push(s);
    }
    match manifest.find(root.name) {
        Some(s) => visit(s, &manifest, &mut order),
        None => order.push(root),
    }
    json!({
        "layout_version": manifest.layout_version,
        "root": root.name,
        "structs": order,
    })
    .to_string()
}

/// The schema name of Foxglove's joint states.
pub const JOINT_STATES: &str = "foxglove.JointStates";

/// The JSON Schema of `foxglove.JointStates` (Foxglove's well-known schema: a timestamp
/// and one `{name, position, velocity, effort}` per joint).
pub fn joint_states_schema() -> String {
    json!({
        "title": JOINT_STATES,
        "description": "The state of a set of joints at a given time",
        "type": "object",
        "properties": {
            "timestamp": {
                "type": "object",
                "properties": {
                    "sec": {"type": "integer", "minimum": 0},
                    "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}
                }
            },
            "joints": {
                "type": "array",
                "items": {
                    "type": "object",
                    "properties": {
                        "name": {"type": "string"},
                        "position": {"type": "number"},
                        "velocity": {"type": "number"},
                        "acceleration": {"type": "number"},
                        "effort": {"type": "number"}
                    }
                }
            }
        }
    })
    .to_string()
}

/// The name of joint `i` in `foxglove.JointStates` and in the URDF limber serves.
pub fn joint_name(i: usize) -> String {
    format!("j{i}")
}

/// The joints of a state, as (position, speed) per joint: an actuator array's actuators;
/// `None` for a state without joints. The one place that tells the interface with joints
/// apart, so that the recorder and the viewer stay generic over the interface.
pub fn joints_of<D: 'static>(d: &D) -> Option<Vec<(f64, f64)>> {
    (d as &dyn Any).downcast_ref::<ActArrayData>().map(|a| {
        a.actuators()
            .iter()
            .map(|x| (x.position, x.speed))
            .collect()
    })
}

/// Whether states of type `D` have joints ([`joints_of`]).
pub fn has_joints<D: 'static>() -> bool {
    TypeId::of::<D>() == TypeId::of::<ActArrayData>()
}

/// Joints as `foxglove.JointStates` (`stamp_ns` since the Unix epoch): positions and
/// speeds (limber's currents are no efforts, and -1 means "unknown" in its accelerations:
/// both are left out, as the schema allows).
pub fn joint_states(joints: &[(f64, f64)], stamp_ns: u64) -> Value {
    json!({
        "timestamp": {"sec": stamp_ns / 1_000_000_000, "nsec": stamp_ns % 1_000_000_000},
        "joints": joints.iter().enumerate().map(|(i, (position, speed))| json!({
            "name": joint_name(i),
            "position": position,
            "velocity": speed,
        })).collect::<Vec<_>>(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use limber_interfaces::WireStruct;

    #[test]
    fn a_state_schema_names_its_struct_and_every_struct_it_uses() {
        let s: Value = serde_json::from_str(&layout_schema(&ActArrayData::LAYOUT)).unwrap();
        assert_eq!(s["root"], "ActArrayData");
        let names: Vec<&str> = s["structs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["name"].as_str().unwrap())
            .collect();
        assert_eq!(names.last(), Some(&"ActArrayData"));
        assert!(names.contains(&"StateHeader"), "{names:?}");
        // Dependencies first.
        let pos = |n: &str| names.iter().position(|x| *x == n).unwrap();
        assert!(pos("StateHeader") < pos("ActArrayData"));
    }
}
