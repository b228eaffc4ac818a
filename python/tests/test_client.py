"""limber.client against the Rust test driver (`limber-test-driver`) in a private domain.

The driver serves `<robot>/actarray/0` (6 rotary joints in ±π, instant moves; SPEED,
CURRENT and BRAKES unsupported), `<robot>/limb/0` (reach 1 m) and `<robot>/gripper/0`
(cannot store). Every test asserts behaviour, never speed; every wait has a timeout.
"""

import itertools
import json
import math
import os
import select
import signal
import subprocess
import sys
import tempfile
import textwrap
import time

import pytest

import limber
from limber import (
    ActArrayClient,
    DriverGoneError,
    DriverStatus,
    Freshness,
    GripperClient,
    IncompatibleError,
    LimberError,
    LimbClient,
    NackError,
    NoDriverError,
    OutcomeMissed,
    RequestTimeout,
    Status,
    Ticket,
    WaitTimeout,
)
from limber import _layout as L

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
T = 5.0  # generous timeout of every wait: a slow machine only makes the test slower
_domains = itertools.count()


def _require(path: str, what: str, hint: str) -> str:
    """`path` if it is an executable; otherwise skip on a developer's machine and fail in CI
    (CI=true), where the binaries must have been built."""
    if not os.access(path, os.X_OK):
        msg = f"{what} not found at {path}: {hint}"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)
    return path


def _binary(env_var: str, default: str, what: str, package: str) -> str:
    """A Rust binary: `$env_var`, else `<repo>/target/debug/<default>`."""
    path = os.environ.get(env_var) or os.path.join(REPO, "target", "debug", default)
    return _require(path, what, f"build it with `cargo build -p {package}` or set {env_var}")


def driver_bin() -> str:
    return _binary("LIMBER_TEST_DRIVER", "limber-test-driver", "the Rust test driver",
                   "limber-tests")


def cli_bin() -> str:
    return _binary("LIMBER_BIN", "limber", "the limber CLI", "limber-cli")


_used_domains = []
# The prefix of this session's domains: conftest.py removes their files at the end with
# `limber clean --all --prefix DOMAIN_PREFIX`.
DOMAIN_PREFIX = f"limber_tpy{os.getpid()}_"


def unique_domain() -> str:
    # `limber_t*`, like the Rust tests' domains; their files go at the end of the run
    # (conftest.py, `limber clean`).
    d = f"{DOMAIN_PREFIX}{next(_domains)}"
    _used_domains.append(d)
    return d


def state_where(client, pred, timeout=T):
    """The first state (the latest, or a newer one) for which `pred` holds."""
    deadline = time.monotonic() + timeout
    s = client.state()
    while s is None or not pred(s):
        s = client.wait_state(max(0.0, deadline - time.monotonic()))
    return s


def nodes_of(domain, device):
    """How many processes (alive, or dead and not cleaned up) are attached to `device`'s
    state channel in `domain`, as `limber list` counts them: 1 is the driver alone."""
    return next(d.nodes for d in limber.list_devices(domain) if str(d.name) == device)


class Driver:
    """The Rust test driver as a child process in its own domain."""

    def __init__(self, robot="test", *args):
        self.robot = robot
        self.domain = unique_domain()
        env = dict(os.environ, LIMBER_DOMAIN=self.domain)
        self._err = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(
            [driver_bin(), "--robot", robot, *args], env=env, stdout=subprocess.PIPE,
            stderr=self._err, stdin=subprocess.DEVNULL, text=True)
        ready, _, _ = select.select([self.proc.stdout], [], [], 30)
        line = self.proc.stdout.readline().strip() if ready else ""
        if line != "ready":
            self.kill()
            self._err.seek(0)
            raise RuntimeError(f"test driver did not start: {line!r} {self._err.read()!r}")
        self.output = None

    def dev(self, iface):
        return f"{self.robot}/{iface}/0"

    def stop(self):
        """SIGTERM, then the driver's report: the `cmd <client> <seq> <kind>` lines."""
        if self.output is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.output = self.proc.communicate(timeout=30)[0]
            except subprocess.TimeoutExpired:
                self.kill()
                raise
        return self.output

    def kill(self):
        self.proc.kill()
        self.output = self.proc.communicate(timeout=30)[0] or ""

    def commands(self):
        """(client, seq, kind) of every actarray command the driver received."""
        out = []
        for line in self.stop().splitlines():
            if line.startswith("cmd "):
                _, c, s, k = line.split()
                out.append((int(c), int(s), int(k)))
        return out


