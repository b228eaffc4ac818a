//! [`DeviceSetHandler`]: what a driver implements to serve a [`DeviceSet`](super::DeviceSet),
//! and each of its devices as a [`DeviceHandler`] of its interface.

use limber_interfaces::prelude::*;

use crate::host::{DeviceHandler, Motion, Origin, Progress};

/// What a driver implements to serve a [`DeviceSet`](super::DeviceSet): the [`DeviceHandler`] methods of
/// each interface, with the index of the device (`gripper/0` or `gripper/1`). A device
/// the set serves but the handler does not override answers [`Status::Unsupported`].
pub trait DeviceSetHandler {
    /// A validated command for `actarray/<index>`; see [`DeviceHandler::command`].
    fn actarray_command(
        &mut self,
        index: u16,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        let _ = (index, cmd, from, state);
        Status::Unsupported
    }
    /// What `cmd` drives on `actarray/<index>` and which of it still moves; see
    /// [`DeviceHandler::motion`]. Default: nothing.
    fn actarray_motion(
        &mut self,
        index: u16,
        cmd: &ActArrayCommand,
        state: &ActArrayData,
    ) -> Motion {
        let _ = (index, cmd, state);
        Motion::NONE
    }
    /// How part `part` of a motion of `actarray/<index>` is doing; see
    /// [`DeviceHandler::progress`]. Default: not known.
    fn actarray_progress(&mut self, index: u16, part: u32, state: &ActArrayData) -> Progress {
        let _ = (index, part, state);
        Progress::UNKNOWN
    }
    /// Stops every motion of `actarray/<index>` (the deadman); see [`DeviceHandler::stop`].
    fn actarray_stop(&mut self, index: u16, state: &mut ActArrayData) -> Status {
        let _ = (index, state);
        Status::Unsupported
    }
    /// A validated request for `actarray/<index>`; see [`DeviceHandler::request`].
    fn actarray_request(
        &mut self,
        index: u16,
        req: &ActArrayRequest,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        let _ = (index, req, from, state);
        Err(Status::Unsupported)
    }
    /// A validated command for `limb/<index>`; see [`DeviceHandler::command`].
    fn limb_command(
        &mut self,
        index: u16,
        cmd: &LimbCommand,
        from: &Origin,
        state: &mut LimbData,
    ) -> Status {
        let _ = (index, cmd, from, state);
        Status::Unsupported
    }
    /// What `cmd` drives on `limb/<index>` and which of it still moves; see
    /// [`DeviceHandler::motion`]. Default: nothing.
    fn limb_motion(&mut self, index: u16, cmd: &LimbCommand, state: &LimbData) -> Motion {
        let _ = (index, cmd, state);
        Motion::NONE
    }
    /// How part `part` of a motion of `limb/<index>` is doing; see
    /// [`DeviceHandler::progress`]. Default: not known.
    fn limb_progress(&mut self, index: u16, part: u32, state: &LimbData) -> Progress {
        let _ = (index, part, state);
        Progress::UNKNOWN
    }
    /// Stops every motion of `limb/<index>` (the deadman); see [`DeviceHandler::stop`].
    fn limb_stop(&mut self, index: u16, state: &mut LimbData) -> Status {
        let _ = (index, state);
        Status::Unsupported
    }
    /// A validated request for `limb/<index>`; see [`DeviceHandler::request`].
    fn limb_request(
        &mut self,
        index: u16,
        req: &LimbRequest,
        from: &Origin,
        state: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        let _ = (index, req, from, state);
        Err(Status::Unsupported)
    }
    /// A validated command for `gripper/<index>`; see [`DeviceHandler::command`].
    fn gripper_command(
        &mut self,
        index: u16,
        cmd: &GripperCommand,
        from: &Origin,
        state: &mut GripperData,
    ) -> Status {
        let _ = (index, cmd, from, state);
        Status::Unsupported
    }
    /// What `cmd` drives on `gripper/<index>` and which of it still moves; see
    /// [`DeviceHandler::motion`]. Default: nothing.
    fn gripper_motion(&mut self, index: u16, cmd: &GripperCommand, state: &GripperData) -> Motion {
        let _ = (index, cmd, state);
        Motion::NONE
    }
    /// How part `part` of a motion of `gripper/<index>` is doing; see
    /// [`DeviceHandler::progress`]. Default: not known.
    fn gripper_progress(&mut self, index: u16, part: u32, state: &GripperData) -> Progress {
        let _ = (index, part, state);
        Progress::UNKNOWN
    }
    /// Stops every motion of `gripper/<index>` (the deadman); see [`DeviceHandler::stop`].
    fn gripper_stop(&mut self, index: u16, state: &mut GripperData) -> Status {
        let _ = (index, state);
        Status::Unsupported
    }
    /// A validated request for `gripper/<index>`; see [`DeviceHandler::request`].
    fn gripper_request(
        &mut self,
        index: u16,
        req: &GripperRequest,
        from: &Origin,
        state: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        let _ = (index, req, from, state);
        Err(Status::Unsupported)
    }
    /// A validated request for `ranger/<index>` (a ranger has no command); see
    /// [`DeviceHandler::request`].
    fn ranger_request(
        &mut self,
        index: u16,
        req: &RangerRequest,
        from: &Origin,
        state: &mut RangerData,
    ) -> Result<RangerReply, Status> {
        let _ = (index, req, from, state);
        Err(Status::Unsupported)
    }
}

