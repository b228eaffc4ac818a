"""Discovery (list_devices) against the Rust test driver, compared with `limber list`."""

import limber
from limber import DeviceInfo, DeviceName, list_devices

from test_client import T, cli, driver, own_driver, unique_domain  # noqa: F401


def test_list_devices_agrees_with_limber_list(driver, monkeypatch):  # noqa: F811
    with limber.GripperClient.connect(driver.dev("gripper"), driver.domain, timeout=T):
        devices = list_devices(driver.domain)
        out = cli(driver, "list")
    assert out.returncode == 0, out.stderr
    rows = [line.split() for line in out.stdout.splitlines()[1:] if line]
    assert [str(d.name) for d in devices] == [r[0] for r in rows]
    assert [d.driver for d in devices] == [r[1] for r in rows]
    assert all(d.alive for d in devices) and all(r[2] == "alive" for r in rows)
    grip = next(d for d in devices if d.name == DeviceName.parse(driver.dev("gripper")))
    assert isinstance(grip, DeviceInfo)
    assert grip.interface == "gripper"
    assert grip.driver == "testdriver"
    assert grip.layout == str(limber.LAYOUT_VERSION)
    assert grip.nodes >= 2  # the driver and the client above (gone by now)
    assert {d.interface for d in devices} == {"actarray", "limb", "gripper"}
    # The domain from LIMBER_DOMAIN when none is given.
    monkeypatch.setenv("LIMBER_DOMAIN", driver.domain)
    assert [d.name for d in list_devices()] == [d.name for d in devices]


def test_an_empty_domain_has_no_devices():
    assert list_devices(unique_domain()) == []


def test_a_killed_driver_is_listed_not_alive(own_driver):  # noqa: F811
    d = own_driver()
    assert all(x.alive for x in list_devices(d.domain))
    d.kill()
    d.proc.wait(timeout=T)
    listed = list_devices(d.domain)
    assert listed and not any(x.alive for x in listed)