@pytest.fixture(scope="module")
def driver():
    d = Driver("pyshared")
    yield d
    d.stop()


@pytest.fixture
def own_driver():
    """A driver for one test (its log of commands is the test's alone)."""
    drivers = []

    def start(*args):
        d = Driver("pyown", *args)
        drivers.append(d)
        return d

    yield start
    for d in drivers:
        if d.output is None:
            d.stop()


@pytest.fixture
def arm(driver):
    with ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T) as c:
        yield c


@pytest.fixture
def limb(driver):
    with LimbClient.connect(driver.dev("limb"), driver.domain, timeout=T) as c:
        yield c


@pytest.fixture
def gripper(driver):
    with GripperClient.connect(driver.dev("gripper"), driver.domain, timeout=T) as c:
        yield c


# ----- state -----------------------------------------------------------------------------


def test_state_is_read(arm, limb, gripper):
    s = arm.wait_state(T)
    assert isinstance(s, L.ActArrayData)
    assert s.header.seq > 0
    assert s.actuators_count == 6
    assert all(a.state == L.ACTSTATE_IDLE for a in s.actuators[:6])
    assert arm.driver_status() is DriverStatus.ALIVE
    assert arm.state_age() is not None and arm.state_age() >= 0
    assert limb.wait_state(T).state == L.LIMB_STATE_IDLE
    assert gripper.wait_state(T).state in (L.GRIPPER_STATE_OPEN, L.GRIPPER_STATE_CLOSED)


def test_state_is_a_copy_and_wait_state_brings_a_newer_one(arm):
    first = arm.wait_state(T)
    second = arm.wait_state(T)
    assert second.header.seq > first.header.seq
    first.actuators[0].position = 123.0  # a copy: changing it changes nothing else
    assert arm.last_state().actuators[0].position != 123.0


# ----- commands and outcomes -------------------------------------------------------------


def test_a_move_and_its_outcome(arm):
    t = arm.move_to(1, 0.25)
    assert t == Ticket(seq=1, receivers=1)
    assert arm.wait_outcome(t, T) is Status.OK
    s = arm.state()
    assert s.actuators[1].position == 0.25
    assert s.header.last_cmd.client_id == arm.client_id
    assert s.header.last_cmd.cmd_seq == 1
    assert s.header.last_cmd.kind == L.ACTARRAY_CMD_POS
    assert arm.positions()[1] == 0.25


def test_multi_position_and_home(arm):
    t = arm.move_to_multi([0.1, -0.2, 0.3, -0.4, 0.5, -0.6])
    assert arm.wait_outcome(t, T) is Status.OK
    assert arm.positions() == [0.1, -0.2, 0.3, -0.4, 0.5, -0.6]
    assert arm.wait_outcome(arm.home(2), T) is Status.OK
    assert arm.positions() == [0.1, -0.2, 0.0, -0.4, 0.5, -0.6]
    assert arm.wait_outcome(arm.home(), T) is Status.OK
    assert arm.positions() == [0.0] * 6


def test_each_client_gets_its_own_outcome_under_contention(driver, arm):
    # Another client's burst, longer than the state channel's buffer, between A's command
    # and A's wait: A's outcome comes on the outcome channel, not only in a state header
    # that the burst's states push out.
    with ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T) as other:
        for _ in range(5):
            mine = arm.move_to(1, 0.25)
            burst = [other.move_to(2, 0.1) for _ in range(64)]
            bad = arm.move_to(0, 4.0)
            assert arm.wait_outcome(mine, T) is Status.OK
            assert arm.wait_outcome(bad, T) is Status.BEYOND_LIMITS
            assert other.wait_outcome(burst[-1], T) is Status.OK


