"""The values of the binding: statuses, tickets, outcomes, the exceptions and the one table
from ``LIMBER_CODE_*`` to exception (:data:`_ERRORS`). See :mod:`limber.client`."""

from __future__ import annotations

import enum
import math
from ctypes import byref
from dataclasses import dataclass
from typing import (
    Dict,
    NamedTuple,
    Optional,
    Type,
)

from . import _layout as L
from . import _lib
from ._lib import lib as _c


#: The environment variable that selects the domain.
DOMAIN_ENV = "LIMBER_DOMAIN"
#: The domain used when ``LIMBER_DOMAIN`` is not set.
DEFAULT_DOMAIN = "limber"
#: Default time a request waits for its reply, seconds (Rust: ``DEFAULT_REQUEST_TIMEOUT``).
DEFAULT_REQUEST_TIMEOUT = 2.0
#: The environment variable that sets the clients' spin budget in µs (``0``: block at once).
SPIN_BUDGET_ENV = "LIMBER_SPIN_US"


def library_path() -> str:
    """The path of the liblimber.so this package loaded (``LIMBER_LIB``, the one inside the
    package, or the source checkout's ``target/{release,debug}``)."""
    return _lib.path


# ----- status codes and small types ------------------------------------------------------


class Status(enum.IntEnum):
    """Why a command or request was refused, or ``OK`` (Rust ``Status``; wire ``STATUS_*``)."""

    OK = L.STATUS_OK
    UNSUPPORTED = L.STATUS_UNSUPPORTED
    UNKNOWN_JOINT = L.STATUS_UNKNOWN_JOINT
    NOT_FINITE = L.STATUS_NOT_FINITE
    BEYOND_LIMITS = L.STATUS_BEYOND_LIMITS
    OUT_OF_REACH = L.STATUS_OUT_OF_REACH
    NOT_CALIBRATED = L.STATUS_NOT_CALIBRATED
    LINK_DOWN = L.STATUS_LINK_DOWN
    BUSY = L.STATUS_BUSY
    TIMEOUT = L.STATUS_TIMEOUT
    INVALID_ARGUMENT = L.STATUS_INVALID_ARGUMENT
    POWERED_OFF = L.STATUS_POWERED_OFF
    UNREACHABLE_ORIENTATION = L.STATUS_UNREACHABLE_ORIENTATION
    CLAMPED = L.STATUS_CLAMPED
    PREEMPTED = L.STATUS_PREEMPTED
    LEASED = L.STATUS_LEASED
    ADJUSTED = L.STATUS_ADJUSTED
    BRAKED = L.STATUS_BRAKED
    STORE_FULL = L.STATUS_STORE_FULL
    NOTHING_TO_STORE = L.STATUS_NOTHING_TO_STORE
    NOTHING_STORED = L.STATUS_NOTHING_STORED
    INVALID_GOAL = L.STATUS_INVALID_GOAL
    OLD_TIMESTAMP = L.STATUS_OLD_TIMESTAMP
    TOO_FAST = L.STATUS_TOO_FAST
    OBJECT_PRESENT = L.STATUS_OBJECT_PRESENT
    GAP_NOT_SETTABLE = L.STATUS_GAP_NOT_SETTABLE
    EFFORT_NOT_SETTABLE = L.STATUS_EFFORT_NOT_SETTABLE
    SPEED_NOT_SETTABLE = L.STATUS_SPEED_NOT_SETTABLE
    PATH_COLLIDES = L.STATUS_PATH_COLLIDES
    PATH_JUMPS = L.STATUS_PATH_JUMPS

    @property
    def is_ok(self) -> bool:
        """``OK`` only: carried out exactly as asked (see :attr:`is_carried_out`)."""
        return self is Status.OK

    @property
    def is_carried_out(self) -> bool:
        """``OK``, ``CLAMPED`` (carried out with a value clamped to the limit) or
        ``ADJUSTED`` (carried out with the orientation turned to one the joints can hold):
        ``limber_status_is_carried_out``."""
        return bool(_c.limber_status_is_carried_out(int(self)))

    def __str__(self) -> str:
        return self.name

    def describe(self) -> str:
        """The short human-readable reason (``limber_status_text``: Rust's
        ``Status::describe``)."""
        raw: bytes = _c.limber_status_text(int(self))
        return raw.decode("utf-8", "replace")


