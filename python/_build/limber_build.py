"""The PEP 517 build backend of the limber Python package (``pyproject.toml``:
``build-backend = "limber_build"``, ``backend-path = ["_build"]``), standard library only.

A wheel holds ``limber/*.py``, ``limber/py.typed``, ``limber/liblimber.so`` and, where a C compiler
and Python's headers are, ``limber._fast`` (``limber/_fast.c`` compiled: the state copy of a control
loop without ctypes; without it the package does the same through ctypes, and the wheel is
tagged ``py3-none-<platform>`` instead of this Python's). The library is
built with ``cargo build --release --locked -p limber-c`` in the source tree this package
lies in (``python/..``), with ``CARGO_TARGET_DIR`` in a temporary directory, or taken from
``LIMBER_LIB`` (the path of a liblimber.so already built: CI packages its debug build so it
does not compile twice). Its debug information is stripped (``strip --strip-debug``, when
``strip`` is there: the release library is ~27 MB with DWARF). Nothing is written into the
source tree.
"""

from __future__ import annotations

import base64
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile
from typing import Dict, List, Mapping, Optional, Tuple

HERE = os.path.dirname(os.path.abspath(__file__))
PKG_ROOT = os.path.dirname(HERE)  # python/
REPO = os.path.dirname(PKG_ROOT)  # the source tree (Cargo.toml, capi/)
LIB_ENV = "LIMBER_LIB"
#: ``1``: build the wheel without ``limber._fast`` (ctypes alone).
NO_EXT_ENV = "LIMBER_PY_NO_EXT"


class BuildError(RuntimeError):
    """The package cannot be built (the message says why and what to do)."""


# ----- metadata, from pyproject.toml's [project] -----------------------------------------


def _project() -> Dict[str, object]:
    path = os.path.join(PKG_ROOT, "pyproject.toml")
    try:
        import tomllib  # Python >= 3.11

        with open(path, "rb") as f:
            project: Dict[str, object] = tomllib.load(f)["project"]
        return project
    except ImportError:
        pass
    # Python < 3.11: the few forms [project] uses here (key = "text", key = ["a", "b"]).
    out: Dict[str, object] = {}
    table = ""
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            m = re.fullmatch(r"\[([^\]]+)\]", line)
            if m:
                table = m.group(1).strip()
                continue
            m = re.fullmatch(r'([A-Za-z0-9_-]+)\s*=\s*(.+)', line)
            if not m or table not in ("project", "project.optional-dependencies"):
                continue
            key, value = m.group(1), m.group(2).strip()
            if value.startswith("["):
                parsed: object = re.findall(r'"([^"]*)"', value)
            else:
                parsed = value.strip('"')
            if table == "project":
                out[key] = parsed
            else:
                extras = out.setdefault("optional-dependencies", {})
                assert isinstance(extras, dict)
                extras[key] = parsed
    return out


def _names() -> Tuple[str, str]:
    p = _project()
    return str(p["name"]), str(p["version"])


def _metadata() -> str:
    p = _project()
    lines = [
        "Metadata-Version: 2.1",
        f"Name: {p['name']}",
        f"Version: {p['version']}",
        f"Summary: {p.get('description', '')}",
        f"Requires-Python: {p.get('requires-python', '>=3.9')}",
    ]
    for dep in p.get("dependencies", []) or []:  # type: ignore[union-attr]
        lines.append(f"Requires-Dist: {dep}")
    extras = p.get("optional-dependencies", {}) or {}
    assert isinstance(extras, dict)
    for extra, deps in extras.items():
        lines.append(f"Provides-Extra: {extra}")
        for dep in deps:
            lines.append(f'Requires-Dist: {dep}; extra == "{extra}"')
    readme = os.path.join(PKG_ROOT, "README.md")
    text = ""
    if os.path.isfile(readme):
        lines.append("Description-Content-Type: text/markdown")
        with open(readme, encoding="utf-8") as f:
            text = f.read()
    return "\n".join(lines) + "\n\n" + text


