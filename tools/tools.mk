# SPDX-License-Identifier: BSD-3-Clause
# The command-line tool's data and the first demo step.
# $(BUILD)/data/scan.dat (OctoMap's real scan, decompressed) is made by tests/integrate.mk.
SCAN_DAT := $(BUILD)/data/scan.dat

# (the demo is the MAVLink feed now; `make demo-stats` still runs the first version)
demo-stats: $(BUILD)/occmap $(SCAN_DAT)
	@echo "== occmap stats on OctoMap's real laser scan (88,206 points), endpoints only"
	$(BUILD)/occmap stats --scan $(SCAN_DAT) --res 0.1

# The tool's statistics against values worked out independently (tests/cli_stats_check.py).
TEST_STEPS += test-cli-stats
test-cli-stats: $(BUILD)/occmap $(SCAN_DAT)
	$(PY) tests/cli_stats_check.py $(BUILD)/occmap $(SCAN_DAT)
.PHONY: demo-stats test-cli-stats

# The README's embedding example compiles and does what it says.
TEST_STEPS += test-readme-example
test-readme-example: $(BUILD)/libocc.a
	bash tests/readme_example.sh $(BUILD)
.PHONY: test-readme-example
