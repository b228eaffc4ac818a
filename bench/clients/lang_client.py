"""The Python client of ``limber bench``'s ``lang`` scenario (run with python/limber on
PYTHONPATH). Usage: lang_client.py WARMUP COUNT OUT SETTLE_NS. Connects to bench/actarray/0
in $LIMBER_DOMAIN and, WARMUP + COUNT times each, times (CLOCK_MONOTONIC, ns) reading the
latest state (``ActArrayClient.state()``, a copy) SETTLE_NS after the previous round trip
ended (spinning on the clock; the bench's SETTLE_NS says why), a command's round trip (``move_to``,
then ``wait_outcome``) and, as Python's floor, one ctypes call into liblimber that does
nothing else (``limber_layout_version``); writes the samples after the warm-up to OUT, one
a line: "state NS", "rtt NS" or "ffi NS". Exits 1 with the reason on stderr."""

import sys
import time

from limber import ActArrayClient, LimberError, Status
from limber._lib import lib as _c  # the ctypes library: for the floor of one call


def main() -> int:
    warm, count, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    settle, settled = int(sys.argv[4]), 0
    now = time.monotonic_ns  # CLOCK_MONOTONIC
    lines = []
    try:
        arm = ActArrayClient.connect("bench/actarray/0", timeout=15.0)
        if arm.state() is None:
            arm.wait_state(5.0)
        for i in range(1, warm + count + 1):
            while now() < settled:
                pass
            t0 = now()
            arm.state()
            t1 = now()
            t2 = now()
            status = arm.wait_outcome(arm.move_to(0, -0.25 if i % 2 else 0.25), 2.0)
            t3 = now()
            settled = t3 + settle
            if status != Status.OK:
                print(f"lang_client.py: refused: {status.describe()}", file=sys.stderr)
                return 1
            # Python's floor: one ctypes call into liblimber that does nothing else.
            t4 = now()
            _c.limber_layout_version()
            t5 = now()
            if i > warm:
                lines.append(f"state {t1 - t0}\nrtt {t3 - t2}\nffi {t5 - t4}\n")
        arm.close()
    except LimberError as e:
        print(f"lang_client.py: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    with open(path, "w") as f:
        f.writelines(lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
