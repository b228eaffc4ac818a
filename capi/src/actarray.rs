//! `limber_actarray_*`: Player's `ActArrayProxy` for C, one function per client call.

use limber_interfaces::prelude::*;

use crate::{Fail, LimberCode, LimberDevice, LimberTicket, arg, guard, sent};

/// A connection to an actuator array: a `limber_device` of this interface (the same type, so every
/// `limber_device_*` call takes it).
pub type LimberActArray = LimberDevice;

/// The values of a `*_multi` call.
///
/// # Safety
/// `p` is NULL (then `count` must be 0) or points to `count` readable doubles.
unsafe fn values<'a>(p: *const f64, count: usize) -> Result<&'a [f64], Fail> {
    if count == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fail::new(LimberCode::NullArgument, "the values are NULL"));
    }
    // SAFETY: not NULL, and the caller promises `count` readable doubles.
    Ok(unsafe { core::slice::from_raw_parts(p, count) })
}

/// CMD POS: moves `joint` to `position` (rad or m). `*ticket` (NULL: not written) is for
/// `limber_actarray_wait_outcome`. Returns at once.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_to(
    h: *mut LimberActArray,
    joint: u32,
    position: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.move_to(joint as usize, position),
            ticket,
        )
    })
}

/// CMD MULTI_POS: moves joints 0..count to `positions[0..count]`.
///
/// # Safety
/// `h` is NULL or a live handle; `positions` points to `count` doubles (or is NULL with
/// `count` 0); `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_to_multi(
    h: *mut LimberActArray,
    positions: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) = unsafe {
            (
                arg(h, "handle")?,
                values(positions, count)?,
                ticket.as_mut(),
            )
        };
        sent(h.typed::<ActArray>()?.move_to_multi(v), ticket)
    })
}

/// CMD SPEED: moves `joint` at `speed` (rad/s or m/s).
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_at_speed(
    h: *mut LimberActArray,
    joint: u32,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.move_at_speed(joint as usize, speed),
            ticket,
        )
    })
}

/// CMD MULTI_SPEED: moves joints 0..count at `speeds[0..count]`.
///
/// # Safety
/// As `limber_actarray_move_to_multi`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_at_speed_multi(
    h: *mut LimberActArray,
    speeds: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) =
            unsafe { (arg(h, "handle")?, values(speeds, count)?, ticket.as_mut()) };
        sent(h.typed::<ActArray>()?.move_at_speed_multi(v), ticket)
    })
}

/// CMD HOME: homes `joint`, or every joint if `joint` is negative.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_home(
    h: *mut LimberActArray,
    joint: i32,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.home(usize::try_from(joint).ok()),
            ticket,
        )
    })
}

/// CMD CURRENT: drives `joint` (every joint if negative) with `current` A.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_current(
    h: *mut LimberActArray,
    joint: i32,
    current: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?
                .set_current(usize::try_from(joint).ok(), current),
            ticket,
        )
    })
}

/// CMD MULTI_CURRENT: drives joints 0..count with `currents[0..count]` A.
///
/// # Safety
/// As `limber_actarray_move_to_multi`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_current_multi(
    h: *mut LimberActArray,
    currents: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) =
            unsafe { (arg(h, "handle")?, values(currents, count)?, ticket.as_mut()) };
        sent(h.typed::<ActArray>()?.set_current_multi(v), ticket)
    })
}

/// REQ POWER: power on (`on` true) or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_power(
    h: *mut LimberActArray,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        crate::request(
            h.typed::<ActArray>()?,
            &ActArrayRequest::Power(on),
            timeout_ms,
        )
        .map(drop)
    })
}

/// REQ BRAKES: brakes on or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_brakes(
    h: *mut LimberActArray,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        crate::request(
            h.typed::<ActArray>()?,
            &ActArrayRequest::Brakes(on),
            timeout_ms,
        )
        .map(drop)
    })
}

/// REQ SPEED: the speed of `joint` for later position moves.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_speed_config(
    h: *mut LimberActArray,
    joint: u32,
    speed: f64,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        let req = ActArrayRequest::speed(i64::from(joint), speed)?;
        crate::request(h.typed::<ActArray>()?, &req, timeout_ms).map(drop)
    })
}

/// REQ ACCEL: the acceleration of `joint` for later position moves.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_accel_config(
    h: *mut LimberActArray,
    joint: u32,
    accel: f64,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        let req = ActArrayRequest::accel(i64::from(joint), accel)?;
        crate::request(h.typed::<ActArray>()?, &req, timeout_ms).map(drop)
    })
}

// ----- control: who commands the device ------------------------------------------------

