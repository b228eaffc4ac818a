"""Paths and gripper goals in Python (issue 28, items 3 and 4), one-liners over liblimber, on
simarm: the square example (python/examples/square.py) draws each edge as a straight line
and every motion ends REACHED within the tolerance; a line out of reach is refused before
anything moves and the state says where; a gripper goal closing on the block stalls with
the object present; a bad value raises before anything is sent."""

import os
import subprocess
import sys

import pytest

import limber
from limber import MotionResult, Status
from test_client import REPO
from test_listing1 import Robot

EXAMPLE = os.path.join(REPO, "python", "examples", "square.py")
T = 60.0
DOWN = ((0.0, 0.0, -1.0), (1.0, 0.0, 0.0))


@pytest.fixture
def simarm():
    # The default world: one block at (0.38, 0.10), its grasp point 0.17 m up.
    r = Robot(["simarm", "--time-scale", "5"])
    yield r
    r.stop()


def test_the_square_example_draws_every_edge_within_the_tolerance(simarm):
    out = subprocess.run([sys.executable, EXAMPLE, "simarm/limb/0", "0.1", "0.1"],
                         env=simarm.env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    strokes = [l for l in out.stdout.splitlines() if l.startswith(("ptp ", "line "))]
    assert len(strokes) == 5, out.stdout
    for line in strokes:
        w = line.split()
        assert w[-5] == "REACHED", line
        assert float(w[-3]) <= float(w[-1]), line
    assert out.stdout.endswith("square drawn\n")


def test_a_line_out_of_reach_is_refused_and_the_state_says_where(simarm):
    with limber.LimbClient.connect("simarm/limb/0", simarm.domain, timeout=5) as limb:
        assert limb.wait_done(limb.set_pose((0.4, 0.0, 0.3), *DOWN), T).reached
        t = limb.line((2.0, 0.0, 0.3))
        assert limb.wait_outcome(t, 5.0) in (Status.OUT_OF_REACH, Status.UNREACHABLE_ORIENTATION)
        # The state that shows the refusal went out before its outcome.
        s = limb.state()
        assert s.refused_kind == limber.LIMB_CMD_LINE
        assert 0.0 < s.refused_fraction < 1.0
        assert 0.4 < s.refused_at.x < 2.0 and abs(s.refused_at.z - 0.3) < 1e-6
        with pytest.raises(limber.NackError):
            limb.wait_done(t, 1.0)
        with pytest.raises(ValueError):
            limb.line((0.3, 0.0, 0.3), speed=-1.0)


def test_a_gripper_goal_on_the_block_stalls_with_the_object_present(simarm):
    with limber.LimbClient.connect("simarm/limb/0", simarm.domain, timeout=5) as limb, \
            limber.GripperClient.connect("simarm/gripper/0", simarm.domain, timeout=5) as grip:
        done = grip.wait_done(grip.goal(0.03, speed=0.05), T)
        assert done.result is MotionResult.REACHED and done.cause is Status.OK, done
        # Wider than the stroke: clamped to it (the fingers wide open around the block).
        wide = grip.goal(1.0)
        assert grip.wait_outcome(wide, 5.0) is Status.CLAMPED
        assert grip.wait_done(wide, T).reached
        assert limb.wait_done(limb.set_pose((0.38, 0.10, 0.17), *DOWN), T).reached
        done = grip.wait_done(grip.goal(0.0, effort=5.0), T)
        assert done.result is MotionResult.STALLED, done
        assert done.cause is Status.OBJECT_PRESENT, done
        assert "an object is between the fingers" in str(done)
