"""Clients of limber devices: the Python counterpart of ``limber_services::client``.

A client connects to one device (``robot/interface/index``) of a domain, reads its state,
sends commands and makes requests, with the same wire messages and the same semantics as
the Rust ``Client<I>``:

* commands are fire-and-forget; each returns a :class:`Ticket` whose outcome the driver
  publishes on the device's ``outcome`` channel (each client keeps its own) and in a later
  state sample (``header.last_cmd``); :meth:`wait_outcome` waits for it;
* requests wait for the driver's reply (ACK with a typed result, or NACK with a
  :class:`Status`), with a timeout and a liveness check of the driver;
* invalid values (NaN, a joint index outside the array capacity, too many values, a zero
  direction vector) raise :class:`ValueError` before anything is sent.

Every iceoryx2 object (node, services, ports) is owned by the client instance. Call
:meth:`close` (or use ``with``) when done; clients still open at interpreter exit are closed
by an ``atexit`` hook, so no dead node is left behind even for clients kept in module
globals. A client is not thread-safe: use it from the thread that created it.

Example::

    from limber import ActArrayClient, Status

    with ActArrayClient.connect("pioneer/actarray/0", timeout=2.0) as arm:
        print(arm.geometry().actuators_count)
        ticket = arm.move_to(1, 0.25)
        assert arm.wait_outcome(ticket, timeout=2.0) == Status.OK
        print(arm.state().actuators[1].position)
"""

from __future__ import annotations

import atexit
import ctypes
import enum
import itertools
import math
import operator
import os
import re
import stat
import sys
import time
import weakref
from dataclasses import dataclass
from typing import Any, ClassVar, Generic, Iterable, Optional, Sequence, Type, TypeVar

from . import _layout as L

__all__ = [
    "DOMAIN_ENV",
    "DEFAULT_DOMAIN",
    "DEFAULT_REQUEST_TIMEOUT",
    "LIVENESS_PERIOD",
    "Domain",
    "DeviceName",
    "DeviceInfo",
    "list_devices",
    "DriverStatsReader",
    "stats_text",
    "Status",
    "DriverStatus",
    "Freshness",
    "WaitMode",
    "SPIN_BUDGET",
    "SPIN_BUDGET_ENV",
    "default_spin_budget",
    "Ticket",
    "Outcome",
    "LeaseHolder",
    "LeaseHeldError",
    "LeaseLostError",
    "LimberError",
    "NoDriverError",
    "IncompatibleError",
    "TransportError",
    "NackError",
    "RequestTimeout",
    "WaitTimeout",
    "DriverGoneError",
    "OutcomeMissed",
    "DecodeError",
    "UnexpectedReplyError",
    "ActArrayClient",
    "LimbClient",
    "GripperClient",
]

#: The environment variable that selects the domain.
DOMAIN_ENV = "LIMBER_DOMAIN"
#: The domain used when ``LIMBER_DOMAIN`` is not set.
DEFAULT_DOMAIN = "limber"
#: Default time a request waits for its reply, seconds (Rust: ``DEFAULT_REQUEST_TIMEOUT``).
DEFAULT_REQUEST_TIMEOUT = 2.0
#: How often a waiting client checks that the driver is still alive, seconds.
LIVENESS_PERIOD = 0.020

MAX_DOMAIN_LEN = L.NAME_MAX_DOMAIN_LEN
MAX_ROBOT_LEN = L.NAME_MAX_ROBOT_LEN
MAX_ACTUATORS = L.LIMITS_MAX_ACTUATORS
#: Direction vectors shorter than this count as zero (Rust: ``limb::MIN_VECTOR_NORM``).
MIN_VECTOR_NORM = 1e-9

_DRIVER_NODE_PREFIX = "limber-driver:"
_CLIENT_NODE_PREFIX = "limber-client:"
_LAYOUT_ATTR = "limber.layout"
_EVENT_COMMAND = L.WAKE_COMMAND
_EVENT_REQUEST = L.WAKE_REQUEST
_OUTCOME_SLOTS = 16
# Outcomes buffered on the `outcome` channel per client (Rust `qos::OUTCOME_BUFFER`).
_OUTCOME_BUFFER = L.QOS_OUTCOME_BUFFER
_IDENT = re.compile(r"^[A-Za-z0-9_-]+$")


def _iox2() -> Any:
    """The iceoryx2 binding, imported on first use (so the layout classes work without it)."""
    import iceoryx2

    return iceoryx2


def monotonic_ns() -> int:
    """``CLOCK_MONOTONIC`` in ns: the time base of every stamp (as in Rust)."""
    return time.clock_gettime_ns(time.CLOCK_MONOTONIC)


# ----- waiting -------------------------------------------------------------------------

#: The spin budget of a client in event mode when nothing else is configured, seconds, on a
#: machine with two or more cores (Rust ``qos::SPIN_BUDGET``).
SPIN_BUDGET = 30e-6
#: The environment variable that sets the clients' spin budget in µs (``0``: block at once).
SPIN_BUDGET_ENV = "LIMBER_SPIN_US"


def _spin_budget_from(env: Optional[str], cores: int) -> float:
    """The spin budget for ``LIMBER_SPIN_US`` = ``env`` (None: unset) on ``cores`` cores."""
    if env is not None:
        try:
            us = int(env.strip())
        except ValueError:
            us = -1
        if us >= 0:
            return min(us, 1_000_000) / 1e6
        import warnings

        warnings.warn(
            f"{SPIN_BUDGET_ENV}={env!r} is not a number of microseconds: using the default",
            stacklevel=3,
        )
    return SPIN_BUDGET if cores >= 2 else 0.0


def default_spin_budget() -> float:
    """The default spin budget of a client in event mode, seconds (Rust
    ``qos::default_spin_budget``): ``LIMBER_SPIN_US`` if set (µs, at most 1 s), else
    :data:`SPIN_BUDGET` on a machine with two or more cores and zero on one core (where a
    spinning client would only delay the driver it waits for)."""
    return _spin_budget_from(os.environ.get(SPIN_BUDGET_ENV), os.cpu_count() or 1)


class WaitMode(enum.Enum):
    """How a client waits for states, outcomes and replies (Rust ``WaitMode``)."""

    #: Block on the driver's notification (default; costs a wake-up, frees the CPU), after
    #: polling for the spin budget right after a command or request.
    EVENT = "event"
    #: Busy-poll shared memory (lowest latency; takes a whole core).
    SPIN = "spin"


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

    @property
    def is_ok(self) -> bool:
        """``OK`` only: carried out exactly as asked (see :attr:`is_carried_out`)."""
        return self is Status.OK

    @property
    def is_carried_out(self) -> bool:
        """``OK``, ``CLAMPED`` (carried out with a value clamped to the limit) or
        ``ADJUSTED`` (carried out with the orientation turned to one the joints can hold)."""
        return self in (Status.OK, Status.CLAMPED, Status.ADJUSTED)

    def __str__(self) -> str:
        return self.name

    def describe(self) -> str:
        """The short human-readable reason (the same text as Rust's ``Status::describe``)."""
        return L.DESCRIBE_STATUS[int(self)]


@dataclass(frozen=True)
class Outcome:
    """The outcome of one of this client's commands (Rust ``Outcome``)."""

    #: The command's sequence number (its :attr:`Ticket.seq`).
    seq: int
    #: What became of it.
    status: Status
    #: The other client involved: the one whose command preempted it (``PREEMPTED``) or
    #: the one holding the device (``LEASED``); 0 if none.
    other_client: int
    #: The other client's name, when it holds the device's lease (empty otherwise).
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


def _name_of(field: "ctypes.Array[ctypes.c_uint8]") -> str:
    """A 32-byte NUL-padded name field (undecodable bytes replaced)."""
    raw = bytes(field)
    end = raw.find(b"\0")
    return (raw if end < 0 else raw[:end]).decode("utf-8", "replace")


class DriverStatus(enum.Enum):
    """Whether the driver of a device is running (Rust ``DriverStatus``)."""

    ALIVE = "alive"
    #: Its process died without cleaning up (found dead and cleaned up now).
    DEAD = "dead"
    #: No driver is attached.
    ABSENT = "absent"


class Freshness(enum.Enum):
    """How fresh the latest state is (Rust ``Freshness``)."""

    FRESH = "fresh"
    STALE = "stale"
    GONE = "gone"
    NO_DATA = "no data"


@dataclass(frozen=True)
class Ticket:
    """A command that was sent, to wait for its outcome (Rust ``Ticket``)."""

    #: The command's sequence number (per client, from 1).
    seq: int
    #: How many driver processes received it (normally 1).
    receivers: int


# ----- errors ----------------------------------------------------------------------------


