"""Python across hosts: python/examples/zenoh_remote.py, a program with only Zenoh's
Python package (`eclipse-zenoh`), reads the emulated Pioneer's state and commands it
through `limber bridge expose`, and a refusal keeps its reason; and the unchanged Python
client (over liblimber) in another domain commands the arm through `limber bridge mirror`.
Every wait has a timeout.
"""

import os
import queue
import signal
import subprocess
import sys
import threading
import time

import pytest

from test_client import unique_domain

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLE = os.path.join(REPO, "python", "examples", "zenoh_remote.py")
T = 30.0  # generous: a slow machine only makes the test slower


def _need(ok, msg):
    if not ok:
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)


def cli_bin():
    path = os.environ.get("LIMBER_BIN") or os.path.join(REPO, "target", "debug", "limber")
    _need(os.access(path, os.X_OK),
          f"the limber CLI not found at {path}: cargo build -p limber-cli or set LIMBER_BIN")
    return path


def private_socket(domain):
    """The endpoint of `limber bridge expose`'s default listener for `domain`."""
    runtime = os.environ.get("LIMBER_RUNTIME_DIR") or f"/tmp/limber-{os.geteuid()}"
    return f"unixsock-stream/{runtime}/bridge/{domain}.sock"


class Job:
    """A `limber` process in the background, its stdout read line by line with timeouts."""

    def __init__(self, domain, *args):
        env = dict(os.environ, LIMBER_DOMAIN=domain)
        self.proc = subprocess.Popen([cli_bin(), *args], env=env, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
                                     text=True)
        self.what = " ".join(args)
        self.lines = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(line.strip())
        self.lines.put(None)

    def wait_line(self, pred):
        deadline = time.monotonic() + T
        seen = []
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            seen.append(line)
            if pred(line):
                return
        self.stop()
        raise AssertionError(f"{self.what}: no expected line; saw {seen}")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=T)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=T)
        return self.proc.returncode


@pytest.fixture(scope="module")
def bridge():
    try:
        import zenoh  # noqa: F401
    except ImportError:
        _need(False, "eclipse-zenoh is not installed (pip install eclipse-zenoh==1.10.2)")
    domain = unique_domain()
    endpoint = private_socket(domain)
    driver = Job(domain, "pioneer", "--emulated")
    driver.wait_line(lambda l: l.endswith("ready"))
    expose = Job(domain, "bridge", "expose")
    expose.wait_line(lambda l: l == "exposed pioneer/actarray/0")
    mirror_domain = unique_domain()
    mirror = Job(mirror_domain, "bridge", "mirror", "--from", domain)
    mirror.wait_line(lambda l: l == "mirrored pioneer/actarray/0 as pioneer/actarray/0")
    yield endpoint, mirror_domain
    assert mirror.stop() == 0
    assert expose.stop() == 0
    assert driver.stop() == 0


def run_example(endpoint, *args):
    return subprocess.run([sys.executable, EXAMPLE, "--connect", endpoint, *args],
                          capture_output=True, text=True, timeout=60)


def test_state_is_read_and_a_command_is_carried_out(bridge):
    r = run_example(bridge[0], "pioneer/actarray/0", "1", "0.3")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("state #") and len(lines[0].split()) == 2 + 6, r.stdout
    assert lines[-1] == "ok", r.stdout


def test_a_refusal_keeps_its_reason(bridge):
    r = run_example(bridge[0], "pioneer/actarray/0", "1", "9")
    assert r.returncode == 5, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1] == "refused: beyond limits", r.stdout


def test_the_python_client_commands_the_arm_through_a_mirror(bridge):
    from limber import ActArrayClient, Status

    with ActArrayClient.connect("pioneer/actarray/0", bridge[1], timeout=T) as arm:
        assert arm.geometry().actuators_count == 6
        t = arm.move_to(2, 0.4)
        assert arm.wait_outcome(t, T) is Status.OK
        deadline = time.monotonic() + T
        while abs(arm.wait_state(T).actuators[2].position - 0.4) > 0.02:
            assert time.monotonic() < deadline, "joint 2 never reached 0.4"
        t = arm.move_to(1, 9.0)
        assert arm.wait_outcome(t, T) is Status.BEYOND_LIMITS


def test_a_session_cannot_command_as_another_principal(bridge):
    # On the owner's Unix socket the session is `local`: a command put under another
    # principal's key is dropped by the bridge's access rules, so no outcome ever comes.
    r = run_example(bridge[0], "--as", "alice", "--timeout", "2", "pioneer/actarray/0", "1", "0.6")
    assert r.returncode == 6, r.stdout + r.stderr
    assert r.stdout.startswith("state #"), r.stdout
    assert "no outcome" in r.stderr, r.stderr
