"""The client of a gripper: Player's ``GripperProxy`` (Rust ``GripperClient``).

Its commands (OPEN, CLOSE, STOP, STORE, RETRIEVE and limber's GOAL, a gap with a maximum
effort and speed whose result says REACHED or STALLED, with ``OBJECT_PRESENT`` when the
break beams see an object) are one-liners over liblimber's ``limber_gripper_*``; states,
waits, outcomes, results and leases are every client's (:class:`~limber.client._Client`).
"""

from __future__ import annotations

from ctypes import sizeof
from typing import Optional

from . import _layout as L
from . import _lib
from ._lib import lib as _c
from .client import Ticket, _Client

__all__ = ["GripperClient"]


class GripperClient(_Client[L.GripperData]):
    """A client of a gripper (Player's ``GripperProxy``; Rust ``GripperClient``)."""

    INTERFACE = "gripper"
    INTERFACE_CODE = _lib.INTERFACE_GRIPPER
    DATA = L.GripperData
    GEOM = L.GripperGeom
    _data_size = sizeof(L.GripperData)

    def open(self) -> Ticket:
        """CMD OPEN."""
        return self._sent(_c.limber_gripper_open(self._h, self._ticket_ref))

    def close_gripper(self) -> Ticket:
        """CMD CLOSE. (Not ``close()``: on every client, :meth:`close` releases the
        connection, so that a cleanup call can never move the hardware.)"""
        return self._sent(_c.limber_gripper_close(self._h, self._ticket_ref))

    def open_gripper(self) -> Ticket:
        """CMD OPEN (the same as :meth:`open`, named to pair with :meth:`close_gripper`)."""
        return self.open()

    def stop(self) -> Ticket:
        """CMD STOP."""
        return self._sent(_c.limber_gripper_stop(self._h, self._ticket_ref))

    def store(self) -> Ticket:
        """CMD STORE."""
        return self._sent(_c.limber_gripper_store(self._h, self._ticket_ref))

    def retrieve(self) -> Ticket:
        """CMD RETRIEVE."""
        return self._sent(_c.limber_gripper_retrieve(self._h, self._ticket_ref))

    def goal(self, gap: float, effort: float = 0.0, speed: float = 0.0) -> Ticket:
        """CMD GOAL: the fingers to ``gap`` m, with at most ``effort`` N, at ``speed`` m/s
        (0: the gripper's own). :meth:`wait_done` gives REACHED or STALLED, with the
        status ``OBJECT_PRESENT`` when the break beams see an object."""
        return self._sent(_c.limber_gripper_goal(self._h, gap, effort, speed, self._ticket_ref))

    def geometry(self, *, timeout: Optional[float] = None) -> "L.GripperGeom":
        """REQ GET_GEOM: the geometry (a ``GripperGeom`` ctypes struct)."""
        g: L.GripperGeom = self._geometry(timeout)
        return g