def test_refusals_carry_the_reason(arm):
    before = arm.wait_state(T).actuators[0].position
    # Joint 6 is within the array capacity (so it is sent) but this arm has 6 joints.
    assert arm.wait_outcome(arm.move_to(6, 0.0), T) is Status.UNKNOWN_JOINT
    assert arm.wait_outcome(arm.move_to(0, 4.0), T) is Status.BEYOND_LIMITS
    assert arm.wait_outcome(arm.move_to_multi([0.0] * 7), T) is Status.UNKNOWN_JOINT
    # The test arm moves one joint at a speed until stopped (it does not integrate the
    # position); it has no multi-joint speed and no current control.
    assert arm.wait_outcome(arm.move_at_speed(0, 0.1), T) is Status.OK
    assert arm.wait_outcome(arm.move_at_speed(0, 0.0), T) is Status.OK
    assert arm.wait_outcome(arm.move_at_speed_multi([0.1]), T) is Status.UNSUPPORTED
    assert arm.wait_outcome(arm.set_current(None, 0.5), T) is Status.UNSUPPORTED
    assert arm.wait_outcome(arm.set_current(1, 0.5), T) is Status.UNSUPPORTED
    assert arm.wait_outcome(arm.set_current_multi([0.5, 0.5]), T) is Status.UNSUPPORTED
    assert arm.state().actuators[0].position == before


def test_brakes_are_refused_with_unsupported(arm, limb):
    with pytest.raises(NackError) as e:
        arm.brakes(True)
    assert e.value.status is Status.UNSUPPORTED
    with pytest.raises(NackError) as e:
        limb.brakes(False)
    assert e.value.status is Status.UNSUPPORTED


def test_requests(arm, limb):
    # A request's effect shows in a later state sample (the driver publishes periodically).
    arm.power(True)
    assert state_where(arm, lambda s: s.motor_state == 1).motor_state == 1
    arm.power(False)
    assert state_where(arm, lambda s: s.motor_state == 0).motor_state == 0
    arm.set_speed_config(1, 0.5)
    arm.set_accel_config(5, 2.0)
    with pytest.raises(NackError) as e:
        arm.set_speed_config(9, 0.5)
    assert e.value.status is Status.UNKNOWN_JOINT
    limb.power(True)
    limb.set_speed(0.1)


def test_geometry(arm, limb, gripper):
    g = arm.geometry()
    assert isinstance(g, L.ActArrayGeom)
    assert g.actuators_count == 6
    for a in g.actuators[:6]:
        assert a.kind == L.ACTUATOR_KIND_ROTARY
        assert (a.min, a.max) == (-math.pi, math.pi)
        assert a.config_speed == 1.0
        assert (a.axis.x, a.axis.y, a.axis.z) == (0.0, 0.0, 1.0)
    lg = limb.geometry()
    assert (lg.base_pos.x, lg.base_pos.y, lg.base_pos.z) == (0.0, 0.0, 0.0)
    assert gripper.geometry().num_beams == 2


def test_limb_out_of_reach_and_moves(limb):
    assert limb.wait_outcome(limb.set_position([2.0, 0.0, 0.0]), T) is Status.OUT_OF_REACH
    assert limb.state().state == L.LIMB_STATE_OOR
    t = limb.set_pose([0.3, 0.0, 0.2], [1, 0, 0], [0, 0, 1])
    assert limb.wait_outcome(t, T) is Status.OK
    s = limb.state()
    assert (s.position.x, s.position.y, s.position.z) == (0.3, 0.0, 0.2)
    assert s.state == L.LIMB_STATE_IDLE
    assert limb.wait_outcome(limb.vec_move([0, 0, 2], 0.5), T) is Status.OK
    assert limb.state().position.z == pytest.approx(0.7)
    assert limb.wait_outcome(limb.vec_move([1, 0, 0], 5.0), T) is Status.OUT_OF_REACH
    assert limb.wait_outcome(limb.home(), T) is Status.OK
    assert limb.state().position.x == 0.5
    assert limb.wait_outcome(limb.stop(), T) is Status.OK


