"""liblimber, loaded with ctypes: where it is found, and the prototype of every function the
package calls (one table, so that a call with a wrong argument is a Python error, never a
crash). The structs here are the C API's own (``limber_ticket``, ``limber_outcome``, ...);
the states and geometries are the generated classes of :mod:`limber._layout`.

The library is found in this order:

1. ``LIMBER_LIB``: the path of a ``liblimber.so`` (only that one is tried);
2. ``liblimber.so`` inside the installed package (``pip install ./python`` puts it there);
3. in a source checkout used with ``PYTHONPATH=python``: ``liblimber.so`` in
   ``${CARGO_TARGET_DIR:-<repo>/target}/release``, then ``.../debug``.
"""

from __future__ import annotations

import ctypes
import os
from ctypes import (
    POINTER,
    c_bool,
    c_char,
    c_char_p,
    c_double,
    c_int32,
    c_size_t,
    c_uint32,
    c_uint64,
    c_void_p,
)
from typing import Any, List, Optional, Tuple

from . import _layout as L

#: The environment variable with the path of the liblimber.so to load.
LIB_ENV = "LIMBER_LIB"
_LIB_NAME = "liblimber.so"


class LibraryNotFound(ImportError):
    """No liblimber.so could be loaded (the message says where it looked and what to do)."""


# ----- the C API's structs -----------------------------------------------------------------


class Ticket(ctypes.Structure):
    """``limber_ticket``."""

    _fields_ = [("seq", c_uint64), ("receivers", c_uint64)]


class Outcome(ctypes.Structure):
    """``limber_outcome``."""

    _fields_ = [
        ("seq", c_uint64),
        ("status", c_uint32),
        ("_pad", c_uint32),
        ("other_client", c_uint64),
        ("stamp_ns", c_uint64),
        ("other_name", c_char * 32),
    ]


class Done(ctypes.Structure):
    """``limber_done``."""

    _fields_ = [
        ("seq", c_uint64),
        ("result", c_uint32),
        ("cause", c_uint32),
        ("other_client", c_uint64),
        ("stamp_ns", c_uint64),
        ("parts", c_uint32),
        ("_pad", c_uint32),
        ("max_error", ctypes.c_double),
        ("tolerance", ctypes.c_double),
        ("position", ctypes.c_double * 32),
        ("error", ctypes.c_double * 32),
        ("sentence", c_char * 160),
    ]


class LeaseHolder(ctypes.Structure):
    """``limber_lease_holder``."""

    _fields_ = [("client_id", c_uint64), ("heartbeat_ms", c_uint64), ("name", c_char * 32)]


DEVICE_NAME_CAPACITY = 96
DRIVER_NAME_CAPACITY = 64


class DeviceInfo(ctypes.Structure):
    """``limber_device_info``."""

    _fields_ = [
        ("name", c_char * DEVICE_NAME_CAPACITY),
        ("driver", c_char * DRIVER_NAME_CAPACITY),
        ("interface", c_int32),
        ("alive", c_bool),
        ("nodes", c_uint32),
        ("layout", c_uint32),
    ]


# ----- codes and enums of limber_client.h ----------------------------------------------------

CODE_OK = 0
CODE_NULL_ARGUMENT = 1
CODE_BAD_UTF8 = 2
CODE_BAD_NAME = 3
CODE_NO_DRIVER = 4
CODE_INCOMPATIBLE = 5
CODE_TIMEOUT = 6
CODE_DRIVER_GONE = 7
CODE_REFUSED = 8
CODE_INVALID_VALUE = 9
CODE_OUTCOME_MISSED = 10
CODE_BORROWED = 11
CODE_BAD_REPLY = 12
CODE_TRANSPORT = 13
CODE_INTERNAL = 14
CODE_LEASE_LOST = 15

INTERFACE_ACTARRAY = 0
INTERFACE_LIMB = 1
INTERFACE_GRIPPER = 2
INTERFACE_RANGER = 3

LIVENESS_ALIVE = 0
LIVENESS_STALE = 1
LIVENESS_GONE = 2
LIVENESS_NO_DATA = 3

DRIVER_ALIVE = 0
DRIVER_DEAD = 1
DRIVER_ABSENT = 2

# ----- the prototypes ------------------------------------------------------------------------

_H = c_void_p  # a limber_device* (or limber_stats*)
_P_TICKET = POINTER(Ticket)
_VEC3 = L.Vec3
_CODE = c_int32

