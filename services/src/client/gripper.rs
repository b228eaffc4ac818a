//! Player's `GripperProxy`: the gripper conveniences of [`GripperClient`](super::GripperClient).

use limber_interfaces::prelude::*;

use super::{Client, CommandError, Ticket};

/// Player's `GripperProxy`: every gripper command and request.
impl Client<Gripper> {
    /// CMD OPEN.
    pub fn open(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Open)
    }
    /// CMD CLOSE.
    pub fn close(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Close)
    }
    /// CMD STOP.
    pub fn stop(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Stop)
    }
    /// CMD STORE.
    pub fn store(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Store)
    }
    /// CMD RETRIEVE.
    pub fn retrieve(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Retrieve)
    }
}
