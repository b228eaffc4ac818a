//! `gripper` (Player 3, limber `gripper`): commands OPEN, CLOSE, STOP, STORE, RETRIEVE
//! (no body) and request GET_GEOM of Player 3, one to one with limber's.

use limber_interfaces::gripper::{cmd, req};
use limber_interfaces::prelude::*;
use limber_services::{DeviceClient, Ticket};

use super::{
    Conventions, MessageError, PlayerDevice, Translator, empty, in_tables, typed, unknown,
    write_vec3,
};
use crate::header::msg_type;
use crate::xdr::XdrWriter;

/// The gripper translator.
pub static GRIPPER: GripperTranslator = GripperTranslator;

/// Translates `gripper`.
#[derive(Debug)]
pub struct GripperTranslator;

const CMDS: [u8; 5] = [1, 2, 3, 4, 5];
const REQS: [u8; 1] = [1];

impl Translator for GripperTranslator {
    fn kind(&self) -> InterfaceKind {
        InterfaceKind::Gripper
    }
    fn open(&self, dev: Box<dyn DeviceClient>, _: Conventions) -> Box<dyn PlayerDevice> {
        Box::new(GripperDevice { dev })
    }
}

struct GripperDevice {
    dev: Box<dyn DeviceClient>,
}

/// The DATA STATE body of `d` (12 bytes: state, beams, stored).
pub fn data_body(d: &GripperData) -> Vec<u8> {
    XdrWriter::new()
        .u32(d.state)
        .u32(d.beams)
        .u32(d.stored)
        .finish()
}

/// The GET_GEOM ACK body of `g` (104 bytes).
pub fn geom_body(g: &GripperGeom) -> Vec<u8> {
    let mut w = XdrWriter::new();
    write_vec3(&mut w, g.pose.position);
    w.f64(g.pose.orientation.roll)
        .f64(g.pose.orientation.pitch)
        .f64(g.pose.orientation.yaw);
    for b in [g.outer_size, g.inner_size] {
        w.f64(b.width).f64(b.length).f64(b.height);
    }
    w.u32(g.num_beams).u32(g.capacity);
    w.finish()
}

/// A Player gripper command as limber's.
pub fn command_of(subtype: u8, body: &[u8]) -> Result<GripperCommand, MessageError> {
    let c = match u32::from(subtype) {
        cmd::OPEN => GripperCommand::Open,
        cmd::CLOSE => GripperCommand::Close,
        cmd::STOP => GripperCommand::Stop,
        cmd::STORE => GripperCommand::Store,
        cmd::RETRIEVE => GripperCommand::Retrieve,
        _ => return Err(unknown(msg_type::CMD, subtype)),
    };
    empty(body)?;
    Ok(c)
}

impl PlayerDevice for GripperDevice {
    fn client(&mut self) -> &mut dyn DeviceClient {
        self.dev.as_mut()
    }
    fn client_ref(&self) -> &dyn DeviceClient {
        self.dev.as_ref()
    }
    fn data(&self) -> Option<Vec<u8>> {
        let c = self.dev.typed_ref::<Gripper>()?;
        c.last_state().map(data_body)
    }
    fn command(&mut self, subtype: u8, body: &[u8]) -> Result<Ticket, MessageError> {
        let c = command_of(subtype, body)?;
        Ok(typed::<Gripper>(self.dev.as_mut())?.send(&c)?)
    }
    fn request(&mut self, subtype: u8, body: &[u8]) -> Result<Vec<u8>, MessageError> {
        if u32::from(subtype) != req::GET_GEOM {
            return Err(unknown(msg_type::REQ, subtype));
        }
        empty(body)?;
        match typed::<Gripper>(self.dev.as_mut())?.request(&GripperRequest::GetGeom)? {
            GripperReply::Geom(g) => Ok(geom_body(&g)),
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

    #[test]
    fn data_and_geometry_have_players_sizes() {
        let d = GripperData {
            state: GripperState::Closed as u32,
            beams: 0b10,
            stored: 0,
            ..Default::default()
        };
        assert_eq!(data_body(&d), [0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 0]);
        assert_eq!(geom_body(&GripperGeom::default()).len(), 104);
    }

    #[test]
    fn commands_have_no_body() {
        assert_eq!(command_of(1, &[]).expect("OPEN"), GripperCommand::Open);
        assert_eq!(
            command_of(5, &[]).expect("RETRIEVE"),
            GripperCommand::Retrieve
        );
        assert!(command_of(2, &[0, 0, 0, 0]).is_err());
        assert!(command_of(6, &[]).is_err());
    }
}
