//! [`DeviceSet::check_motions`]: the motion results of every device of a set.

use limber_interfaces::prelude::*;

use super::{At, DeviceSet, DeviceSetHandler};

impl DeviceSet {
    /// Asks `handler` how each running motion of every device is doing and publishes the
    /// result of each that ended ([`DeviceHost::check_motions`](crate::DeviceHost::check_motions)).
    /// A driver calls it after publishing the states.
    pub fn check_motions<H: DeviceSetHandler + ?Sized>(&mut self, handler: &mut H) {
        for h in &mut self.actarrays {
            let index = h.device().index();
            h.check_motions::<At<'_, H>>(&mut At {
                handler: &mut *handler,
                index,
            });
        }
        for h in &mut self.limbs {
            let index = h.device().index();
            h.check_motions::<At<'_, H>>(&mut At {
                handler: &mut *handler,
                index,
            });
        }
        for h in &mut self.grippers {
            let index = h.device().index();
            h.check_motions::<At<'_, H>>(&mut At {
                handler: &mut *handler,
                index,
            });
        }
    }

    /// Ends every running motion of every device with `result` because of `cause` (a
    /// driver whose link went down: aborted, `LINK_DOWN`), publishing their results.
    pub fn end_motions(&mut self, result: MotionResult, cause: Status) {
        for h in &mut self.actarrays {
            h.end_motions(result, cause);
        }
        for h in &mut self.limbs {
            h.end_motions(result, cause);
        }
        for h in &mut self.grippers {
            h.end_motions(result, cause);
        }
    }
}