def test_limb_reach_answers_without_moving(limb):
    before = limb.wait_state(T).position
    r = limb.reach([0.3, 0.1, 0.2], [0, 0, -1], [1, 0, 0])
    assert isinstance(r, L.LimbReach)
    assert (r.position.x, r.position.y, r.position.z) == (0.3, 0.1, 0.2)
    assert r.adjusted == 0 and r.orientation_adjustment == 0.0
    after = limb.wait_state(T).position
    assert (after.x, after.y, after.z) == (before.x, before.y, before.z)
    with pytest.raises(NackError) as e:
        limb.reach([3.0, 0.0, 0.0], [0, 0, -1], [1, 0, 0])
    assert e.value.status is Status.OUT_OF_REACH
    with pytest.raises(ValueError):
        limb.reach([0.3, 0.0, 0.2], [0, 0, 0], [1, 0, 0])


def test_gripper_close_open_and_store(gripper):
    assert gripper.wait_outcome(gripper.close_gripper(), T) is Status.OK
    assert gripper.state().state == L.GRIPPER_STATE_CLOSED
    assert gripper.wait_outcome(gripper.open(), T) is Status.OK
    assert gripper.state().state == L.GRIPPER_STATE_OPEN
    assert gripper.wait_outcome(gripper.stop(), T) is Status.OK
    assert gripper.wait_outcome(gripper.store(), T) is Status.UNSUPPORTED
    assert gripper.wait_outcome(gripper.retrieve(), T) is Status.UNSUPPORTED


def test_invalid_values_raise_and_send_nothing(own_driver):
    d = own_driver()
    with ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T) as arm, \
            LimbClient.connect(d.dev("limb"), d.domain, timeout=T) as limb:
        bad = [
            lambda: arm.move_to(0, float("nan")),
            lambda: arm.move_to(0, float("inf")),
            lambda: arm.move_to(32, 0.0),
            lambda: arm.move_to(-1, 0.0),
            lambda: arm.move_to(2**32, 0.0),
            lambda: arm.move_to(2**64 + 1, 0.0),
            lambda: arm.move_to_multi([0.0] * 33),
            lambda: arm.move_to_multi([0.0, float("nan")]),
            lambda: arm.move_at_speed(40, 0.1),
            lambda: arm.move_at_speed_multi([float("-inf")]),
            lambda: arm.home(32),
            lambda: arm.set_current(None, float("nan")),
            lambda: arm.set_current_multi([1.0] * 40),
            lambda: arm.set_speed_config(0, float("nan")),
            lambda: arm.set_accel_config(99, 1.0),
            lambda: limb.set_position([float("nan"), 0, 0]),
            lambda: limb.set_position([1, 2]),
            lambda: limb.set_pose([0, 0, 0], [0, 0, 0], [0, 0, 1]),
            lambda: limb.set_pose([0, 0, 0], [1, 0, 0], [0, 0, 1e-12]),
            lambda: limb.vec_move([0, 0, 0], 1.0),
            lambda: limb.vec_move([1, 0, 0], float("nan")),
            lambda: limb.set_speed(float("inf")),
        ]
        for f in bad:
            with pytest.raises(ValueError):
                f()
        # Nothing was numbered either: the next command is the client's first.
        # Not an index: TypeError, as for any Python sequence.
        for joint in (0.5, "0", None):
            with pytest.raises(TypeError):
                arm.move_to(joint, 0.0)  # type: ignore[arg-type]
        # Nothing was numbered either: the next command is the client's first.
        t = arm.move_to(0, 0.5)
        assert t.seq == 1
        assert arm.wait_outcome(t, T) is Status.OK
        # The timeout a loop passes again is converted once; a bad one is refused each
        # time, whatever came before (None too, after a valid one).
        assert arm.wait_outcome(t, T) is Status.OK
        for timeout in (float("nan"), -1.0, float("inf")):
            with pytest.raises(ValueError):
                arm.wait_outcome(t, timeout)
        with pytest.raises(TypeError):
            arm.wait_outcome(t, None)  # type: ignore[arg-type]
        client_id = arm.client_id
    assert d.commands() == [(client_id, 1, L.ACTARRAY_CMD_POS)]


