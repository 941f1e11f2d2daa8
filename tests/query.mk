# tests/query.mk - the query tests (issue 5): test_query, test_collide, test_castray are picked up
# by the top Makefile as tests/test_*.c. The brute-force oracle is plain Eigen/OctoMap code that
# runs millions of cell tests: it is built optimized (-O2 placed after the rule's -O1) and without
# sanitizers, while the core and the test drivers keep ASan+UBSan, so the tests take seconds.
$(BUILD)/asanhost/tests/support/oracle_query.o: SAN :=
$(BUILD)/asanhost/tests/support/oracle_query.o: INC += -O2

# The command line: JSON shape, batch == single queries, the unknown policy, error exits.
QUERY_CLI_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
TEST_STEPS += test-query-cli
test-query-cli: $(BUILD)/occmap
	$(PY) tests/query_cli_check.py $(BUILD)/occmap $(QUERY_CLI_MAP)
.PHONY: test-query-cli
