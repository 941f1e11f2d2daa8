# SPDX-License-Identifier: BSD-3-Clause
# tests/symbols.mk - the export check (issue 17, "Symbols"): libocc.a exports the public API
# (declared under include/occmap/) and, besides it, only occi_ internals; every public declaration
# is defined in the library or, for host-only APIs, in port/. The self-test first proves the check
# fails on a library with an extra occ_ function and on one missing a public definition.
# tests/symbols.py rename is the fix it asks for (see its header).
SYMBOLS_DIR := $(BUILD)/symbols

symbols: $(BUILD)/libocc.a
	@python3 tests/symbols.py selftest $(BUILD)/libocc.a $(SYMBOLS_DIR)
	@python3 tests/symbols.py check $(BUILD)/libocc.a

TEST_STEPS += symbols
.PHONY: symbols
