"""Wait modes: busy-polling (WaitMode.SPIN) and the event mode's spin-then-block after a send
(the spin budget, LIMBER_SPIN_US), against the Rust test driver."""

import pytest

import os
import subprocess
import sys
import textwrap

from limber import ActArrayClient, LimbClient, Status, WaitMode
from limber import _layout as L

from test_client import T, driver  # noqa: F401  (the shared driver fixture)


def test_spin_mode_polls_and_never_blocks_on_a_notification(driver):  # noqa: F811
    with ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T) as arm:
        assert arm.wait_mode is WaitMode.EVENT
        arm.set_wait_mode(WaitMode.SPIN)
        assert arm.wait_mode is WaitMode.SPIN
        first = arm.wait_state(T)
        assert arm.wait_state(T).header.seq > first.header.seq
        t = arm.move_to(2, -0.5)
        assert arm.wait_outcome(t, T) is Status.OK
        assert arm.state().actuators[2].position == -0.5
        assert arm.geometry().actuators_count == 6
        with pytest.raises(ValueError):
            arm.set_wait_mode("spin")


def test_event_mode_polls_for_its_budget_after_a_send_then_blocks(driver):  # noqa: F811
    with LimbClient.connect(driver.dev("limb"), driver.domain, timeout=T) as limb:
        # A budget longer than any answer of a live driver: the outcome and the reply
        # arrive while the client polls, and it never needs a notification.
        limb.set_spin_budget(T)
        assert limb.spin_budget == T
        assert limb.wait_outcome(limb.home(), T) is Status.OK
        assert isinstance(limb.geometry(), L.LimbGeom)
        # Budget zero: a wait that finds nothing blocks on a notification at once.
        limb.set_spin_budget(0)
        assert limb.spin_budget == 0
        assert limb.wait_outcome(limb.stop(), T) is Status.OK
        first = limb.wait_state(T)
        assert limb.wait_state(T).header.seq > first.header.seq
        for bad in (-1.0, float("nan"), float("inf")):
            with pytest.raises(ValueError):
                limb.set_spin_budget(bad)


def test_default_spin_budget_follows_the_environment(driver):  # noqa: F811
    """The library's default (LIMBER_SPIN_US, else 30 µs on two or more cores, 0 on one),
    read once per process: a process of its own for each setting."""
    script = textwrap.dedent(f"""
        import os
        import limber
        b = limber.default_spin_budget()
        with limber.ActArrayClient.connect({driver.dev("actarray")!r}, {driver.domain!r},
                                           timeout=5) as arm:
            assert arm.spin_budget == b, (arm.spin_budget, b)
        print(round(b * 1e6))
    """)

    def budget(env):
        e = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
        e.pop("LIMBER_SPIN_US", None)
        e.update(env)
        out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             timeout=60, env=e)
        assert out.returncode == 0, out.stderr
        return int(out.stdout)

    assert budget({"LIMBER_SPIN_US": "75"}) == 75
    assert budget({"LIMBER_SPIN_US": "0"}) == 0
    assert budget({"LIMBER_SPIN_US": "5000000"}) == 1_000_000
    assert budget({}) == (30 if (os.cpu_count() or 1) >= 2 else 0)
