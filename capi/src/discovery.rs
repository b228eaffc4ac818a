//! `limber_list_devices`: the devices of a domain, with whether their driver lives.

use core::ffi::c_char;

use limber_services::list_devices;

use crate::device::copy_str;
use crate::{Fail, LimberCode, arg, domain_of, guard, opt_str};

/// Longest device name kept in `limber_device_info.name`, with its NUL.
pub const LIMBER_DEVICE_NAME_CAPACITY: usize = 96;
/// Longest driver name kept in `limber_device_info.driver`, with its NUL.
pub const LIMBER_DRIVER_NAME_CAPACITY: usize = 64;

/// Which interface a device offers.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimberInterface {
    /// An actuator array (`limber_actarray_connect`).
    Actarray = 0,
    /// A limb (`limber_limb_connect`).
    Limb = 1,
    /// A gripper (`limber_gripper_connect`).
    Gripper = 2,
    /// A ranger (`limber_ranger_connect`).
    Ranger = 3,
}

/// One device found by `limber_list_devices`.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct LimberDeviceInfo {
    /// Its name, `robot/interface/index`, NUL-terminated.
    pub name: [c_char; LIMBER_DEVICE_NAME_CAPACITY],
    /// The driver that offers it, NUL-terminated (cut to fit).
    pub driver: [c_char; LIMBER_DRIVER_NAME_CAPACITY],
    /// Its interface.
    pub interface: LimberInterface,
    /// True while the driver's process lives.
    pub alive: bool,
    /// Processes attached to its state channel (the driver and the clients).
    pub nodes: u32,
    /// The layout version it speaks (`LIMBER_LAYOUT_VERSION`); 0 if it does not say.
    pub layout: u32,
}

/// Lists the devices of `domain` (NULL: `LIMBER_DOMAIN`, or "limber"), sorted by name:
/// writes the first `capacity` into `out[]` and the number found into `*count` (which
/// may exceed `capacity`: call again with a larger array). `out` may be NULL when
/// `capacity` is 0.
///
/// # Safety
/// `domain` is NULL or a NUL-terminated string; `out` points to `capacity` writable
/// entries (or is NULL with `capacity` 0); `count` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_list_devices(
    domain: *const c_char,
    out: *mut LimberDeviceInfo,
    capacity: usize,
    count: *mut usize,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (domain, count) = unsafe { (opt_str(domain, "domain")?, arg(count, "count")?) };
        if out.is_null() && capacity > 0 {
            return Err(Fail::new(LimberCode::NullArgument, "out is NULL"));
        }
        let devices = list_devices(&domain_of(domain)?)?;
        *count = devices.len();
        for (i, d) in devices.iter().take(capacity).enumerate() {
            let mut info = LimberDeviceInfo {
                name: [0; LIMBER_DEVICE_NAME_CAPACITY],
                driver: [0; LIMBER_DRIVER_NAME_CAPACITY],
                interface: LimberInterface::of(d.interface()),
                alive: d.alive,
                nodes: u32::try_from(d.nodes).unwrap_or(u32::MAX),
                layout: d.layout.parse().unwrap_or(0),
            };
            copy_str(&mut info.name, &d.name.to_string());
            copy_str(&mut info.driver, &d.driver);
            // SAFETY: i < capacity, and `out` points to `capacity` writable entries.
            unsafe { out.add(i).write(info) };
        }
        Ok(())
    })
}

/// Removes every file of `domain` (NULL: `LIMBER_DOMAIN`, or "limber") once no process runs
/// in it: the files its killed processes left, the node counter in `/dev/shm`, its token;
/// `*removed` (NULL: not written) is how many files and directories went. A domain without
/// files is left as it is. Processes still running in it: `LIMBER_CODE_TRANSPORT`, naming
/// how many.
///
/// # Safety
/// `domain` is NULL or a NUL-terminated string; `removed` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_remove_domain_files(
    domain: *const c_char,
    removed: *mut usize,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers.
        let (domain, removed) = unsafe { (opt_str(domain, "domain")?, removed.as_mut()) };
        let n = limber_services::cleanup::remove_domain_files(&domain_of(domain)?)
            .map_err(|e| Fail::from_error(LimberCode::Transport, &e))?;
        if let Some(out) = removed {
            *out = n;
        }
        Ok(())
    })
}
