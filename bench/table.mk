# SPDX-License-Identifier: BSD-3-Clause
# table.mk - the one table of `make bench` (issue 22). Every bench writes its rows
# (bench/bench_rows.hpp) to $(BENCH_ROWS_DIR)/<bench>.json; `make bench` empties that folder, runs
# the steps and ends with bench-table.
#   make bench-table    join the rows there into build/bench/table.md and table.json
#                       (bench/table.py: a malformed rows file is an error naming it; an expected
#                       row no bench wrote reads "not measured") and print the table
#   make bench-readme   copy the latest table.json to bench/results/latest.json (committed: the
#                       README's numbers have their source in the repository) and rewrite the
#                       README's Performance section from it; make test-bench-table checks it.
BENCH_ROWS_DIR := $(BUILD)/bench/rows
bench-table:
	@python3 bench/table.py --rows $(BENCH_ROWS_DIR) --out $(BUILD)/bench
bench-readme:
	@[ -f $(BUILD)/bench/table.json ] || \
	  { echo "bench-readme: no $(BUILD)/bench/table.json: run make bench (or bench-table)"; \
	    exit 1; }
	@mkdir -p bench/results && cp $(BUILD)/bench/table.json bench/results/latest.json
	@python3 bench/table.py --readme README.md --results bench/results/latest.json --write
	@echo "bench-readme: commit bench/results/latest.json and README.md together"
.PHONY: bench-table bench-readme