#: Status by wire code; an unknown code reads as ``INVALID_ARGUMENT`` (as in Rust).
_STATUS: "Dict[int, Status]" = {int(s): s for s in Status}


def _status(code: int) -> Status:
    return _STATUS.get(code, Status.INVALID_ARGUMENT)


@dataclass(frozen=True)
class Outcome:
    """The outcome of one of this client's commands with the other client involved (Rust
    ``Outcome``; C ``limber_outcome``)."""

    #: The command's sequence number (its :attr:`Ticket.seq`).
    seq: int
    #: What became of it.
    status: Status
    #: The other client involved: the one whose command preempted it (``PREEMPTED``) or
    #: the one holding the device (``LEASED``); 0 if none.
    other_client: int
    #: The other client's lease name (empty when it holds none).
    other_name: str


@dataclass(frozen=True)
class LeaseHolder:
    """Who holds a device (:meth:`holder`; Rust ``LeaseHolder``)."""

    #: The holder's client id.
    client_id: int
    #: The holder's name.
    name: str
    #: Its heartbeat timeout, seconds.
    timeout: float


class DriverStatus(enum.Enum):
    """Whether the driver of a device is running (Rust ``DriverStatus``)."""

    ALIVE = "alive"
    #: Its process died without cleaning up (found dead and cleaned up now).
    DEAD = "dead"
    #: No driver is attached.
    ABSENT = "absent"


_DRIVER_STATUS = {
    _lib.DRIVER_ALIVE: DriverStatus.ALIVE,
    _lib.DRIVER_DEAD: DriverStatus.DEAD,
    _lib.DRIVER_ABSENT: DriverStatus.ABSENT,
}


class Freshness(enum.Enum):
    """How fresh the latest state is (Rust ``Freshness``)."""

    FRESH = "fresh"
    STALE = "stale"
    GONE = "gone"
    NO_DATA = "no data"


_FRESHNESS = {
    _lib.LIVENESS_ALIVE: Freshness.FRESH,
    _lib.LIVENESS_STALE: Freshness.STALE,
    _lib.LIVENESS_GONE: Freshness.GONE,
    _lib.LIVENESS_NO_DATA: Freshness.NO_DATA,
}


class WaitMode(enum.Enum):
    """How a client waits for states, outcomes and replies (Rust ``WaitMode``)."""

    #: Block on the driver's notification (default; costs a wake-up, frees the CPU), after
    #: polling for the spin budget right after a command or request.
    EVENT = "event"
    #: Busy-poll shared memory (lowest latency; takes a whole core).
    SPIN = "spin"


def default_spin_budget() -> float:
    """The spin budget a new client starts with, seconds (``limber_default_spin_budget_us``,
    Rust ``qos::default_spin_budget``): ``LIMBER_SPIN_US`` if set when the library first
    read it (µs, at most 1 s), else 30 µs on a machine with two or more cores and zero on
    one."""
    us: int = _c.limber_default_spin_budget_us()
    return us / 1e6


class Ticket(NamedTuple):
    """A command that was sent, to wait for its outcome (Rust ``Ticket``). Immutable."""

    #: The command's sequence number (per client, from 1).
    seq: int
    #: How many driver processes received it (normally 1).
    receivers: int


_tuple_new = tuple.__new__


# ----- errors ----------------------------------------------------------------------------


class LimberError(Exception):
    """Base of every limber error (invalid values raise the builtin ``ValueError``)."""


class NoDriverError(LimberError):
    """No driver offers this device in this domain (connect), receives its commands (send),
    or serves its requests (request). ``LIMBER_CODE_NO_DRIVER``."""


class IncompatibleError(LimberError):
    """The device exists but speaks another layout version or is another interface."""


class TransportError(LimberError):
    """iceoryx2 failed, or the domain's files cannot be used (``LIMBER_CODE_TRANSPORT``)."""


class NackError(LimberError):
    """The driver refused a request and said why: :attr:`status`."""

    def __init__(self, status: Status, message: Optional[str] = None) -> None:
        self.status = status
        super().__init__(message or f"refused: {status.describe()} ({status.name})")


class LeaseHeldError(LimberError):
    """Another client holds the device's lease: :attr:`client_id` and :attr:`name`."""

    def __init__(self, client_id: int, name: str, message: Optional[str] = None) -> None:
        self.client_id = client_id
        self.name = name
        super().__init__(
            message or f"held by another client ({name or 'unnamed'}, client {client_id})"
        )


