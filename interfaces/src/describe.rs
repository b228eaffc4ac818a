//! How a state reads for people and scripts: one line of text ([`Describe::human`], what
//! `limber echo` and the monitor print) and one JSON object ([`Describe::json`], what
//! `limber echo --json` prints). Each interface's state implements it next to its layout,
//! so every generic consumer (the CLI, the monitor, a recorder) prints any interface without
//! naming it.

use serde_json::{Value, json};

use crate::actarray::{ActArrayData, ActuatorFlags};
use crate::common::{StateHeader, Status, device_flag};
use crate::gripper::{GripperData, GripperState};
use crate::limb::{LimbData, LimbState};
use crate::ranger::RangerData;

/// A state that can be printed: one human-readable line, one JSON object.
pub trait Describe {
    /// One human-readable line.
    fn human(&self) -> String;
    /// One JSON object (the schema of `limber echo --json`, docs/reference/echo-json.md): the fields
    /// of the state's C struct (limber.h) by their names, with their values (codes as
    /// numbers, vectors as `{"x", "y", "z"}`, the `actuators` array cut to
    /// `actuators_count`), and beside each code its name (`state_name`, `status_name`).
    fn json(&self) -> Value;
}

/// The JSON of a state header (`"header"` of every state): the fields of
/// `limber_state_header` by their C names and values, and beside them what they mean
/// (`link_up`, `calibrated` from `flags`; `status_name` of `last_cmd.status`).
pub fn header_json(h: &StateHeader) -> Value {
    json!({
        "seq": h.seq,
        "stamp_ns": h.stamp_ns,
        "last_cmd": {
            "client_id": h.last_cmd.client_id,
            "cmd_seq": h.last_cmd.cmd_seq,
            "kind": h.last_cmd.kind,
            "status": h.last_cmd.status,
            "status_name": Status::try_from(h.last_cmd.status).map_or("UNKNOWN", Status::name),
        },
        "flags": h.flags,
        "cmd_overflows": h.cmd_overflows,
        "link_up": h.flags & device_flag::LINK_UP != 0,
        "calibrated": h.flags & device_flag::CALIBRATED != 0,
    })
}

/// A `limber_vec3` as JSON: `{"x", "y", "z"}`.
fn vec3_json(v: crate::common::Vec3) -> Value {
    json!({"x": v.x, "y": v.y, "z": v.z})
}

/// The start of every human line: the sequence number, a link that is down, and the last
/// command's outcome when it was not a plain OK.
pub fn header_human(h: &StateHeader) -> String {
    let mut s = format!("#{:<6}", h.seq);
    if h.flags & device_flag::LINK_UP == 0 && h.flags != 0 {
        s.push_str(" LINK DOWN");
    }
    if h.last_cmd.client_id != 0 && h.last_cmd.status != 0 {
        match Status::try_from(h.last_cmd.status) {
            // "ok, clamped to the limit", "ok, orientation adjusted": carried out.
            Ok(st) if st.is_carried_out() => {
                s.push_str(&format!(" [last command: {st}]"));
            }
            Ok(st) => {
                s.push_str(&format!(" [last command refused: {st}]"));
            }
            Err(_) => s.push_str(" [last command refused: ?]"),
        }
    }
    s
}

/// The name of an actuator's state bits: `stalled`, `moving`, `braked`, `idle`, `-`, `?`.
pub fn actuator_state_name(bits: u32) -> &'static str {
    match ActuatorFlags::from_bits(bits) {
        Some(f) if f.contains(ActuatorFlags::STALLED) => "stalled",
        Some(f) if f.contains(ActuatorFlags::MOVING) => "moving",
        Some(f) if f.contains(ActuatorFlags::BRAKED) => "braked",
        Some(f) if f.contains(ActuatorFlags::IDLE) => "idle",
        Some(_) => "-",
        None => "?",
    }
}

impl Describe for ActArrayData {
    fn human(&self) -> String {
        let mut s = header_human(&self.header);
        s.push_str(&format!(
            " power {}",
            if self.motor_state != 0 { "on " } else { "off" }
        ));
        for (i, a) in self.actuators().iter().enumerate() {
            s.push_str(&format!(
                " | j{i} {:+.4} {}",
                a.position,
                actuator_state_name(a.state)
            ));
        }
        if self.trajectory.active == 1 {
            let t = &self.trajectory;
            s.push_str(&format!(
                " | trajectory point {}/{} max error {:.4}{}",
                t.point.min(t.points),
                t.points,
                t.max_error,
                if t.scale == 0.0 { " paused" } else { "" }
            ));
        }
        s
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "motor_state": self.motor_state,
            "actuators_count": self.actuators_count,
            "actuators": self.actuators().iter().map(|a| json!({
                "position": a.position,
                "speed": a.speed,
                "acceleration": a.acceleration,
                "current": a.current,
                "state": a.state,
                "state_name": actuator_state_name(a.state),
            })).collect::<Vec<_>>(),
            "trajectory": {
                "active": self.trajectory.active,
                "point": self.trajectory.point,
                "points": self.trajectory.points,
                "result": self.trajectory.result,
                "max_error": self.trajectory.max_error,
                "time": self.trajectory.time,
                "scale": self.trajectory.scale,
            },
        })
    }
}

