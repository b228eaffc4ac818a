"""The client of a ranger (a laser scanner): Player's ``RangerProxy`` (``LaserProxy``).

A ranger has no command: a scan is its state (``RangerData``: ``ranges`` with
``ranges_count``, ``min_angle``, ``angular_res``, ``max_range``...), read like any
client's (:meth:`~limber.client.ActArrayClient.state`, ``wait_state``...), and its
geometry says where the sensor sits on the robot. The bearing and point of a range are
computed by liblimber (``limber_ranger_point``), as in C and C++.
"""

from __future__ import annotations

from ctypes import byref, c_double, sizeof
from typing import List, Optional, Tuple

from . import _layout as L
from . import _lib
from ._lib import lib as _c
from ._types import _error
from .client import _Client

__all__ = ["RangerClient", "LaserClient", "ranges", "point"]


def ranges(scan: "L.RangerData") -> List[float]:
    """The valid ranges of ``scan`` (m), cut to its ``ranges_count``."""
    return list(scan.ranges[: min(scan.ranges_count, len(scan.ranges))])


def point(scan: "L.RangerData", index: int) -> Tuple[float, float, float]:
    """Range ``index`` of ``scan`` as ``(bearing, x, y)``: its bearing (rad) and the
    point it hit in the sensor's frame (m), Player's ``GetBearing`` and ``GetPoint``.
    ValueError beyond the scan's count (liblimber's ``LIMBER_CODE_INVALID_VALUE``)."""
    b, x, y = c_double(), c_double(), c_double()
    rc = _c.limber_ranger_point(byref(scan), int(index), byref(b), byref(x), byref(y))
    if rc:
        raise _error(rc)
    return b.value, x.value, y.value


class RangerClient(_Client[L.RangerData]):
    """A client of a ranger (Player's ``RangerProxy``; Rust ``RangerClient``)."""

    INTERFACE = "ranger"
    INTERFACE_CODE = _lib.INTERFACE_RANGER
    DATA = L.RangerData
    GEOM = L.RangerGeom
    _data_size = sizeof(L.RangerData)

    def geometry(self, *, timeout: Optional[float] = None) -> "L.RangerGeom":
        """REQ GET_GEOM: the sensor's pose on the robot, its size and configuration (a
        ``RangerGeom`` ctypes struct)."""
        g: L.RangerGeom = self._geometry(timeout)
        return g


#: Player's name for a planar laser's client.
LaserClient = RangerClient
