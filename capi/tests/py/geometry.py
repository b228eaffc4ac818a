"""The Python client of the four-language test (capi/tests/c_programs.rs): it requests
geometry. Connects to the arm and the arm gripper, prints "ready", and on the line "go"
requests the arm's and the gripper's geometry again and again while the other clients
command, until the line "report" arrives; then prints how many requests were answered and
what the geometry said ("geometry: N requests, A actuators, joint 0 in [min, max], gripper
geometry ok"), reads a fresh state of each device and prints what it saw: "seen: <the six
joint positions> gripper <state>". Every wait is bounded."""

import select
import sys
import time

from limber import ActArrayClient, GripperClient

T = 5.0


def line(timeout: float) -> str:
    """The next line of stdin within `timeout` seconds, or "" if none came."""
    ready, _, _ = select.select([sys.stdin], [], [], timeout)
    return sys.stdin.readline().strip() if ready else ""


def main() -> int:
    arm = ActArrayClient.connect("pioneer/actarray/0", timeout=T)
    gripper = GripperClient.connect("pioneer/gripper/1", timeout=T)
    print("ready", flush=True)
    if line(120.0) != "go":
        return 1
    requests = 0
    deadline = time.monotonic() + 120.0
    while True:
        geom = arm.geometry(timeout=T)
        gripper.geometry(timeout=T)
        requests += 1
        word = line(0.0)
        if word == "report":
            break
        if word:
            print(f"unexpected line {word!r}", file=sys.stderr)
            return 1
        if time.monotonic() > deadline:
            print("no report asked for", file=sys.stderr)
            return 1
    a = geom.actuators[0]
    print(
        f"geometry: {requests} requests, {geom.actuators_count} actuators, "
        f"joint 0 in [{a.min:.9f}, {a.max:.9f}], gripper geometry ok"
    )
    d = arm.wait_state(T)
    g = gripper.wait_state(T)
    joints = " ".join(f"{d.actuators[j].position:.9f}" for j in range(d.actuators_count))
    print(f"seen: {joints} gripper {g.state}", flush=True)
    arm.close()
    gripper.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
