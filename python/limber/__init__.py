"""limber for Python: clients of limber devices and the wire contract.

* :mod:`limber.client`: :class:`ActArrayClient`, :class:`LimbClient`, :class:`GripperClient`
  (connect, state, commands with outcomes, requests), :class:`Domain`, :class:`Status` and
  the errors. See ``python/README.md``.
* :mod:`limber._layout`: the ctypes classes generated from the layout manifest, with exactly
  the layout of the Rust structs, so a sample received through the ``iceoryx2`` Python
  binding can be read in place::

    from limber import ActArrayData
    state = sample.payload().contents   # an ActArrayData living in shared memory
"""

from ._layout import *  # noqa: F401,F403
from ._layout import LAYOUT_VERSION, STRUCTS  # noqa: F401
from .client import (  # noqa: F401
    DEFAULT_DOMAIN,
    SPIN_BUDGET,
    SPIN_BUDGET_ENV,
    DEFAULT_REQUEST_TIMEOUT,
    DOMAIN_ENV,
    ActArrayClient,
    DecodeError,
    DeviceInfo,
    DeviceName,
    Domain,
    DriverGoneError,
    DriverStatsReader,
    DriverStatus,
    Freshness,
    GripperClient,
    IncompatibleError,
    LeaseHeldError,
    LeaseHolder,
    LeaseLostError,
    LimberError,
    LimbClient,
    NackError,
    NoDriverError,
    Outcome,
    OutcomeMissed,
    RequestTimeout,
    Status,
    Ticket,
    TransportError,
    WaitMode,
    default_spin_budget,
    list_devices,
    stats_text,
    UnexpectedReplyError,
    WaitTimeout,
)
