# SPDX-License-Identifier: BSD-3-Clause
# layout.mk - the dependency checks (issue 17).
# deps-check: every #include of src/<module>/*.c|h resolved and tested against the one allowed
# direction geom <- core <- {integrate, query, io, evict} <- front ends (public headers only);
# nothing in src includes port/ or tools/. It prints the module graph it found and proves itself
# on planted wrong-way includes in a scratch copy of the tree.
# deps-calls: the same direction for the calls the compiled objects of libocc.a make (nm), so a
# hand-written prototype cannot go around the include check; proves itself on planted calls.
deps-check:
	@python3 tests/deps_check.py .
deps-calls: $(BUILD)/libocc.a
	@python3 tests/deps_calls.py $(BUILD)/rel
TEST_STEPS += deps-check deps-calls
.PHONY: deps-check deps-calls

# Firmware sees only portable headers (issue 17, Headers). The cross build's include path FW_INC
# (top Makefile) holds include/occmap/*.h without host/. This step proves, with the Cortex-M4
# compiler and the firmware flags:
#  - each portable header compiles alone with nothing but the compiler's freestanding headers
#    (-nostdinc: no <stdio.h>, no sockets, no files, no libccd can be reached);
#  - a source that includes a host header does not compile on FW_INC (planted below), and does
#    on the host path, so the failure is the missing host/ and nothing else.
FW_FREESTANDING = -nostdinc -isystem $(shell $(CROSS_CC) -print-file-name=include 2>/dev/null)
FW_PLANTED := '\#include "occmap/host/occ_file.h"'
fw-headers: $(DEPS_STAMP) $(FW_HEADERS)
	@set -e; n=0; for h in $(notdir $(FW_HEADERS)); do \
	  printf '#include "occmap/%s"\n' $$h | $(CROSS_CC) $(WARN) -ffreestanding $(FW_FREESTANDING) \
	    $(FW_INC) $(CROSS_M4) -x c -fsyntax-only - \
	    || { echo "FAIL fw-headers: occmap/$$h needs more than the freestanding headers"; exit 1; }; \
	  n=$$((n + 1)); done; \
	echo "fw-headers: $$n portable headers compile alone, freestanding, on FW_INC"
	@printf '%s\n' $(FW_PLANTED) | $(CROSS_CC) $(WARN) -ffreestanding $(INC) $(CROSS_M4) \
	  -x c -fsyntax-only - >/dev/null 2>&1 \
	  || { echo "FAIL fw-headers: the planted host include does not compile even on the host path"; exit 1; }
	@if printf '%s\n' $(FW_PLANTED) | $(CROSS_CC) $(CROSS_COMMON) $(CROSS_M4) -x c -fsyntax-only - \
	    >/dev/null 2>&1; then echo "FAIL fw-headers: a host header is reachable from FW_INC"; exit 1; fi
	@echo "fw-headers: planted #include of occmap/host/occ_file.h refused on FW_INC"
	@echo "PASS fw-headers"
TEST_STEPS += fw-headers
.PHONY: fw-headers