class LimberError(Exception):
    """Base of every limber error (invalid values raise the builtin ``ValueError``)."""


class NoDriverError(LimberError):
    """No driver offers this device in this domain (connect), receives its commands (send),
    or serves its requests (request). Rust: ``ConnectError::NoDriver``,
    ``CommandError::NoDriver``, ``RequestError::NoDriver``."""


class IncompatibleError(LimberError):
    """The device exists but speaks another layout version or is another interface."""


class TransportError(LimberError):
    """iceoryx2 failed (opening a service, creating a port, loaning, sending, receiving)."""


class NackError(LimberError):
    """The driver refused a request (NACK) and said why: :attr:`status`."""

    def __init__(self, status: Status) -> None:
        self.status = status
        super().__init__(f"refused: {status.describe()} ({status.name})")


class LeaseHeldError(LimberError):
    """Another client holds the device's lease: :attr:`client_id` and :attr:`name`."""

    def __init__(self, client_id: int, name: str) -> None:
        self.client_id = client_id
        self.name = name
        super().__init__(f"the device is held by {name or '?'} (client {client_id:#x})")


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

    def __init__(self, newer_seq: int) -> None:
        self.newer_seq = newer_seq
        super().__init__(f"outcome missed; a later command (seq {newer_seq}) was applied since")


class DecodeError(LimberError):
    """A reply could not be decoded (driver of another layout, or corrupted)."""


class UnexpectedReplyError(DecodeError):
    """The reply was an ACK of an unexpected kind."""


# ----- names -----------------------------------------------------------------------------


RUNTIME_DIR_ENV = "LIMBER_RUNTIME_DIR"
GROUP_ENV = "LIMBER_GROUP"


def _runtime_dir() -> str:
    """``$LIMBER_RUNTIME_DIR``, else ``/tmp/limber-<uid>`` (as in Rust's ``domain_dir``).

    Group mode (``LIMBER_GROUP``) is refused: the Python client does not open the files
    iceoryx2 makes to the group, so the other members could not use them."""
    group = os.environ.get(GROUP_ENV)
    if group:
        raise TransportError(
            f"LIMBER_GROUP={group} asks for group mode, which the Python client does not "
            "support (it would not open its files to the group's other members): use the "
            "limber command line, the Rust or the C API, or unset LIMBER_GROUP (README, Security)"
        )
    return os.environ.get(RUNTIME_DIR_ENV) or f"/tmp/limber-{os.geteuid()}"


def _foreign(path: str, uid: int) -> "TransportError":
    return TransportError(
        f"{path} belongs to uid {uid}, not to you (uid {os.geteuid()}): limber does not use "
        "files another user controls; remove it, or set LIMBER_RUNTIME_DIR to a directory "
        "of your own"
    )


def _private_dir(path: str, mode: int) -> None:
    try:
        os.mkdir(path, mode)
    except FileExistsError:
        pass
    st = os.lstat(path)
    if not stat.S_ISDIR(st.st_mode):
        raise TransportError(f"{path} is not a directory (a symbolic link or a file)")
    if st.st_uid != os.geteuid():
        raise _foreign(path, st.st_uid)
    if stat.S_IMODE(st.st_mode) != mode:
        os.chmod(path, mode)


def _domain_token(directory: str, domain: str) -> str:
    path = os.path.join(directory, f"{domain}.token")
    if not os.path.lexists(path):
        token = os.urandom(8).hex()
        # Unique to this attempt (several threads of a process may race too).
        tmp = os.path.join(directory, f".{domain}.token.{os.getpid()}.{token}")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(token + "\n")
        try:
            os.link(tmp, path)  # never replaces: the first process to make the token wins
        except FileExistsError:
            pass
        finally:
            os.unlink(tmp)
    st = os.lstat(path)
    if not stat.S_ISREG(st.st_mode):
        raise TransportError(f"{path} does not hold a domain token")
    if st.st_uid != os.geteuid():
        raise _foreign(path, st.st_uid)
    with open(path) as f:
        token = f.read().strip()
    if not re.fullmatch(r"[0-9a-fA-F]{16}", token):
        raise TransportError(f"{path} does not hold a domain token (16 hexadecimal digits)")
    return token


def _global_mgmt_files(prefix: str) -> "list[str]":
    try:
        names = os.listdir("/dev/shm")
    except OSError:
        return []
    return [
        os.path.join("/dev/shm", n)
        for n in names
        if n.startswith(prefix) and n.endswith(".global_mgmt")
    ]


def _join_domain(domain: "Domain", node_name: str) -> Any:
    """A node named `node_name` in `domain` (iceoryx2's signal handling off: the program's
    own handlers stay in charge), with the domain's node counter narrowed to the owner."""
    iox2 = _iox2()
    try:
        node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(node_name))
            .config(domain.iceoryx2_config())
            .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
            .create(iox2.ServiceType.Ipc)
        )
    except Exception as e:
        raise TransportError(f"cannot join domain {domain}: {e!r}") from None
    _secure_shm(domain.prefix)
    return node


def _open_error_kind(e: BaseException) -> Optional[str]:
    """The iceoryx2 variant of a failed service open (``"DoesNotExist"``,
    ``"IncompatibleTypes"``, ...), or None for any other error.

    The PyPI binding raises one exception class per operation and carries the Rust enum's
    variant as its only argument (``PublishSubscribeOpenError('DoesNotExist')``): that
    variant is the typed cause, read here instead of the error's text.
    """
    iox2 = _iox2()
    opens = (iox2.PublishSubscribeOpenError, iox2.RequestResponseOpenError, iox2.EventOpenError)
    if isinstance(e, opens) and len(e.args) == 1 and isinstance(e.args[0], str):
        return e.args[0]
    return None


def _secure_shm(prefix: str) -> None:
    """Refuses a node counter of the domain owned by someone else; narrows ours to 0600
    (iceoryx2 makes it 0666)."""
    for path in _global_mgmt_files(prefix):
        st = os.lstat(path)
        if st.st_uid != os.geteuid():
            raise _foreign(path, st.st_uid)
        if stat.S_IMODE(st.st_mode) & 0o077:
            os.chmod(path, 0o600)


class Domain:
    """A domain: the set of devices and clients that can see each other.

    ``Domain()`` is the domain named by ``LIMBER_DOMAIN`` (default ``limber``); ``Domain(name)``
    a domain by name (1 to 48 characters of ``[A-Za-z0-9_-]``). As in Rust, its files live in
    the owner's runtime directory (``$LIMBER_RUNTIME_DIR``, else ``/tmp/limber-<uid>``, mode
    0711) under the iceoryx2 root path ``<runtime>/iceoryx2/`` with the prefix
    ``limber_<token>_``, where the token is random and kept in ``<runtime>/<name>.token``
    (0600), on top of iceoryx2's built-in defaults (a ``./config/iceoryx2.toml`` is ignored).
    """

    __slots__ = ("_name", "_prefix")

    def __init__(self, name: Optional[str] = None) -> None:
        if name is None:
            name = os.environ.get(DOMAIN_ENV) or DEFAULT_DOMAIN
        if not isinstance(name, str) or len(name) > MAX_DOMAIN_LEN or not _IDENT.match(name):
            raise ValueError(f"invalid domain {name!r}: use 1 to {MAX_DOMAIN_LEN} characters of [A-Za-z0-9_-]")
        self._name = name
        self._prefix: Optional[str] = None

    @classmethod
    def from_env(cls) -> "Domain":
        """The domain named by ``LIMBER_DOMAIN``, or ``limber``."""
        return cls(None)

    @property
    def name(self) -> str:
        return self._name

    @property
    def root_path(self) -> str:
        """The iceoryx2 root path of this domain (``<runtime>/iceoryx2/``)."""
        return os.path.join(_runtime_dir(), "iceoryx2") + "/"

    @property
    def prefix(self) -> str:
        """The iceoryx2 prefix of this domain (``limber_<token>_``; prepares the files)."""
        if self._prefix is None:
            runtime = _runtime_dir()
            _private_dir(runtime, 0o711)
            prefix = f"limber_{_domain_token(runtime, self._name)}_"
            for path in _global_mgmt_files(prefix):
                st = os.lstat(path)
                if st.st_uid != os.geteuid():
                    raise _foreign(path, st.st_uid)
            _private_dir(os.path.join(runtime, "iceoryx2"), 0o700)
            self._prefix = prefix
        return self._prefix

    def iceoryx2_config(self) -> Any:
        """A fresh iceoryx2 config for this domain (defaults plus its root path and prefix)."""
        iox2 = _iox2()
        cfg = iox2.config.default()
        prefix = self.prefix
        cfg.global_cfg.prefix = iox2.FileName.new(prefix)
        cfg.global_cfg.root_path = iox2.Path.new(self.root_path)
        return cfg

    def __str__(self) -> str:
        return self._name

    def __repr__(self) -> str:
        return f"Domain({self._name!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Domain) and other._name == self._name

    def __hash__(self) -> int:
        return hash(self._name)