class LeaseLostError(LimberError):
    """The lease this client held was ended by the driver (a missed heartbeat)."""


class RequestTimeout(LimberError, TimeoutError):
    """No reply within the timeout (the driver is alive but did not answer)."""


class WaitTimeout(LimberError, TimeoutError):
    """No new state / no outcome within the timeout (the driver is alive)."""


class DriverGoneError(LimberError):
    """The driver died (or was never there) while waiting."""


class OutcomeMissed(LimberError):
    """The outcome of this command was overwritten before it was read (a later command of
    this client has been applied since). :attr:`newer_seq` is that command's number."""

    def __init__(self, newer_seq: int, message: Optional[str] = None) -> None:
        self.newer_seq = newer_seq
        super().__init__(
            message or f"outcome missed; a later command (seq {newer_seq}) was applied since"
        )


class DecodeError(LimberError):
    """A reply could not be decoded, or was of an unexpected kind
    (``LIMBER_CODE_BAD_REPLY``)."""


class UnexpectedReplyError(DecodeError):
    """The reply was of an unexpected kind (kept for compatibility: liblimber reports it as
    a :class:`DecodeError`)."""


#: The exception of every ``LIMBER_CODE_*`` (a timeout of a request is a
#: :class:`RequestTimeout` instead; a refusal by a lease holder a :class:`LeaseHeldError`).
_ERRORS: "Dict[int, Type[Exception]]" = {
    _lib.CODE_NULL_ARGUMENT: LimberError,
    _lib.CODE_BAD_UTF8: ValueError,
    _lib.CODE_BAD_NAME: ValueError,
    _lib.CODE_NO_DRIVER: NoDriverError,
    _lib.CODE_INCOMPATIBLE: IncompatibleError,
    _lib.CODE_TIMEOUT: WaitTimeout,
    _lib.CODE_DRIVER_GONE: DriverGoneError,
    _lib.CODE_REFUSED: NackError,
    _lib.CODE_INVALID_VALUE: ValueError,
    _lib.CODE_OUTCOME_MISSED: OutcomeMissed,
    _lib.CODE_BORROWED: LimberError,
    _lib.CODE_BAD_REPLY: DecodeError,
    _lib.CODE_TRANSPORT: TransportError,
    _lib.CODE_INTERNAL: LimberError,
    _lib.CODE_LEASE_LOST: LeaseLostError,
}


def _error(code: int, timeout: "Type[LimberError]" = WaitTimeout, newer_seq: int = 0) -> Exception:
    """The exception of a failed call that returned ``code``: its class from
    :data:`_ERRORS`, its message ``limber_last_error()``, and for a refusal
    ``limber_last_refusal()`` and ``limber_last_holder()``."""
    message = _lib.last_error()
    cls = _ERRORS.get(code, LimberError)
    if cls is NackError:
        status = _status(_c.limber_last_refusal())
        if status is Status.LEASED:
            h = _lib.LeaseHolder()
            _c.limber_last_holder(byref(h))
            if h.client_id != 0:
                return LeaseHeldError(h.client_id, _lib.text(h.name), message)
        return NackError(status, message)
    if cls is OutcomeMissed:
        return OutcomeMissed(newer_seq, message)
    if cls is WaitTimeout:
        cls = timeout
    if cls is LimberError and code not in _ERRORS:
        message = f"{message} (unknown limber code {code})"
    return cls(message)


def _check_layout(what: str) -> None:
    """IncompatibleError unless this package's ``_layout.py`` is of the layout version the
    library speaks (``limber_layout_version``)."""
    ours = _c.limber_layout_version()
    if L.LAYOUT_VERSION != ours:
        raise IncompatibleError(
            f"{what} is incompatible: this package's limber/_layout.py is layout version "
            f"{L.LAYOUT_VERSION}, but liblimber ({_lib.path}) speaks layout version {ours}: "
            "use the limber package built with this library"
        )


def _ms(what: str, seconds: float) -> int:
    """Seconds as whole milliseconds (rounded up), for the library; ValueError when it is
    not a finite number >= 0."""
    s = float(seconds)
    if not 0.0 <= s <= 1e9:
        raise ValueError(f"{what} must be a finite number of seconds >= 0, not {seconds!r}")
    return math.ceil(s * 1000.0)
