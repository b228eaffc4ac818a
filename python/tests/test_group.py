"""Group mode (LIMBER_GROUP) from Python: the rules are liblimber's, as for every language.
A domain of a group this user is in works (here a driver and a Python client share one in
the group's runtime directory); a group this user is not in, or one that does not exist,
is refused with the library's reason."""

import grp
import os
import shutil
import tempfile

import pytest

import limber
from limber import ActArrayClient, Status, list_devices

from test_client import T, Driver, driver_bin, unique_domain


@pytest.fixture
def runtime_dir():
    """A runtime directory of the test's own, with a short path (iceoryx2's sockets live
    under it, and a socket's path has at most 107 bytes)."""
    d = tempfile.mkdtemp(prefix="lpg", dir="/tmp")
    yield d
    shutil.rmtree(d, ignore_errors=True)


def test_a_group_domain_works_from_python(monkeypatch, runtime_dir):
    driver_bin()  # skips (fails in CI) without the Rust test driver
    group = grp.getgrgid(os.getegid()).gr_name  # a group this user is in
    monkeypatch.setenv("LIMBER_GROUP", group)
    monkeypatch.setenv("LIMBER_RUNTIME_DIR", runtime_dir)
    d = Driver("pygroup")
    try:
        names = [str(x.name) for x in list_devices(d.domain)]
        assert d.dev("actarray") in names
        with ActArrayClient.connect(d.dev("actarray"), d.domain, timeout=T) as arm:
            assert arm.wait_outcome(arm.move_to(1, 0.25), T) is Status.OK
            assert arm.state().actuators[1].position == 0.25
    finally:
        d.stop()
    # The domain's files are in the group's runtime directory given, with its token.
    assert os.path.isfile(os.path.join(runtime_dir, f"{d.domain}.token"))
    limber.remove_domain_files(d.domain)


def test_a_group_this_user_is_not_in_is_refused_with_the_reason(monkeypatch):
    monkeypatch.setenv("LIMBER_GROUP", "limber-no-such-group")
    with pytest.raises(limber.TransportError, match="limber-no-such-group"):
        list_devices(unique_domain())
