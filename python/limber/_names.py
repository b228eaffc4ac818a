"""Domains, device names and discovery, over liblimber. See :mod:`limber.client`."""

from __future__ import annotations

import os
import re
import sys
import weakref
from ctypes import byref, c_size_t
from dataclasses import dataclass
from typing import (
    Any,
    TypeVar,
    Optional,
)

from . import _lib
from ._lib import lib as _c
from ._types import *  # noqa: F401,F403
from ._types import _error


# ----- names -----------------------------------------------------------------------------


class Domain:
    """A domain: the set of devices and clients that can see each other (liblimber's
    ``domain`` argument). ``Domain()`` is the domain named by ``LIMBER_DOMAIN`` (default
    ``limber``); ``Domain(name)`` a domain by name. The library checks the name (1 to 48
    characters of ``[A-Za-z0-9_-]``; a bad one raises ``ValueError`` where it is used) and
    keeps the domain's files (docs/guide/security.md)."""

    __slots__ = ("_name",)

    def __init__(self, name: Optional[str] = None) -> None:
        if name is None:
            name = os.environ.get(DOMAIN_ENV) or DEFAULT_DOMAIN
        if not isinstance(name, str):
            raise ValueError(f"a domain name is a string, not {name!r}")
        self._name = name

    @classmethod
    def from_env(cls) -> "Domain":
        """The domain named by ``LIMBER_DOMAIN``, or ``limber``."""
        return cls(None)

    @property
    def name(self) -> str:
        return self._name

    def __str__(self) -> str:
        return self._name

    def __repr__(self) -> str:
        return f"Domain({self._name!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Domain) and other._name == self._name

    def __hash__(self) -> int:
        return hash(self._name)


def _domain_arg(domain: "Domain | str | None") -> Optional[bytes]:
    """The ``domain`` argument of a C call: the name, or NULL (``LIMBER_DOMAIN``)."""
    if domain is None:
        return None
    if isinstance(domain, Domain):
        return domain.name.encode("utf-8", "surrogateescape")
    if isinstance(domain, str):
        return domain.encode("utf-8", "surrogateescape")
    raise ValueError(f"a domain is a Domain, a name or None, not {domain!r}")


_INTERFACES = ("actarray", "limb", "gripper", "ranger")


@dataclass(frozen=True)
class DeviceName:
    """The name of a device: ``robot/interface/index``, e.g. ``pioneer/actarray/0``. The
    library checks the robot's name when the device is used."""

    robot: str
    interface: str
    index: int

    @classmethod
    def parse(cls, s: str) -> "DeviceName":
        """Splits ``robot/interface/index``; ValueError when it has not that form."""
        parts = s.split("/") if isinstance(s, str) else []
        if (
            len(parts) != 3
            or parts[1] not in _INTERFACES
            or not (parts[2].isascii() and parts[2].isdigit())
        ):
            raise ValueError(
                f"invalid device name {s!r}: expected robot/interface/index, e.g. "
                "pioneer/actarray/0 (interfaces: actarray, limb, gripper, ranger)"
            )
        return cls(parts[0], parts[1], int(parts[2]))

    def __str__(self) -> str:
        return f"{self.robot}/{self.interface}/{self.index}"


# ----- discovery -------------------------------------------------------------------------


@dataclass(frozen=True)
class DeviceInfo:
    """One device found in a domain (Rust ``discovery::DeviceInfo``)."""

    #: Its name (``robot/interface/index``).
    name: DeviceName
    #: The driver that offers it.
    driver: str
    #: The layout version it speaks ("" if it does not say).
    layout: str
    #: True while the driver's process lives.
    alive: bool
    #: Processes attached to its state channel (driver and clients).
    nodes: int

    @property
    def interface(self) -> str:
        """The interface: ``actarray``, ``limb``, ``gripper`` or ``ranger``."""
        return self.name.interface


def list_devices(domain: "Domain | str | None" = None) -> "list[DeviceInfo]":
    """Every device of ``domain`` (default: from ``LIMBER_DOMAIN``), sorted as ``limber
    list`` shows them (``limber_list_devices``). A device whose driver died is listed as not
    alive until its services are cleaned up. Raises :class:`TransportError` when the domain
    cannot be read, ``ValueError`` for a bad domain name."""
    dom = _domain_arg(domain)
    count = c_size_t(0)
    capacity = 16
    while True:
        out = (_lib.DeviceInfo * capacity)()
        rc = _c.limber_list_devices(dom, out, capacity, byref(count))
        if rc:
            raise _error(rc)
        if count.value <= capacity:
            break
        capacity = count.value
    return [
        DeviceInfo(
            name=DeviceName.parse(_lib.text(d.name)),
            driver=_lib.text(d.driver),
            layout=str(d.layout) if d.layout else "",
            alive=bool(d.alive),
            nodes=int(d.nodes),
        )
        for d in out[: count.value]
    ]


def remove_domain_files(domain: "Domain | str | None" = None) -> int:
    """Removes every file of ``domain`` once no process runs in it (what its killed
    processes left, the node counter in ``/dev/shm``, its token), as a test's domain does
    when it ends; returns how many files and directories went. Raises
    :class:`TransportError` while processes run in it (``limber_remove_domain_files``)."""
    removed = c_size_t(0)
    rc = _c.limber_remove_domain_files(_domain_arg(domain), byref(removed))
    if rc:
        raise _error(rc)
    return int(removed.value)


# ----- the generic client ----------------------------------------------------------------


#: Every client still open (closed by the atexit hook).
_open_clients: "weakref.WeakSet[Any]" = weakref.WeakSet()


def _default_process_name() -> str:
    """The script's name (what ``limber list`` shows for this process by default)."""
    name = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "python"
    return name[:60]


_O = TypeVar("_O", bound="_Owned")


class _Owned:
    """What owns a liblimber handle: closed by :meth:`close`, at the end of a ``with``, or
    when it is collected."""

    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self: _O) -> _O:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass
