# SPDX-License-Identifier: BSD-3-Clause
"""Shared fixtures: the repository, the C tool (the reference answers), the real maps."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(os.environ.get("OCCMAP_ROOT") or Path(__file__).resolve().parents[3])
GEB079 = Path("/usr/share/doc/liboctomap-dev/examples/data/geb079.bt")
SHARED_MAPS = Path(os.environ.get("OCCMAP_SHARED") or ROOT.parent / "shared") / "data" / "maps"
FR078 = SHARED_MAPS / "fr_078_tidyup.bt"
FR079_OT = SHARED_MAPS / "fr_079_t1_model.ot"

sys.path.insert(0, str(ROOT / "tools"))  # octomap_bt.py, sector_ref.py: independent references


def _need(path, why):
    if not path.exists():
        pytest.skip(f"{path} absent ({why})")
    return path


@pytest.fixture(scope="session")
def tool():
    """build/occmap: its answers are what the binding must reproduce."""
    path = Path(os.environ.get("OCCMAP_TOOL") or ROOT / "build" / "occmap")
    if not path.exists():
        pytest.fail(f"{path} absent: run `make build/occmap`")

    def run(*args, stdin=None):
        r = subprocess.run([str(path), *map(str, args)], input=stdin, capture_output=True,
                           text=True, check=False)
        return r
    return run


def tool_json_lines(run, *args, stdin=None):
    r = run(*args, stdin=stdin)
    assert r.returncode == 0, r.stderr
    return [json.loads(line) for line in r.stdout.splitlines() if line.strip()]


@pytest.fixture(scope="session")
def geb079():
    return _need(GEB079, "liboctomap-dev's example map: make deps installs it")


@pytest.fixture(scope="session")
def fr078():
    return _need(FR078, "../shared/data/maps")


@pytest.fixture(scope="session")
def fr079_ot():
    return _need(FR079_OT, "../shared/data/maps")


class _Calls(list):
    undo = None


@pytest.fixture
def batch_calls(monkeypatch):
    """Records n of every occ_map_states_at call the binding makes, and makes the single-point
    lookups (occ_map_state_at, occ_lookup_state) fail: a per-point loop over them shows.
    .undo() gives the library's functions back (for a test's own single-point references)."""
    from occmap._lib import lib
    calls = _Calls()
    calls.undo = monkeypatch.undo
    batch = lib.occ_map_states_at

    def counted(map_ref, pts, n, out):
        calls.append(n)
        return batch(map_ref, pts, n, out)

    def forbidden(*_):
        raise AssertionError("a single-point lookup was called: per-point loop")

    monkeypatch.setattr(lib, "occ_map_states_at", counted)
    for name in ("occ_map_state_at", "occ_lookup_state"):
        monkeypatch.setattr(lib, name, forbidden)
    return calls