def test_outcome_overwritten_by_later_commands_is_reported_missed(arm):
    first = arm.move_to(0, 0.1)
    assert arm.wait_outcome(first, T) is Status.OK
    tickets = [arm.move_to(0, 0.001 * i) for i in range(16)]
    assert arm.wait_outcome(tickets[-1], T) is Status.OK  # seq 17 took seq 1's slot
    with pytest.raises(OutcomeMissed) as e:
        arm.wait_outcome(first, T)
    assert e.value.newer_seq >= tickets[-1].seq


def test_waits_time_out_while_the_driver_lives(arm):
    with pytest.raises(WaitTimeout):
        arm.wait_outcome(Ticket(seq=1000, receivers=1), 0.2)
    assert isinstance(WaitTimeout("x"), TimeoutError)


def test_request_timeout(own_driver):
    d = own_driver("--reply-delay-ms", "1500")
    with ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T) as arm:
        with pytest.raises(RequestTimeout):
            arm.geometry(timeout=0.2)
        assert arm.driver_status() is DriverStatus.ALIVE


# ----- connecting, names, liveness -------------------------------------------------------


def test_no_driver_for_an_absent_device(driver):
    with pytest.raises(NoDriverError, match="no driver offers nobody/actarray/0"):
        ActArrayClient.connect("nobody/actarray/0", driver.domain)
    with pytest.raises(NoDriverError):
        GripperClient.connect(driver.dev("gripper").replace("/0", "/3"), driver.domain,
                              timeout=0.1)
    with pytest.raises(NoDriverError):  # the right device in another domain
        LimbClient.connect(driver.dev("limb"), unique_domain())


def test_incompatible_and_invalid_names(driver):
    with pytest.raises(IncompatibleError, match="actarray"):
        LimbClient.connect(driver.dev("actarray"), driver.domain)
    for bad in ["pioneer/arm/0", "pioneer/actarray", "pioneer/actarray/x", "pi oneer/limb/0",
                "a/limb/0/1", "/limb/0", "r/limb/70000"]:
        with pytest.raises(ValueError):
            LimbClient.connect(bad, driver.domain)
    for bad in ["", "a b", "x" * 49]:
        with pytest.raises(ValueError):
            limber.list_devices(bad)
        with pytest.raises(ValueError):
            LimbClient.connect(driver.dev("limb"), bad)


def test_another_layout_version_or_type_is_incompatible(driver, monkeypatch):
    class WrongData(ActArrayClient):
        DATA = L.LimbData  # same interface, another payload type

    with pytest.raises(IncompatibleError, match="data"):
        WrongData.connect(driver.dev("actarray"), driver.domain, timeout=T)
    monkeypatch.setattr(L, "LAYOUT_VERSION", L.LAYOUT_VERSION + 1)
    with pytest.raises(IncompatibleError, match="layout"):
        ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T)
    # The failed attempts left no node behind, alive or dead.
    assert nodes_of(driver.domain, driver.dev("actarray")) == 1


def test_domain_from_env(monkeypatch):
    monkeypatch.delenv("LIMBER_DOMAIN", raising=False)
    assert limber.Domain().name == "limber"
    robot, other = unique_domain(), unique_domain()
    monkeypatch.setenv("LIMBER_DOMAIN", robot)
    assert limber.Domain().name == robot
    assert limber.Domain() == limber.Domain(robot) != limber.Domain(other)
    assert limber.Domain(other).name == other


def test_driver_stopped(own_driver):
    d = own_driver()
    arm = ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T)
    try:
        assert arm.wait_state(T) is not None
        assert arm.freshness(3600.0) is Freshness.FRESH
        d.stop()
        assert arm.driver_status() is DriverStatus.ABSENT
        assert arm.freshness(0.0) is Freshness.GONE
        arm.refresh()  # samples published before the driver stopped are still readable
        with pytest.raises(DriverGoneError):
            arm.wait_state(T)
        with pytest.raises(NoDriverError):
            arm.move_to(0, 0.0)
        with pytest.raises(NoDriverError):
            arm.geometry()
    finally:
        arm.close()


