# SPDX-License-Identifier: BSD-3-Clause
# lint.mk - `make lint`: cppcheck and gcc -fanalyzer over src/ (issue 17), a step of `make test`.
# Clean means no report at all: a real finding is fixed; a false positive is silenced only at its
# site, with the reason beside it (cppcheck: a `cppcheck-suppress id ; why` comment; -fanalyzer:
# OCC_ANALYZER_UNINIT_OFF/ON from src/core/tree_internal.h). Before trusting a clean run the step
# makes sure both tools do report the defect planted in tests/lint/planted.c.
APT_PKGS += cppcheck

LINT_SRC := $(OCC_CORE_SRC) $(OCC_FEED_SRC) $(OCC_CCD_SRC)
LINT_DIR := $(BUILD)/lint
# cppcheck: the host (double rays) and the firmware (float rays) configurations.
CPPCHECK := cppcheck --enable=warning,portability,performance --std=c99 --inline-suppr \
            --error-exitcode=1 --quiet $(INC)
CPPCHECK_CONFIGS := -DOCC_RAY_DOUBLE=1 -DOCC_RAY_DOUBLE=0
ANALYZER_CFLAGS := $(WARN) -O2 -fanalyzer $(INC)

# One stamp per source, so a re-run analyses only what changed (headers via the .d files).
# EXTRA_CFLAGS (MAVLINK_FLAGS for src/mavlink/mavlink.c) and `mavgen` (tests/mavlink.mk): the
# generated MAVLink headers src/mavlink includes.
$(LINT_DIR)/%.analyzer.ok: %.c | mavgen
	@mkdir -p $(dir $@)
	$(CC) $(ANALYZER_CFLAGS) $(EXTRA_CFLAGS) -MMD -MP -MT $@ -MF $@.d -c $< -o /dev/null
	@touch $@

lint-planted:
	@for d in $(firstword $(CPPCHECK_CONFIGS)); do \
	  if $(CPPCHECK) $$d tests/lint/planted.c >/dev/null 2>&1; then \
	    echo "FAIL lint: cppcheck does not report tests/lint/planted.c"; exit 1; fi; done
	@if $(CC) $(ANALYZER_CFLAGS) -c tests/lint/planted.c -o /dev/null >/dev/null 2>&1; then \
	  echo "FAIL lint: gcc -fanalyzer does not report tests/lint/planted.c"; exit 1; fi
	@echo "lint: both tools report the planted defect"

lint-cppcheck: lint-planted
	@for d in $(CPPCHECK_CONFIGS); do \
	  echo "cppcheck $$d src/"; $(CPPCHECK) $$d src/ || exit 1; done

lint-analyzer: lint-planted $(LINT_SRC:%.c=$(LINT_DIR)/%.analyzer.ok)

lint: lint-cppcheck lint-analyzer
	@echo "PASS lint: cppcheck and gcc -fanalyzer clean on $(words $(LINT_SRC)) files of src/"

TEST_STEPS += lint
.PHONY: lint lint-planted lint-cppcheck lint-analyzer