#: name: (restype, argtypes) of every function the package calls.
PROTOTYPES: "dict[str, Tuple[Any, List[Any]]]" = {
    # errors and statuses
    "limber_strerror": (c_char_p, [c_int32]),
    "limber_last_error": (c_char_p, []),
    "limber_last_refusal": (c_uint32, []),
    "limber_last_holder": (None, [POINTER(LeaseHolder)]),
    "limber_layout_version": (c_uint32, []),
    "limber_status_text": (c_char_p, [c_uint32]),
    "limber_status_is_carried_out": (c_bool, [c_uint32]),
    "limber_default_spin_budget_us": (c_uint64, []),
    "limber_set_program_name": (_CODE, [c_char_p]),
    # every interface
    "limber_device_connect_checked": (
        _CODE,
        [c_char_p, c_char_p, c_uint64, c_uint32, c_int32, c_size_t, c_size_t, POINTER(_H)],
    ),
    "limber_device_disconnect": (None, [_H]),
    "limber_device_state": (_CODE, [_H, c_uint64, c_void_p, c_size_t]),
    "limber_device_last_state": (_CODE, [_H, c_void_p, c_size_t]),
    "limber_device_wait_state": (_CODE, [_H, c_uint64, c_void_p, c_size_t]),
    "limber_device_refresh": (_CODE, [_H, POINTER(c_bool)]),
    "limber_device_fd": (_CODE, [_H, POINTER(c_int32)]),
    "limber_device_outcome": (_CODE, [_H, Ticket, c_uint64, POINTER(Outcome)]),
    "limber_device_wait_done": (_CODE, [_H, Ticket, c_uint64, POINTER(Done)]),
    "limber_device_preemption": (_CODE, [_H, Ticket, POINTER(c_bool), POINTER(Outcome)]),
    "limber_device_liveness": (_CODE, [_H, c_uint64, POINTER(c_int32)]),
    "limber_device_state_age": (_CODE, [_H, POINTER(c_uint64)]),
    "limber_device_driver_status": (_CODE, [_H, POINTER(c_int32)]),
    "limber_device_geometry": (_CODE, [_H, c_uint64, c_void_p, c_size_t]),
    "limber_device_set_wait": (_CODE, [_H, c_bool, c_uint64]),
    "limber_device_set_request_timeout": (_CODE, [_H, c_uint64]),
    "limber_device_client_id": (_CODE, [_H, POINTER(c_uint64)]),
    "limber_device_acquire": (_CODE, [_H, c_char_p, c_uint64]),
    "limber_device_renew": (_CODE, [_H]),
    "limber_device_keep_lease": (_CODE, [_H, POINTER(c_bool)]),
    "limber_device_release_lease": (_CODE, [_H]),
    "limber_device_holds_lease": (_CODE, [_H, POINTER(c_bool)]),
    "limber_device_holder": (_CODE, [_H, POINTER(LeaseHolder)]),
    "limber_list_devices": (_CODE, [c_char_p, POINTER(DeviceInfo), c_size_t, POINTER(c_size_t)]),
    "limber_remove_domain_files": (_CODE, [c_char_p, POINTER(c_size_t)]),
    # actarray
    "limber_actarray_move_to": (_CODE, [_H, c_uint32, c_double, _P_TICKET]),
    "limber_actarray_move_to_multi": (_CODE, [_H, POINTER(c_double), c_size_t, _P_TICKET]),
    "limber_actarray_move_at_speed": (_CODE, [_H, c_uint32, c_double, _P_TICKET]),
    "limber_actarray_move_at_speed_multi": (_CODE, [_H, POINTER(c_double), c_size_t, _P_TICKET]),
    "limber_actarray_home": (_CODE, [_H, c_int32, _P_TICKET]),
    "limber_actarray_set_current": (_CODE, [_H, c_int32, c_double, _P_TICKET]),
    "limber_actarray_set_current_multi": (_CODE, [_H, POINTER(c_double), c_size_t, _P_TICKET]),
    "limber_actarray_power": (_CODE, [_H, c_bool, c_uint64]),
    "limber_actarray_brakes": (_CODE, [_H, c_bool, c_uint64]),
    "limber_actarray_set_speed_config": (_CODE, [_H, c_uint32, c_double, c_uint64]),
    "limber_actarray_set_accel_config": (_CODE, [_H, c_uint32, c_double, c_uint64]),
    "limber_actarray_follow_trajectory": (
        _CODE,
        [
            _H,
            POINTER(c_uint32),
            c_size_t,
            POINTER(c_double),
            c_size_t,
            POINTER(c_double),
            POINTER(c_double),
            POINTER(c_double),
            POINTER(c_double),
            POINTER(c_double),
            c_double,
            c_uint64,
            _P_TICKET,
        ],
    ),
    "limber_actarray_set_trajectory_scale": (_CODE, [_H, c_double, _P_TICKET]),
    # limb
    "limber_limb_home": (_CODE, [_H, _P_TICKET]),
    "limber_limb_stop": (_CODE, [_H, _P_TICKET]),
    "limber_limb_set_pose": (_CODE, [_H, _VEC3, _VEC3, _VEC3, _P_TICKET]),
    "limber_limb_set_position": (_CODE, [_H, _VEC3, _P_TICKET]),
    "limber_limb_line": (_CODE, [_H, _VEC3, POINTER(_VEC3), POINTER(_VEC3), c_double, _P_TICKET]),
    "limber_limb_ptp": (_CODE, [_H, _VEC3, POINTER(_VEC3), POINTER(_VEC3), c_double, _P_TICKET]),
    "limber_limb_vec_move": (_CODE, [_H, _VEC3, c_double, _P_TICKET]),
    "limber_limb_power": (_CODE, [_H, c_bool, c_uint64]),
    "limber_limb_brakes": (_CODE, [_H, c_bool, c_uint64]),
    "limber_limb_set_speed": (_CODE, [_H, c_double, c_uint64]),
    "limber_limb_can_reach": (
        _CODE,
        [_H, _VEC3, _VEC3, _VEC3, c_uint64, POINTER(L.LimbReach)],
    ),
    # gripper
    "limber_gripper_open": (_CODE, [_H, _P_TICKET]),
    "limber_gripper_close": (_CODE, [_H, _P_TICKET]),
    "limber_gripper_stop": (_CODE, [_H, _P_TICKET]),
    "limber_gripper_store": (_CODE, [_H, _P_TICKET]),
    "limber_gripper_retrieve": (_CODE, [_H, _P_TICKET]),
    "limber_gripper_goal": (_CODE, [_H, c_double, c_double, c_double, _P_TICKET]),
    # ranger
    "limber_ranger_point": (
        _CODE,
        [POINTER(L.RangerData), c_size_t, POINTER(c_double), POINTER(c_double), POINTER(c_double)],
    ),
    # driver statistics
    "limber_stats_open": (_CODE, [c_char_p, c_char_p, POINTER(_H)]),
    "limber_stats_close": (None, [_H]),
    "limber_stats_latest": (_CODE, [_H, POINTER(L.DriverStats)]),
    "limber_stats_wait": (_CODE, [_H, c_uint64, POINTER(L.DriverStats)]),
}


