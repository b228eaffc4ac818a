"""The rows of the paper's Tables 1, 2 and 4 that simarm once answered "unsupported",
through the Python client against `limber simarm` (10x time, a store of one, a block
between the fingers at home): BRAKES, ACCEL, CURRENT, MULTI_CURRENT, STORE, RETRIEVE.
Every wait has a timeout; nothing asserts speed."""

import os
import select
import signal
import subprocess

import pytest

from limber import ActArrayClient, GripperClient, LimbClient, NackError, Status
from test_client import T, cli_bin, state_where, unique_domain

ACTSTATE_MOVING = 2
ACTSTATE_BRAKED = 4
ACTSTATE_STALLED = 8
LIMB_BRAKED = 2
GRIPPER_CLOSED = 2


class SimArm:
    """`limber simarm` as a child process in its own domain."""

    def __init__(self, domain, *args):
        env = dict(os.environ, LIMBER_DOMAIN=domain)
        self.proc = subprocess.Popen(
            [cli_bin(), "simarm", "--time-scale", "10", *args], env=env,
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
            text=True)
        ready, _, _ = select.select([self.proc.stdout], [], [], 30)
        line = self.proc.stdout.readline().strip() if ready else ""
        if not line.endswith("ready"):
            self.stop()
            raise RuntimeError(f"limber simarm did not start: {line!r}")

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        try:
            self.proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.communicate(timeout=30)


@pytest.fixture
def sim():
    """simarm with a store of one and a 3 cm block where the tool is at home (read from
    a first simarm's limb state)."""
    domain = unique_domain()
    first = SimArm(domain)
    try:
        with LimbClient.connect("simarm/limb/0", domain, timeout=T) as limb:
            p = state_where(limb, lambda s: True).position
            tool = (p.x, p.y, p.z)
    finally:
        first.stop()
    s = SimArm(domain, "--store-capacity", "1", "--object", "{},{},{},0.03".format(*tool))
    yield domain
    s.stop()


def test_brakes_accel_and_current(sim):
    with ActArrayClient.connect("simarm/actarray/0", sim, timeout=T) as arm, \
            LimbClient.connect("simarm/limb/0", sim, timeout=T) as limb:
        assert all(a.has_brakes == 1 for a in arm.geometry().actuators[:6])
        arm.brakes(True)
        assert arm.wait_outcome(arm.move_to(0, 0.5), T) is Status.BRAKED
        assert limb.wait_outcome(limb.home(), T) is Status.BRAKED
        assert Status.BRAKED.describe() == "brakes on"
        state_where(arm, lambda s: s.actuators[0].state == ACTSTATE_BRAKED)
        state_where(limb, lambda s: s.state == LIMB_BRAKED)
        limb.brakes(False)
        state_where(arm, lambda s: s.actuators[0].state != ACTSTATE_BRAKED)
        # MULTI_CURRENT closing the gripper on the block (the joints at home, 0 A): stalls.
        t = arm.set_current_multi([0, 0, 0, 0, 0, 0, -1.0])
        assert arm.wait_outcome(t, T) is Status.OK
        s = state_where(arm, lambda s: s.actuators[6].state == ACTSTATE_STALLED)
        assert abs(s.actuators[6].position - 0.03) < 1e-9
        # ACCEL: a limited move reports its acceleration.
        arm.set_accel_config(0, 0.5)
        with pytest.raises(NackError) as e:
            arm.set_accel_config(0, 0.0)
        assert e.value.status is Status.INVALID_ARGUMENT
        assert arm.wait_outcome(arm.move_to(0, 1.0), T) is Status.OK
        s = state_where(arm, lambda s: s.actuators[0].acceleration > 0)
        assert s.actuators[0].acceleration <= 0.5 + 1e-9
        # CURRENT: the model's current in the state.
        assert arm.wait_outcome(arm.set_current(0, 0.5), T) is Status.OK
        s = state_where(arm, lambda s: s.actuators[0].current == 0.5)
        assert s.actuators[0].state in (ACTSTATE_MOVING, ACTSTATE_STALLED)


def test_store_and_retrieve(sim):
    with GripperClient.connect("simarm/gripper/0", sim, timeout=T) as grip:
        assert grip.geometry().capacity == 1
        assert grip.wait_outcome(grip.retrieve(), T) is Status.NOTHING_STORED
        assert grip.wait_outcome(grip.close_gripper(), T) is Status.OK
        state_where(grip, lambda s: s.state == GRIPPER_CLOSED and s.beams == 1)
        assert grip.wait_outcome(grip.store(), T) is Status.OK
        state_where(grip, lambda s: s.stored == 1 and s.beams == 0)
        assert grip.wait_outcome(grip.store(), T) is Status.STORE_FULL
        assert grip.wait_outcome(grip.retrieve(), T) is Status.OK
        state_where(grip, lambda s: s.stored == 0 and s.beams == 1)