/// One device of the set, as a [`DeviceHandler`] of its interface.
pub(super) struct At<'a, H: ?Sized> {
    pub(super) handler: &'a mut H,
    pub(super) index: u16,
}

impl<H: DeviceSetHandler + ?Sized> DeviceHandler<ActArray> for At<'_, H> {
    fn progress(&mut self, part: u32, s: &ActArrayData) -> Progress {
        self.handler.actarray_progress(self.index, part, s)
    }
    fn motion(&mut self, cmd: &ActArrayCommand, s: &ActArrayData) -> Motion {
        self.handler.actarray_motion(self.index, cmd, s)
    }
    fn stop(&mut self, s: &mut ActArrayData) -> Status {
        self.handler.actarray_stop(self.index, s)
    }
    fn command(&mut self, cmd: &ActArrayCommand, from: &Origin, s: &mut ActArrayData) -> Status {
        self.handler.actarray_command(self.index, cmd, from, s)
    }
    fn request(
        &mut self,
        req: &ActArrayRequest,
        from: &Origin,
        s: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        self.handler.actarray_request(self.index, req, from, s)
    }
}

impl<H: DeviceSetHandler + ?Sized> DeviceHandler<Limb> for At<'_, H> {
    fn progress(&mut self, part: u32, s: &LimbData) -> Progress {
        self.handler.limb_progress(self.index, part, s)
    }
    fn motion(&mut self, cmd: &LimbCommand, s: &LimbData) -> Motion {
        self.handler.limb_motion(self.index, cmd, s)
    }
    fn stop(&mut self, s: &mut LimbData) -> Status {
        self.handler.limb_stop(self.index, s)
    }
    fn command(&mut self, cmd: &LimbCommand, from: &Origin, s: &mut LimbData) -> Status {
        self.handler.limb_command(self.index, cmd, from, s)
    }
    fn request(
        &mut self,
        req: &LimbRequest,
        from: &Origin,
        s: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        self.handler.limb_request(self.index, req, from, s)
    }
}

impl<H: DeviceSetHandler + ?Sized> DeviceHandler<Gripper> for At<'_, H> {
    fn progress(&mut self, part: u32, s: &GripperData) -> Progress {
        self.handler.gripper_progress(self.index, part, s)
    }
    fn motion(&mut self, cmd: &GripperCommand, s: &GripperData) -> Motion {
        self.handler.gripper_motion(self.index, cmd, s)
    }
    fn stop(&mut self, s: &mut GripperData) -> Status {
        self.handler.gripper_stop(self.index, s)
    }
    fn command(&mut self, cmd: &GripperCommand, from: &Origin, s: &mut GripperData) -> Status {
        self.handler.gripper_command(self.index, cmd, from, s)
    }
    fn request(
        &mut self,
        req: &GripperRequest,
        from: &Origin,
        s: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        self.handler.gripper_request(self.index, req, from, s)
    }
}

impl<H: DeviceSetHandler + ?Sized> DeviceHandler<Ranger> for At<'_, H> {
    fn command(&mut self, cmd: &RangerCommand, _: &Origin, _: &mut RangerData) -> Status {
        match *cmd {}
    }
    fn request(
        &mut self,
        req: &RangerRequest,
        from: &Origin,
        s: &mut RangerData,
    ) -> Result<RangerReply, Status> {
        self.handler.ranger_request(self.index, req, from, s)
    }
    fn stop(&mut self, _: &mut RangerData) -> Status {
        // Nothing moves.
        Status::Ok
    }
}