_INTERFACES = ("actarray", "limb", "gripper")


@dataclass(frozen=True)
class DeviceName:
    """The name of a device: ``robot/interface/index``, e.g. ``pioneer/actarray/0``."""

    robot: str
    interface: str
    index: int

    @classmethod
    def parse(cls, s: str) -> "DeviceName":
        parts = s.split("/") if isinstance(s, str) else []
        bad = ValueError(
            f"invalid device name {s!r}: expected robot/interface/index, e.g. "
            "pioneer/actarray/0 (interfaces: actarray, limb, gripper)"
        )
        if len(parts) != 3:
            raise bad
        robot, iface, index = parts
        if iface not in _INTERFACES or not index.isdigit() or not index.isascii():
            raise bad
        n = int(index)
        if n > 0xFFFF:
            raise bad
        if len(robot) > MAX_ROBOT_LEN or not _IDENT.match(robot):
            raise ValueError(
                f"invalid robot name {robot!r}: use 1 to {MAX_ROBOT_LEN} characters of [A-Za-z0-9_-]"
            )
        return cls(robot, iface, n)

    def service_name(self, channel: str) -> str:
        """The iceoryx2 service name of one channel (data, cmd, req, wake, notify)."""
        return f"limber/{self.robot}/{self.interface}/{self.index}/{channel}"

    def __str__(self) -> str:
        return f"{self.robot}/{self.interface}/{self.index}"


# ----- discovery -------------------------------------------------------------------------

_DRIVER_ATTR = "limber.driver"


@dataclass(frozen=True)
class DeviceInfo:
    """One device found in a domain (Rust ``discovery::DeviceInfo``)."""

    #: Its name (``robot/interface/index``).
    name: DeviceName
    #: The driver that offers it (its ``limber.driver`` attribute).
    driver: str
    #: The layout version it speaks.
    layout: str
    #: True while the driver's process lives.
    alive: bool
    #: Processes attached to its state channel (driver and clients).
    nodes: int

    @property
    def interface(self) -> str:
        """The interface: ``actarray``, ``limb`` or ``gripper``."""
        return self.name.interface


def list_devices(domain: "Optional[Domain | str]" = None) -> "list[DeviceInfo]":
    """Every device of ``domain`` (default: from ``LIMBER_DOMAIN``), sorted by name, as
    ``limber list`` shows them. A device whose driver died is listed as not alive until its
    services are cleaned up. Raises :class:`TransportError` when the domain cannot be read."""
    iox2 = _iox2()
    dom = domain if isinstance(domain, Domain) else Domain(domain)
    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
    try:
        _secure_shm(dom.prefix)
        services = iox2.Service.list(dom.iceoryx2_config(), iox2.ServiceType.Ipc)
    except LimberError:
        raise
    except Exception as e:
        raise TransportError(f"cannot list the services of domain {dom}: {e!r}") from None
    out = []
    for details in services:
        try:
            if details.messaging_pattern() != iox2.MessagingPattern.PublishSubscribe:
                continue
            parts = details.name().to_string().split("/")
            if len(parts) != 5 or parts[0] != "limber" or parts[4] != "data":
                continue
            try:
                name = DeviceName.parse("/".join(parts[1:4]))
            except ValueError:
                continue
            attrs = {
                a.key.to_string(): a.value.to_string() for a in details.attributes().values
            }
            nodes = details.nodes()
        except Exception as e:
            raise TransportError(f"cannot read the services of domain {dom}: {e!r}") from None
        alive = False
        for n in nodes:
            if isinstance(n, iox2.NodeState.Alive):
                try:
                    node_details = n[0].details
                    is_driver = node_details is not None and node_details.name.as_str().startswith(
                        _DRIVER_NODE_PREFIX
                    )
                except Exception:
                    is_driver = False
                alive = alive or is_driver
        out.append(
            DeviceInfo(
                name=name,
                driver=attrs.get(_DRIVER_ATTR, ""),
                layout=attrs.get(_LAYOUT_ATTR, ""),
                alive=alive,
                nodes=len(nodes),
            )
        )
    out.sort(key=lambda d: (d.name.robot, _INTERFACES.index(d.name.interface), d.name.index))
    return out


def _why_incompatible(dev: DeviceName, domain: Domain) -> str:
    """Why a device's services did not open with this client's types: the layout version its
    driver speaks (the ``limber.layout`` attribute of its services) against this client's."""
    ours = L.LAYOUT_VERSION
    try:
        theirs = next((d.layout for d in list_devices(domain) if d.name == dev), "")
    except LimberError:
        theirs = ""
    if theirs and theirs != str(ours):
        return (
            f"its driver speaks layout version {theirs}, this client layout version {ours} "
            f"(limber/_layout.py): use the limber package of the driver's release"
        )
    return f"its services do not have this client's types of layout version {ours}"


# ----- validation (the Rust constructors' rules) -----------------------------------------


def _finite(field: str, v: Any) -> float:
    f = float(v)
    if not math.isfinite(f):
        raise ValueError(f"{field} is not finite")
    return f


def _joint(j: Any) -> int:
    """A joint index within the array capacity (0..32), as Rust's ``joint()``."""
    if isinstance(j, bool):
        raise TypeError("a joint index must be an int, not bool")
    i: int = operator.index(j)
    if not 0 <= i < MAX_ACTUATORS:
        raise ValueError(f"joint {i} is not a valid joint index (0..{MAX_ACTUATORS})")
    return i


def _joint_sel(j: Any) -> int:
    """``None`` (every joint, -1 on the wire) or a joint index."""
    return -1 if j is None else _joint(j)


def _values(field: str, values: Iterable[Any]) -> "list[float]":
    vs = list(values)
    if len(vs) > MAX_ACTUATORS:
        raise ValueError(f"{field}: {len(vs)} values, at most {MAX_ACTUATORS} allowed")
    out = [float(v) for v in vs]
    if not all(math.isfinite(v) for v in out):
        raise ValueError(f"{field} is not finite")
    return out


def _vec3(field: str, v: Sequence[Any]) -> "L.Vec3":
    vs = list(v)
    if len(vs) != 3:
        raise ValueError(f"{field} needs 3 components, got {len(vs)}")
    x, y, z = (float(c) for c in vs)
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise ValueError(f"{field} is not finite")
    return L.Vec3(x, y, z)


def _direction(field: str, v: Sequence[Any]) -> "L.Vec3":
    d = _vec3(field, v)
    if math.sqrt(d.x * d.x + d.y * d.y + d.z * d.z) < MIN_VECTOR_NORM:
        raise ValueError(f"{field} has zero length")
    return d


_S = TypeVar("_S", bound=ctypes.Structure)


def _copy(cls: "Type[_S]", ptr: int) -> _S:
    """A copy of the ``cls`` struct at address ``ptr``."""
    out = cls()
    ctypes.memmove(ctypes.addressof(out), ptr, ctypes.sizeof(cls))
    return out


def _body(cls: "Type[_S]", raw_body: Any) -> _S:
    """The ``cls`` struct at the front of an envelope's ``body`` (a copy)."""
    return cls.from_buffer_copy(bytes(raw_body)[: ctypes.sizeof(cls)])


def _all_finite(*vals: float) -> bool:
    return all(math.isfinite(v) for v in vals)


# ----- the generic client ----------------------------------------------------------------

_client_seq = itertools.count(1)
_open_clients: "weakref.WeakSet[Any]" = weakref.WeakSet()


def _new_client_id() -> int:
    """Process id in the high 32 bits, a per-process counter in the low 32 bits (as Rust's
    ``Context::new_client_id``): unique in the domain while this process lives, never 0."""
    return ((os.getpid() & 0xFFFFFFFF) << 32) | (next(_client_seq) & 0xFFFFFFFF)


def _default_process_name() -> str:
    name = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "python"
    return name[:64]


#: The state type of a client (``ActArrayData``, ``LimbData``, ``GripperData``).
_D = TypeVar("_D", bound=ctypes.Structure)
_C = TypeVar("_C", bound="_Client[Any]")


