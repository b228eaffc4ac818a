"""Shared by every Python test module: the domains the tests used leave nothing behind."""

import pytest

from test_client import _used_domains, remove_domain_files


@pytest.fixture(scope="session", autouse=True)
def _remove_test_domains():
    yield
    for d in _used_domains:
        remove_domain_files(d)
