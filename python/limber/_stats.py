"""A driver's statistics (``limber_driver_stats``), over liblimber. See :mod:`limber.client`."""

from __future__ import annotations

import ctypes
from ctypes import byref, c_void_p
from typing import Optional

from . import _layout as L
from . import _lib
from ._lib import lib as _c
from ._names import Domain, _default_process_name, _domain_arg, _open_clients, _Owned
from ._types import DecodeError, LimberError, _check_layout, _error, _ms

def stats_text(field: "ctypes.Array[ctypes.c_uint8]") -> str:
    """A text field of :class:`DriverStats` (NUL-padded UTF-8) as a string; raises
    :class:`DecodeError` when it is not UTF-8."""
    raw = bytes(field)
    end = raw.find(b"\0")
    try:
        return (raw if end < 0 else raw[:end]).decode("utf-8")
    except UnicodeDecodeError:
        raise DecodeError("undecodable text field in the driver statistics") from None


class DriverStatsReader(_Owned):
    """Reads the statistics a driver publishes on ``<robot>/driver/0`` (its loop, link and
    hardware: :class:`DriverStats`), as ``limber echo pioneer/driver`` does
    (``limber_stats_*``). Open with :meth:`open`; close with :meth:`close` or ``with``."""

    def __init__(self) -> None:  # use open()
        self._h: Optional[c_void_p] = None
        self._latest: "Optional[L.DriverStats]" = None

    @property
    def _closed(self) -> bool:
        return self._h is None

    @classmethod
    def open(
        cls, robot: str = "pioneer", domain: "Domain | str | None" = None
    ) -> "DriverStatsReader":
        """Opens the statistics of ``robot``'s driver in ``domain`` (default: from
        ``LIMBER_DOMAIN``). Raises :class:`NoDriverError` when no driver publishes them,
        :class:`ValueError` for a bad robot name, :class:`TransportError` otherwise."""
        if not isinstance(robot, str):
            raise ValueError(f"a robot name is a string, not {robot!r}")
        _check_layout(f"the statistics of {robot}")
        rc = _c.limber_set_program_name(_default_process_name().encode("utf-8"))
        if rc:
            raise _error(rc)
        h = c_void_p()
        rc = _c.limber_stats_open(robot.encode("utf-8"), _domain_arg(domain), byref(h))
        if rc:
            raise _error(rc)
        self = cls()
        self._h = h
        _open_clients.add(self)
        return self

    def _take(self) -> bool:
        if self._h is None:
            raise LimberError("the statistics reader is closed")
        s = L.DriverStats()
        rc = _c.limber_stats_latest(self._h, byref(s))
        if rc == _lib.CODE_TIMEOUT:
            return False
        if rc:
            raise _error(rc)
        new = self._latest is None or s.header.seq != self._latest.header.seq
        self._latest = s
        return new

    def refresh(self) -> bool:
        """Takes what arrived; true if there was something new."""
        return self._take()

    def latest(self) -> "Optional[L.DriverStats]":
        """The latest statistics taken (a copy), or None."""
        return self._latest

    def wait(self, timeout: float) -> "L.DriverStats":
        """Waits up to ``timeout`` s for new statistics and returns them (a copy). Raises
        :class:`WaitTimeout`."""
        if self._h is None:
            raise LimberError("the statistics reader is closed")
        s = L.DriverStats()
        rc = _c.limber_stats_wait(self._h, _ms("timeout", timeout), byref(s))
        if rc:
            raise _error(rc)
        self._latest = s
        return s

    def close(self) -> None:
        """Closes the reader (idempotent)."""
        h = self.__dict__.get("_h")
        if h is not None:
            self._h = None
            _open_clients.discard(self)
            _c.limber_stats_close(h)