/// The name of a limb state: `idle`, `braked`, `moving`, `out-of-reach`, `collision`, `?`.
pub fn limb_state_name(v: u32) -> &'static str {
    match LimbState::try_from(v) {
        Ok(LimbState::Idle) => "idle",
        Ok(LimbState::Braked) => "braked",
        Ok(LimbState::Moving) => "moving",
        Ok(LimbState::OutOfReach) => "out-of-reach",
        Ok(LimbState::Collision) => "collision",
        Err(_) => "?",
    }
}

impl Describe for LimbData {
    fn human(&self) -> String {
        let (p, a, o) = (self.position, self.approach, self.orientation);
        let adjusted = if self.orientation_adjustment > 0.0 {
            format!(
                " (orientation adjusted by {:.6} rad)",
                self.orientation_adjustment
            )
        } else {
            String::new()
        };
        let path = match limb_path_name(self.path_kind) {
            Some(kind) => format!(" {kind} {:.0}%", self.path_progress * 100.0),
            None => String::new(),
        };
        let refused = if let Some(kind) = limb_path_name(self.refused_kind) {
            let r = self.refused_at;
            format!(
                " ({kind} refused at {:.0}%, ({:+.4}, {:+.4}, {:+.4}))",
                self.refused_fraction * 100.0,
                r.x,
                r.y,
                r.z
            )
        } else {
            String::new()
        };
        format!(
            "{} {:<12} pos ({:+.4}, {:+.4}, {:+.4}) approach ({:+.3}, {:+.3}, {:+.3}) orient ({:+.3}, {:+.3}, {:+.3}){adjusted}{path}{refused}",
            header_human(&self.header),
            limb_state_name(self.state),
            p.x,
            p.y,
            p.z,
            a.x,
            a.y,
            a.z,
            o.x,
            o.y,
            o.z
        )
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "position": vec3_json(self.position),
            "approach": vec3_json(self.approach),
            "orientation": vec3_json(self.orientation),
            "state": self.state,
            "state_name": limb_state_name(self.state),
            "orientation_adjustment": self.orientation_adjustment,
            "path_kind": self.path_kind,
            "path_kind_name": limb_path_name(self.path_kind),
            "path_progress": self.path_progress,
            "refused_kind": self.refused_kind,
            "refused_kind_name": limb_path_name(self.refused_kind),
            "refused_at": vec3_json(self.refused_at),
            "refused_fraction": self.refused_fraction,
        })
    }
}

/// The name of a running limb path (`LimbData::path_kind`): `line`, `ptp`; `None` if none.
pub fn limb_path_name(kind: u32) -> Option<&'static str> {
    match kind {
        crate::limb::cmd::LINE => Some("line"),
        crate::limb::cmd::PTP => Some("ptp"),
        _ => None,
    }
}

/// The name of a gripper state: `open`, `closed`, `moving`, `error`, `?`.
pub fn gripper_state_name(v: u32) -> &'static str {
    match GripperState::try_from(v) {
        Ok(GripperState::Open) => "open",
        Ok(GripperState::Closed) => "closed",
        Ok(GripperState::Moving) => "moving",
        Ok(GripperState::Error) => "error",
        Err(_) => "?",
    }
}

impl Describe for GripperData {
    fn human(&self) -> String {
        format!(
            "{} {:<7} beams {:#06b} stored {}",
            header_human(&self.header),
            gripper_state_name(self.state),
            self.beams,
            self.stored
        )
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "state": self.state,
            "state_name": gripper_state_name(self.state),
            "beams": self.beams,
            "stored": self.stored,
        })
    }
}

impl Describe for RangerData {
    /// The number of ranges, the closest one with its bearing, and the field of view.
    fn human(&self) -> String {
        let ranges = self.ranges();
        let closest = ranges
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, r)| {
                format!(
                    " closest {r:.3} m at {:+.1} deg",
                    self.bearing(i).to_degrees()
                )
            })
            .unwrap_or_default();
        format!(
            "{} {} ranges over {:+.1}..{:+.1} deg{closest}",
            header_human(&self.header),
            ranges.len(),
            self.min_angle.to_degrees(),
            self.max_angle.to_degrees(),
        )
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "min_angle": self.min_angle,
            "max_angle": self.max_angle,
            "angular_res": self.angular_res,
            "min_range": self.min_range,
            "max_range": self.max_range,
            "range_res": self.range_res,
            "frequency": self.frequency,
            "ranges_count": self.ranges_count,
            "intensities_count": self.intensities_count,
            "ranges": self.ranges(),
            "intensities": self.intensities(),
        })
    }
}
