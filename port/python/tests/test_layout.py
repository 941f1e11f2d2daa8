# SPDX-License-Identifier: BSD-3-Clause
"""The ctypes mirrors (occmap/_structs.py) against the C headers: a C program generated from the
mirrors prints sizeof of every struct and offsetof / sizeof of every field path (nested structs
and unions included), compiled against include/ with the flags of libocc.so's build. A renamed,
added, removed, retyped or moved field fails here (a name the header lacks does not compile)."""
import ctypes as C
import shutil
import subprocess

import pytest

from occmap import _structs as S
from conftest import ROOT


def _is_record(t):
    return isinstance(t, type) and issubclass(t, (C.Structure, C.Union))


def _fields(t, prefix="", base=0):
    """(path, offset, size) of every field, descending into nested records (not arrays)."""
    for name, ftype in t._fields_:
        off = base + getattr(t, name).offset
        path = prefix + name
        yield path, off, C.sizeof(ftype)
        if _is_record(ftype):
            yield from _fields(ftype, path + ".", off)


def _expected(structs):
    want = {}
    for t in structs:
        want[f"{t.c_name} sizeof"] = C.sizeof(t)
        for path, off, size in _fields(t):
            want[f"{t.c_name} {path} offsetof"] = off
            want[f"{t.c_name} {path} sizeof"] = size
    return want


def _c_program(structs):
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "occmap/occmap.h"',
             '#include "occmap/occ_depth.h"', '#include "occmap/occ_sectors.h"',
             "int main(void)", "{"]
    for t in structs:
        n = t.c_name
        lines.append(f'    printf("{n} sizeof %zu\\n", sizeof({n}));')
        for path, _, _ in _fields(t):
            lines.append(f'    printf("{n} {path} offsetof %zu\\n", offsetof({n}, {path}));')
            lines.append(f'    printf("{n} {path} sizeof %zu\\n", sizeof((({n} *)0)->{path}));')
    lines += ["    return 0;", "}"]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    """What the C compiler says for every field path of the mirrors."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.fail("no C compiler (cc) to check the struct layouts with")
    tmp = tmp_path_factory.mktemp("layout")
    src = tmp / "layout.c"
    src.write_text(_c_program(S.PUBLIC))
    exe = tmp / "layout"
    build = subprocess.run([cc, "-std=c99", "-Wall", "-Werror", f"-I{ROOT / 'include'}",
                            str(src), "-o", str(exe)], capture_output=True, text=True)
    assert build.returncode == 0, "layout program does not compile:\n" + build.stderr[-3000:]
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    got = {}
    for line in out.splitlines():
        key, _, value = line.rpartition(" ")
        got[key] = int(value)
    return got


def _differences(got, structs):
    want = _expected(structs)
    return {k: (got.get(k), want[k]) for k in want if got.get(k) != want[k]}


def test_structs_match_headers(c_layout):
    bad = _differences(c_layout, S.PUBLIC)
    assert not bad, "C (header) vs ctypes mirror differ: {key: (C, Python)}: " + repr(bad)
    assert len(c_layout) == len(_expected(S.PUBLIC)) > 300


def test_a_wrong_mirror_is_caught(c_layout):
    """The comparison can fail: occ_map_config_t mirrored with two fields swapped, and
    occ_map_t with its size_t as 32 bits, both differ from what the compiler says."""
    swapped = type("occ_map_config_t", (S.Struct,), {
        "c_name": "occ_map_config_t",
        "_fields_": [S.MapConfig._fields_[1], S.MapConfig._fields_[0]] + S.MapConfig._fields_[2:]})
    narrow = type("occ_map_t", (S.Struct,), {
        "c_name": "occ_map_t",
        "_fields_": [(n, C.c_uint32 if n == "arena_bytes" else t) for n, t in S.MapT._fields_]})
    assert "occ_map_config_t resolution_m offsetof" in _differences(c_layout, [swapped])
    assert "occ_map_t inner offsetof" in _differences(c_layout, [narrow])
