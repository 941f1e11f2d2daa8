# SPDX-License-Identifier: BSD-3-Clause
"""A plain (non-editable) install bundles the C library: build_py copies $OCCMAP_LIB or the
repository's build/libocc.so (make build/libocc.so) into the package, where occmap/_lib.py looks
first. An editable install and a run from the tree find build/libocc.so by walking up."""
import os
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


class BuildPyWithLib(build_py):
    def run(self):
        super().run()
        if self.editable_mode:
            return
        src = Path(os.environ.get("OCCMAP_LIB") or HERE.parent.parent / "build" / "libocc.so")
        if not src.exists():
            raise SystemExit(f"occmap: {src} not found: run `make build/libocc.so` first "
                             "(or set OCCMAP_LIB to a built libocc.so)")
        dst = Path(self.build_lib) / "occmap" / "libocc.so"
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst)


setup(cmdclass={"build_py": BuildPyWithLib})
