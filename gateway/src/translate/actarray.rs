//! `actarray` (Player 53, limber `actarray`): every command (POS, MULTI_POS, SPEED,
//! MULTI_SPEED, HOME, CURRENT, MULTI_CURRENT) and request (POWER, BRAKES, GET_GEOM, SPEED,
//! ACCEL) of Player 3, one to one with limber's of the same numbers; positions, speeds and
//! currents as `f32` on Player's side, `f64` on limber's.
//!
//! An array of one linear actuator (the Pioneer's lift) is shown normalised when
//! [`Conventions::normalise_lift`] says so: 0 at its lower limit and 1 at its upper one,
//! as Player's p2os driver shows the lift (and playerjoy moves it, `MoveTo(0, 1.0)` up).

use limber_interfaces::actarray::{cmd, req};
use limber_interfaces::prelude::*;
use limber_services::{DeviceClient, Ticket};

use super::{
    Conventions, MessageError, PlayerDevice, Translator, empty, in_tables, on_off, typed, unknown,
};
use crate::header::msg_type;
use crate::xdr::{XdrReader, XdrWriter};

/// The actarray translator.
pub static ACTARRAY: ActArrayTranslator = ActArrayTranslator;

/// Translates `actarray`.
#[derive(Debug)]
pub struct ActArrayTranslator;

const CMDS: [u8; 7] = [1, 2, 3, 4, 5, 6, 7];
const REQS: [u8; 5] = [1, 2, 3, 4, 5];

/// The affine map of a normalised actuator: `metres = min + player * range`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// The lower limit, m.
    pub min: f64,
    /// Upper minus lower limit, m (> 0).
    pub range: f64,
}

impl Scale {
    /// The normalisation of `geom`, when it is one linear actuator with a travel.
    pub fn of(geom: &ActArrayGeom) -> Option<Scale> {
        let a = geom.actuators.first()?;
        let range = a.max - a.min;
        (geom.actuators_count == 1
            && a.kind == ActuatorKind::Linear as u32
            && range.is_finite()
            && range > 0.0)
            .then_some(Scale { min: a.min, range })
    }
    fn limber_to_player(self, metres: f64) -> f64 {
        (metres - self.min) / self.range
    }
    fn player_to_limber(self, v: f64) -> f64 {
        self.min + v * self.range
    }
}

impl Translator for ActArrayTranslator {
    fn kind(&self) -> InterfaceKind {
        InterfaceKind::ActArray
    }
    fn open(&self, mut dev: Box<dyn DeviceClient>, conv: Conventions) -> Box<dyn PlayerDevice> {
        let scale = if conv.normalise_lift {
            match dev
                .typed::<ActArray>()
                .map(|c| c.request(&ActArrayRequest::GetGeom))
            {
                Some(Ok(ActArrayReply::Geom(g))) => Scale::of(&g),
                Some(Ok(ActArrayReply::Done)) | None => None,
                Some(Err(e)) => {
                    tracing::warn!(device = %dev.device(), error = %e,
                        "no geometry: positions are shown in metres or radians");
                    None
                }
            }
        } else {
            None
        };
        Box::new(ActArrayDevice { dev, scale })
    }
}

struct ActArrayDevice {
    dev: Box<dyn DeviceClient>,
    scale: Option<Scale>,
}

/// The DATA STATE body of `d` (`scale`: shown normalised).
pub fn data_body(d: &ActArrayData, scale: Option<Scale>) -> Vec<u8> {
    let n = (d.actuators_count as usize).min(MAX_ACTUATORS);
    let mut w = XdrWriter::new();
    w.count(n);
    for a in &d.actuators[..n] {
        let (pos, speed) = match scale {
            Some(s) => (s.limber_to_player(a.position), a.speed / s.range),
            None => (a.position, a.speed),
        };
        w.f32(pos as f32)
            .f32(speed as f32)
            .f32(a.acceleration as f32)
            .f32(a.current as f32)
            .u32(a.state);
    }
    w.u32(d.motor_state);
    w.finish()
}

