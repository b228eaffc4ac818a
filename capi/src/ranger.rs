//! `limber_ranger_*`: Player's `RangerProxy` (`LaserProxy`) for C. A ranger has no
//! command: its scans (`limber_ranger_state`, `limber_ranger_wait_state`...) and its
//! geometry (`limber_ranger_geometry`) are the typed calls every interface has
//! (limber_client.h's trailer); the scan's fields are `limber_ranger_data`'s (limber.h).

use limber_interfaces::prelude::*;

use crate::{Fail, LimberCode, LimberDevice, guard};

/// A connection to a ranger: a `limber_device` of this interface (the same type, so every
/// `limber_device_*` call takes it).
pub type LimberRanger = LimberDevice;

/// The bearing of range `index` of `scan` (rad, counter-clockwise from the sensor's x
/// axis: `min_angle + index * angular_res`) and the point it hit (`x`, `y` in the
/// sensor's frame, m; Player's `GetBearing` and `GetPoint`). `bearing`, `x`, `y` may be
/// NULL (not written). An index at or beyond `ranges_count` is
/// `LIMBER_CODE_INVALID_VALUE`.
///
/// # Safety
/// `scan` is NULL or points to a readable `limber_ranger_data`; `bearing`, `x` and `y`
/// are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_ranger_point(
    scan: *const RangerData,
    index: usize,
    bearing: *mut f64,
    x: *mut f64,
    y: *mut f64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (scan, bearing, x, y) =
            unsafe { (scan.as_ref(), bearing.as_mut(), x.as_mut(), y.as_mut()) };
        let scan = scan.ok_or_else(|| Fail::new(LimberCode::NullArgument, "scan is NULL"))?;
        let p = scan.point(index).ok_or_else(|| {
            Fail::new(
                LimberCode::InvalidValue,
                format!(
                    "range {index} does not exist: the scan has {}",
                    scan.ranges().len()
                ),
            )
        })?;
        if let Some(b) = bearing {
            *b = scan.bearing(index);
        }
        if let Some(x) = x {
            *x = p[0];
        }
        if let Some(y) = y {
            *y = p[1];
        }
        Ok(())
    })
}
