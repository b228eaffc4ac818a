"""Group mode (LIMBER_GROUP) is refused by the Python client with what to do instead."""

import pytest

import limber
from limber import list_devices

from test_client import unique_domain


def test_group_mode_is_refused_clearly(monkeypatch):
    monkeypatch.setenv("LIMBER_GROUP", "limber-arm")
    with pytest.raises(limber.TransportError, match="group mode, which the Python client does not support"):
        list_devices(unique_domain())
    with pytest.raises(limber.TransportError, match="unset LIMBER_GROUP"):
        limber.Domain(unique_domain()).prefix
