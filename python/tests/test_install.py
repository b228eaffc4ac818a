"""`pip install ./python` into a fresh venv: the in-tree build backend packages liblimber
(here LIMBER_LIB's, the debug build CI made, so that nothing compiles twice) with the
Python files and py.typed, writes nothing into the source tree, and the installed package
finds its own library and lists a driver's devices; with a C compiler the wheel carries
limber._fast, whose state copies equal ctypes' (LIMBER_PY_CTYPES=1), and without one
(LIMBER_PY_NO_EXT=1) it is a ctypes package for any Python 3."""

import os
import subprocess
import sys
import zipfile

import pytest

import limber

from test_client import REPO, Driver, driver  # noqa: F401  (the shared driver fixture)

LIMIT = 300  # seconds for each step: a venv with pip, a local install


def porcelain():
    out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all", "python/"],
                         cwd=REPO, capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        pytest.skip(f"not a git checkout: {out.stderr.strip()}")
    return out.stdout


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """`pip install ./python` into a fresh venv: (its python, the environment without
    LIMBER_LIB and PYTHONPATH, the tree's `git status` before, and after)."""
    lib = limber.library_path()  # the library the tests run with
    before = porcelain()
    tmp = tmp_path_factory.mktemp("install")
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=LIMIT)
    py = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "LIMBER_LIB", "LIMBER_PY_CTYPES", "LIMBER_PY_NO_EXT")}
    out = subprocess.run(
        [py, "-m", "pip", "install", "--no-index", "--disable-pip-version-check", "--quiet",
         os.path.join(REPO, "python")],
        env=dict(env, LIMBER_LIB=lib), capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stdout + out.stderr
    return py, env, before, porcelain()


def run(py, env, script, *args, cwd=None):
    """`script` run by the installed package's python with `args` (its output, as text)."""
    return subprocess.run([py, "-c", script, *args], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=LIMIT)


def test_pip_install_packages_the_library_and_leaves_the_tree_as_it_was(driver, installed, tmp_path):  # noqa: F811
    py, env, before, after = installed
    assert after == before
    # The installed package, from another directory, without LIMBER_LIB or PYTHONPATH.
    script = (
        "import os, sys, limber\n"
        "pkg = os.path.dirname(limber.__file__)\n"
        "assert limber.library_path() == os.path.join(pkg, 'liblimber.so'), limber.library_path()\n"
        "assert os.path.isfile(os.path.join(pkg, 'py.typed'))\n"
        "assert 'site-packages' in pkg, pkg\n"
        "print(' '.join(str(d.name) for d in limber.list_devices(sys.argv[1])))\n"
    )
    out = run(py, env, script, driver.domain, cwd=str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert driver.dev("actarray") in out.stdout.split()


# Reads states through the installed package's copy_out (argv: domain, device, "compiled" or
# "ctypes", the one expected) and prints what it read, for the two to be compared.
STATES = """
import sys, limber, limber._lib as l
from limber import ActArrayClient, ActArrayData, LimberError
domain, device, expected = sys.argv[1:]
assert ("compiled" if l.COMPILED else "ctypes") == expected, (l.COMPILED, expected)
arm = ActArrayClient.connect(device, domain, timeout=10.0)
waited = arm.wait_state(5.0)
assert type(waited) is ActArrayData, type(waited)
assert bytes(waited) == bytes(arm.last_state())  # a copy of what the library took
now = arm.state()
assert type(now) is ActArrayData and bytes(now) == bytes(arm.last_state())
assert now is not arm.state()  # a new copy each time
print(now.actuators_count, now.header.seq > 0)
try:
    now.postion = 1.0  # a misspelt field: the classes take no other attributes
except AttributeError:
    print("misspelt: AttributeError")
# Copied and pickled as their bytes (ctypes' own pickling needs an instance dict).
import copy, pickle
for twin in (copy.copy(now), copy.deepcopy(now), pickle.loads(pickle.dumps(now)),
             pickle.loads(pickle.dumps(now, protocol=0))):
    assert type(twin) is ActArrayData and twin is not now and bytes(twin) == bytes(now)
part = pickle.loads(pickle.dumps(now.actuators[0]))
assert bytes(part) == bytes(now.actuators[0])
# What the compiled copy recycles is a state nothing references: one held, directly or
# through a part of it, keeps its bytes while newer states are read and dropped.
held = arm.wait_state(5.0)
raw = bytes(held)
header = arm.wait_state(5.0).header  # holds its state through the part
hseq = header.seq
for _ in range(4):
    arm.wait_state(5.0)  # dropped at once: recycled by the compiled copy
    arm.state()
assert bytes(held) == raw and header.seq == hseq > held.header.seq
a, b = arm.wait_state(5.0), arm.wait_state(5.0)
assert a is not b and a.header.seq < b.header.seq
x = arm.wait_state(5.0)
del x
y = arm.wait_state(5.0)
print("recycled:", any(y is o for o in arm._spare))
arm.close()
for call in (arm.state, lambda: arm.wait_state(1.0)):
    try:
        call()
    except LimberError as e:
        print("closed:", e)
"""


@pytest.mark.parametrize("how", ["compiled", "ctypes"])
def test_the_installed_package_copies_states_in_c_or_through_ctypes_alike(driver, installed, how):  # noqa: F811
    # pip built limber._fast (a C compiler and Python's headers are here, as on CI); with
    # LIMBER_PY_CTYPES=1 the same package copies through ctypes: the same answers.
    py, env, _, _ = installed
    if how == "ctypes":
        env = dict(env, LIMBER_PY_CTYPES="1")
    out = run(py, env, STATES, driver.domain, driver.dev("actarray"), how)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == [
        "6 True",
        "misspelt: AttributeError",
        f"recycled: {how == 'compiled'}",
        "closed: ActArrayClient is closed",
        "closed: ActArrayClient is closed",
    ], out.stdout


def test_the_compiled_wait_lets_other_threads_run_and_times_out_as_ctypes_does(installed):
    # A driver that publishes only when commanded: a wait for a newer state times out. While
    # it waits, another thread of the program runs (the GIL is released, as ctypes does): it
    # gets about as far as while this thread sleeps as long (held, it got ~2 % of that).
    py, env, _, _ = installed
    d = Driver("pyquiet", "--period-ms", "600000")
    try:
        script = (
            "import sys, threading, limber._lib as l\n"
            "from limber import ActArrayClient, WaitTimeout\n"
            "assert l.COMPILED\n"
            "arm = ActArrayClient.connect(sys.argv[2], sys.argv[1], timeout=10.0)\n"
            "arm.wait_state(5.0) if arm.state() is None else None\n"
            "count, stop = [0], threading.Event()\n"
            "def spin():\n"
            "    while not stop.is_set():\n"
            "        count[0] += 1\n"
            "t = threading.Thread(target=spin)\n"
            "t.start()\n"
            "import time\n"
            "before = count[0]\n"
            "time.sleep(0.3)  # how far it gets while this thread sleeps: the reference\n"
            "ref = count[0] - before\n"
            "before = count[0]\n"
            "try:\n"
            "    arm.wait_state(0.3)\n"
            "except WaitTimeout as e:\n"
            "    print('timeout:', e)\n"
            "ran = count[0] - before\n"
            "stop.set()\n"
            "t.join()\n"
            "print('other thread ran:', ran > ref / 4, ran, ref)\n"
        )
        out = run(py, env, script, d.domain, d.dev("actarray"))
    finally:
        d.stop()
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("timeout: "), lines
    assert lines[1].startswith("other thread ran: True"), lines


def test_the_compiled_copy_refuses_bad_arguments_with_an_error(installed):
    py, env, _, _ = installed
    script = (
        "import ctypes\n"
        "from limber import _fast, _lib\n"
        "fn = ctypes.cast(_lib.lib.limber_device_state, ctypes.c_void_p).value\n"
        "for args in [(), (fn, None, 0), (0, None, 0, int), (fn, None, -1, int),\n"
        "             (fn, 'h', 0, int), (fn, None, 0, int), (fn, None, 0, 3),\n"
        "             (fn, None, 0, bytes), (fn, None, 0, _lib.L.ActArrayData, [None]),\n"
        "             (fn, None, 0, _lib.L.ActArrayData, (None, None))]:\n"
        "    try:\n"
        "        _fast.copy_out(*args)\n"
        "    except (TypeError, ValueError, OverflowError, BufferError) as e:\n"
        "        print(type(e).__name__)\n"
        "print(_fast.copy_out(fn, None, 0, _lib.L.ActArrayData) == _lib.CODE_NULL_ARGUMENT)\n"
    )
    out = run(py, env, script)
    assert out.returncode == 0, out.stderr
    # Each a Python exception (nothing called), and a NULL handle liblimber's own refusal.
    assert out.stdout.split() == ["TypeError", "TypeError", "ValueError", "OverflowError",
                                  "TypeError", "TypeError", "TypeError", "BufferError",
                                  "TypeError", "TypeError", "True"], out.stdout


def test_the_compiled_copy_recycles_only_a_slotted_state_nothing_references(driver, installed):  # noqa: F811
    # copy_out's spare: an instance it returned comes back only once nothing but the spare
    # references it, and only of a class without an instance dict or weak references (an
    # attribute or a weak reference could otherwise outlive the state it was made on).
    py, env, _, _ = installed
    script = (
        "import ctypes, sys, weakref\n"
        "from limber import ActArrayClient, ActArrayData, _fast, _lib\n"
        "arm = ActArrayClient.connect(sys.argv[2], sys.argv[1], timeout=10.0)\n"
        "arm.wait_state(5.0)\n"
        "fn = _lib.copier('limber_device_state')\n"
        "hv = arm._hv\n"
        "class Loose(ctypes.Structure):\n"
        "    _fields_ = ActArrayData._fields_\n"
        "for cls in (ActArrayData, Loose):\n"
        "    spare = _lib.new_spare()\n"
        "    first = _fast.copy_out(fn, hv, 0, cls, spare)\n"
        "    assert spare[1] is first and spare[0] is None\n"
        "    again = _fast.copy_out(fn, hv, 0, cls, spare)  # first is held: a new one\n"
        "    assert again is not first and spare == [first, again]\n"
        "    del first, again\n"
        "    last = id(spare[1])\n"
        "    w = weakref.ref(spare[1]) if cls is Loose else None\n"
        "    third = _fast.copy_out(fn, hv, 0, cls, spare)\n"
        "    print(cls.__name__, 'recycled' if id(third) in (id(spare[0]), last) and\n"
        "          any(third is o for o in spare) else 'new', w is None or w() is not third)\n"
    )
    out = run(py, env, script, driver.domain, driver.dev("actarray"))
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["ActArrayData recycled True", "Loose new True"], \
        out.stdout


def test_a_wheel_without_a_c_compiler_is_ctypes_alone_for_any_python_3(tmp_path):
    # LIMBER_PY_NO_EXT=1 stands for a machine without a C compiler or Python's headers.
    env = dict(os.environ, LIMBER_LIB=limber.library_path(), LIMBER_PY_NO_EXT="1")
    env.pop("PYTHONPATH", None)
    out = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "--disable-pip-version-check", "--quiet", "-w", str(tmp_path),
         os.path.join(REPO, "python")],
        env=env, capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stdout + out.stderr
    (wheel,) = [p for p in os.listdir(tmp_path) if p.endswith(".whl")]
    assert "-py3-none-" in wheel, wheel
    with zipfile.ZipFile(tmp_path / wheel) as z:
        names = z.namelist()
    assert "limber/liblimber.so" in names and "limber/client.py" in names
    assert not [n for n in names if "_fast" in n], names


def test_a_missing_library_says_where_it_looked_and_what_to_do(tmp_path):
    env = dict(os.environ, LIMBER_LIB=str(tmp_path / "nowhere" / "liblimber.so"),
               PYTHONPATH=os.path.join(REPO, "python"))
    out = subprocess.run([sys.executable, "-c", "import limber"], env=env,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode != 0
    assert "LibraryNotFound" in out.stderr
    assert f"{tmp_path}/nowhere/liblimber.so (LIMBER_LIB): not there" in out.stderr
    assert "pip install ./python" in out.stderr and "cargo build -p limber-c" in out.stderr
