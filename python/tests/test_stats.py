"""The driver statistics reader against `limber pioneer --emulated`, compared with
`limber echo --json <robot>/driver`."""

import json
import os
import signal
import subprocess
import time

import pytest

import limber
from limber import DriverStatsReader, NoDriverError, stats_text
from limber import _layout as L

from test_client import T, cli_bin, unique_domain


@pytest.fixture(scope="module")
def pioneer():
    domain = unique_domain()
    env = dict(os.environ, LIMBER_DOMAIN=domain)
    proc = subprocess.Popen([cli_bin(), "pioneer", "--emulated", "--robot", "pystats"],
                            env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        yield domain
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def open_reader(domain):
    """Opens the reader once the driver offers its statistics (bounded by T)."""
    deadline = time.monotonic() + T
    while True:
        try:
            return DriverStatsReader.open("pystats", domain)
        except NoDriverError:
            if time.monotonic() >= deadline:
                raise
            time.sleep(0.02)


def test_the_reader_sees_what_limber_echo_sees(pioneer):
    with open_reader(pioneer) as r:
        assert r.latest() is None
        s = r.wait(T)
        assert isinstance(s, L.DriverStats)
        assert stats_text(s.driver) == "pioneer"
        assert s.hardware & L.HARDWARE_ARM
        assert s.loop_mode == L.LOOP_MODE_EVENT
        later = r.wait(T)
        assert later.cycles >= s.cycles and later.header.seq > s.header.seq
        out = subprocess.run([cli_bin(), "echo", "--json", "--count", "1", "pystats/driver"],
                             env=dict(os.environ, LIMBER_DOMAIN=pioneer), capture_output=True,
                             text=True, timeout=60, stdin=subprocess.DEVNULL)
        assert out.returncode == 0, out.stderr
        echoed = json.loads(out.stdout)
        assert echoed["driver"] == stats_text(later.driver)
        assert echoed["robot"]["name"] == stats_text(later.robot_name)
        assert echoed["robot"]["arm"] is True
    assert r._closed


def test_no_driver_and_bad_names(pioneer):
    with pytest.raises(NoDriverError):
        DriverStatsReader.open("nosuchrobot", pioneer)
    with pytest.raises(ValueError):
        DriverStatsReader.open("bad robot", pioneer)
    with pytest.raises(limber.DecodeError):
        stats_text((L.DriverStats().driver.__class__)(*([0xFF] * 4)))
