"""Clients of limber devices: a thin ctypes binding over liblimber (the C API of the Rust
core, ``limber_services``), with the same semantics as the Rust ``Client<I>``:

* commands are fire-and-forget; each returns a :class:`Ticket`, and :meth:`wait_outcome`
  waits for the driver's verdict;
* requests wait for the driver's reply (with a timeout and a liveness check of the driver);
* invalid values (NaN, a joint index outside the array capacity, too many values, a zero
  direction vector) raise :class:`ValueError` before anything is sent.

Every rule (names, domains, waits, leases, outcomes) is the library's: this module only
converts arguments, calls liblimber (``limber_device_*``, ``limber_actarray_*``, ...) and
turns its codes into exceptions (:data:`_ERRORS`). States and geometries are the generated
ctypes classes of :mod:`limber._layout`, filled in place by the library.

A client owns its liblimber handle (its iceoryx2 node and ports). Call :meth:`close` (or use
``with``) when done; clients still open at interpreter exit are closed by an ``atexit``
hook. A client is not thread-safe: use it from one thread at a time.

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
from ctypes import (
    byref,
    c_bool,
    c_double,
    c_int32,
    c_size_t,
    c_uint32,
    c_uint64,
    c_void_p,
    sizeof,
)
from operator import index as _index
from typing import (
    Any,
    ClassVar,
    Generic,
    Optional,
    Sequence,
    Tuple,
    Type,
    TypeVar,
)

from . import _layout as L
from . import _lib
from ._lib import lib as _c
from ._types import *  # noqa: F401,F403
from ._types import (  # noqa: F401
    _DRIVER_STATUS,
    _FRESHNESS,
    _STATUS,
    _check_layout,
    _error,
    _ms,
    _status,
    _tuple_new,
)
from ._names import *  # noqa: F401,F403
from ._names import _default_process_name, _domain_arg, _open_clients, _Owned  # noqa: F401
from ._stats import DriverStatsReader, stats_text  # noqa: F401
from .done import Done, wait_done as _wait_done

__all__ = [
    "DOMAIN_ENV",
    "DEFAULT_DOMAIN",
    "DEFAULT_REQUEST_TIMEOUT",
    "SPIN_BUDGET_ENV",
    "Domain",
    "DeviceName",
    "DeviceInfo",
    "list_devices",
    "remove_domain_files",
    "library_path",
    "DriverStatsReader",
    "stats_text",
    "Status",
    "DriverStatus",
    "Freshness",
    "WaitMode",
    "default_spin_budget",
    "Ticket",
    "Outcome",
    "LeaseHolder",
    "LimberError",
    "NoDriverError",
    "IncompatibleError",
    "TransportError",
    "NackError",
    "LeaseHeldError",
    "LeaseLostError",
    "RequestTimeout",
    "WaitTimeout",
    "DriverGoneError",
    "OutcomeMissed",
    "DecodeError",
    "UnexpectedReplyError",
    "ActArrayClient",
]


def _vec3(v: Sequence[float]) -> "L.Vec3":
    """A 3-sequence as a ``limber_vec3`` (ValueError unless it has 3 components)."""
    x, y, z = v
    return L.Vec3(float(x), float(y), float(z))


def _doubles(values: Sequence[float]) -> "Tuple[Any, int]":
    """A sequence of numbers as a C array of doubles and its length."""
    vs = [float(v) for v in values]
    return (c_double * max(1, len(vs)))(*vs), len(vs)


def _flat(rows: Optional[Sequence[Sequence[float]]]) -> Any:
    """Rows of numbers as one row-major C array of doubles (None stays None: NULL)."""
    return None if rows is None else _doubles([x for row in rows for x in row])[0]


#: The state type of a client (``ActArrayData``, ``LimbData``, ``GripperData``).
_D = TypeVar("_D", bound=ctypes.Structure)
_C = TypeVar("_C", bound="_Client[Any]")

_connect = _c.limber_device_connect_checked
_disconnect = _c.limber_device_disconnect
# The state copies: through the compiled `limber._fast` when the package has it, else ctypes
# (`_lib.copy_out`).
_copy_out = _lib.copy_out
_STATE = _lib.copier("limber_device_state")
_WAIT_STATE = _lib.copier("limber_device_wait_state")
# The calls of a control loop, unchecked (see `_lib.unchecked`): every argument below is
# passed as a ctypes value of its C type.
_last_state = _lib.unchecked("limber_device_last_state")
_outcome = _lib.unchecked("limber_device_outcome")
# Equal to no timeout a caller passes (None included): the first one is converted.
_NO_TIMEOUT_YET = object()


class _Client(_Owned, Generic[_D]):
    """A connection to one device (a liblimber ``limber_device``). Use
    :class:`ActArrayClient`, :class:`LimbClient` or :class:`~limber.gripper.GripperClient`."""

    INTERFACE: ClassVar[str]
    #: ``LIMBER_INTERFACE_*``.
    INTERFACE_CODE: ClassVar[int]
    DATA: ClassVar[Type[ctypes.Structure]]
    GEOM: ClassVar[Type[ctypes.Structure]]

    _h: Optional[c_void_p]
    #: The handle as `_lib.copy_out` takes it (``None`` once closed).
    _hv: Any

    def __init__(self) -> None:  # use connect()
        self._h = None
        self._hv = None
        # The states `state()` and `wait_state()` may recycle (`_lib.copy_out`): only an
        # instance nothing else references any more.
        self._spare = _lib.new_spare()
        # Reused by every call: no allocation per command or outcome.
        self._ticket = _lib.Ticket()
        self._ticket_ref = byref(self._ticket)
        self._tk = _lib.Ticket()
        self._out = _lib.Outcome()
        self._out_ref = byref(self._out)
        # The last timeout of wait_outcome and its milliseconds (a loop passes the same one).
        self._wait_timeout: object = _NO_TIMEOUT_YET
        self._wait_ms = c_uint64(0)
        self._size = c_size_t(self._data_size)
        self._flag = c_bool(False)
        self._flag_ref = byref(self._flag)
        self._u64 = c_uint64(0)
        self._i32 = c_int32(0)
        self._request_timeout = DEFAULT_REQUEST_TIMEOUT
        self._request_ms = _ms("request_timeout", DEFAULT_REQUEST_TIMEOUT)
        self._wait_mode = WaitMode.EVENT
        self._spin_budget = 0.0
        self._client_id = 0
        self._device = DeviceName("", self.INTERFACE, 0)
        self._domain = Domain(DEFAULT_DOMAIN)

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
    ) -> _C:
        """Connects to ``device`` (``robot/interface/index``) in ``domain`` (a :class:`Domain`,
        a domain name, or ``None`` for ``LIMBER_DOMAIN``/``limber``).

        With ``timeout == 0`` (default) it fails at once with :class:`NoDriverError` if no
        driver offers the device; with ``timeout > 0`` it waits up to that many seconds for
        a driver.

        Raises ``ValueError`` for an invalid name, :class:`IncompatibleError` for another
        interface or layout version, :class:`TransportError` if iceoryx2 fails. ``name``
        names this process in ``limber list`` (default: the script's name).
        """
        if not isinstance(device, str):
            raise ValueError(f"a device name is a string, not {device!r}")
        dom = Domain(domain) if not isinstance(domain, Domain) else domain
        wait_ms = _ms("timeout", timeout)
        _ms("request_timeout", request_timeout)  # ValueError before anything is done
        _check_layout(device)
        rc = _c.limber_set_program_name((name or _default_process_name()).encode("utf-8"))
        if rc:
            raise _error(rc)
        h = c_void_p()
        rc = _connect(
            device.encode("utf-8", "surrogateescape"),
            _domain_arg(dom),
            wait_ms,
            L.LAYOUT_VERSION,
            cls.INTERFACE_CODE,
            sizeof(cls.DATA),
            sizeof(cls.GEOM),
            byref(h),
        )
        if rc:
            # This package's layout and the library's were compared above
            # (`_check_layout`): an incompatibility here is the driver's, as the library
            # says it.
            raise _error(rc)
        self = cls()
        self._h = h
        self._hv = _lib.handle_arg(h)
        self._device = DeviceName.parse(device)
        self._domain = dom
        _open_clients.add(self)
        cid = c_uint64(0)
        rc = _c.limber_device_client_id(h, byref(cid))
        if rc:
            self.close()
            raise _error(rc)
        self._client_id = int(cid.value)
        self._spin_budget = default_spin_budget()
        self.request_timeout = request_timeout
        return self

    # ----- lifetime ---------------------------------------------------------------------

    def close(self) -> None:
        """Releases the lease if held, then the handle (idempotent). The client is unusable
        afterwards."""
        h = self.__dict__.get("_h")
        if h is not None:
            self._h = None
            self._hv = None
            self._spare[:] = _lib.new_spare()
            _open_clients.discard(self)
            _disconnect(h)

    @property
    def closed(self) -> bool:
        return self._h is None


    def __repr__(self) -> str:
        state = "closed" if self.__dict__.get("_h") is None else "open"
        return f"<{type(self).__name__} {self.__dict__.get('_device', '?')} {state}>"

    def _fail(self, code: int, timeout: "Type[LimberError]" = WaitTimeout) -> Exception:
        """The exception of a call that returned ``code``; a closed client says so."""
        if self._h is None:
            return LimberError(f"{type(self).__name__} is closed")
        return _error(code, timeout)

    # ----- identity ---------------------------------------------------------------------

    @property
    def device(self) -> DeviceName:
        return self._device

    @property
    def domain(self) -> Domain:
        return self._domain

    @property
    def client_id(self) -> int:
        """This client's id (how the driver, outcomes and lease holders name it)."""
        return self._client_id

    def fileno(self) -> int:
        """A descriptor that becomes readable when the driver notifies this client (a new
        state, an outcome, a reply), for ``select``/``selectors``: then call
        :meth:`refresh` (``limber_device_fd``). Valid until :meth:`close`; do not close it."""
        fd = c_int32(-1)
        rc = _c.limber_device_fd(self._h, byref(fd))
        if rc:
            raise self._fail(rc)
        return int(fd.value)

    # ----- state ------------------------------------------------------------------------

    def refresh(self) -> bool:
        """Takes every state and outcome that arrived; returns True if a new state came."""
        rc = _c.limber_device_refresh(self._h, self._flag_ref)
        if rc:
            raise self._fail(rc)
        return bool(self._flag.value)

    def state(self) -> Optional[_D]:
        """The latest state, after taking what arrived: a *copy* of the ``*Data`` ctypes
        struct (``ActArrayData``, ``LimbData``, ``GripperData``; same fields as in Rust), or
        ``None`` if no sample arrived yet."""
        d = _copy_out(_STATE, self._hv, 0, self.DATA, self._spare)
        if d.__class__ is int:
            if d == _lib.CODE_TIMEOUT:
                return None
            raise self._fail(d)
        return d  # type: ignore[no-any-return]

    def last_state(self) -> Optional[_D]:
        """The latest state already taken (a copy), without looking for a newer one."""
        d = self.DATA()
        rc = _last_state(self._h, byref(d), self._size)
        if rc:
            if rc == _lib.CODE_TIMEOUT:
                return None
            raise self._fail(rc)
        return d  # type: ignore[return-value]

    def wait_state(self, timeout: float) -> _D:
        """Waits up to ``timeout`` s for a state newer than the latest one taken and returns
        it (a copy). Raises :class:`WaitTimeout` or :class:`DriverGoneError`."""
        d = _copy_out(_WAIT_STATE, self._hv, _ms("timeout", timeout), self.DATA, self._spare)
        if d.__class__ is int:
            raise self._fail(d)
        return d  # type: ignore[no-any-return]

    def state_age(self) -> Optional[float]:
        """Age of the latest state taken in seconds (now minus its acquisition time), or
        None before the first."""
        rc = _c.limber_device_state_age(self._h, byref(self._u64))
        if rc:
            if rc == _lib.CODE_TIMEOUT:
                return None
            raise self._fail(rc)
        return self._u64.value / 1e9

    def freshness(self, max_age: float) -> Freshness:
        """Fresh (younger than ``max_age`` s), stale (older, driver alive), gone, or no data."""
        rc = _c.limber_device_liveness(self._h, _ms("max_age", max_age), byref(self._i32))
        if rc:
            raise self._fail(rc)
        return _FRESHNESS[self._i32.value]

    def driver_status(self) -> DriverStatus:
        """Whether the device's driver process is alive. A dead driver's resources are
        cleaned up on the way, so that a restarted driver is picked up by this client."""
        rc = _c.limber_device_driver_status(self._h, byref(self._i32))
        if rc:
            raise self._fail(rc)
        return _DRIVER_STATUS[self._i32.value]

    # ----- outcomes ---------------------------------------------------------------------

    def _sent(self, rc: int) -> Ticket:
        """The ticket of a command just sent (``rc`` its code)."""
        if rc:
            raise self._fail(rc)
        t = self._ticket
        return _tuple_new(Ticket, (t.seq, t.receivers))

    def wait_outcome(self, ticket: Ticket, timeout: float) -> Status:
        """Waits up to ``timeout`` s for the outcome of the command of ``ticket`` and returns
        its :class:`Status` (``Status.OK`` if carried out). When it returns, the latest state
        shows the command. Raises :class:`OutcomeMissed`, :class:`WaitTimeout` or
        :class:`DriverGoneError`."""
        tk = self._tk
        tk.seq, tk.receivers = ticket
        rc = _outcome(self._h, tk, self._outcome_ms(timeout), self._out_ref)
        if rc:
            if rc == _lib.CODE_OUTCOME_MISSED and self._h is not None:
                raise _error(rc, newer_seq=self._out.seq)
            raise self._fail(rc)
        return _STATUS.get(self._out.status, Status.INVALID_ARGUMENT)

    def _outcome_ms(self, timeout: float) -> c_uint64:
        """``timeout`` (s) in whole milliseconds, rounded up, as the C call takes it; the last
        one is kept, since a control loop passes the same timeout every time."""
        if timeout == self._wait_timeout:
            return self._wait_ms
        self._wait_ms = c_uint64(_ms("timeout", timeout))
        self._wait_timeout = timeout
        return self._wait_ms

    def outcome(self, ticket: Ticket, timeout: float) -> Outcome:
        """As :meth:`wait_outcome`, with the other client involved (the holder of the device
        for ``LEASED``, with its name): ``limber_device_outcome``."""
        tk = self._tk
        tk.seq = ticket.seq
        tk.receivers = ticket.receivers
        rc = _outcome(self._h, tk, self._outcome_ms(timeout), self._out_ref)
        o = self._out
        if rc:
            if rc == _lib.CODE_OUTCOME_MISSED and self._h is not None:
                raise _error(rc, newer_seq=o.seq)
            raise self._fail(rc)
        return Outcome(o.seq, _status(o.status), o.other_client, _lib.text(o.other_name))

    def wait_done(self, ticket: Ticket, timeout: float) -> Done:
        """Waits up to ``timeout`` s until the motion the command of ``ticket`` started has
        ended, and returns how (:class:`Done`: reached within the device's tolerance,
        stalled, stopped, preempted, aborted, timed out; each part's final position and
        error against the goal): ``limber_device_wait_done``. Raises :class:`NackError`
        for a refused command, :class:`WaitTimeout` when it has not ended in time."""
        return _wait_done(self, ticket, timeout)

    # ----- waiting ----------------------------------------------------------------------

    @property
    def wait_mode(self) -> WaitMode:
        """How this client waits (default :attr:`WaitMode.EVENT`)."""
        return self._wait_mode

    def set_wait_mode(self, mode: WaitMode) -> None:
        """Sets how this client waits for states, outcomes and replies."""
        if not isinstance(mode, WaitMode):
            raise ValueError(f"wait mode must be a WaitMode, not {mode!r}")
        self._set_wait(mode, self._spin_budget)

    @property
    def spin_budget(self) -> float:
        """The spin budget in seconds (see :meth:`set_spin_budget`)."""
        return self._spin_budget

    def set_spin_budget(self, seconds: float) -> None:
        """In :attr:`WaitMode.EVENT`, how long a wait that follows a command or request polls
        (yielding the CPU) before it blocks (default :func:`default_spin_budget`; zero: block
        at once)."""
        s = float(seconds)
        if not 0.0 <= s <= 1e9:
            raise ValueError(f"spin budget must be a finite number of seconds >= 0, not {seconds!r}")
        self._set_wait(self._wait_mode, s)

    def _set_wait(self, mode: WaitMode, budget: float) -> None:
        rc = _c.limber_device_set_wait(self._h, mode is WaitMode.SPIN, round(budget * 1e6))
        if rc:
            raise self._fail(rc)
        self._wait_mode = mode
        self._spin_budget = budget

    @property
    def request_timeout(self) -> float:
        """How long a request waits for its reply when it is given no ``timeout=``, seconds
        (default 2): the lease calls too."""
        return self._request_timeout

    @request_timeout.setter
    def request_timeout(self, seconds: float) -> None:
        ms = _ms("request_timeout", seconds)
        rc = _c.limber_device_set_request_timeout(self._h, ms)
        if rc:
            raise self._fail(rc)
        self._request_timeout = float(seconds)
        self._request_ms = ms

    def _timeout_ms(self, timeout: Optional[float]) -> int:
        return self._request_ms if timeout is None else _ms("timeout", timeout)

    def _replied(self, rc: int) -> None:
        if rc:
            raise self._fail(rc, RequestTimeout)

    # ----- ownership --------------------------------------------------------------------

    def preempted(self, ticket: Ticket) -> Optional[Outcome]:
        """Whether the motion that the command of ``ticket`` started was cut short by another
        client's command: its :class:`Outcome` (with the other client and its lease name),
        or None. Looks at what arrived; remembers the last 16 commands."""
        tk = self._tk
        tk.seq = ticket.seq
        tk.receivers = ticket.receivers
        rc = _c.limber_device_preemption(self._h, tk, self._flag_ref, self._out_ref)
        if rc:
            raise self._fail(rc)
        if not self._flag.value:
            return None
        o = self._out
        return Outcome(o.seq, _status(o.status), o.other_client, _lib.text(o.other_name))

    def acquire(self, name: str, heartbeat: float) -> None:
        """Takes the device: until :meth:`release` (or :meth:`close`), other clients'
        commands, and their requests that change the device, are refused with ``LEASED``
        naming ``name`` (1 to 31 bytes); readers are unaffected. The lease lives as long as
        this client renews it (:meth:`renew`, :meth:`keep_lease`) at least every
        ``heartbeat`` seconds, and as long as its process lives: otherwise the driver stops
        the device and frees it. Raises :class:`LeaseHeldError` when another client holds
        it."""
        if not isinstance(name, str):
            raise ValueError(f"a lease name is a string, not {name!r}")
        hb = _ms("heartbeat", heartbeat)
        if hb == 0:
            raise ValueError(f"heartbeat must be a number of seconds > 0, not {heartbeat!r}")
        rc = _c.limber_device_acquire(self._h, name.encode("utf-8"), hb)
        if rc:
            raise self._fail(rc, RequestTimeout)

    def renew(self) -> None:
        """The heartbeat: tells the driver this holder is alive. Raises
        :class:`LeaseLostError` when the driver ended the lease, :class:`LeaseHeldError`
        when another client took it since."""
        rc = _c.limber_device_renew(self._h)
        if rc:
            raise self._fail(rc, RequestTimeout)

    def keep_lease(self) -> bool:
        """For a control loop: renews the lease when a third of its heartbeat has passed
        since the last renewal (returns whether it did); does nothing when none is held."""
        rc = _c.limber_device_keep_lease(self._h, self._flag_ref)
        if rc:
            raise self._fail(rc, RequestTimeout)
        return bool(self._flag.value)

    def release(self) -> None:
        """Gives the device back (the motion in progress goes on). Releasing a lease not
        held is no error."""
        rc = _c.limber_device_release_lease(self._h)
        if rc:
            raise self._fail(rc, RequestTimeout)

    @property
    def holds_lease(self) -> bool:
        """Whether this client holds the device (as far as it knows: :meth:`renew` finds
        out whether the driver ended the lease)."""
        rc = _c.limber_device_holds_lease(self._h, self._flag_ref)
        if rc:
            raise self._fail(rc)
        return bool(self._flag.value)

    def holder(self) -> Optional[LeaseHolder]:
        """Who holds the device, if anybody (a request to the driver)."""
        h = _lib.LeaseHolder()
        rc = _c.limber_device_holder(self._h, byref(h))
        if rc:
            raise self._fail(rc, RequestTimeout)
        if h.client_id == 0:
            return None
        return LeaseHolder(int(h.client_id), _lib.text(h.name), h.heartbeat_ms / 1000.0)

    # ----- requests every interface has ---------------------------------------------------

    def _geometry(self, timeout: Optional[float]) -> Any:
        g = self.GEOM()
        rc = _c.limber_device_geometry(self._h, self._timeout_ms(timeout), byref(g), sizeof(g))
        if rc:
            raise self._fail(rc, RequestTimeout)
        return g

    _data_size: ClassVar[int]


# ----- actarray --------------------------------------------------------------------------

_aa_move_to = _lib.unchecked("limber_actarray_move_to")


class ActArrayClient(_Client[L.ActArrayData]):
    """A client of an actuator array (Player's ``ActArrayProxy``; Rust ``ActArrayClient``).

    Commands return a :class:`Ticket`. Joint indices outside the array capacity (0..31),
    non-finite values and more than 32 values raise ``ValueError`` (nothing sent); a joint
    the device does not have is refused by the driver with ``Status.UNKNOWN_JOINT``.
    """

    INTERFACE = "actarray"
    INTERFACE_CODE = _lib.INTERFACE_ACTARRAY
    DATA = L.ActArrayData
    GEOM = L.ActArrayGeom
    _data_size = sizeof(L.ActArrayData)

    def move_to(self, joint: int, position: float) -> Ticket:
        """CMD POS: move ``joint`` to ``position`` (rad or m)."""
        j = _index(joint)
        if not 0 <= j <= 0xFFFF_FFFF:
            raise ValueError(f"joint {joint} is not a valid joint index")
        rc = _aa_move_to(self._h, j, c_double(position), self._ticket_ref)
        if rc:
            raise self._fail(rc)
        t = self._ticket
        return _tuple_new(Ticket, (t.seq, t.receivers))

    def move_to_multi(self, positions: Sequence[float]) -> Ticket:
        """CMD MULTI_POS: move joints 0..n to ``positions``."""
        arr, n = _doubles(positions)
        return self._sent(_c.limber_actarray_move_to_multi(self._h, arr, n, self._ticket_ref))

    def follow_trajectory(
        self,
        joints: Sequence[int],
        times: Sequence[float],
        positions: Sequence[Sequence[float]],
        velocities: Optional[Sequence[Sequence[float]]] = None,
        accelerations: Optional[Sequence[Sequence[float]]] = None,
        path_tolerance: Optional[Sequence[float]] = None,
        goal_tolerance: Optional[Sequence[float]] = None,
        goal_time_tolerance: float = 0.0,
        start_ns: int = 0,
    ) -> Ticket:
        """CMD TRAJ: follow a joint trajectory (``limber_actarray_follow_trajectory``):
        point i reached ``times[i]`` s after the start with ``positions[i]`` (one per joint
        of ``joints``), optional velocities and accelerations per point (cubic, quintic),
        tolerances per joint (0: not enforced). It replaces a running trajectory from its
        start time; :meth:`wait_done` returns its result. An invalid trajectory raises
        ``ValueError`` with the reason (nothing sent)."""
        ts, n = _doubles(times)
        rows = [_flat(positions), _flat(velocities), _flat(accelerations)]
        tols = [None if v is None else _doubles(v)[0] for v in (path_tolerance, goal_tolerance)]
        ids = (c_uint32 * max(1, len(joints)))(*joints)
        rc = _c.limber_actarray_follow_trajectory(
            self._h, ids, len(joints), ts, n, *rows, *tols, goal_time_tolerance, start_ns,
            self._ticket_ref)
        return self._sent(rc)

    def set_trajectory_scale(self, scale: float) -> Ticket:
        """CMD TRAJ_SCALE: the speed scaling of trajectories (0 pauses, 1 nominal)."""
        return self._sent(_c.limber_actarray_set_trajectory_scale(self._h, scale, self._ticket_ref))

    def move_at_speed(self, joint: int, speed: float) -> Ticket:
        """CMD SPEED: move ``joint`` at ``speed`` (rad/s or m/s)."""
        j = _joint(joint)
        return self._sent(_c.limber_actarray_move_at_speed(self._h, j, speed, self._ticket_ref))

    def move_at_speed_multi(self, speeds: Sequence[float]) -> Ticket:
        """CMD MULTI_SPEED: move joints 0..n at ``speeds``."""
        arr, n = _doubles(speeds)
        rc = _c.limber_actarray_move_at_speed_multi(self._h, arr, n, self._ticket_ref)
        return self._sent(rc)

    def home(self, joint: Optional[int] = None) -> Ticket:
        """CMD HOME: home ``joint``, or every joint with ``None``."""
        j = -1 if joint is None else _joint(joint)
        return self._sent(_c.limber_actarray_home(self._h, j, self._ticket_ref))

    def set_current(self, joint: Optional[int], current: float) -> Ticket:
        """CMD CURRENT: drive ``joint`` (or every joint with ``None``) with ``current`` A."""
        j = -1 if joint is None else _joint(joint)
        return self._sent(_c.limber_actarray_set_current(self._h, j, current, self._ticket_ref))

    def set_current_multi(self, currents: Sequence[float]) -> Ticket:
        """CMD MULTI_CURRENT: drive joints 0..n with ``currents`` A."""
        arr, n = _doubles(currents)
        rc = _c.limber_actarray_set_current_multi(self._h, arr, n, self._ticket_ref)
        return self._sent(rc)

    def power(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ POWER."""
        self._replied(_c.limber_actarray_power(self._h, bool(on), self._timeout_ms(timeout)))

    def brakes(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ BRAKES."""
        self._replied(_c.limber_actarray_brakes(self._h, bool(on), self._timeout_ms(timeout)))

    def set_speed_config(
        self, joint: int, speed: float, *, timeout: Optional[float] = None
    ) -> None:
        """REQ SPEED: the speed of ``joint`` for later moves."""
        j, ms = _joint(joint), self._timeout_ms(timeout)
        self._replied(_c.limber_actarray_set_speed_config(self._h, j, speed, ms))

    def set_accel_config(
        self, joint: int, accel: float, *, timeout: Optional[float] = None
    ) -> None:
        """REQ ACCEL: the acceleration of ``joint`` for later moves."""
        j, ms = _joint(joint), self._timeout_ms(timeout)
        self._replied(_c.limber_actarray_set_accel_config(self._h, j, accel, ms))

    def geometry(self, *, timeout: Optional[float] = None) -> "L.ActArrayGeom":
        """REQ GET_GEOM: the geometry (an ``ActArrayGeom`` ctypes struct, validated)."""
        g: L.ActArrayGeom = self._geometry(timeout)
        return g

    def positions(self) -> "list[float]":
        """The positions of the valid actuators in the latest state (empty if none yet)."""
        s = self.state()
        if s is None:
            return []
        return [a.position for a in s.actuators[: s.actuators_count]]


def _joint(j: int) -> int:
    """A joint index for the C call (the library checks its range; a negative one cannot be
    passed as the C ``uint32_t``)."""
    if isinstance(j, bool) or not isinstance(j, int):
        raise TypeError(f"a joint index is an int, not {j!r}")
    if j < 0:
        raise ValueError(f"joint {j} is not a valid joint index")
    return j


@atexit.register
def _close_all() -> None:
    """Closes every client still open at interpreter exit, before module teardown, so that
    no dead node is left behind (clients in module globals would otherwise leak)."""
    for c in list(_open_clients):
        try:
            c.close()
        except Exception:
            pass
