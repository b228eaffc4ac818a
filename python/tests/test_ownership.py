"""Ownership against `limber pioneer --emulated`: leases (acquire with a name and heartbeat,
renew, keep_lease, release, holder) and preemption told to the preempted client."""

import os
import signal
import subprocess
import time

import pytest

from limber import (ActArrayClient, DriverStatus, LeaseHeldError, LeaseHolder, NackError,
                    Outcome, Status)
from limber import _layout as L

from test_client import T, cli_bin, unique_domain

ROBOT = "pyown"


@pytest.fixture(scope="module")
def pioneer():
    domain = unique_domain()
    env = dict(os.environ, LIMBER_DOMAIN=domain)
    proc = subprocess.Popen([cli_bin(), "pioneer", "--emulated", "--robot", ROBOT],
                            env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        yield domain
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def arm(domain, name, power=True):
    c = ActArrayClient.connect(f"{ROBOT}/actarray/0", domain, timeout=T, name=name)
    if power:
        c.power(True)
    return c


def test_a_lease_refuses_others_and_names_its_holder(pioneer):
    with arm(pioneer, "pya") as a, arm(pioneer, "pyb") as b:
        assert b.holder() is None
        a.acquire("py-owner", 2.0)
        assert a.holds_lease
        h = b.holder()
        assert h == LeaseHolder(a.client_id, "py-owner", 2.0)
        # B's command is refused, naming the holder; B cannot take the device.
        t = b.move_to(2, 0.1)
        assert b.wait_outcome(t, T) is Status.LEASED
        t = b.move_to(2, 0.1)
        o = b.outcome(t, T)
        assert o == Outcome(t.seq, Status.LEASED, a.client_id, "py-owner")
        with pytest.raises(LeaseHeldError) as e:
            b.acquire("py-other", 1.0)
        assert e.value.client_id == a.client_id and e.value.name == "py-owner"
        assert "py-owner" in str(e.value) and f"{a.client_id:x}" not in str(e.value)
        # A request that changes the device is refused, with the reason.
        with pytest.raises(NackError) as n:
            b.power(True)
        assert n.value.status is Status.LEASED
        # The holder commands; renewing and keeping the lease go on working.
        assert a.keep_lease() is False  # a third of the heartbeat has not passed
        a.renew()
        assert a.wait_outcome(a.move_to(2, 0.1), T).is_carried_out
        # Released: B commands again.
        a.release()
        assert not a.holds_lease
        a.release()  # not held: no error
        assert b.holder() is None
        assert b.wait_outcome(b.move_to(2, 0.0), T).is_carried_out
        with pytest.raises(ValueError):
            a.acquire("x", 0.0)
        with pytest.raises(ValueError):
            a.acquire("n" * 40, 1.0)


def test_close_releases_the_lease(pioneer):
    a = arm(pioneer, "pyc")
    a.acquire("py-closer", 2.0)
    with arm(pioneer, "pyd", power=False) as b:  # a reader: unaffected by the lease
        assert b.holder().name == "py-closer"
        a.close()
        assert b.holder() is None


def test_a_motion_cut_short_by_another_client_is_told_preempted(pioneer):
    with arm(pioneer, "pye") as a, arm(pioneer, "pyf") as b:
        a.set_speed_config(0, 0.2)
        ta = a.move_at_speed(0, 0.1)
        assert a.wait_outcome(ta, T).is_carried_out
        deadline = time.monotonic() + T
        while not a.wait_state(T).actuators[0].state & L.ACTSTATE_MOVING:
            assert time.monotonic() < deadline, "joint 0 never moved"
        assert a.preempted(ta) is None
        b.acquire("py-stopper", 2.0)  # a holder's command names it in the preemption
        tb = b.move_at_speed(0, 0.0)  # B stops joint 0: A's motion is cut short
        assert b.wait_outcome(tb, T).is_carried_out
        deadline = time.monotonic() + T
        while (p := a.preempted(ta)) is None:
            assert time.monotonic() < deadline, "A was never told it was preempted"
            a.wait_state(T)
        assert isinstance(p, Outcome)
        assert p.status is Status.PREEMPTED and p.seq == ta.seq
        assert p.other_client == b.client_id
        assert p.other_name == "py-stopper"
        assert b.preempted(tb) is None
        b.release()
        assert a.driver_status() is DriverStatus.ALIVE