def test_driver_killed(own_driver):
    d = own_driver()
    arm = ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T)
    try:
        assert arm.wait_state(T) is not None
        d.kill()
        # The dead server still looks connected: the liveness check tells (or, once the dead
        # node is cleaned up, nobody serves requests any more).
        with pytest.raises((DriverGoneError, NoDriverError)):
            arm.geometry(timeout=T)
        arm.refresh()  # samples published before the driver died are still readable
        with pytest.raises(DriverGoneError):
            arm.wait_state(T)
        # The dead driver was cleaned up on the way, and this client, which found it dead,
        # says so (DEAD, not ABSENT) until a driver lives again: nothing is left to answer.
        assert arm.driver_status() is DriverStatus.DEAD
        with pytest.raises(NoDriverError):
            arm.geometry(timeout=T)
    finally:
        arm.close()


def test_close_releases_everything(driver):
    dev = driver.dev("actarray")
    arm = ActArrayClient.connect(dev, driver.domain, timeout=T)
    assert nodes_of(driver.domain, dev) == 2  # the driver and this client
    arm.close()
    arm.close()  # idempotent
    assert arm.closed
    with pytest.raises(LimberError):
        arm.move_to(0, 0.0)
    with ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T) as arm2:
        assert not arm2.closed
    assert arm2.closed
    assert nodes_of(driver.domain, dev) == 1  # nothing left, alive or dead


