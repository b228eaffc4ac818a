"""Types: the package is marked typed (py.typed, shipped as package data), every module
compiles, and every public function and method of the API carries full type hints."""

import inspect
import os
import py_compile
import sys

import limber
from limber import client

PKG = os.path.dirname(limber.__file__)


def test_py_typed_marker_ships_with_the_package():
    assert os.path.isfile(os.path.join(PKG, "py.typed"))
    # The build backend puts it in the wheel (test_install.py installs one).
    sys.path.insert(0, os.path.join(PKG, "..", "_build"))
    try:
        import limber_build
    finally:
        sys.path.pop(0)
    shipped = [arc for arc, _ in limber_build._package_files()]
    assert "limber/py.typed" in shipped and "limber/client.py" in shipped


def test_every_module_compiles(tmp_path):
    for name in sorted(os.listdir(PKG)):
        if name.endswith(".py"):
            py_compile.compile(os.path.join(PKG, name), cfile=str(tmp_path / (name + "c")),
                               doraise=True)


def public_callables():
    for name in client.__all__:
        obj = getattr(client, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj):
            for klass in obj.__mro__:
                if not klass.__module__.startswith("limber."):
                    continue
                for n, f in vars(klass).items():
                    if n.startswith("_") and n not in ("__init__", "__enter__", "__exit__"):
                        continue
                    if isinstance(f, (classmethod, staticmethod)):
                        f = f.__func__
                    if isinstance(f, property):
                        f = f.fget
                    if inspect.isfunction(f):
                        yield f"{name}.{n}", f


def test_the_public_api_is_fully_annotated():
    missing = []
    checked = 0
    for qual, f in public_callables():
        checked += 1
        sig = inspect.signature(f)
        bad = [p for p, v in sig.parameters.items()
               if p not in ("self", "cls") and v.annotation is inspect.Parameter.empty]
        if sig.return_annotation is inspect.Signature.empty:
            bad.append("return")
        if bad:
            missing.append((qual, bad))
    assert checked > 50
    assert missing == []


def test_every_c_function_called_has_its_prototype():
    """Each liblimber function the package calls is in the one table of prototypes
    (argtypes and restype set at load), so that a wrong call is a Python error."""
    import re

    from limber import _lib

    called = set()
    for name in os.listdir(PKG):
        if name.endswith(".py") and name != "_lib.py":
            with open(os.path.join(PKG, name)) as f:
                called |= set(re.findall(r"\.(limber_[a-z0-9_]+)\b", f.read()))
    assert called, "no C call found"
    assert sorted(called - set(_lib.PROTOTYPES)) == []
    for name, (res, args) in _lib.PROTOTYPES.items():
        f = getattr(_lib.lib, name)
        assert f.argtypes == args and f.restype is res, name


def test_the_package_imports_no_iceoryx2(tmp_path):
    """Every rule is liblimber's: the package does not use the iceoryx2 binding."""
    import subprocess

    for name in os.listdir(PKG):
        if name.endswith(".py"):
            with open(os.path.join(PKG, name)) as f:
                assert "import iceoryx2" not in f.read(), name
    script = "import sys, limber; assert 'iceoryx2' not in sys.modules; print('ok')"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=60, env=dict(os.environ, PYTHONPATH=os.path.dirname(PKG)))
    assert out.stdout.strip() == "ok", out.stderr
