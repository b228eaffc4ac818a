"""The paper's Listing 2 in Python (python/examples/pick_block.py) on the emulated Pioneer and
on simarm, each with a block placed where the test says: the laser finds it, the arm picks it
up and puts it down, and the laser then sees it at the drop point. And the ranger client
itself: the geometry, a scan, the bearing and point of a range."""

import math
import os
import select
import subprocess
import sys
import tempfile

import pytest

import limber
from limber.ranger import point, ranges
from test_client import REPO, cli_bin, unique_domain

EXAMPLE = os.path.join(REPO, "python", "examples", "pick_block.py")
DROP = (0.38, -0.10)


class Robot:
    """`limber simarm` or `limber pioneer --emulated` with a block at `block`, noiseless."""

    def __init__(self, args, block):
        self.domain = unique_domain()
        self.env = dict(os.environ, LIMBER_DOMAIN=self.domain)
        self._err = tempfile.TemporaryFile()
        xy = [str(v) for v in block]
        # Unbuffered bytes: select() sees every line the driver writes.
        self.proc = subprocess.Popen(
            [cli_bin(), *args, "--block", *xy, "--laser-noise", "0"], env=self.env,
            stdout=subprocess.PIPE, stderr=self._err, stdin=subprocess.DEVNULL, bufsize=0)
        out = b""
        while not out.rstrip().endswith(b"ready"):
            ready, _, _ = select.select([self.proc.stdout], [], [], 60)
            chunk = os.read(self.proc.stdout.fileno(), 4096) if ready else b""
            if not chunk:
                self.stop()
                self._err.seek(0)
                raise RuntimeError(f"{args} did not start: {out!r} {self._err.read()!r}")
            out += chunk

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.communicate(timeout=30)


def block_seen(laser_name, domain, radius=0.02):
    """Where the laser sees the block: its closest point plus the radius along the beam."""
    with limber.RangerClient.connect(laser_name, domain, timeout=5) as laser:
        pose = laser.geometry().pose.position
        scan = laser.wait_state(5.0)
        r = ranges(scan)
        i = min(range(len(r)), key=r.__getitem__)
        b, _, _ = point(scan, i)
        return (pose.x + (r[i] + radius) * math.cos(b), pose.y + (r[i] + radius) * math.sin(b))


@pytest.mark.parametrize("robot,devices,block", [
    (["simarm"], ["simarm/limb/0", "simarm/gripper/0", "simarm/ranger/0"], (0.36, 0.06)),
    (["pioneer", "--emulated"], [], (0.40, 0.08)),
])
def test_listing_2_finds_picks_and_puts_down_the_block(robot, devices, block):
    r = Robot(robot, block)
    try:
        out = subprocess.run([sys.executable, EXAMPLE, *devices], env=r.env,
                             capture_output=True, text=True, timeout=120)
        assert out.returncode == 0, out.stdout + out.stderr
        assert out.stdout.count("gripper closed") == 1, out.stdout
        assert out.stdout.endswith("done: block picked up and put down\n"), out.stdout
        found = out.stdout.split("found the block at (")[1].split(")")[0].split(", ")
        assert math.dist([float(v) for v in found], block) < 0.01, out.stdout
        laser = devices[2] if devices else "pioneer/ranger/0"
        assert math.dist(block_seen(laser, r.domain), DROP) < 0.03, out.stdout
    finally:
        r.stop()


def test_a_block_out_of_reach_sends_the_arm_home():
    r = Robot(["simarm"], (2.0, 0.0))
    try:
        out = subprocess.run(
            [sys.executable, EXAMPLE, "simarm/limb/0", "simarm/gripper/0", "simarm/ranger/0"],
            env=r.env, capture_output=True, text=True, timeout=120)
        assert out.returncode == 2, out.stdout + out.stderr
        assert "Target out of reach, terminating" in out.stdout
        assert "gripper closed" not in out.stdout
    finally:
        r.stop()


def test_the_ranger_client_reads_the_scan_and_the_geometry():
    r = Robot(["simarm"], (0.5, 0.0))
    try:
        with limber.LaserClient.connect("simarm/ranger/0", r.domain, timeout=5) as laser:
            g = laser.geometry()
            assert (g.ranges_count, g.max_range) == (181, 8.0)
            assert (g.pose.position.x, g.pose.position.y) == (0.16, 0.0)
            scan = laser.wait_state(5.0)
            assert len(ranges(scan)) == 181
            b, x, y = point(scan, 90)
            assert b == 0.0 and abs(x - (0.5 - 0.16 - 0.02)) < 1e-9 and y == 0.0
            with pytest.raises(ValueError):
                point(scan, 181)
    finally:
        r.stop()
