"""The client of a limb: Player's ``LimbProxy`` (Rust ``LimbClient``).

Its commands (HOME, STOP, SETPOSE, SETPOSITION, VECMOVE and limber's LINE and PTP paths) and
requests (POWER, BRAKES, SPEED, GEOM, REACH) are one-liners over liblimber's
``limber_limb_*``; states, waits, outcomes, results and leases are every client's
(:class:`~limber.client._Client`).
"""

from __future__ import annotations

from ctypes import byref, sizeof
from typing import Any, Optional, Sequence, Tuple

from . import _layout as L
from . import _lib
from ._lib import lib as _c
from .client import Ticket, _Client, _vec3

__all__ = ["LimbClient"]


def _path_orientation(
    o: "Optional[Tuple[Sequence[float], Sequence[float]]]",
) -> "Tuple[Any, Any]":
    """A path's orientation for C: two NULLs (kept) or pointers to the two vectors."""
    if o is None:
        return None, None
    a, v = o
    return byref(_vec3(a)), byref(_vec3(v))


class LimbClient(_Client[L.LimbData]):
    """A client of a limb (Player's ``LimbProxy``; Rust ``LimbClient``). Vectors are any
    3-sequences (robot frame, m); direction vectors must not be zero."""

    INTERFACE = "limb"
    INTERFACE_CODE = _lib.INTERFACE_LIMB
    DATA = L.LimbData
    GEOM = L.LimbGeom
    _data_size = sizeof(L.LimbData)

    def home(self) -> Ticket:
        """CMD HOME."""
        return self._sent(_c.limber_limb_home(self._h, self._ticket_ref))

    def stop(self) -> Ticket:
        """CMD STOP: stop every joint now."""
        return self._sent(_c.limber_limb_stop(self._h, self._ticket_ref))

    def set_pose(
        self, position: Sequence[float], approach: Sequence[float], orientation: Sequence[float]
    ) -> Ticket:
        """CMD SETPOSE: end effector to ``position`` with ``approach`` and ``orientation``."""
        p, a, o = _vec3(position), _vec3(approach), _vec3(orientation)
        return self._sent(_c.limber_limb_set_pose(self._h, p, a, o, self._ticket_ref))

    def set_position(self, position: Sequence[float]) -> Ticket:
        """CMD SETPOSITION: end effector to ``position``, orientation chosen by the driver."""
        p = _vec3(position)
        return self._sent(_c.limber_limb_set_position(self._h, p, self._ticket_ref))

    def vec_move(self, direction: Sequence[float], length: float) -> Ticket:
        """CMD VECMOVE: move ``length`` m along ``direction`` in a straight line."""
        d = _vec3(direction)
        return self._sent(_c.limber_limb_vec_move(self._h, d, length, self._ticket_ref))

    def line(
        self,
        position: Sequence[float],
        orientation: Optional[Tuple[Sequence[float], Sequence[float]]] = None,
        speed: float = 0.0,
    ) -> Ticket:
        """CMD LINE: the tool in a straight line to ``position``, its orientation kept
        (``None``) or turned evenly to ``(approach, orientation)``, at most ``speed`` m/s
        (0: the limb's own). Refused before anything moves when the line leaves the reach
        or hits the world (the state's ``refused_at`` says where)."""
        a, o = _path_orientation(orientation)
        p = _vec3(position)
        return self._sent(_c.limber_limb_line(self._h, p, a, o, speed, self._ticket_ref))

    def ptp(
        self,
        position: Sequence[float],
        orientation: Optional[Tuple[Sequence[float], Sequence[float]]] = None,
        speed: float = 0.0,
    ) -> Ticket:
        """CMD PTP: the joints interpolated to where the tool is at ``position`` with its
        orientation kept (``None``) or the given ``(approach, orientation)``, the fastest
        joint at most ``speed`` rad/s (0: the joints' own); refused as :meth:`line`."""
        a, o = _path_orientation(orientation)
        p = _vec3(position)
        return self._sent(_c.limber_limb_ptp(self._h, p, a, o, speed, self._ticket_ref))

    def power(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ POWER."""
        self._replied(_c.limber_limb_power(self._h, bool(on), self._timeout_ms(timeout)))

    def brakes(self, on: bool, *, timeout: Optional[float] = None) -> None:
        """REQ BRAKES."""
        self._replied(_c.limber_limb_brakes(self._h, bool(on), self._timeout_ms(timeout)))

    def set_speed(self, speed: float, *, timeout: Optional[float] = None) -> None:
        """REQ SPEED: end-effector speed, m/s."""
        self._replied(_c.limber_limb_set_speed(self._h, speed, self._timeout_ms(timeout)))

    def geometry(self, *, timeout: Optional[float] = None) -> "L.LimbGeom":
        """REQ GEOM: the geometry (a ``LimbGeom`` ctypes struct)."""
        g: L.LimbGeom = self._geometry(timeout)
        return g

    def reach(
        self,
        position: Sequence[float],
        approach: Sequence[float],
        orientation: Sequence[float],
        *,
        timeout: Optional[float] = None,
    ) -> "L.LimbReach":
        """REQ REACH: where a SETPOSE to this pose would end (a ``LimbReach`` ctypes struct:
        the pose, ``orientation_adjustment`` in rad, ``adjusted`` 0 or 1); nothing moves.
        A pose the limb cannot get to raises :class:`NackError` with its cause."""
        p, a, o = _vec3(position), _vec3(approach), _vec3(orientation)
        r = L.LimbReach()
        rc = _c.limber_limb_can_reach(self._h, p, a, o, self._timeout_ms(timeout), byref(r))
        self._replied(rc)
        return r