/// The GET_GEOM ACK body of `g` (`scale`: shown normalised).
pub fn geom_body(g: &ActArrayGeom, scale: Option<Scale>) -> Vec<u8> {
    let n = (g.actuators_count as usize).min(MAX_ACTUATORS);
    let mut w = XdrWriter::new();
    w.count(n);
    for a in &g.actuators[..n] {
        let (min, centre, max, home, speed) = match scale {
            Some(s) => (
                s.limber_to_player(a.min),
                s.limber_to_player(a.centre),
                s.limber_to_player(a.max),
                s.limber_to_player(a.home),
                a.config_speed / s.range,
            ),
            None => (a.min, a.centre, a.max, a.home, a.config_speed),
        };
        w.u32(a.kind).f32(a.length as f32);
        w.f64(a.orientation.roll)
            .f64(a.orientation.pitch)
            .f64(a.orientation.yaw);
        super::write_vec3(&mut w, a.axis);
        w.f32(min as f32)
            .f32(centre as f32)
            .f32(max as f32)
            .f32(home as f32)
            .f32(speed as f32)
            .u32(a.has_brakes);
    }
    super::write_vec3(&mut w, g.base_pos);
    w.f64(g.base_orientation.roll)
        .f64(g.base_orientation.pitch)
        .f64(g.base_orientation.yaw);
    w.finish()
}

/// `count` f32 values of a MULTI_* command (at most [`MAX_ACTUATORS`]).
fn values(r: &mut XdrReader<'_>, field: &'static str) -> Result<Vec<f64>, MessageError> {
    let n = r.count(field, MAX_ACTUATORS, 4)?;
    (0..n)
        .map(|_| r.f32(field).map(f64::from).map_err(MessageError::from))
        .collect()
}

/// A Player actarray command as limber's (`scale`: the client speaks normalised).
pub fn command_of(
    subtype: u8,
    body: &[u8],
    scale: Option<Scale>,
) -> Result<ActArrayCommand, MessageError> {
    let pos = |v: f64| scale.map_or(v, |s| s.player_to_limber(v));
    let speed = |v: f64| scale.map_or(v, |s| v * s.range);
    let mut r = XdrReader::new(body);
    let c = match u32::from(subtype) {
        cmd::POS => {
            let j = r.i32("joint")?;
            ActArrayCommand::position(j.into(), pos(r.f32("position")?.into()))?
        }
        cmd::MULTI_POS => {
            let v: Vec<f64> = values(&mut r, "positions")?.into_iter().map(pos).collect();
            ActArrayCommand::multi_position(&v)?
        }
        cmd::SPEED => {
            let j = r.i32("joint")?;
            ActArrayCommand::speed(j.into(), speed(r.f32("speed")?.into()))?
        }
        cmd::MULTI_SPEED => {
            let v: Vec<f64> = values(&mut r, "speeds")?.into_iter().map(speed).collect();
            ActArrayCommand::multi_speed(&v)?
        }
        cmd::HOME => ActArrayCommand::home(r.i32("joint")?.into())?,
        cmd::CURRENT => {
            let j = r.i32("joint")?;
            ActArrayCommand::current(j.into(), r.f32("current")?.into())?
        }
        cmd::MULTI_CURRENT => ActArrayCommand::multi_current(&values(&mut r, "currents")?)?,
        _ => return Err(unknown(msg_type::CMD, subtype)),
    };
    r.end()?;
    Ok(c)
}

/// A Player actarray request as limber's.
pub fn request_of(
    subtype: u8,
    body: &[u8],
    scale: Option<Scale>,
) -> Result<ActArrayRequest, MessageError> {
    let mut r = XdrReader::new(body);
    let q = match u32::from(subtype) {
        req::POWER => ActArrayRequest::Power(on_off(&mut r, "power")?),
        req::BRAKES => ActArrayRequest::Brakes(on_off(&mut r, "brakes")?),
        req::GET_GEOM => {
            empty(body)?;
            ActArrayRequest::GetGeom
        }
        req::SPEED => {
            let j = r.i32("joint")?;
            let v = f64::from(r.f32("speed")?);
            ActArrayRequest::speed(j.into(), scale.map_or(v, |s| v * s.range))?
        }
        req::ACCEL => {
            let j = r.i32("joint")?;
            let v = f64::from(r.f32("accel")?);
            ActArrayRequest::accel(j.into(), scale.map_or(v, |s| v * s.range))?
        }
        _ => return Err(unknown(msg_type::REQ, subtype)),
    };
    r.end()?;
    Ok(q)
}

