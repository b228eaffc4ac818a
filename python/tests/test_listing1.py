"""The paper's Listing 1 in Python (python/examples/random_moves.py), written the obvious way
(``wait_done`` after each move), on simarm and on the emulated Pioneer: each move prints its
final error, and every error is within the device's tolerance. And ``wait_done`` itself:
a move replaced by the next ends preempted, a refused one raises."""

import os
import subprocess
import sys

import pytest

import limber
from test_client import REPO, cli_bin, unique_domain
from test_listing2 import Robot as _Robot

EXAMPLE = os.path.join(REPO, "python", "examples", "random_moves.py")


class Robot(_Robot):
    """`limber simarm` or `limber pioneer --emulated`, no block."""

    def __init__(self, args):
        import select
        import tempfile

        self.domain = unique_domain()
        self.env = dict(os.environ, LIMBER_DOMAIN=self.domain)
        self._err = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(
            [cli_bin(), *args], env=self.env, stdout=subprocess.PIPE, stderr=self._err,
            stdin=subprocess.DEVNULL, bufsize=0)
        out = b""
        while not out.rstrip().endswith(b"ready"):
            ready, _, _ = select.select([self.proc.stdout], [], [], 60)
            chunk = os.read(self.proc.stdout.fileno(), 4096) if ready else b""
            if not chunk:
                self.stop()
                self._err.seek(0)
                raise RuntimeError(f"{args} did not start: {out!r} {self._err.read()!r}")
            out += chunk


@pytest.mark.parametrize("robot,args", [
    # Random moves of each joint through its range: with simarm's floor some would stop at
    # it (STALLED, COLLISION), so the arm is mounted without one here.
    (["simarm", "--no-floor"], ["simarm/actarray/0", "2"]),
    (["pioneer", "--emulated"], ["pioneer/actarray/0", "1"]),
])
def test_listing_1_prints_each_moves_final_error_within_the_tolerance(robot, args):
    r = Robot(robot)
    try:
        out = subprocess.run([sys.executable, EXAMPLE, *args], env=r.env,
                             capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stdout + out.stderr
        lines = [l for l in out.stdout.splitlines() if l.startswith("round ")]
        rounds = int(args[1])
        assert len(lines) >= rounds * 5, out.stdout
        for line in lines:
            w = line.split()
            assert w[6] == "REACHED", line
            error, tolerance = float(w[8]), float(w[10])
            assert error <= tolerance, line
    finally:
        r.stop()


def test_wait_done_says_preempted_and_a_refusal_raises():
    r = Robot(["simarm"])
    try:
        with limber.ActArrayClient.connect("simarm/actarray/0", r.domain, timeout=5) as arm:
            g = arm.geometry().actuators[0]
            first = arm.move_to(0, g.max - 0.05)
            assert arm.wait_outcome(first, 5.0) is limber.Status.OK
            second = arm.move_to(0, g.min + 0.05)
            done = arm.wait_done(first, 10.0)
            assert done.result is limber.MotionResult.PREEMPTED, done
            assert done.cause is limber.Status.PREEMPTED
            done = arm.wait_done(second, 60.0)
            assert done.reached and done.max_error <= done.tolerance, done
            assert "reached" in str(done)
            refused = arm.move_to(0, g.max + 1.0)
            with pytest.raises(limber.LimberError):
                arm.wait_done(refused, 5.0)
    finally:
        r.stop()