def _repo_target_dirs() -> "list[str]":
    """``<target>/release`` and ``<target>/debug`` of the source checkout this package lies
    in (``<repo>/python/limber``), or nothing when it is not in one."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if not os.path.isfile(os.path.join(repo, "Cargo.toml")):
        return []
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(repo, "target")
    return [os.path.join(target, "release"), os.path.join(target, "debug")]


def candidates() -> "list[Tuple[str, str]]":
    """(where, path) of every liblimber.so this package would try, in order."""
    env = os.environ.get(LIB_ENV)
    if env:
        return [(LIB_ENV, env)]
    out = [("the installed package", os.path.join(os.path.dirname(__file__), _LIB_NAME))]
    for d in _repo_target_dirs():
        out.append(("the source checkout", os.path.join(d, _LIB_NAME)))
    return out


def _load() -> "Tuple[ctypes.CDLL, str]":
    tried = []
    for where, path in candidates():
        if not os.path.isfile(path):
            tried.append(f"{path} ({where}): not there")
            continue
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            raise LibraryNotFound(
                f"limber: cannot load liblimber from {path} ({where}): {e}"
            ) from None
        missing = [name for name in PROTOTYPES if not hasattr(lib, name)]
        if missing:
            raise LibraryNotFound(
                f"limber: {path} ({where}) lacks {', '.join(missing)}: it is an older "
                "liblimber than this package; build the one of this release "
                "(cargo build -p limber-c) or set LIMBER_LIB to it"
            )
        return lib, path
    raise LibraryNotFound(
        "limber: no liblimber.so found; tried: " + "; ".join(tried) + ". Install the package "
        "with `pip install ./python` (it builds and carries the library), or build it with "
        "`cargo build -p limber-c` in the source tree, or set LIMBER_LIB to the path of a "
        "liblimber.so"
    )


lib, path = _load()
for _name, (_res, _args) in PROTOTYPES.items():
    _f = getattr(lib, _name)
    _f.restype = _res
    _f.argtypes = _args


def unchecked(name: str) -> Any:
    """A second handle on the C function ``name``, with its ``restype`` but no ``argtypes``:
    ctypes then passes each argument as it is instead of converting it, and a call costs a
    half to a third of one through the checked prototype (measured with ctypes on CPython
    3.11: 0.72 -> 0.35 us for ``limber_actarray_move_to``). For the hot path only, and only
    with arguments of the exact C types: ctypes values (``c_double``, ``c_uint64``,
    ``c_size_t``, a struct passed by value, ``byref``), a handle (``c_void_p`` or ``None``),
    or a Python int for a 32-bit integer that the caller has checked for range."""
    f = lib[name]
    f.restype = PROTOTYPES[name][0]
    return f


# ----- the state copy of a control loop ----------------------------------------------------

#: ``1``: call liblimber through ctypes alone even where the package carries its compiled
#: ``limber._fast`` (to compare the two; they return the same).
CTYPES_ENV = "LIMBER_PY_CTYPES"


_NO_WAIT = c_uint64(0)


def _ctypes_copy_out(
    fn: Any, handle: Any, timeout_ms: int, cls: Any, spare: Optional[List[Any]] = None
) -> Any:
    """``copy_out`` through ctypes: ``fn`` is liblimber's function without its argument
    types (``unchecked``: a call costs half), ``handle`` its ``c_void_p`` (or ``None``).
    ``spare`` is not used: every instance is new (what the compiled one recycles is an
    instance nobody can tell from a new one)."""
    out = cls()
    ms = _NO_WAIT if timeout_ms == 0 else c_uint64(timeout_ms)
    code: int = fn(handle, ms, ctypes.byref(out), c_size_t(ctypes.sizeof(out)))
    return code or out


def _copy_out_impl() -> "Tuple[Any, bool]":
    """The ``copy_out`` this process uses, and whether it is the compiled one."""
    if os.environ.get(CTYPES_ENV, "") not in ("", "0"):
        return _ctypes_copy_out, False
    try:
        from . import _fast  # type: ignore[attr-defined]
    except ImportError:  # a source checkout, or a wheel built without a C compiler
        return _ctypes_copy_out, False
    return _fast.copy_out, True


#: ``copy_out(fn, handle, timeout_ms, cls, spare=None)``: calls a liblimber function of the
#: shape of ``limber_device_state`` (``copier(name)``) with the handle's address (``None`` for
#: none), ``timeout_ms`` and a new ``cls()``; returns that instance when the call returns 0,
#: else the code. The compiled ``limber._fast`` when the package carries it (pip builds it),
#: else ctypes: both call the same function of the same library, with the same arguments.
#: ``spare`` (``new_spare()``, kept by the caller): the compiled one may hand back an instance
#: it returned before that nothing else references any more instead of allocating one.
copy_out, COMPILED = _copy_out_impl()


def new_spare() -> List[Any]:
    """The ``spare`` of ``copy_out``: two entries, empty at first."""
    return [None, None]


def copier(name: str) -> Any:
    """The ``fn`` that ``copy_out`` takes for liblimber's function ``name``: its address for
    the compiled ``copy_out``, for ctypes' the function (``unchecked``)."""
    if COMPILED:
        return ctypes.cast(getattr(lib, name), c_void_p).value
    return unchecked(name)


def handle_arg(h: Optional[c_void_p]) -> Any:
    """A handle as ``copy_out`` takes it: its address for the compiled one (``None`` for
    none), the ``c_void_p`` itself for ctypes'."""
    if h is None:
        return None
    return h.value if COMPILED else h


def last_error() -> str:
    """``limber_last_error()``: the detail of the last failure on this thread."""
    raw: Optional[bytes] = lib.limber_last_error()
    return (raw or b"").decode("utf-8", "replace")


def text(raw: bytes) -> str:
    """A NUL-terminated C string field, decoded (bytes that are not UTF-8 replaced)."""
    return raw.decode("utf-8", "replace")