/// A C array of `n` doubles that may be NULL (then `None`).
///
/// # Safety
/// `p` is NULL or points to `n` readable doubles.
unsafe fn optional<'a>(p: *const f64, n: usize) -> Option<&'a [f64]> {
    // SAFETY: the caller's promise; NULL is None.
    (!p.is_null()).then(|| unsafe { core::slice::from_raw_parts(p, n) })
}

/// CMD TRAJ: follows a joint trajectory (control_msgs' FollowJointTrajectory) of
/// `point_count` points (up to `LIMBER_TRAJ_MAX_POINTS`) for the `joint_count` actarray
/// joints `joints[0..joint_count]`. Point i is reached `times[i]` s after the start (strictly
/// increasing); its positions are `positions[i * joint_count + c]` (column c drives
/// `joints[c]`); `velocities` and `accelerations` are laid out the same way or NULL
/// (positions only: linear; with velocities: cubic; with accelerations too: quintic).
/// `path_tolerance` and `goal_tolerance` hold one value per column or are NULL (0: not
/// enforced); `goal_time_tolerance` s (0: the driver's default); `start_ns` the
/// `CLOCK_MONOTONIC` start (0: when it arrives). It replaces a running trajectory from its
/// start time. `limber_actarray_wait_done` returns its result. An invalid trajectory is
/// `LIMBER_CODE_INVALID_VALUE` with the reason in `limber_last_error()`, nothing sent.
///
/// # Safety
/// `h` is NULL or a live handle; `joints` points to `joint_count` values; `times` to
/// `point_count`; `positions` (and `velocities`, `accelerations` unless NULL) to
/// `point_count * joint_count`; the tolerances (unless NULL) to `joint_count`; `ticket` is
/// NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn limber_actarray_follow_trajectory(
    h: *mut LimberActArray,
    joints: *const u32,
    joint_count: usize,
    times: *const f64,
    point_count: usize,
    positions: *const f64,
    velocities: *const f64,
    accelerations: *const f64,
    path_tolerance: *const f64,
    goal_tolerance: *const f64,
    goal_time_tolerance: f64,
    start_ns: u64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        let invalid = |e: TrajectoryError| Fail::from_error(LimberCode::InvalidValue, &e);
        let n = joint_count.min(MAX_ACTUATORS + 1);
        let p = point_count.min(MAX_TRAJ_POINTS + 1);
        // SAFETY: the caller's promise on the pointers, checked for NULL here; the counts
        // are capped one beyond the capacity (a larger one is refused below, unread).
        let (h, ticket, times, positions, joints) = unsafe {
            (
                arg(h, "handle")?,
                ticket.as_mut(),
                values(times, p)?,
                values(positions, p * n)?,
                if joints.is_null() || n == 0 {
                    &[][..]
                } else {
                    core::slice::from_raw_parts(joints, n)
                },
            )
        };
        // SAFETY: as above; NULL is "not given".
        let (vel, acc, path, goal) = unsafe {
            (
                optional(velocities, p * n),
                optional(accelerations, p * n),
                optional(path_tolerance, n),
                optional(goal_tolerance, n),
            )
        };
        let ids: Vec<u16> = joints
            .iter()
            .map(|&j| j.min(u16::MAX as u32) as u16)
            .collect();
        let mut t = JointTrajectory::new(&ids).map_err(invalid)?;
        if p > MAX_TRAJ_POINTS {
            return Err(invalid(TrajectoryError::PointCount(point_count)));
        }
        for (i, &time) in times.iter().enumerate() {
            let r = i * n..(i + 1) * n;
            let (v, a) = (vel.map(|v| &v[r.clone()]), acc.map(|a| &a[r.clone()]));
            t.push(time, &positions[r], v, a).map_err(invalid)?;
        }
        if let Some(v) = path {
            t.set_path_tolerance(v).map_err(invalid)?;
        }
        if let Some(v) = goal {
            t.set_goal_tolerance(v).map_err(invalid)?;
        }
        t.set_goal_time_tolerance(goal_time_tolerance)
            .map_err(invalid)?;
        t.set_start_ns(start_ns);
        let r = h.typed::<ActArray>()?.follow_trajectory(&t);
        let r = r.map_err(|e| match e {
            limber_services::TrajectorySendError::Invalid(e) => invalid(e),
            limber_services::TrajectorySendError::Send(e) => Fail::from(e),
        })?;
        sent(Ok(r), ticket)
    })
}

/// CMD TRAJ_SCALE: the speed scaling of trajectories: 0 pauses the running one, 1 is
/// nominal (above 1: clamped, the outcome `LIMBER_STATUS_CLAMPED`).
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_trajectory_scale(
    h: *mut LimberActArray,
    scale: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<ActArray>()?.set_trajectory_scale(scale), ticket)
    })
}