impl PlayerDevice for ActArrayDevice {
    fn client(&mut self) -> &mut dyn DeviceClient {
        self.dev.as_mut()
    }
    fn client_ref(&self) -> &dyn DeviceClient {
        self.dev.as_ref()
    }
    fn data(&self) -> Option<Vec<u8>> {
        let c = self.dev.typed_ref::<ActArray>()?;
        c.last_state().map(|d| data_body(d, self.scale))
    }
    fn command(&mut self, subtype: u8, body: &[u8]) -> Result<Ticket, MessageError> {
        let c = command_of(subtype, body, self.scale)?;
        Ok(typed::<ActArray>(self.dev.as_mut())?.send(&c)?)
    }
    fn request(&mut self, subtype: u8, body: &[u8]) -> Result<Vec<u8>, MessageError> {
        let q = request_of(subtype, body, self.scale)?;
        match typed::<ActArray>(self.dev.as_mut())?.request(&q)? {
            ActArrayReply::Geom(g) => Ok(geom_body(&g, self.scale)),
            ActArrayReply::Done => Ok(Vec::new()),
        }
    }
    fn translates(&self, mtype: u8, subtype: u8) -> bool {
        in_tables(mtype, subtype, &CMDS, &REQS)
    }
    fn changes(&self, subtype: u8) -> bool {
        u32::from(subtype) != req::GET_GEOM
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(v: &[u32]) -> Vec<u8> {
        v.iter().flat_map(|w| w.to_be_bytes()).collect()
    }

    /// Two actuators: 12 + 20 N bytes, counts twice, state and motor state widened.
    #[test]
    fn data_is_counted_twice_and_each_actuator_is_five_words() {
        let mut d = ActArrayData {
            actuators_count: 2,
            motor_state: 1,
            ..Default::default()
        };
        d.actuators[0].position = 0.5;
        d.actuators[0].state = ActuatorFlags::IDLE.bits();
        d.actuators[1].position = -1.0;
        d.actuators[1].acceleration = -1.0;
        d.actuators[1].current = -1.0;
        d.actuators[1].state = ActuatorFlags::MOVING.bits();
        let body = data_body(&d, None);
        assert_eq!(body.len(), 12 + 20 * 2);
        let mut want = words(&[2, 2]);
        want.extend(words(&[0x3F00_0000, 0, 0, 0, 1]));
        want.extend(words(&[0xBF80_0000, 0, 0xBF80_0000, 0xBF80_0000, 2]));
        want.extend(words(&[1]));
        assert_eq!(body, want);
    }

    #[test]
    fn the_geometry_is_56_plus_80_bytes_per_actuator() {
        let g = ActArrayGeom {
            actuators_count: 3,
            ..Default::default()
        };
        assert_eq!(geom_body(&g, None).len(), 56 + 80 * 3);
    }

    /// POS joint 2 to 0.5 rad: `i32 joint; f32 position`.
    #[test]
    fn commands_read_players_bytes() {
        let pos = words(&[2, 0x3F00_0000]);
        assert_eq!(
            command_of(1, &pos, None).expect("POS"),
            ActArrayCommand::position(2, 0.5).expect("valid")
        );
        let multi = words(&[2, 2, 0x3F80_0000, 0]);
        assert_eq!(
            command_of(2, &multi, None).expect("MULTI_POS"),
            ActArrayCommand::multi_position(&[1.0, 0.0]).expect("valid")
        );
        let home_all = words(&[u32::MAX]);
        assert_eq!(
            command_of(5, &home_all, None).expect("HOME"),
            ActArrayCommand::home(-1).expect("valid")
        );
        assert!(matches!(
            command_of(9, &[], None),
            Err(MessageError::Unknown { .. })
        ));
        assert!(command_of(1, &pos[..4], None).is_err());
        assert!(command_of(1, &words(&[99, 0]), None).is_err());
        assert!(request_of(1, &words(&[2]), None).is_err());
    }

    /// The lift: 0 .. 0.07 m shown as 0 .. 1.
    #[test]
    fn a_lift_is_normalised_both_ways() {
        let mut g = ActArrayGeom {
            actuators_count: 1,
            ..Default::default()
        };
        g.actuators[0].kind = ActuatorKind::Linear as u32;
        g.actuators[0].max = 0.07;
        let s = Scale::of(&g).expect("a lift");
        match command_of(1, &words(&[0, 0x3F80_0000]), Some(s)).expect("POS 1.0") {
            ActArrayCommand::Position { joint: 0, position } => {
                assert!((position - 0.07).abs() < 1e-9)
            }
            other => panic!("{other:?}"),
        }
        let mut d = ActArrayData {
            actuators_count: 1,
            ..Default::default()
        };
        d.actuators[0].position = 0.035;
        let body = data_body(&d, Some(s));
        assert_eq!(&body[8..12], &0.5f32.to_be_bytes());
    }
}
