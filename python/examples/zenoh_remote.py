#!/usr/bin/env python3
"""Read an arm's state and command one joint over Zenoh alone: no iceoryx2, no limber
domain on this host, only `eclipse-zenoh` and the wire layouts of `limber/_layout.py`
(pure ctypes, loaded by path so that the `limber` package and the liblimber it binds are
not needed).

The robot's PC runs `limber bridge expose` (see bridge/README.md for the keys and payloads).
On that PC, as the bridge's owner, through its private Unix socket:

    python3 python/examples/zenoh_remote.py \
        --connect unixsock-stream/$LIMBER_RUNTIME_DIR/bridge/robot.sock pioneer/actarray/0 1 0.3

(`$LIMBER_RUNTIME_DIR` defaults to /tmp/limber-<uid>.) From another host, with Zenoh's
user/password authentication: `--zenoh-config FILE --as USER` (the bridge accepts commands
only under the principal the session authenticated as).

prints the joints' positions, sends "move joint 1 to 0.3 rad" and prints the driver's
outcome. Exit status: 0 carried out, 5 refused (the reason is printed), 6 no state or no
outcome in time.
"""

import argparse
import ctypes
import importlib.util
import json
import os
import queue
import random
import sys
import time

import zenoh

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location(
    "limber_layout", os.path.join(HERE, "..", "limber", "_layout.py"))
L = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(L)

STATUS_NAMES = {v: k[len("STATUS_"):].lower().replace("_", " ")
                for k, v in vars(L).items() if k.startswith("STATUS_")}
CARRIED_OUT = {L.STATUS_OK, L.STATUS_CLAMPED, L.STATUS_ADJUSTED}


def key(device, channel):
    return f"limber/{device}/{channel}"


def open_session(endpoint, config_file):
    conf = zenoh.Config.from_file(config_file) if config_file else zenoh.Config()
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(conf)


def first(q, timeout):
    try:
        return q.get(timeout=timeout)
    except queue.Empty:
        return None


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--connect", required=True, help="the bridge's endpoint")
    p.add_argument("--zenoh-config", help="a Zenoh configuration file (user/password, TLS)")
    p.add_argument("--as", dest="principal", default="local",
                   help="who this session is to the bridge: its user/password user or "
                        "certificate name; 'local' on the owner's Unix socket")
    p.add_argument("--timeout", type=float, default=5.0, help="seconds per wait")
    p.add_argument("device", help="an actarray, e.g. pioneer/actarray/0")
    p.add_argument("joint", type=int)
    p.add_argument("position", type=float, help="radians (metres for a linear joint)")
    a = p.parse_args()

    # <principal>/<session>: where our commands go and our outcomes come back.
    origin = f"{a.principal}/py{random.getrandbits(48):012x}"
    client_id = random.getrandbits(63) | 1
    session = open_session(a.connect, a.zenoh_config)
    try:
        states, outcomes = queue.Queue(), queue.Queue()
        session.declare_subscriber(key(a.device, "state"),
                                   lambda s: states.put(s.payload.to_bytes()))
        session.declare_subscriber(key(a.device, f"outcome/{origin}"),
                                   lambda s: outcomes.put(s.payload.to_bytes()))

        raw = first(states, a.timeout)
        if raw is None or len(raw) != ctypes.sizeof(L.ActArrayData):
            print(f"no state of {a.device} within {a.timeout} s", file=sys.stderr)
            return 6
        state = L.ActArrayData.from_buffer_copy(raw)
        joints = " ".join(f"{state.actuators[i].position:+.3f}"
                          for i in range(state.actuators_count))
        print(f"state #{state.header.seq}: {joints}")

        msg = L.ActArrayCmdMsg()
        body = L.ActArrayPositionCmd(joint=a.joint, position=a.position)
        ctypes.memmove(msg.body, ctypes.addressof(body), ctypes.sizeof(body))
        msg.meta.client_id = client_id
        msg.meta.seq = 1
        msg.meta.stamp_ns = time.monotonic_ns()
        msg.meta.kind = L.ACTARRAY_CMD_POS
        msg.meta.body_len = ctypes.sizeof(body)
        # As the bridges put commands and outcomes: express (never batched behind another
        # message) at the priority of their own queue, ahead of the states.
        session.put(key(a.device, f"cmd/{origin}"), bytes(msg),
                    encoding=zenoh.Encoding("application/octet-stream;" + msg.type_name()),
                    express=True, priority=zenoh.Priority.INTERACTIVE_HIGH)

        deadline = time.monotonic() + a.timeout
        while True:
            raw = first(outcomes, max(0.0, deadline - time.monotonic()))
            if raw is None:
                print(f"no outcome within {a.timeout} s", file=sys.stderr)
                return 6
            o = L.OutcomeMsg.from_buffer_copy(raw)
            if o.client_id == client_id and o.cmd_seq == 1 and o.status != L.STATUS_PREEMPTED:
                break
        name = STATUS_NAMES.get(o.status, f"status {o.status}")
        if o.status in CARRIED_OUT:
            print(name)
            return 0
        print(f"refused: {name}")
        return 5
    finally:
        session.close()


if __name__ == "__main__":
    sys.exit(main())
