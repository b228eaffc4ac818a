"""Wait modes: busy-polling (WaitMode.SPIN) and the event mode's spin-then-block after a send
(the spin budget, LIMBER_SPIN_US), against the Rust test driver."""

import pytest

from limber import ActArrayClient, LimbClient, Status, WaitMode, client as C
from limber import SPIN_BUDGET, default_spin_budget
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
        # Polling only: the client never listened for the driver's notifications.
        assert arm._notify is None
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
        assert limb._notify is None
        # Budget zero: a wait that finds nothing blocks on a notification at once.
        limb.set_spin_budget(0)
        assert limb.wait_outcome(limb.stop(), T) is Status.OK
        for _ in range(100):  # each wait that finds no newer state listens for one
            limb.wait_state(T)
            if limb._notify is not None:
                break
        assert limb._notify is not None
        for bad in (-1.0, float("nan"), float("inf")):
            with pytest.raises(ValueError):
                limb.set_spin_budget(bad)


def test_default_spin_budget_follows_the_environment_and_the_cores(monkeypatch):
    assert C._spin_budget_from(None, 2) == SPIN_BUDGET == 30e-6
    assert C._spin_budget_from(None, 1) == 0.0
    assert C._spin_budget_from("0", 8) == 0.0
    assert C._spin_budget_from(" 120 ", 1) == pytest.approx(120e-6)
    assert C._spin_budget_from("5000000", 2) == 1.0
    with pytest.warns(UserWarning, match="LIMBER_SPIN_US"):
        assert C._spin_budget_from("fast", 2) == SPIN_BUDGET
    monkeypatch.setenv("LIMBER_SPIN_US", "75")
    assert default_spin_budget() == pytest.approx(75e-6)
