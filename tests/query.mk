# SPDX-License-Identifier: BSD-3-Clause
# tests/query.mk - the query tests (issue 5): test_query, test_collide, test_castray and
# test_lookup_index (the lookup index, issue 22: every probe on geb079 / fr_079 at every level
# equals occ_map_state_at) are picked up by the top Makefile as tests/test_*.c. Their brute-force oracle (tests/support/oracle_query.cpp)
# runs millions of cell tests: it is in ORACLE_SRC (top Makefile), built with ORACLE_FLAGS.

# The command line: JSON shape, batch == single queries, the unknown policy, error exits.
QUERY_CLI_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
TEST_STEPS += test-query-cli
test-query-cli: $(BUILD)/occmap
	$(PY) tests/query_cli_check.py $(BUILD)/occmap $(QUERY_CLI_MAP)
.PHONY: test-query-cli
