"""How a motion ended: :meth:`wait_done` of every client returns a :class:`Done`, read from
``limber_device_wait_done`` (the result, its cause, each part's final position and error and
the sentence are the Rust core's; nothing is computed here)."""

from __future__ import annotations

import ctypes
import enum
import math
from dataclasses import dataclass
from typing import Any, Tuple

from . import _layout as L
from . import _lib
from ._types import Status, Ticket, _status


class MotionResult(enum.IntEnum):
    """How a motion ended (Rust ``MotionResult``; wire ``RESULT_*``)."""

    REACHED = L.RESULT_REACHED
    STALLED = L.RESULT_STALLED
    STOPPED = L.RESULT_STOPPED
    PREEMPTED = L.RESULT_PREEMPTED
    ABORTED = L.RESULT_ABORTED
    TIMED_OUT = L.RESULT_TIMED_OUT
    PATH_TOLERANCE_VIOLATED = L.RESULT_PATH_TOLERANCE_VIOLATED
    GOAL_TOLERANCE_VIOLATED = L.RESULT_GOAL_TOLERANCE_VIOLATED

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class Done:
    """How the motion of one of this client's commands ended (Rust ``Done``; C
    ``limber_done``)."""

    #: The command's sequence number (its :attr:`Ticket.seq`).
    seq: int
    #: How it ended.
    result: MotionResult
    #: Why: ``OK`` when reached; the cause of an abort (``LINK_DOWN``, ``POWERED_OFF``,
    #: ``BRAKED``); ``PREEMPTED``; ``LEASED`` for the deadman's stop.
    cause: Status
    #: The client whose command preempted or stopped it (0: none or the driver).
    other_client: int
    #: The largest |final error| against the goal (rad or m); NaN if not known.
    max_error: float
    #: The device's tolerance for "reached".
    tolerance: float
    #: Each part's final position (part i: joint i); NaN where not known.
    positions: Tuple[float, ...]
    #: Each part's final error against the goal (position - goal); NaN where not known.
    errors: Tuple[float, ...]
    #: The result in one sentence.
    sentence: str

    @property
    def reached(self) -> bool:
        """Every part reached its goal within the device's tolerance."""
        return self.result is MotionResult.REACHED

    def __str__(self) -> str:
        return self.sentence


_wait_done = _lib.lib.limber_device_wait_done


def wait_done(client: Any, ticket: Ticket, timeout: float) -> Done:
    """``limber_device_wait_done`` for ``client`` (see :meth:`limber.ActArrayClient.wait_done`)."""
    s = float(timeout)
    if not 0.0 <= s <= 1e9:
        raise ValueError(f"timeout must be a finite number of seconds >= 0, not {timeout!r}")
    tk = _lib.Ticket(ticket.seq, ticket.receivers)
    out = _lib.Done()
    rc = _wait_done(client._h, tk, math.ceil(s * 1000.0), ctypes.byref(out))
    if rc:
        raise client._fail(rc)
    n = min(out.parts, len(out.position))
    return Done(
        out.seq,
        MotionResult(out.result),
        _status(out.cause),
        out.other_client,
        out.max_error,
        out.tolerance,
        tuple(out.position[:n]),
        tuple(out.error[:n]),
        _lib.text(out.sentence),
    )
