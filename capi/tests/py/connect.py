"""Connects to pioneer/actarray/0 with the limber package on PYTHONPATH (capi/tests/
c_programs.rs runs it with a limber whose _layout.py has a field moved). Prints
"connected: joint 0 at X" and exits 0, or prints "incompatible: <the error>" and exits 3
when the client refuses the driver's layout; any other error exits 1."""

import sys

from limber import ActArrayClient, IncompatibleError, LimberError


def main() -> int:
    try:
        arm = ActArrayClient.connect("pioneer/actarray/0", timeout=5.0)
    except IncompatibleError as e:
        print(f"incompatible: {e}")
        return 3
    except LimberError as e:
        print(f"failed: {type(e).__name__}: {e}")
        return 1
    print(f"connected: joint 0 at {arm.wait_state(5.0).actuators[0].position:.3f}")
    arm.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
