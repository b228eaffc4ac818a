"""`pip install ./python` into a fresh venv: the in-tree build backend packages liblimber
(here LIMBER_LIB's, the debug build CI made, so that nothing compiles twice) with the
Python files and py.typed, writes nothing into the source tree, and the installed package
finds its own library and lists a driver's devices."""

import os
import subprocess
import sys

import pytest

import limber

from test_client import REPO, driver  # noqa: F401  (the shared driver fixture)

LIMIT = 300  # seconds for each step: a venv with pip, a local install


def porcelain():
    out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all", "python/"],
                         cwd=REPO, capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        pytest.skip(f"not a git checkout: {out.stderr.strip()}")
    return out.stdout


def test_pip_install_packages_the_library_and_leaves_the_tree_as_it_was(driver, tmp_path):  # noqa: F811
    lib = limber.library_path()  # the library the tests run with
    before = porcelain()
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=LIMIT)
    py = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LIMBER_LIB")}
    out = subprocess.run(
        [py, "-m", "pip", "install", "--no-index", "--disable-pip-version-check", "--quiet",
         os.path.join(REPO, "python")],
        env=dict(env, LIMBER_LIB=lib), capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stdout + out.stderr
    assert porcelain() == before
    # The installed package, from another directory, without LIMBER_LIB or PYTHONPATH.
    script = (
        "import os, sys, limber\n"
        "pkg = os.path.dirname(limber.__file__)\n"
        "assert limber.library_path() == os.path.join(pkg, 'liblimber.so'), limber.library_path()\n"
        "assert os.path.isfile(os.path.join(pkg, 'py.typed'))\n"
        "assert 'site-packages' in pkg, pkg\n"
        "print(' '.join(str(d.name) for d in limber.list_devices(sys.argv[1])))\n"
    )
    out = subprocess.run([py, "-c", script, driver.domain], env=env, cwd=str(tmp_path),
                         capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stderr
    assert driver.dev("actarray") in out.stdout.split()


def test_a_missing_library_says_where_it_looked_and_what_to_do(tmp_path):
    env = dict(os.environ, LIMBER_LIB=str(tmp_path / "nowhere" / "liblimber.so"),
               PYTHONPATH=os.path.join(REPO, "python"))
    out = subprocess.run([sys.executable, "-c", "import limber"], env=env,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode != 0
    assert "LibraryNotFound" in out.stderr
    assert f"{tmp_path}/nowhere/liblimber.so (LIMBER_LIB): not there" in out.stderr
    assert "pip install ./python" in out.stderr and "cargo build -p limber-c" in out.stderr
