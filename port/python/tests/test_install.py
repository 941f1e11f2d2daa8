# SPDX-License-Identifier: BSD-3-Clause
"""Where the package finds libocc.so: bundled by a plain install (setup.py's build_py copies it
in), the repository's build/ from the tree, and $OCCMAP_LIB, which is never silently replaced."""
import os
import subprocess
import sys

from conftest import ROOT

PKG = ROOT / "port" / "python"
PROBE = ("import occmap; m = occmap.Map.load({map!r}); "
         "print(occmap.LIB_PATH); print(m.stats()['occupied_voxels'])")


def _run(code, env, cwd, pythonpath):
    env = {k: v for k, v in os.environ.items() if k != "OCCMAP_LIB"} | env
    env["PYTHONPATH"] = str(pythonpath)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=cwd, env=env)


def test_plain_install_bundles_the_library(tmp_path, geb079):
    lib = tmp_path / "lib"
    build = subprocess.run([sys.executable, "setup.py", "-q", "build_py", "-d", str(lib)],
                           cwd=PKG, capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    bundled = lib / "occmap" / "libocc.so"
    assert bundled.stat().st_size == (ROOT / "build" / "libocc.so").stat().st_size
    r = _run(PROBE.format(map=str(geb079)), {}, tmp_path, lib)  # OCCMAP_LIB unset
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [str(bundled), "185673"]


def test_tree_finds_build_libocc(tmp_path, geb079):
    r = _run(PROBE.format(map=str(geb079)), {}, tmp_path, PKG)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [str(ROOT / "build" / "libocc.so"), "185673"]


def test_occmap_lib_is_never_replaced(tmp_path):
    r = _run("import occmap", {"OCCMAP_LIB": str(tmp_path / "nothere.so")}, tmp_path, PKG)
    assert r.returncode != 0 and "nothere.so" in r.stderr and "ImportError" in r.stderr