def test_a_client_in_module_globals_leaves_no_dead_node(driver):
    script = textwrap.dedent(f"""
        import limber
        arm = limber.ActArrayClient.connect({driver.dev("actarray")!r}, {driver.domain!r},
                                            timeout=5, name="globalclient")
        assert arm.wait_state(5) is not None
        print("connected")
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=60, env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    assert out.stdout.strip() == "connected", out.stderr
    assert nodes_of(driver.domain, driver.dev("actarray")) == 1  # nothing left, alive or dead


def test_status_names_are_the_rust_names():
    consts = {k[len("STATUS_"):]: v for k, v in vars(L).items() if k.startswith("STATUS_")}
    assert {s.name: s.value for s in Status} == consts
    assert Status.BEYOND_LIMITS.describe() == "beyond the joint limits"
    assert str(Status.UNKNOWN_JOINT) == "UNKNOWN_JOINT"
    assert Status(4) is Status.BEYOND_LIMITS
    # Every cause has its text (the same as Rust's), and CLAMPED counts as carried out.
    assert all(s.describe() for s in Status)
    assert Status.POWERED_OFF.describe() == "powered off"
    assert Status.CLAMPED.describe() == "ok, clamped to the limit"
    assert Status.CLAMPED.is_carried_out and not Status.CLAMPED.is_ok
    assert [s for s in Status if s.is_carried_out] == [Status.OK, Status.CLAMPED, Status.ADJUSTED]
    assert Status.ADJUSTED.describe() == "ok, orientation adjusted"
    assert Status(16) is Status.ADJUSTED


# ----- Python and Rust side by side ------------------------------------------------------


def cli(driver, *args):
    env = dict(os.environ, LIMBER_DOMAIN=driver.domain)
    return subprocess.run([cli_bin(), *args], capture_output=True, text=True, timeout=60,
                          env=env, stdin=subprocess.DEVNULL)


def test_python_and_the_rust_cli_see_the_same_state(driver, arm):
    assert arm.wait_outcome(arm.move_to(3, 0.75), T) is Status.OK
    echo = cli(driver, "echo", "--json", "--count", "1", driver.dev("actarray"))
    assert echo.returncode == 0, echo.stderr
    seen = json.loads(echo.stdout.splitlines()[0])
    assert seen["actuators"][3]["position"] == 0.75
    assert [a["position"] for a in seen["actuators"]] == arm.positions()
    assert seen["header"]["last_cmd"]["client_id"] == arm.client_id

    # A command from the Rust CLI shows up in Python's state, from another client.
    r = cli(driver, "actarray", driver.dev("actarray"), "pos", "4", "-0.5")
    assert r.returncode == 0, r.stderr
    s = arm.wait_state(T)
    assert s.actuators[4].position == -0.5
    assert s.actuators[3].position == 0.75
    assert s.header.last_cmd.client_id not in (0, arm.client_id)

    # The CLI's refusal is the same status Python gets.
    r = cli(driver, "actarray", driver.dev("actarray"), "pos", "7", "0.5")
    assert r.returncode != 0 and "unknown joint" in r.stderr
    assert arm.wait_outcome(arm.move_to(7, 0.5), T) is Status.UNKNOWN_JOINT


def test_python_sees_what_the_rust_driver_logged(own_driver):
    d = own_driver()
    with ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T) as arm:
        tickets = [arm.move_to(0, 0.1), arm.move_to_multi([0.2, 0.3]), arm.home(None),
                   arm.move_to(9, 0.0)]
        assert [arm.wait_outcome(t, T) for t in tickets[-1:]] == [Status.UNKNOWN_JOINT]
        cid = arm.client_id
    assert d.commands() == [
        (cid, 1, L.ACTARRAY_CMD_POS),
        (cid, 2, L.ACTARRAY_CMD_MULTI_POS),
        (cid, 3, L.ACTARRAY_CMD_HOME),
        (cid, 4, L.ACTARRAY_CMD_POS),
    ]
    assert "overflows=0" in d.output


def test_limber_list_counts_the_python_process(driver, gripper):
    out = cli(driver, "list")
    assert out.returncode == 0, out.stderr
    rows = {line.split()[0]: line.split() for line in out.stdout.splitlines()[1:] if line}
    row = rows[driver.dev("gripper")]
    assert row[1:3] == ["testdriver", "alive"]
    assert int(row[3]) >= 2  # the driver and this Python process


def test_python_and_rust_clients_command_one_device_together(own_driver):
    d = own_driver()
    rust_client = _require(os.path.join(os.path.dirname(driver_bin()), "limber-test-client"),
                           "the Rust test client", "build it with `cargo build -p limber-tests`")
    n = 40
    with ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T) as arm:
        rust = subprocess.Popen([rust_client, "--robot", d.robot, "burst", str(n)],
                                env=dict(os.environ, LIMBER_DOMAIN=d.domain),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        tickets = [arm.move_to(i % 6, i * 1e-3) for i in range(n)]
        out, err = rust.communicate(timeout=60)
        assert rust.returncode == 0, err
        assert out.strip() == f"sent {n}"
        # While the Rust client commanded too, the outcome of our last command may have
        # been pushed out of our 2-sample buffer by its outcomes (see README: as in Rust,
        # wait_outcome then times out). Alone again, our next outcome is certain to be seen,
        # and commands of one client are applied in order.
        last = arm.move_to(0, 0.0)
        assert last.seq == n + 1
        assert arm.wait_outcome(last, T) is Status.OK
        assert [t.seq for t in tickets] == list(range(1, n + 1))
        cid = arm.client_id
    log = d.commands()
    mine = [s for c, s, _ in log if c == cid]
    theirs = {c for c, _, _ in log if c != cid}
    assert mine == list(range(1, n + 2))  # every command, in order
    assert len(theirs) == 1  # one Rust client, with another id
    assert len(log) == 2 * n + 1
    assert "overflows=0" in d.output


def test_every_limber_code_has_its_exception_and_the_library_s_message(driver):
    """One table maps each LIMBER_CODE_* to its exception; the message is
    limber_last_error()'s."""
    from limber import _lib, _types

    codes = [c for c in range(1, 64) if _lib.lib.limber_strerror(c) != b"unknown limber code"]
    assert codes == list(range(1, 16))
    assert sorted(_types._ERRORS) == codes
    with pytest.raises(NoDriverError) as e:
        ActArrayClient.connect("nobody/actarray/0", driver.domain)
    assert str(e.value) == _lib.last_error()
    assert "no driver offers nobody/actarray/0" in str(e.value)


def test_a_closed_client_says_so(driver):
    arm = ActArrayClient.connect(driver.dev("actarray"), driver.domain, timeout=T)
    arm.close()
    for call in (lambda: arm.move_to(0, 0.0), arm.state, lambda: arm.wait_state(T),
                 arm.holder, lambda: arm.geometry()):
        with pytest.raises(LimberError, match="ActArrayClient is closed"):
            call()