def _tag(with_ext: bool) -> str:
    """The wheel's tag: this CPython's with ``limber._fast``, any Python 3's without."""
    plat = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    if with_ext:
        py = f"cp{sys.version_info.major}{sys.version_info.minor}"
        return f"{py}-{py}{getattr(sys, 'abiflags', '')}-{plat}"
    return f"py3-none-{plat}"


def _wheel_file(with_ext: bool) -> str:
    return (
        "Wheel-Version: 1.0\n"
        "Generator: limber_build\n"
        "Root-Is-Purelib: false\n"
        f"Tag: {_tag(with_ext)}\n"
    )


# ----- the extension ---------------------------------------------------------------------


def _compiler() -> Optional[List[str]]:
    """The C compiler's command (``CC``, else ``cc`` or ``gcc``), or None."""
    cc = os.environ.get("CC", "").strip()
    if cc:
        return shlex.split(cc)
    found = shutil.which("cc") or shutil.which("gcc")
    return [found] if found else None


def _ext_unbuildable() -> Optional[str]:
    """Why ``limber._fast`` cannot be built here, or None if it can be tried."""
    if os.environ.get(NO_EXT_ENV, "") not in ("", "0"):
        return f"{NO_EXT_ENV} is set"
    if sys.implementation.name != "cpython":
        return f"{sys.implementation.name} is not CPython"
    if _compiler() is None:
        return "no C compiler (cc, gcc or CC)"
    if not os.path.isfile(os.path.join(sysconfig.get_paths()["include"], "Python.h")):
        return "Python's headers are not installed (Debian: apt-get install python3-dev)"
    return None


def _extension(tmp: str) -> Optional[str]:
    """``limber._fast`` compiled into ``tmp``, or None (the reason on stderr: the package then
    works through ctypes alone)."""
    why = _ext_unbuildable()
    compiler = _compiler()
    if why is None and compiler is not None:
        out = os.path.join(tmp, "_fast" + str(sysconfig.get_config_var("EXT_SUFFIX") or ".so"))
        cmd = compiler + [
            "-O2", "-shared", "-fPIC", "-Wall", "-Wextra",
            "-I", sysconfig.get_paths()["include"],
            os.path.join(PKG_ROOT, "limber", "_fast.c"), "-o", out,
        ]
        done = subprocess.run(cmd)
        if done.returncode == 0:
            return out
        why = f"{' '.join(cmd)} failed (exit {done.returncode})"
    print(f"limber_build: the wheel has no limber._fast ({why}): states are copied through ctypes",
          file=sys.stderr)
    return None


# ----- the library -----------------------------------------------------------------------


def _library(tmp: str) -> str:
    """A liblimber.so for the wheel, in ``tmp``: ``LIMBER_LIB``'s, or one cargo builds."""
    given = os.environ.get(LIB_ENV)
    if given:
        if not os.path.isfile(given):
            raise BuildError(f"{LIB_ENV}={given}: no such file (the path of a liblimber.so)")
        src = given
    else:
        if not os.path.isfile(os.path.join(REPO, "capi", "Cargo.toml")):
            raise BuildError(
                f"the Rust sources are not at {REPO} (capi/Cargo.toml): build the package from "
                f"the limber source tree, or set {LIB_ENV} to the path of a liblimber.so"
            )
        cargo = shutil.which("cargo")
        if cargo is None:
            raise BuildError(
                f"cargo is needed to build liblimber (https://rustup.rs), or set {LIB_ENV} to "
                "the path of a liblimber.so already built"
            )
        target = os.path.join(tmp, "target")
        env = dict(os.environ, CARGO_TARGET_DIR=target)
        cmd = [cargo, "build", "--release", "--locked", "-p", "limber-c"]
        done = subprocess.run(cmd, cwd=REPO, env=env)
        if done.returncode != 0:
            raise BuildError(f"{' '.join(cmd)} failed (exit {done.returncode}) in {REPO}")
        src = os.path.join(target, "release", "liblimber.so")
    out = os.path.join(tmp, "liblimber.so")
    shutil.copyfile(src, out)
    strip = shutil.which("strip")
    if strip is not None:
        subprocess.run([strip, "--strip-debug", out], check=True)
    return out


