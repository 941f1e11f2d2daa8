# SPDX-License-Identifier: BSD-3-Clause
# tests/python.mk - the Python package's pytest suite (port/python/tests): the binding against
# the C tool's answers on the real maps, the struct layouts against the headers, errors,
# round trips. One PASS / FAIL line per test; tests of ../shared maps print SKIP when it is
# absent (the step then counts as skipped).
TEST_STEPS += test-python
TEST_BUILD_EXTRA += $(BUILD)/libocc.so
PY_TEST_ENV := MPLBACKEND=Agg MPLCONFIGDIR=$(abspath $(BUILD))/mpl PYTHONDONTWRITEBYTECODE=1 \
               OCCMAP_LIB=$(abspath $(BUILD))/libocc.so OCCMAP_TOOL=$(abspath $(BUILD))/occmap
test-python: $(PY_PKG_STAMP) $(BUILD)/occmap
	@set -o pipefail; cd port/python && $(PY_TEST_ENV) $(abspath $(PY)) -m pytest -q -rA \
	  -p no:cacheprovider tests | sed -u -e 's/^PASSED /PASS /' -e 's/^FAILED /FAIL /' \
	  -e 's/^ERROR /FAIL /' -e 's/^SKIPPED \[[0-9]*\] /SKIP: /'
.PHONY: test-python
