"""limber for Python: clients of limber devices, a thin ctypes binding over liblimber.

* :mod:`limber.client`: :class:`ActArrayClient`; :mod:`limber.limb`: :class:`LimbClient`; :mod:`limber.gripper`: :class:`GripperClient`
  (connect, state, commands with outcomes, requests, leases), :class:`Domain`,
  :class:`Status`, :func:`list_devices`, :class:`DriverStatsReader` and the errors. See
  ``python/README.md``.
* :mod:`limber.ranger`: :class:`RangerClient` (:class:`LaserClient`), a laser's scans and
  geometry, and :func:`~limber.ranger.point`, the bearing and point of a range.
* :mod:`limber._layout`: the ctypes classes generated from the layout manifest, with exactly
  the layout of the Rust structs (the states and geometries the library fills in place).
* :mod:`limber._lib`: where liblimber is found (``LIMBER_LIB``, the package, a source
  checkout's ``target/``) and the prototype of every C function called.
"""

from ._layout import *  # noqa: F401,F403
from ._layout import (
    LAYOUT_VERSION as LAYOUT_VERSION,
    STRUCTS as STRUCTS,
    ActArrayData as ActArrayData,
    ActArrayGeom as ActArrayGeom,
    DriverStats as DriverStats,
    GripperData as GripperData,
    GripperGeom as GripperGeom,
    LimbData as LimbData,
    LimbGeom as LimbGeom,
    LimbReach as LimbReach,
    RangerData as RangerData,
    RangerGeom as RangerGeom,
    Vec3 as Vec3,
)
from .client import (
    DEFAULT_DOMAIN as DEFAULT_DOMAIN,
    DEFAULT_REQUEST_TIMEOUT as DEFAULT_REQUEST_TIMEOUT,
    DOMAIN_ENV as DOMAIN_ENV,
    SPIN_BUDGET_ENV as SPIN_BUDGET_ENV,
    ActArrayClient as ActArrayClient,
    DecodeError as DecodeError,
    DeviceInfo as DeviceInfo,
    DeviceName as DeviceName,
    Domain as Domain,
    DriverGoneError as DriverGoneError,
    DriverStatsReader as DriverStatsReader,
    DriverStatus as DriverStatus,
    Freshness as Freshness,
    IncompatibleError as IncompatibleError,
    LeaseHeldError as LeaseHeldError,
    LeaseHolder as LeaseHolder,
    LeaseLostError as LeaseLostError,
    LimberError as LimberError,
    NackError as NackError,
    NoDriverError as NoDriverError,
    Outcome as Outcome,
    OutcomeMissed as OutcomeMissed,
    RequestTimeout as RequestTimeout,
    Status as Status,
    Ticket as Ticket,
    TransportError as TransportError,
    UnexpectedReplyError as UnexpectedReplyError,
    WaitMode as WaitMode,
    WaitTimeout as WaitTimeout,
    default_spin_budget as default_spin_budget,
    library_path as library_path,
    list_devices as list_devices,
    remove_domain_files as remove_domain_files,
    stats_text as stats_text,
)
from .done import (
    Done as Done,
    MotionResult as MotionResult,
)
from .gripper import GripperClient as GripperClient
from .limb import LimbClient as LimbClient
from .ranger import (
    LaserClient as LaserClient,
    RangerClient as RangerClient,
)
