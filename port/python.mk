# SPDX-License-Identifier: BSD-3-Clause
# port/python.mk - the Python package (port/python/: ctypes over build/libocc.so, no C of its
# own), installed editable into the project venv: `make python`. A plain `pip install
# port/python` (any venv) copies build/libocc.so into the package (port/python/setup.py).
PIP_PKGS += numpy==2.2.6 matplotlib==3.10.3 pytest==8.4.1
PY_PKG_STAMP := $(BUILD)/.py-occmap
# pip builds the editable wheel in an isolated environment (setuptools from the registry).
$(PY_PKG_STAMP): $(BUILD)/.deps-ok $(BUILD)/libocc.so port/python/pyproject.toml port/python/setup.py
	$(PY) -m pip install -q --no-deps -e port/python
	@touch $@
python: $(PY_PKG_STAMP)
.PHONY: python