class _Client(Generic[_D]):
    """A connection to one device. Use :class:`ActArrayClient`, :class:`LimbClient` or
    :class:`GripperClient`."""

    INTERFACE: ClassVar[str]
    DATA: ClassVar[type]
    CMD_MSG: ClassVar[type]
    REQ_MSG: ClassVar[type]
    REPLY_MSG: ClassVar[type]

    # iceoryx2 objects (the binding has no types: Any), None until connected or once closed.
    _lease_port: Any
    _node: Any
    _data_svc: Any
    _states: Any
    _commands: Any
    _req_svc: Any
    _requests: Any
    _wake: Any
    _notify_svc: Any
    _notify: Any
    _outcome_sub: Any
    _lease_held: "Optional[tuple[float, float]]"  # heartbeat, last renewal
    _latest: "Optional[_D]"

    def __init__(self) -> None:  # use connect()
        self._closed = True
        self._lease_port = None
        self._lease_held = None
        self._node = None
        self._data_svc = None
        self._states = None
        self._commands = None
        self._req_svc = None
        self._requests = None
        self._wake = None
        self._notify_svc = None
        self._notify = None

    # ----- connecting -------------------------------------------------------------------

    @classmethod
    def connect(
        cls: Type[_C],
        device: str,
        domain: "Domain | str | None" = None,
        timeout: float = 0.0,
        *,
        name: Optional[str] = None,
        request_timeout: float = DEFAULT_REQUEST_TIMEOUT,
        wake_driver: bool = True,
    ) -> _C:
        """Connects to ``device`` (``robot/interface/index``) in ``domain`` (a :class:`Domain`,
        a domain name, or ``None`` for ``LIMBER_DOMAIN``/``limber``).

        With ``timeout == 0`` (default) it fails at once with :class:`NoDriverError` if no
        driver offers the device (Rust ``Client::connect``); with ``timeout > 0`` it waits up
        to that many seconds for a driver (Rust ``Client::connect_timeout``).

        Raises ``ValueError`` for an invalid name, :class:`IncompatibleError` for another
        interface or layout version, :class:`TransportError` if iceoryx2 fails.
        ``name`` names this process in ``limber list`` (default: the script's name).
        """
        dev = DeviceName.parse(device)
        if dev.interface != cls.INTERFACE:
            raise IncompatibleError(
                f"{dev} is incompatible: it is a {dev.interface} device, not a {cls.INTERFACE}"
            )
        dom = domain if isinstance(domain, Domain) else Domain(domain)
        deadline = time.monotonic() + max(0.0, float(timeout))
        proc_name = name or _default_process_name()
        while True:
            self = cls()
            try:
                self._open(dev, dom, proc_name)
            except LimberError as e:
                err = e
            except BaseException:
                self.close()
                raise
            else:
                self.request_timeout = float(request_timeout)
                self.wake_driver = bool(wake_driver)
                return self
            self.close()
            if isinstance(err, NoDriverError) and time.monotonic() < deadline:
                time.sleep(0.020)
                continue
            # Drop the failed attempt's frames (they still name iceoryx2 objects) so that
            # a caller keeping the exception does not keep a node alive.
            err.__context__ = err.__cause__ = None
            raise err.with_traceback(None)

    def _open(self, dev: DeviceName, domain: Domain, proc_name: str) -> None:
        iox2 = _iox2()
        self._device = dev
        self._domain = domain
        self._client_id = _new_client_id()
        self._cmd_seq = 0
        self._req_seq = 0
        self._outcomes = [(0, 0)] * _OUTCOME_SLOTS
        self._preemptions = [Outcome(0, Status.OK, 0, "")] * _OUTCOME_SLOTS
        self._lease_port = None
        self._lease_seq = 0
        self._lease_held = None
        self._latest = None
        self.request_timeout = DEFAULT_REQUEST_TIMEOUT
        self.wake_driver = True
        self._wait_mode = WaitMode.EVENT
        self._spin_budget = default_spin_budget()
        self._spin_until: Optional[float] = None
        iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
        node_name = (_CLIENT_NODE_PREFIX + proc_name)[: iox2.NodeName.max_len()]
        self._node = _join_domain(domain, node_name)
        self._closed = False
        _open_clients.add(self)

        def fail(channel: str, e: Exception) -> LimberError:
            kind = _open_error_kind(e)
            if kind == "DoesNotExist":
                return NoDriverError(
                    f"no driver offers {dev} in domain {domain} "
                    f"(is the driver running? is {DOMAIN_ENV} the same?)"
                )
            if kind is not None and kind.startswith("Incompatible"):
                return IncompatibleError(f"{dev} is incompatible: {_why_incompatible(dev, domain)} ({channel}: {e!r})")
            return TransportError(f"{dev}: cannot open the {channel} channel: {e!r}")

        layout = iox2.AttributeVerifier.new().require(
            iox2.AttributeKey.new(_LAYOUT_ATTR), iox2.AttributeValue.new(str(L.LAYOUT_VERSION))
        )
        name = dev.service_name
        # Open, never create; same types and attributes as the Rust client, QoS left to the
        # driver (an opener's unset values are not checked).
        try:
            self._data_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("data")))
                .publish_subscribe(self.DATA)
                .open_with_attributes(layout)
            )
            self._states = self._data_svc.subscriber_builder().create()
        except Exception as e:
            raise fail("data", e) from None
        try:
            cmd_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("cmd")))
                .publish_subscribe(self.CMD_MSG)
                .open_with_attributes(layout)
            )
            self._commands = cmd_svc.publisher_builder().max_loaned_samples(1).create()
            del cmd_svc
        except Exception as e:
            raise fail("cmd", e) from None
        try:
            self._req_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("req")))
                .request_response(self.REQ_MSG, self.REPLY_MSG)
                .enable_fire_and_forget_requests(False)
                .open_with_attributes(layout)
            )
            self._requests = self._req_svc.client_builder().create()
        except Exception as e:
            raise fail("req", e) from None
        try:
            wake_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("wake")))
                .event()
                .open_with_attributes(layout)
            )
            self._wake = wake_svc.notifier_builder().create()
            del wake_svc
        except Exception as e:
            raise fail("wake", e) from None
        try:
            # Every outcome of the device, each client keeping its own (layout version 2):
            # an outcome is never lost because other clients' commands came in between.
            out_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("outcome")))
                .publish_subscribe(L.OutcomeMsg)
                .open_with_attributes(layout)
            )
            self._outcome_sub = out_svc.subscriber_builder().buffer_size(_OUTCOME_BUFFER).create()
            del out_svc
        except Exception as e:
            raise fail("outcome", e) from None
        try:
            self._notify_svc = (
                self._node.service_builder(iox2.ServiceName.new(name("notify")))
                .event()
                .open_with_attributes(layout)
            )
        except Exception as e:
            raise fail("notify", e) from None

    # ----- lifetime ---------------------------------------------------------------------

    def close(self) -> None:
        """Releases the lease if held, then every port and the node (idempotent). The client
        is unusable afterwards."""
        if self.__dict__.get("_lease_held") is not None and not self.__dict__.get("_closed", True):
            try:
                self.release()
            except LimberError as e:
                import warnings

                warnings.warn(f"{self._device}: cannot release the lease: {e}", stacklevel=2)
        for attr in ("_lease_port", "_notify", "_wake", "_requests", "_commands", "_outcome_sub", "_states"):
            port = self.__dict__.get(attr)
            if port is not None:
                try:
                    port.delete()
                except Exception:
                    pass
            self.__dict__[attr] = None
        for attr in ("_notify_svc", "_req_svc", "_data_svc", "_node"):
            self.__dict__[attr] = None
        if not self.__dict__.get("_closed", True):
            self._closed = True
            _open_clients.discard(self)

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self: _C) -> _C:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass

    def __repr__(self) -> str:
        dev = self.__dict__.get("_device", "?")
        state = "closed" if self.__dict__.get("_closed", True) else "open"
        return f"<{type(self).__name__} {dev} {state}>"

    def _check_open(self) -> None:
        if self._closed:
            raise LimberError(f"{type(self).__name__} is closed")

    # ----- identity ---------------------------------------------------------------------

    @property
    def device(self) -> DeviceName:
        return self._device

    @property
    def domain(self) -> Domain:
        return self._domain

    @property
    def client_id(self) -> int:
        """This client's id (carried in every command and request it sends)."""
        return self._client_id

    # ----- state ------------------------------------------------------------------------

    def refresh(self) -> bool:
        """Takes every state sample that arrived; returns True if there was a new one."""
        self._check_open()
        got = False
        last: "Optional[_D]" = None
        while True:
            try:
                s = self._states.receive()
            except Exception as e:
                raise TransportError(f"receiving failed: {e!r}") from None
            if s is None:
                break
            try:
                ptr = s.payload_ptr
                h = L.StateHeader.from_address(ptr)  # the header is at offset 0
                if h.last_cmd.client_id == self._client_id:
                    seq = h.last_cmd.cmd_seq
                    self._outcomes[seq % _OUTCOME_SLOTS] = (seq, h.last_cmd.status)
                last = _copy(self.DATA, ptr)
                got = True
            finally:
                s.delete()
        if last is not None:
            self._latest = last
        self._take_outcomes()
        return got

    def _take_outcomes(self) -> None:
        """Takes the outcomes that arrived on the ``outcome`` channel, keeping this
        client's own (a ``PREEMPTED`` one is a second outcome of a command carried out, not
        its first)."""
        while True:
            try:
                s = self._outcome_sub.receive()
            except Exception as e:
                raise TransportError(f"receiving failed: {e!r}") from None
            if s is None:
                return
            try:
                o = L.OutcomeMsg.from_address(s.payload_ptr)
                if o.client_id == self._client_id and o.status != L.STATUS_PREEMPTED:
                    seq = o.cmd_seq
                    self._outcomes[seq % _OUTCOME_SLOTS] = (seq, o.status)
                elif o.client_id == self._client_id:
                    self._preemptions[o.cmd_seq % _OUTCOME_SLOTS] = Outcome(
                        o.cmd_seq, Status.PREEMPTED, o.other_client, _name_of(o.other_name)
                    )
            finally:
                s.delete()

    def state(self) -> Optional[_D]:
        """The latest state, after taking what arrived: a *copy* of the ``*Data`` ctypes
        struct (``ActArrayData``, ``LimbData``, ``GripperData``; same fields as in Rust), or
        ``None`` if no sample arrived yet."""
        self.refresh()
        return self._latest

    def last_state(self) -> Optional[_D]:
        """The latest state already taken, without looking for a newer one."""
        return self._latest

    def state_age(self) -> Optional[float]:
        """Age of the latest state in seconds: now minus its acquisition time."""
        if self._latest is None:
            return None
        stamp: int = self._latest.header.stamp_ns
        return max(0, monotonic_ns() - stamp) / 1e9

    def freshness(self, max_age: float) -> Freshness:
        """Fresh (younger than ``max_age`` s), stale (older, driver alive), gone, or no data."""
        self.refresh()
        age = self.state_age()
        if age is None:
            return Freshness.NO_DATA
        if age <= max_age:
            return Freshness.FRESH
        return Freshness.STALE if self.driver_status() is DriverStatus.ALIVE else Freshness.GONE

    def wait_state(self, timeout: float) -> _D:
        """Waits up to ``timeout`` s for a state sample newer than the latest one taken and
        returns it (a copy). Raises :class:`WaitTimeout` or :class:`DriverGoneError`."""
        self._check_open()
        deadline = time.monotonic() + timeout
        next_check = time.monotonic() + LIVENESS_PERIOD
        while True:
            if self.refresh() and self._latest is not None:
                return self._latest
            now = time.monotonic()
            if now >= deadline:
                raise WaitTimeout(f"no state within {timeout} s")
            if now >= next_check:
                next_check = now + LIVENESS_PERIOD
                if self.driver_status() is not DriverStatus.ALIVE:
                    raise DriverGoneError("the driver is gone")
            self._pause(min(deadline, next_check))

    def wait_outcome(self, ticket: Ticket, timeout: float) -> Status:
        """Waits up to ``timeout`` s for the outcome of the command of ``ticket``, as
        published by the driver, and returns its :class:`Status` (``Status.OK`` if carried
        out). Raises :class:`OutcomeMissed`, :class:`WaitTimeout` or :class:`DriverGoneError`."""
        self._check_open()
        deadline = time.monotonic() + timeout
        next_check = time.monotonic() + LIVENESS_PERIOD
        while True:
            self.refresh()
            seq, status = self._outcomes[ticket.seq % _OUTCOME_SLOTS]
            if seq == ticket.seq:
                try:
                    return Status(status)
                except ValueError:
                    return Status.INVALID_ARGUMENT  # as Rust: an unknown code
            d = self._latest
            if (
                d is not None
                and d.header.last_cmd.client_id == self._client_id
                and d.header.last_cmd.cmd_seq > ticket.seq
            ):
                raise OutcomeMissed(d.header.last_cmd.cmd_seq)
            now = time.monotonic()
            if now >= deadline:
                raise WaitTimeout(f"no outcome of command {ticket.seq} within {timeout} s")
            if now >= next_check:
                next_check = now + LIVENESS_PERIOD
                if self.driver_status() is not DriverStatus.ALIVE:
                    raise DriverGoneError("the driver is gone")
            self._pause(min(deadline, next_check))

    @property
    def wait_mode(self) -> WaitMode:
        """How this client waits (default :attr:`WaitMode.EVENT`)."""
        return self._wait_mode

    def set_wait_mode(self, mode: WaitMode) -> None:
        """Sets how this client waits for states, outcomes and replies."""
        if not isinstance(mode, WaitMode):
            raise ValueError(f"wait mode must be a WaitMode, not {mode!r}")
        self._wait_mode = mode

    @property
    def spin_budget(self) -> float:
        """The spin budget in seconds (see :meth:`set_spin_budget`)."""
        return self._spin_budget

    def set_spin_budget(self, seconds: float) -> None:
        """In :attr:`WaitMode.EVENT`, how long a wait that follows a command or request polls
        (yielding the CPU) before it blocks (default :func:`default_spin_budget`; zero: block
        at once). The answer of a driver that is awake then arrives without a wake-up of this
        process, at the price of up to this much CPU time per exchange."""
        s = float(seconds)
        if not math.isfinite(s) or s < 0:
            raise ValueError(f"spin budget must be a finite number of seconds >= 0, not {seconds!r}")
        self._spin_budget = s
        self._spin_until = None  # a window opened under the old budget ends now

    def _sent(self) -> None:
        """Starts the busy-poll window of a send."""
        self._spin_until = time.monotonic() + self._spin_budget if self._spin_budget > 0 else None

    def _pause(self, until: float) -> None:
        """Blocks (event mode) or polls once (spin mode) until ``until`` (time.monotonic) or
        the driver's next notification."""
        if self._wait_mode is WaitMode.SPIN:
            return
        if self._spin_until is not None:
            # Right after a send: poll for the answer of a driver that is awake, yielding
            # the CPU so that a driver sharing this core runs at once.
            if time.monotonic() < min(self._spin_until, until):
                os.sched_yield()
                return
            self._spin_until = None
        iox2 = _iox2()
        if self._notify is None:
            try:
                self._notify = self._notify_svc.listener_builder().create()
            except Exception as e:
                raise TransportError(f"cannot listen for notifications: {e!r}") from None
            return  # something may have arrived before the listener existed
        left = until - time.monotonic()
        if left <= 0:
            return
        try:
            self._notify.timed_wait(iox2.Duration.from_secs_f64(left))
        except Exception as e:
            raise TransportError(f"waiting failed: {e!r}") from None

    # ----- ownership --------------------------------------------------------------------

    def preempted(self, ticket: Ticket) -> Optional[Outcome]:
        """Whether the motion that the command of ``ticket`` started was cut short by another
        client's command: its :class:`Outcome` (with the other client, and its name if it
        held the device), or None. Looks at what arrived; remembers the last 16 commands."""
        self.refresh()
        p = self._preemptions[ticket.seq % _OUTCOME_SLOTS]
        return p if p.seq == ticket.seq else None

    def acquire(self, name: str, heartbeat: float) -> None:
        """Takes the device: until :meth:`release` (or :meth:`close`), other clients'
        commands, and their requests that change the device, are refused with ``LEASED``
        naming ``name``; readers are unaffected. The lease lives as long as this client
        renews it (:meth:`renew`, :meth:`keep_lease`) at least every ``heartbeat`` seconds,
        and as long as its process lives: otherwise the driver stops the device and frees it.
        Raises :class:`LeaseHeldError` when another client holds it."""
        hb = float(heartbeat)
        if not math.isfinite(hb) or hb <= 0:
            raise ValueError(f"heartbeat must be a finite number of seconds > 0, not {heartbeat!r}")
        if not isinstance(name, str) or len(name.encode("utf-8")) > 31:
            raise ValueError(f"lease name must be a string of at most 31 bytes, not {name!r}")
        reply = self._lease_call(L.LEASE_OP_ACQUIRE, min(int(hb * 1e9), 2**64 - 1), name)
        if reply.status == L.STATUS_OK and reply.holder_client == self._client_id:
            self._lease_held = (hb, time.monotonic())
            return
        raise self._lease_refusal(reply)

    def renew(self) -> None:
        """The heartbeat: tells the driver this holder is alive. Raises
        :class:`LeaseLostError` when the driver ended the lease."""
        reply = self._lease_call(L.LEASE_OP_RENEW, 0, "")
        if reply.status == L.STATUS_OK and reply.holder_client == self._client_id:
            if self._lease_held is not None:
                self._lease_held = (self._lease_held[0], time.monotonic())
            return
        if reply.status == L.STATUS_OK:
            self._lease_held = None
            raise LeaseLostError("the lease was ended by the driver (a missed heartbeat?)")
        if reply.status == L.STATUS_LEASED:
            self._lease_held = None
        raise self._lease_refusal(reply)

    def keep_lease(self) -> bool:
        """For a control loop: renews the lease when a third of its heartbeat has passed
        since the last renewal (returns whether it did); does nothing when none is held."""
        if self._lease_held is None:
            return False
        hb, last = self._lease_held
        if time.monotonic() - last < hb / 3:
            return False
        self.renew()
        return True

    def release(self) -> None:
        """Gives the device back (the motion in progress goes on). Releasing a lease not
        held is no error."""
        if self._lease_held is None:
            return
        try:
            reply = self._lease_call(L.LEASE_OP_RELEASE, 0, "")
        finally:
            self._lease_held = None
        if reply.status != L.STATUS_OK:
            raise self._lease_refusal(reply)

    @property
    def holds_lease(self) -> bool:
        """Whether this client holds the device (as far as it knows: :meth:`renew` finds
        out whether the driver ended the lease)."""
        return self._lease_held is not None

    def holder(self) -> Optional[LeaseHolder]:
        """Who holds the device, if anybody (a request to the driver)."""
        reply = self._lease_call(L.LEASE_OP_QUERY, 0, "")
        if reply.holder_client == 0:
            return None
        return LeaseHolder(reply.holder_client, _name_of(reply.holder_name), reply.timeout_ns / 1e9)

    @staticmethod
    def _lease_refusal(reply: "L.LeaseReply") -> LimberError:
        if reply.status == L.STATUS_LEASED:
            return LeaseHeldError(reply.holder_client, _name_of(reply.holder_name))
        try:
            return NackError(Status(reply.status))
        except ValueError:
            return DecodeError(f"undecodable lease reply: status {reply.status}")

    def _lease_call(self, op: int, timeout_ns: int, name: str) -> "L.LeaseReply":
        """One lease request and its reply, within the request timeout."""
        self._check_open()
        iox2 = _iox2()
        if self._lease_port is None:
            layout = iox2.AttributeVerifier.new().require(
                iox2.AttributeKey.new(_LAYOUT_ATTR), iox2.AttributeValue.new(str(L.LAYOUT_VERSION))
            )
            try:
                svc = (
                    self._node.service_builder(iox2.ServiceName.new(self._device.service_name("lease")))
                    .request_response(L.LeaseReq, L.LeaseReply)
                    .enable_fire_and_forget_requests(False)
                    .open_with_attributes(layout)
                )
                self._lease_port = svc.client_builder().create()
                del svc
            except Exception as e:
                if _open_error_kind(e) == "DoesNotExist":
                    raise NoDriverError(f"no driver offers leases of {self._device}") from None
                raise TransportError(f"{self._device}: cannot open the lease channel: {e!r}") from None
        self._lease_seq += 1
        req = L.LeaseReq()
        req.client_id = self._client_id
        req.seq = self._lease_seq
        req.timeout_ns = timeout_ns
        req.op = op
        node_id = self._node.id.value
        req.node_lo = node_id & (2**64 - 1)
        req.node_hi = (node_id >> 64) & (2**64 - 1)
        raw = name.encode("utf-8")[:31]
        ctypes.memmove(ctypes.addressof(req.name), raw, len(raw))
        try:
            pending = self._lease_port.loan_uninit().write_payload(req).send()
        except Exception as e:
            raise TransportError(f"lease request failed: {e!r}") from None
        try:
            if pending.number_of_server_connections == 0:
                raise NoDriverError("no driver serves lease requests")
            if self.wake_driver:
                try:
                    self._wake.notify_with_custom_event_id(iox2.EventId.new(_EVENT_REQUEST))
                except Exception:
                    pass
            self._sent()
            timeout = self.request_timeout
            deadline = time.monotonic() + timeout
            next_check = time.monotonic() + LIVENESS_PERIOD
            while True:
                try:
                    r = pending.receive()
                except Exception as e:
                    raise TransportError(f"lease request failed: {e!r}") from None
                if r is not None:
                    try:
                        return _copy(L.LeaseReply, r.payload_ptr)
                    finally:
                        r.delete()
                now = time.monotonic()
                if now >= deadline:
                    raise RequestTimeout(f"no lease reply within {timeout} s")
                if now >= next_check:
                    next_check = now + LIVENESS_PERIOD
                    if self.driver_status() is not DriverStatus.ALIVE:
                        raise DriverGoneError("the driver is gone")
                self._pause(min(deadline, next_check))
        finally:
            pending.delete()

    # ----- liveness ---------------------------------------------------------------------

    def driver_status(self) -> DriverStatus:
        """Whether the device's driver process is alive. A dead driver's resources are
        cleaned up on the way, so that a restarted driver is picked up by this client."""
        self._check_open()
        iox2 = _iox2()
        alive = dead = False
        try:
            nodes = self._data_svc.nodes
        except Exception:
            nodes = []
        for n in nodes:
            try:
                view = n[0]
                details = view.details
                is_driver = details is not None and details.name.as_str().startswith(
                    _DRIVER_NODE_PREFIX
                )
            except Exception:
                continue
            if not is_driver:
                continue
            if isinstance(n, iox2.NodeState.Alive):
                alive = True
            elif isinstance(n, iox2.NodeState.Dead):
                dead = True
        if alive:
            return DriverStatus.ALIVE
        if dead:
            try:
                self._data_svc.try_cleanup_dead_nodes()
            except Exception:
                pass
            return DriverStatus.DEAD
        return DriverStatus.ABSENT

    # ----- commands ---------------------------------------------------------------------

    def _send(self, kind: int, body: Optional[ctypes.Structure] = None) -> Ticket:
        """Sends a command of ``kind`` with ``body`` (a ctypes struct or None)."""
        self._check_open()
        iox2 = _iox2()
        msg = self.CMD_MSG()
        msg.meta.kind = kind
        if body is not None:
            n = ctypes.sizeof(body)
            ctypes.memmove(ctypes.addressof(msg.body), ctypes.addressof(body), n)
            msg.meta.body_len = n
        try:
            loan = self._commands.loan_uninit()
        except Exception as e:
            raise TransportError(f"cannot send the command: {e!r}") from None
        self._cmd_seq += 1
        msg.meta.client_id = self._client_id
        msg.meta.seq = self._cmd_seq
        msg.meta.stamp_ns = monotonic_ns()
        try:
            receivers = loan.write_payload(msg).send()
        except Exception as e:
            raise TransportError(f"cannot send the command: {e!r}") from None
        if self.wake_driver:
            try:
                self._wake.notify_with_custom_event_id(iox2.EventId.new(_EVENT_COMMAND))
            except Exception:
                pass
        if receivers == 0:
            raise NoDriverError("no driver receives commands")
        self._sent()
        return Ticket(self._cmd_seq, receivers)

    # ----- requests ---------------------------------------------------------------------

    def _request(
        self, kind: int, body: Optional[ctypes.Structure] = None, timeout: Optional[float] = None
    ) -> Any:
        """Sends a request and waits for the reply; returns the reply envelope (a copy) of
        an ACK, raises :class:`NackError` for a NACK."""
        self._check_open()
        iox2 = _iox2()
        if timeout is None:
            timeout = self.request_timeout
        msg = self.REQ_MSG()
        msg.meta.kind = kind
        if body is not None:
            n = ctypes.sizeof(body)
            ctypes.memmove(ctypes.addressof(msg.body), ctypes.addressof(body), n)
            msg.meta.body_len = n
        try:
            loan = self._requests.loan_uninit()
        except Exception as e:
            raise TransportError(f"request transport failed: {e!r}") from None
        self._req_seq += 1
        msg.meta.client_id = self._client_id
        msg.meta.seq = self._req_seq
        msg.meta.stamp_ns = monotonic_ns()
        try:
            pending = loan.write_payload(msg).send()
        except Exception as e:
            raise TransportError(f"request transport failed: {e!r}") from None
        try:
            if pending.number_of_server_connections == 0:
                raise NoDriverError("no driver serves requests")
            if self.wake_driver:
                try:
                    self._wake.notify_with_custom_event_id(iox2.EventId.new(_EVENT_REQUEST))
                except Exception:
                    pass
            self._sent()
            deadline = time.monotonic() + timeout
            next_check = time.monotonic() + LIVENESS_PERIOD
            while True:
                reply = self._take_reply(pending)
                if reply is not None:
                    return self._check_reply(reply, kind)
                if not pending.is_connected:
                    # The server may have answered and closed in between: look once more.
                    reply = self._take_reply(pending)
                    if reply is not None:
                        return self._check_reply(reply, kind)
                    raise DriverGoneError("the driver is gone")
                now = time.monotonic()
                if now >= deadline:
                    raise RequestTimeout(f"no reply within {timeout} s")
                if now >= next_check:
                    next_check = now + LIVENESS_PERIOD
                    if self.driver_status() is not DriverStatus.ALIVE:
                        raise DriverGoneError("the driver is gone")
                self._pause(min(deadline, next_check))
        finally:
            # Closes the request at once (frees the slot; max 4 in flight per client).
            pending.delete()

    def _take_reply(self, pending: Any) -> Any:
        try:
            r = pending.receive()
        except Exception as e:
            raise TransportError(f"request transport failed: {e!r}") from None
        if r is None:
            return None
        try:
            return _copy(self.REPLY_MSG, r.payload_ptr)
        finally:
            r.delete()

    def _check_reply(self, reply: Any, kind: int) -> Any:
        try:
            status = Status(reply.meta.status)
        except ValueError:
            raise DecodeError(
                f"undecodable reply: unknown status code {reply.meta.status}"
            ) from None
        if status is not Status.OK:
            raise NackError(status)
        if reply.meta.kind != kind:
            raise UnexpectedReplyError(
                f"reply of kind {reply.meta.kind} to a request of kind {kind}"
            )
        return reply


