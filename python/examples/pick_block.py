#!/usr/bin/env python3
"""pick_block.py: the paper's Listing 2 in Python -- find a block with the laser, pick it up,
move it to another position and put it down -- with limber's Python clients (README.md
beside this file).

Usage: pick_block.py [LIMB GRIPPER LASER]  (default pioneer/limb/0 pioneer/gripper/1
pioneer/ranger/0; the domain from LIMBER_DOMAIN)
Exit status: 0 done, 2 out of reach (the arm went home), 1 any other failure.
"""

import math
import sys

import limber
from limber import _layout as L
from limber.ranger import point

HandleHeight = 0.17  # Height above floor that the arm should grab at
BlockRadius = 0.02  # From the closest point the laser sees to the block's centre
DropPoint = (0.38, -0.10)  # Where to put it
T = 30.0  # How long any step may take


def wait_for_limb(limb, ticket):
    """Where the paper slept, wait for the command's outcome, then until the limb stops."""
    try:
        status = limb.wait_outcome(ticket, T)
    except limber.OutcomeMissed:  # applied, then superseded
        status = limber.Status.OK
    data = limb.state()
    if status is limber.Status.OUT_OF_REACH:
        return data
    if not status.is_carried_out:
        raise RuntimeError(f"limb command refused: {status}")
    while data.state == L.LIMB_STATE_MOVING:
        data = limb.wait_state(T)
    p = data.position
    print(f"limb at ({p.x:.3f}, {p.y:.3f}, {p.z:.3f})", flush=True)
    return data


def wait_for_gripper(gripper, ticket, want):
    status = gripper.wait_outcome(ticket, T)
    if not status.is_carried_out:
        raise RuntimeError(f"gripper command refused: {status}")
    data = gripper.state()
    while data.state != want:
        data = gripper.wait_state(T)
    print("gripper " + ("closed" if want == L.GRIPPER_STATE_CLOSED else "open"), flush=True)


def main(argv):
    names = argv[1:] or ["pioneer/limb/0", "pioneer/gripper/1", "pioneer/ranger/0"]
    if len(names) != 3:
        print("usage: pick_block.py [LIMB GRIPPER LASER]", file=sys.stderr)
        return 1
    with limber.LimbClient.connect(names[0], timeout=5) as Limb, \
            limber.GripperClient.connect(names[1], timeout=5) as Gripper, \
            limber.RangerClient.connect(names[2], timeout=5) as Laser:
        wait_for_limb(Limb, Limb.home())
        Limb.geometry()

        LaserPose = Laser.geometry().pose.position
        scan = Laser.state() or Laser.wait_state(T)
        # Find the closest point in the laser scan
        MinIndex = 0
        for ii in range(1, scan.ranges_count):
            if scan.ranges[ii] < scan.ranges[MinIndex]:
                MinIndex = ii
        Bearing, cx, cy = point(scan, MinIndex)
        Closest = (cx + LaserPose.x, cy + LaserPose.y)
        # Calculate a point in the middle of the block
        PreRange = scan.ranges[MinIndex] + BlockRadius
        CentrePoint = (PreRange * math.cos(Bearing) + LaserPose.x,
                       PreRange * math.sin(Bearing) + LaserPose.y)
        Orientation = (CentrePoint[0] - Closest[0], CentrePoint[1] - Closest[1], 0.0)
        print(f"found the block at ({CentrePoint[0]:.3f}, {CentrePoint[1]:.3f})", flush=True)

        wait_for_gripper(Gripper, Gripper.open_gripper(), L.GRIPPER_STATE_OPEN)
        # Calculate a point about 5 cm above the target point.
        above = (CentrePoint[0], CentrePoint[1], HandleHeight + 0.05)
        if wait_for_limb(Limb, Limb.set_pose(above, (0, 0, -1), Orientation)).state \
                == L.LIMB_STATE_OOR:
            print("Target out of reach, terminating", flush=True)
            wait_for_limb(Limb, Limb.home())
            return 2
        # Move to grasp position
        wait_for_limb(Limb, Limb.set_pose((CentrePoint[0], CentrePoint[1], HandleHeight),
                                          (0, 0, -1), Orientation))
        # Grip the block
        wait_for_gripper(Gripper, Gripper.close_gripper(), L.GRIPPER_STATE_CLOSED)
        # Lift it, move it, put it down
        wait_for_limb(Limb, Limb.set_pose(above, (0, 0, -1), Orientation))
        drop_above = (DropPoint[0], DropPoint[1], HandleHeight + 0.05)
        wait_for_limb(Limb, Limb.set_pose(drop_above, (0, 0, -1), Orientation))
        wait_for_limb(Limb, Limb.set_pose((DropPoint[0], DropPoint[1], HandleHeight),
                                          (0, 0, -1), Orientation))
        # Release the block
        wait_for_gripper(Gripper, Gripper.open_gripper(), L.GRIPPER_STATE_OPEN)
        wait_for_limb(Limb, Limb.set_pose(drop_above, (0, 0, -1), Orientation))
        # And home again
        wait_for_limb(Limb, Limb.home())
        print("done: block picked up and put down", flush=True)
        return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except (limber.LimberError, RuntimeError, ValueError) as e:
        print(f"pick_block.py: {e}", file=sys.stderr)
        sys.exit(1)
