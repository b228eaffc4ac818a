//! The limb's outcome rules, one place for every driver: how the result of a limb command
//! becomes its [`Status`] and the limb state's OUT_OF_REACH and `orientation_adjustment`.
//!
//! * A SETPOSE carried out with its orientation turned by more than
//!   [`ADJUSTMENT_REPORTED`] is `ADJUSTED` (the amount in the limb state); less is `OK`.
//! * A command refused because the limb cannot get there (beyond its reach, an
//!   orientation its joints cannot hold, a joint limit in the way: [`cannot_get_there`])
//!   sets OUT_OF_REACH until the next limb command carried out; any other refusal leaves
//!   the state as it was.

use crate::common::Status;

/// Orientation adjustments (rad) up to this are numerical noise: the command is `OK`, not
/// `ADJUSTED`, and the limb state shows 0. Equal to
/// `limber_kinematics::pioneer::ADJUSTMENT_REPORTED` (the drivers' tests check it).
pub const ADJUSTMENT_REPORTED: f64 = 1e-5;

/// True when an orientation adjustment (rad) is reported (`ADJUSTED`, REACH's `adjusted`).
pub fn adjustment_reported(adjustment: f64) -> bool {
    adjustment > ADJUSTMENT_REPORTED
}

/// True for the statuses that mean "the limb cannot get there" (the limb's OUT_OF_REACH
/// state): beyond its reach, an orientation its joints cannot hold, or a joint limit.
pub fn cannot_get_there(s: Status) -> bool {
    matches!(
        s,
        Status::OutOfReach | Status::UnreachableOrientation | Status::BeyondLimits
    )
}

/// What the limb's last command left in its state: OUT_OF_REACH and the orientation
/// adjustment of the last SETPOSE.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LimbOutcome {
    /// The last limb target could not be reached (cleared by the next limb command
    /// carried out).
    pub out_of_reach: bool,
    /// How much the last SETPOSE turned the orientation, rad (0 after any other limb
    /// command, and for adjustments not reported).
    pub adjustment: f64,
}

impl LimbOutcome {
    /// A limb command starts: the previous adjustment no longer describes the target.
    pub fn begin(&mut self) {
        self.adjustment = 0.0;
    }

    /// The SETPOSE being carried out turned the orientation by `adjustment` rad.
    pub fn adjusted_by(&mut self, adjustment: f64) {
        self.adjustment = if adjustment_reported(adjustment) {
            adjustment
        } else {
            0.0
        };
    }

    /// The command's result becomes its status: `ADJUSTED` or `OK` when carried out,
    /// the refusal otherwise (OUT_OF_REACH set when the limb cannot get there).
    pub fn settle(&mut self, result: Result<(), Status>) -> Status {
        match result {
            Ok(()) => {
                self.out_of_reach = false;
                if self.adjustment > 0.0 {
                    Status::Adjusted
                } else {
                    Status::Ok
                }
            }
            Err(e) => {
                if cannot_get_there(e) {
                    self.out_of_reach = true;
                }
                self.adjustment = 0.0;
                e
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adjusted_only_above_the_threshold_and_out_of_reach_until_the_next_success() {
        let mut o = LimbOutcome::default();
        o.begin();
        o.adjusted_by(ADJUSTMENT_REPORTED / 2.0);
        assert_eq!(o.settle(Ok(())), Status::Ok);
        assert_eq!(o.adjustment, 0.0);
        o.begin();
        o.adjusted_by(0.3);
        assert_eq!(o.settle(Ok(())), Status::Adjusted);
        assert_eq!(o.adjustment, 0.3);
        for (refusal, oor) in [
            (Status::OutOfReach, true),
            (Status::UnreachableOrientation, true),
            (Status::BeyondLimits, true),
            (Status::LinkDown, false),
            (Status::NotFinite, false),
        ] {
            let mut o = LimbOutcome::default();
            o.begin();
            assert_eq!(o.settle(Err(refusal)), refusal);
            assert_eq!(o.out_of_reach, oor, "{refusal:?}");
            assert_eq!(o.settle(Ok(())), Status::Ok);
            assert!(!o.out_of_reach);
        }
    }
}