def _package_files() -> List[Tuple[str, str]]:
    """(path in the wheel, file) of the package's Python files and py.typed."""
    src = os.path.join(PKG_ROOT, "limber")
    out = []
    for name in sorted(os.listdir(src)):
        if name.endswith(".py") or name == "py.typed":
            out.append((f"limber/{name}", os.path.join(src, name)))
    return out


# ----- the hooks -------------------------------------------------------------------------


def _record_line(arcname: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def get_requires_for_build_wheel(config_settings: Optional[Mapping[str, object]] = None) -> List[str]:
    return []


def get_requires_for_build_sdist(config_settings: Optional[Mapping[str, object]] = None) -> List[str]:
    return []


def prepare_metadata_for_build_wheel(
    metadata_directory: str, config_settings: Optional[Mapping[str, object]] = None
) -> str:
    name, version = _names()
    dist_info = f"{name}-{version}.dist-info"
    d = os.path.join(metadata_directory, dist_info)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata())
    with open(os.path.join(d, "WHEEL"), "w", encoding="utf-8") as f:
        f.write(_wheel_file(_ext_unbuildable() is None))
    return dist_info


def build_wheel(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, object]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    name, version = _names()
    dist_info = f"{name}-{version}.dist-info"
    with tempfile.TemporaryDirectory(prefix="limber-build-") as tmp:
        files: List[Tuple[str, bytes]] = []
        for arcname, path in _package_files():
            with open(path, "rb") as f:
                files.append((arcname, f.read()))
        with open(_library(tmp), "rb") as f:
            files.append(("limber/liblimber.so", f.read()))
        ext = _extension(tmp)
        if ext is not None:
            with open(ext, "rb") as f:
                files.append((f"limber/{os.path.basename(ext)}", f.read()))
        wheel_name = f"{name}-{version}-{_tag(ext is not None)}.whl"
        files.append((f"{dist_info}/METADATA", _metadata().encode("utf-8")))
        files.append((f"{dist_info}/WHEEL", _wheel_file(ext is not None).encode("utf-8")))
        record = [_record_line(a, d) for a, d in files] + [f"{dist_info}/RECORD,,"]
        files.append((f"{dist_info}/RECORD", ("\n".join(record) + "\n").encode("utf-8")))
        out = os.path.join(wheel_directory, wheel_name)
        with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for arcname, data in files:
                info = zipfile.ZipInfo(arcname, date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if arcname.endswith(".so") else 0o644) << 16
                z.writestr(info, data)
    return wheel_name


def build_sdist(
    sdist_directory: str, config_settings: Optional[Mapping[str, object]] = None
) -> str:
    """The Python sources alone (limber/, _build/, pyproject.toml, README.md): building a
    wheel from it needs ``LIMBER_LIB`` (the Rust sources are not in it)."""
    name, version = _names()
    base = f"{name}-{version}"
    out = os.path.join(sdist_directory, f"{base}.tar.gz")
    with tarfile.open(out, "w:gz") as t:
        for rel in ["pyproject.toml", "README.md", "_build/limber_build.py", "limber/_fast.c"]:
            t.add(os.path.join(PKG_ROOT, rel), arcname=f"{base}/{rel}")
        for arcname, path in _package_files():
            t.add(path, arcname=f"{base}/{arcname}")
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        data = _metadata().encode("utf-8")
        info.size = len(data)
        import io

        t.addfile(info, io.BytesIO(data))
    return os.path.basename(out)
