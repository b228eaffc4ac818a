"""The generated ctypes classes agree with the Rust layout manifest (`limber layout --json`)."""

import ctypes
import json
import os
import subprocess

import pytest

import limber
from limber import _layout

SCALARS = {
    "u8": ctypes.c_uint8, "u16": ctypes.c_uint16, "u32": ctypes.c_uint32, "u64": ctypes.c_uint64,
    "i8": ctypes.c_int8, "i16": ctypes.c_int16, "i32": ctypes.c_int32, "i64": ctypes.c_int64,
    "f32": ctypes.c_float, "f64": ctypes.c_double,
}


def limber_bin():
    return os.environ.get("LIMBER_BIN") or os.path.join(
        os.path.dirname(__file__), "..", "..", "target", "debug", "limber")


@pytest.fixture(scope="module")
def manifest():
    out = subprocess.run([limber_bin(), "layout", "--json"], check=True, capture_output=True,
                         text=True, timeout=60)
    return json.loads(out.stdout)


def test_every_struct_is_generated(manifest):
    names = [s["name"] for s in manifest["structs"]]
    assert names == [c.__name__ for c in limber.STRUCTS]
    assert manifest["layout_version"] == limber.LAYOUT_VERSION


def mismatches(cls, s):
    """Every way the ctypes class `cls` disagrees with manifest entry `s`."""
    bad = []
    if ctypes.sizeof(cls) != s["size"]:
        bad.append("size")
    if ctypes.alignment(cls) != s["align"]:
        bad.append("align")
    if [f[0] for f in cls._fields_] != [f["name"] for f in s["fields"]]:
        bad.append("field order")
    types = dict(cls._fields_)
    for f in s["fields"]:
        desc = getattr(cls, f["name"], None)
        if desc is None or desc.offset != f["offset"] or desc.size != f["size"]:
            bad.append(f"offset/size of {f['name']}")
            continue
        ctype = types[f["name"]]
        elem = SCALARS.get(f["type"]) or getattr(_layout, f["type"])
        if f["array_len"]:
            if getattr(ctype, "_length_", None) != f["array_len"] or ctype._type_ is not elem:
                bad.append(f"type of {f['name']}")
        elif ctype is not elem:
            bad.append(f"type of {f['name']}")
    return bad


def test_sizes_alignments_offsets_and_types_agree(manifest):
    for s in manifest["structs"]:
        cls = getattr(_layout, s["name"])
        assert mismatches(cls, s) == [], s["name"]
        assert cls.type_name() == s["type_name"]


def test_constants_agree(manifest):
    for g in manifest["constants"]:
        for c in g["constants"]:
            assert getattr(_layout, f"{g['name']}_{c['name']}") == c["value"]


def test_a_moved_field_would_be_caught(manifest):
    """The comparison is not vacuous: a class with two fields swapped is reported."""
    s = next(s for s in manifest["structs"] if s["name"] == "CmdOutcome")
    fields = list(_layout.CmdOutcome._fields_)
    fields[2], fields[3] = fields[3], fields[2]
    moved = type("CmdOutcome", (ctypes.Structure,), {"_fields_": fields})
    assert "offset/size of kind" in mismatches(moved, s)


def test_bytes_written_by_python_decode_as_expected():
    """A command built in Python has the byte layout the Rust decoder expects."""
    msg = _layout.ActArrayCmdMsg()
    msg.meta.client_id = 7
    msg.meta.seq = 1
    msg.meta.kind = _layout.ACTARRAY_CMD_POS
    body = _layout.ActArrayPositionCmd(joint=2, position=0.5)
    msg.meta.body_len = ctypes.sizeof(body)
    ctypes.memmove(msg.body, ctypes.addressof(body), ctypes.sizeof(body))
    raw = bytes(msg)
    assert len(raw) == 296
    assert int.from_bytes(raw[0:8], "little") == 7
    assert int.from_bytes(raw[24:28], "little") == 1
    assert int.from_bytes(raw[32:36], "little", signed=True) == 2


def test_status_texts_are_rusts(manifest):
    """Every status code has an enum member whose text is Rust's ``Status::describe``."""
    texts = {t["code"]: t["text"] for t in manifest["status_texts"]}
    assert texts == _layout.DESCRIBE_STATUS
    assert sorted(int(s) for s in limber.Status) == sorted(texts)
    for s in limber.Status:
        assert s.describe() == texts[int(s)]
    assert limber.Status.LEASED.describe() == "held by another client"


def test_the_library_speaks_this_layout_and_enforces_the_manifest_s_name_limits():
    from limber import _lib

    assert _lib.lib.limber_layout_version() == _layout.LAYOUT_VERSION
    limber.list_devices("d" * _layout.NAME_MAX_DOMAIN_LEN)
    with pytest.raises(ValueError):
        limber.list_devices("d" * (_layout.NAME_MAX_DOMAIN_LEN + 1))
    with pytest.raises(limber.NoDriverError):
        limber.LimbClient.connect("r" * _layout.NAME_MAX_ROBOT_LEN + "/limb/0",
                                  "d" * _layout.NAME_MAX_DOMAIN_LEN)
    with pytest.raises(ValueError):
        limber.LimbClient.connect("r" * (_layout.NAME_MAX_ROBOT_LEN + 1) + "/limb/0",
                                  "d" * _layout.NAME_MAX_DOMAIN_LEN)
    limber.remove_domain_files("d" * _layout.NAME_MAX_DOMAIN_LEN)
