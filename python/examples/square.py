#!/usr/bin/env python3
"""square.py: draw a square with a limb's tool -- a point-to-point move (PTP) to the first
corner with the tool pointing down, then each edge a straight line (LINE) at a speed limit,
each motion waited for with ``wait_done`` and its final error printed (the same program as
the Rust example ``cargo run -p limber-examples --bin square``).

Usage: square.py [LIMB [SIDE [SPEED]]]  (default simarm/limb/0, 0.1 m, 0.05 m/s; the
domain from LIMBER_DOMAIN)
Exit status: 0 when every motion reached its goal, 1 otherwise (a refused path says why).
"""

import sys

import limber

Centre = (0.4, 0.0, 0.25)  # The square's centre, m (robot frame)
Down = ((0.0, 0.0, -1.0), (1.0, 0.0, 0.0))  # The tool pointing down, fingers along x
T = 60.0  # How long any motion may take


def main() -> int:
    name = sys.argv[1] if len(sys.argv) > 1 else "simarm/limb/0"
    side = float(sys.argv[2]) if len(sys.argv) > 2 else 0.1
    speed = float(sys.argv[3]) if len(sys.argv) > 3 else 0.05
    x, y, z = Centre
    h = side / 2
    corners = [(x - h, y - h, z), (x + h, y - h, z), (x + h, y + h, z), (x - h, y + h, z)]
    with limber.LimbClient.connect(name, timeout=5) as limb:
        for motion in range(5):
            corner = corners[motion % 4]
            if motion == 0:
                ticket, how = limb.ptp(corner, Down), "ptp"
            else:
                ticket, how = limb.line(corner, speed=speed), "line"
            try:
                done = limb.wait_done(ticket, T)
            except limber.NackError as e:
                print(f"square: motion {motion} refused: {e}", file=sys.stderr)
                return 1
            print(f"{how} {motion} to ({corner[0]:.3f}, {corner[1]:.3f}, {corner[2]:.3f}): "
                  f"{done.result} error {done.max_error:.6f} tolerance {done.tolerance:.6f}",
                  flush=True)
            if not done.reached:
                return 1
    print("square drawn")
    return 0


if __name__ == "__main__":
    sys.exit(main())
