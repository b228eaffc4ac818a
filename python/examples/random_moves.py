#!/usr/bin/env python3
"""random_moves.py: the paper's Listing 1 in Python -- move every joint of an actuator array
to random positions inside the limits the array reports, round after round -- written the
obvious way: each move waits for its motion's result (``wait_done``) and prints its final
error (README.md beside this file).

Usage: random_moves.py [ARM [ROUNDS [SEED]]]  (default pioneer/actarray/0, 2 rounds, seed
2006; the domain from LIMBER_DOMAIN)
Exit status: 0 when every move reached its target, 1 otherwise.
"""

import random
import sys

import limber

Margin = 0.05  # Keep targets this far inside each limit
T = 60.0  # How long any move may take


def main() -> int:
    name = sys.argv[1] if len(sys.argv) > 1 else "pioneer/actarray/0"
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    rng = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 2006)
    all_reached = True
    with limber.ActArrayClient.connect(name, timeout=5) as arm:
        geom = arm.geometry()
        for r in range(rounds):
            for j in range(geom.actuators_count):
                a = geom.actuators[j]
                target = rng.uniform(a.min + Margin, a.max - Margin)
                done = arm.wait_done(arm.move_to(j, target), T)
                print(f"round {r} joint {j}: target {target:.4f} {done.result} "
                      f"error {abs(done.errors[j]):.6f} tolerance {done.tolerance:.6f}",
                      flush=True)
                all_reached &= done.reached
    return 0 if all_reached else 1


if __name__ == "__main__":
    sys.exit(main())
