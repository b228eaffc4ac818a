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
    /// CMD GOAL (limber's): the fingers to `gap` m, gripping with at most `effort` N, at
    /// `speed` m/s (0: the gripper's own effort, its configured speed). Its result
    /// (`wait_done`) is REACHED or STALLED (stopped short of the goal, on an object), with
    /// the status `OBJECT_PRESENT` when the break beams see an object between the fingers;
    /// a gripper that cannot set the gap, the effort or the speed refuses the goal with
    /// the reason.
    pub fn goal(&mut self, gap: f64, effort: f64, speed: f64) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::goal(gap, effort, speed)?)
    }
    /// CMD RETRIEVE.
    pub fn retrieve(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Retrieve)
    }
}
