# SPDX-License-Identifier: BSD-3-Clause
# bench_table.mk - `make test-bench-table` (issue 22): bench/table.py on synthetic rows (good
# rows, a missing row, malformed files, tests/bench_table_check.py) and the README's Performance
# section against what bench/table.py renders from the committed bench/results/latest.json (no
# numbers typed by hand); proves the check fails on a README with one digit changed.
test-bench-table:
	@python3 tests/bench_table_check.py $(BUILD)/test-bench-table
TEST_STEPS += test-bench-table
.PHONY: test-bench-table