# ----- actarray --------------------------------------------------------------------------


class ActArrayClient(_Client[L.ActArrayData]):
    """A client of an actuator array (Player's ``ActArrayProxy``; Rust ``ActArrayClient``).

    Commands return a :class:`Ticket`. Joint indices outside the array capacity (0..31),
    non-finite values and more than 32 values raise ``ValueError`` (nothing sent); a joint
    the device does not have is refused by the driver with ``Status.UNKNOWN_JOINT``.
    """

    INTERFACE = "actarray"
    DATA = L.ActArrayData
    CMD_MSG = L.ActArrayCmdMsg
    REQ_MSG = L.ActArrayReqMsg
    REPLY_MSG = L.ActArrayReplyMsg

    def move_to(self, joint: int, position: float) -> Ticket:
        """CMD POS: move ``joint`` to ``position`` (rad or m)."""
        body = L.ActArrayPositionCmd(joint=_joint(joint), position=_finite("position", position))
        return self._send(L.ACTARRAY_CMD_POS, body)

    def move_to_multi(self, positions: Sequence[float]) -> Ticket:
        """CMD MULTI_POS: move joints 0..n to ``positions``."""
        vs = _values("positions", positions)
        body = L.ActArrayMultiPositionCmd(count=len(vs))
        body.positions[: len(vs)] = vs
        return self._send(L.ACTARRAY_CMD_MULTI_POS, body)

    def move_at_speed(self, joint: int, speed: float) -> Ticket:
        """CMD SPEED: move ``joint`` at ``speed`` (rad/s or m/s)."""
        body = L.ActArraySpeedCmd(joint=_joint(joint), speed=_finite("speed", speed))
        return self._send(L.ACTARRAY_CMD_SPEED, body)

    def move_at_speed_multi(self, speeds: Sequence[float]) -> Ticket:
        """CMD MULTI_SPEED: move joints 0..n at ``speeds``."""
        vs = _values("speeds", speeds)
        body = L.ActArrayMultiSpeedCmd(count=len(vs))
        body.speeds[: len(vs)] = vs
        return self._send(L.ACTARRAY_CMD_MULTI_SPEED, body)

    def home(self, joint: Optional[int] = None) -> Ticket:
        """CMD HOME: home ``joint``, or every joint with ``None``."""
        return self._send(L.ACTARRAY_CMD_HOME, L.ActArrayHomeCmd(joint=_joint_sel(joint)))

    def set_current(self, joint: Optional[int], current: float) -> Ticket:
        """CMD CURRENT: drive ``joint`` (or every joint with ``None``) with ``current`` A."""
        body = L.ActArrayCurrentCmd(joint=_joint_sel(joint), current=_finite("current", current))
        return self._send(L.ACTARRAY_CMD_CURRENT, body)

    def set_current_multi(self, currents: Sequence[float]) -> Ticket:
        """CMD MULTI_CURRENT: drive joints 0..n with ``currents`` A."""
        vs = _values("currents", currents)
        body = L.ActArrayMultiCurrentCmd(count=len(vs))
        body.currents[: len(vs)] = vs
        return self._send(L.ACTARRAY_CMD_MULTI_CURRENT, body)

    def power(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ POWER."""
        self._request(L.ACTARRAY_REQ_POWER, L.ActArrayPowerReq(value=int(bool(on))), timeout)

    def brakes(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ BRAKES."""
        self._request(L.ACTARRAY_REQ_BRAKES, L.ActArrayBrakesReq(value=int(bool(on))), timeout)

    def set_speed_config(
        self, joint: int, speed: float, *, timeout: Optional[float] = None
    ) -> None:
        """REQ SPEED: the speed of ``joint`` for later moves."""
        body = L.ActArraySpeedReq(joint=_joint(joint), speed=_finite("speed", speed))
        self._request(L.ACTARRAY_REQ_SPEED, body, timeout)

    def set_accel_config(
        self, joint: int, accel: float, *, timeout: Optional[float] = None
    ) -> None:
        """REQ ACCEL: the acceleration of ``joint`` for later moves."""
        body = L.ActArrayAccelReq(joint=_joint(joint), accel=_finite("accel", accel))
        self._request(L.ACTARRAY_REQ_ACCEL, body, timeout)

    def geometry(self, *, timeout: Optional[float] = None) -> "L.ActArrayGeom":
        """REQ GET_GEOM: the geometry (an ``ActArrayGeom`` ctypes struct, validated)."""
        reply = self._request(L.ACTARRAY_REQ_GET_GEOM, None, timeout)
        g = _body(L.ActArrayGeom, reply.body)
        if g.actuators_count > MAX_ACTUATORS:
            raise DecodeError(f"undecodable reply: {g.actuators_count} actuators")
        for a in g.actuators[: g.actuators_count]:
            if a.kind not in (L.ACTUATOR_KIND_LINEAR, L.ACTUATOR_KIND_ROTARY):
                raise DecodeError(f"undecodable reply: unknown actuator kind {a.kind}")
            if not _all_finite(a.length, a.min, a.centre, a.max, a.home, a.config_speed,
                               a.axis.x, a.axis.y, a.axis.z, a.orientation.roll,
                               a.orientation.pitch, a.orientation.yaw):
                raise DecodeError("undecodable reply: a geometry value is not finite")
        return g

    def positions(self) -> "list[float]":
        """The positions of the valid actuators in the latest state (empty if none yet)."""
        s = self.state()
        if s is None:
            return []
        return [a.position for a in s.actuators[: min(s.actuators_count, MAX_ACTUATORS)]]


# ----- limb ------------------------------------------------------------------------------


class LimbClient(_Client[L.LimbData]):
    """A client of a limb (Player's ``LimbProxy``; Rust ``LimbClient``). Vectors are any
    3-sequences (robot frame, m); direction vectors must not be zero."""

    INTERFACE = "limb"
    DATA = L.LimbData
    CMD_MSG = L.LimbCmdMsg
    REQ_MSG = L.LimbReqMsg
    REPLY_MSG = L.LimbReplyMsg

    def home(self) -> Ticket:
        """CMD HOME."""
        return self._send(L.LIMB_CMD_HOME)

    def stop(self) -> Ticket:
        """CMD STOP: stop every joint now."""
        return self._send(L.LIMB_CMD_STOP)

    def set_pose(self, position: Sequence[float], approach: Sequence[float],
                 orientation: Sequence[float]) -> Ticket:
        """CMD SETPOSE: end effector to ``position`` with ``approach`` and ``orientation``."""
        body = L.LimbSetPoseCmd(
            position=_vec3("position", position),
            approach=_direction("approach", approach),
            orientation=_direction("orientation", orientation),
        )
        return self._send(L.LIMB_CMD_SETPOSE, body)

    def set_position(self, position: Sequence[float]) -> Ticket:
        """CMD SETPOSITION: end effector to ``position``, orientation chosen by the driver."""
        return self._send(L.LIMB_CMD_SETPOSITION,
                          L.LimbSetPositionCmd(position=_vec3("position", position)))

    def vec_move(self, direction: Sequence[float], length: float) -> Ticket:
        """CMD VECMOVE: move ``length`` m along ``direction`` in a straight line."""
        length = _finite("length", length)
        body = L.LimbVecMoveCmd(direction=_direction("direction", direction), length=length)
        return self._send(L.LIMB_CMD_VECMOVE, body)

    def power(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ POWER."""
        self._request(L.LIMB_REQ_POWER, L.LimbPowerReq(value=int(bool(on))), timeout)

    def brakes(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ BRAKES."""
        self._request(L.LIMB_REQ_BRAKES, L.LimbBrakesReq(value=int(bool(on))), timeout)

    def set_speed(self, speed: float, *, timeout: Optional[float] = None) -> None:
        """REQ SPEED: end-effector speed, m/s."""
        self._request(L.LIMB_REQ_SPEED, L.LimbSpeedReq(speed=_finite("speed", speed)), timeout)

    def geometry(self, *, timeout: Optional[float] = None) -> "L.LimbGeom":
        """REQ GEOM: the geometry (a ``LimbGeom`` ctypes struct)."""
        reply = self._request(L.LIMB_REQ_GEOM, None, timeout)
        g = _body(L.LimbGeom, reply.body)
        if not _all_finite(g.base_pos.x, g.base_pos.y, g.base_pos.z):
            raise DecodeError("undecodable reply: base_pos is not finite")
        return g

    def reach(self, position: Sequence[float], approach: Sequence[float],
              orientation: Sequence[float], *, timeout: Optional[float] = None) -> "L.LimbReach":
        """REQ REACH: where a SETPOSE to this pose would end (a ``LimbReach`` ctypes struct:
        the pose, ``orientation_adjustment`` in rad, ``adjusted`` 0 or 1); nothing moves.
        A pose the limb cannot get to raises :class:`NackError` with its cause."""
        body = L.LimbReachReq(
            position=_vec3("position", position),
            approach=_direction("approach", approach),
            orientation=_direction("orientation", orientation),
        )
        reply = self._request(L.LIMB_REQ_REACH, body, timeout)
        r = _body(L.LimbReach, reply.body)
        v = r.position, r.approach, r.orientation
        if not _all_finite(*(c for p in v for c in (p.x, p.y, p.z)), r.orientation_adjustment,
                           r.position_error, r.approach_error) or r.adjusted not in (0, 1):
            raise DecodeError("undecodable reply: REACH values not finite or flag not 0/1")
        return r


# ----- gripper ---------------------------------------------------------------------------


class GripperClient(_Client[L.GripperData]):
    """A client of a gripper (Player's ``GripperProxy``; Rust ``GripperClient``)."""

    INTERFACE = "gripper"
    DATA = L.GripperData
    CMD_MSG = L.GripperCmdMsg
    REQ_MSG = L.GripperReqMsg
    REPLY_MSG = L.GripperReplyMsg

    def open(self) -> Ticket:
        """CMD OPEN."""
        return self._send(L.GRIPPER_CMD_OPEN)

    def close_gripper(self) -> Ticket:
        """CMD CLOSE. (Not ``close()``: on every client, :meth:`close` releases the
        connection, so that a cleanup call can never move the hardware.)"""
        return self._send(L.GRIPPER_CMD_CLOSE)

    def open_gripper(self) -> Ticket:
        """CMD OPEN (the same as :meth:`open`, named to pair with :meth:`close_gripper`)."""
        return self._send(L.GRIPPER_CMD_OPEN)

    def stop(self) -> Ticket:
        """CMD STOP."""
        return self._send(L.GRIPPER_CMD_STOP)

    def store(self) -> Ticket:
        """CMD STORE."""
        return self._send(L.GRIPPER_CMD_STORE)

    def retrieve(self) -> Ticket:
        """CMD RETRIEVE."""
        return self._send(L.GRIPPER_CMD_RETRIEVE)

    def geometry(self, *, timeout: Optional[float] = None) -> "L.GripperGeom":
        """REQ GET_GEOM: the geometry (a ``GripperGeom`` ctypes struct)."""
        reply = self._request(L.GRIPPER_REQ_GET_GEOM, None, timeout)
        g = _body(L.GripperGeom, reply.body)
        p, o, i = g.pose, g.outer_size, g.inner_size
        if not _all_finite(p.position.x, p.position.y, p.position.z, p.orientation.roll,
                           p.orientation.pitch, p.orientation.yaw, o.width, o.length,
                           o.height, i.width, i.length, i.height):
            raise DecodeError("undecodable reply: gripper geometry is not finite")
        return g


# ----- driver statistics -----------------------------------------------------------------


def stats_text(field: "ctypes.Array[ctypes.c_uint8]") -> str:
    """A text field of :class:`DriverStats` (NUL-padded UTF-8) as a string; raises
    :class:`DecodeError` when it is not UTF-8 (Rust ``diagnostics::get_text``)."""
    raw = bytes(field)
    end = raw.find(b"\0")
    try:
        return (raw if end < 0 else raw[:end]).decode("utf-8")
    except UnicodeDecodeError:
        raise DecodeError("undecodable text field in the driver statistics") from None


class DriverStatsReader:
    """Reads the statistics a driver publishes on ``<robot>/driver/0`` (its loop, link and
    hardware: :class:`DriverStats`), as ``limber echo pioneer/driver`` does (Rust
    ``diagnostics::StatsReader``). Open with :meth:`open`; close with :meth:`close` or
    ``with``."""

    _sub: Any
    _node: Any

    def __init__(self) -> None:  # use open()
        self._closed = True
        self._sub = None
        self._node = None
        self._latest: "Optional[L.DriverStats]" = None

    @classmethod
    def open(
        cls, robot: str = "pioneer", domain: "Optional[Domain | str]" = None
    ) -> "DriverStatsReader":
        """Opens the statistics of ``robot``'s driver in ``domain`` (default: from
        ``LIMBER_DOMAIN``). Raises :class:`NoDriverError` when no driver publishes them,
        :class:`ValueError` for a bad robot name, :class:`TransportError` otherwise."""
        if not isinstance(robot, str) or len(robot) > MAX_ROBOT_LEN or not _IDENT.match(robot):
            raise ValueError(
                f"invalid robot name {robot!r}: use 1 to {MAX_ROBOT_LEN} characters of [A-Za-z0-9_-]"
            )
        dom = domain if isinstance(domain, Domain) else Domain(domain)
        iox2 = _iox2()
        iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
        self = cls()
        node_name = (_CLIENT_NODE_PREFIX + _default_process_name())[: iox2.NodeName.max_len()]
        self._node = _join_domain(dom, node_name)
        self._closed = False
        _open_clients.add(self)
        try:
            svc = (
                self._node.service_builder(iox2.ServiceName.new(f"limber/{robot}/driver/0/data"))
                .publish_subscribe(L.DriverStats)
                .open()
            )
            self._sub = svc.subscriber_builder().create()
            del svc
        except Exception as e:
            self.close()
            if _open_error_kind(e) == "DoesNotExist":
                raise NoDriverError(
                    f"no driver of robot {robot} publishes statistics in domain {dom}"
                ) from None
            raise TransportError(f"cannot open the statistics of {robot}: {e!r}") from None
        return self

    def refresh(self) -> bool:
        """Takes what arrived; true if there was something new."""
        if self._closed:
            raise LimberError("the statistics reader is closed")
        got = False
        while True:
            try:
                sample = self._sub.receive()
            except Exception as e:
                raise TransportError(f"cannot receive statistics: {e!r}") from None
            if sample is None:
                return got
            try:
                self._latest = _copy(L.DriverStats, sample.payload_ptr)
            finally:
                sample.delete()
            got = True

    def latest(self) -> "Optional[L.DriverStats]":
        """The latest statistics taken (a copy), or None."""
        return self._latest

    def wait(self, timeout: float) -> "L.DriverStats":
        """Waits up to ``timeout`` s (polling every 5 ms, as Rust) for new statistics and
        returns them (a copy). Raises :class:`WaitTimeout`."""
        deadline = time.monotonic() + timeout
        while True:
            if self.refresh():
                assert self._latest is not None
                return self._latest
            if time.monotonic() >= deadline:
                raise WaitTimeout(f"no driver statistics within {timeout} s")
            time.sleep(0.005)

    def close(self) -> None:
        """Releases the subscriber and the node (idempotent)."""
        if self._sub is not None:
            try:
                self._sub.delete()
            except Exception:
                pass
        self._sub = None
        self._node = None
        if not self._closed:
            self._closed = True
            _open_clients.discard(self)

    def __enter__(self) -> "DriverStatsReader":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@atexit.register
def _close_all() -> None:
    """Closes every client still open at interpreter exit, before module teardown, so that
    no dead node is left behind (clients in module globals would otherwise leak)."""
    for c in list(_open_clients):
        try:
            c.close()
        except Exception:
            pass
