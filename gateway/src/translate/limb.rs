//! `limb` (Player 54, limber `limb`): commands HOME, STOP, SETPOSE, SETPOSITION, VECMOVE
//! and requests POWER, BRAKES, GEOM, SPEED of Player 3, one to one with limber's; points
//! and vectors are `f64` on both sides, in robot coordinates. limber's own REACH request
//! is not Player's and is not offered.

use limber_interfaces::limb::{cmd, req};
use limber_interfaces::prelude::*;
use limber_services::{DeviceClient, Ticket};

use super::{
    Conventions, MessageError, PlayerDevice, Translator, empty, in_tables, on_off, read_vec3,
    typed, unknown, write_vec3,
};
use crate::header::msg_type;
use crate::xdr::{XdrReader, XdrWriter};

/// The limb translator.
pub static LIMB: LimbTranslator = LimbTranslator;

/// Translates `limb`.
#[derive(Debug)]
pub struct LimbTranslator;

const CMDS: [u8; 5] = [1, 2, 3, 4, 5];
const REQS: [u8; 4] = [1, 2, 3, 4];

impl Translator for LimbTranslator {
    fn kind(&self) -> InterfaceKind {
        InterfaceKind::Limb
    }
    fn open(&self, dev: Box<dyn DeviceClient>, _: Conventions) -> Box<dyn PlayerDevice> {
        Box::new(LimbDevice { dev })
    }
}

struct LimbDevice {
    dev: Box<dyn DeviceClient>,
}

/// The DATA STATE body of `d` (76 bytes).
pub fn data_body(d: &LimbData) -> Vec<u8> {
    let mut w = XdrWriter::new();
    write_vec3(&mut w, d.position);
    write_vec3(&mut w, d.approach);
    write_vec3(&mut w, d.orientation);
    w.u32(d.state);
    w.finish()
}

/// A Player limb command as limber's.
pub fn command_of(subtype: u8, body: &[u8]) -> Result<LimbCommand, MessageError> {
    let mut r = XdrReader::new(body);
    let c = match u32::from(subtype) {
        cmd::HOME => LimbCommand::Home,
        cmd::STOP => LimbCommand::Stop,
        cmd::SETPOSE => {
            let p = read_vec3(&mut r, "position")?;
            let a = read_vec3(&mut r, "approach")?;
            let o = read_vec3(&mut r, "orientation")?;
            LimbCommand::set_pose(p, a, o)?
        }
        cmd::SETPOSITION => LimbCommand::set_position(read_vec3(&mut r, "position")?)?,
        cmd::VECMOVE => {
            let d = read_vec3(&mut r, "direction")?;
            LimbCommand::vec_move(d, r.f32("length")?.into())?
        }
        _ => return Err(unknown(msg_type::CMD, subtype)),
    };
    r.end()?;
    Ok(c)
}

/// A Player limb request as limber's.
pub fn request_of(subtype: u8, body: &[u8]) -> Result<LimbRequest, MessageError> {
    let mut r = XdrReader::new(body);
    let q = match u32::from(subtype) {
        req::POWER => LimbRequest::Power(on_off(&mut r, "power")?),
        req::BRAKES => LimbRequest::Brakes(on_off(&mut r, "brakes")?),
        req::GEOM => {
            empty(body)?;
            LimbRequest::Geom
        }
        req::SPEED => LimbRequest::speed(r.f32("speed")?.into())?,
        _ => return Err(unknown(msg_type::REQ, subtype)),
    };
    r.end()?;
    Ok(q)
}

impl PlayerDevice for LimbDevice {
    fn client(&mut self) -> &mut dyn DeviceClient {
        self.dev.as_mut()
    }
    fn client_ref(&self) -> &dyn DeviceClient {
        self.dev.as_ref()
    }
    fn data(&self) -> Option<Vec<u8>> {
        let c = self.dev.typed_ref::<Limb>()?;
        c.last_state().map(data_body)
    }
    fn command(&mut self, subtype: u8, body: &[u8]) -> Result<Ticket, MessageError> {
        let c = command_of(subtype, body)?;
        Ok(typed::<Limb>(self.dev.as_mut())?.send(&c)?)
    }
    fn request(&mut self, subtype: u8, body: &[u8]) -> Result<Vec<u8>, MessageError> {
        let q = request_of(subtype, body)?;
        match typed::<Limb>(self.dev.as_mut())?.request(&q)? {
            LimbReply::Geom(g) => {
                let mut w = XdrWriter::new();
                write_vec3(&mut w, g.base_pos);
                Ok(w.finish())
            }
            LimbReply::Done | LimbReply::Reach(_) => Ok(Vec::new()),
        }
    }
    fn translates(&self, mtype: u8, subtype: u8) -> bool {
        in_tables(mtype, subtype, &CMDS, &REQS)
    }
    fn changes(&self, subtype: u8) -> bool {
        u32::from(subtype) != req::GEOM
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f64s(v: &[f64]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_be_bytes()).collect()
    }

    #[test]
    fn data_is_three_points_and_a_state_word() {
        let d = LimbData {
            position: Vec3::new(0.5, 0.0, 0.3),
            approach: Vec3::new(1.0, 0.0, 0.0),
            orientation: Vec3::new(0.0, 0.0, 1.0),
            state: LimbState::Idle as u32,
            ..Default::default()
        };
        let body = data_body(&d);
        assert_eq!(body.len(), 76);
        let mut want = f64s(&[0.5, 0.0, 0.3, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        want.extend(1u32.to_be_bytes());
        assert_eq!(body, want);
    }

    #[test]
    fn commands_read_players_bytes() {
        let pose = f64s(&[0.4, 0.0, 0.2, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0]);
        assert_eq!(pose.len(), 72);
        assert_eq!(
            command_of(3, &pose).expect("SETPOSE"),
            LimbCommand::set_pose(
                Vec3::new(0.4, 0.0, 0.2),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 0.0)
            )
            .expect("valid")
        );
        let mut vec = f64s(&[0.0, 0.0, 1.0]);
        vec.extend(0.05f32.to_be_bytes());
        assert_eq!(vec.len(), 28);
        assert!(matches!(
            command_of(5, &vec).expect("VECMOVE"),
            LimbCommand::VecMove { .. }
        ));
        assert_eq!(command_of(1, &[]).expect("HOME"), LimbCommand::Home);
        assert!(command_of(1, &[0; 4]).is_err());
        // A zero approach vector is refused, not sent.
        assert!(command_of(3, &f64s(&[0.0; 9])).is_err());
        assert_eq!(
            request_of(4, &0.1f32.to_be_bytes()).expect("SPEED"),
            LimbRequest::Speed(f64::from(0.1f32))
        );
    }
}
