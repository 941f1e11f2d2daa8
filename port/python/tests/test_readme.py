# SPDX-License-Identifier: BSD-3-Clause
"""The README's Python example runs as printed, and prints what its comments say."""
import os
import re
import subprocess
import sys

import occmap
from conftest import ROOT


def _snippet():
    text = (ROOT / "README.md").read_text()
    m = re.search(r"^## Python\n.*?^```python\n(.*?)^```", text, re.S | re.M)
    assert m, "README.md has no ```python block under '## Python'"
    return m.group(1)


def _claimed(line):
    """What a `print(...)  # comment` line promises: the comment up to ':' or its first word."""
    comment = line.split("#", 1)[1].strip()
    value = comment.split(":", 1)[0] if ":" in comment else comment.split()[0]
    return value.replace(" ", "")


def test_readme_example(tmp_path, geb079):
    code = _snippet()
    assert len(code.splitlines()) < 15  # a short, copy-paste example
    claims = [_claimed(ln) for ln in code.splitlines() if ln.startswith("print(") and "#" in ln]
    run = subprocess.run([sys.executable, "-c", code.replace("/tmp/", f"{tmp_path}/")],
                         capture_output=True, text=True, cwd=tmp_path,
                         env={**os.environ, "MPLBACKEND": "Agg"})
    assert run.returncode == 0, run.stderr
    printed = [ln.replace(" ", "") for ln in run.stdout.splitlines()]
    assert len(printed) == len(claims) == 5
    for got, want in zip(printed, claims):
        assert got.startswith(want), (got, want)
    saved = occmap.Map.load(tmp_path / "geb079.occ")
    assert saved.stats()["occupied_voxels"] >= 185673
    assert (tmp_path / "geb079_slice.png").stat().st_size > 1000
