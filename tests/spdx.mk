# SPDX-License-Identifier: BSD-3-Clause
# Every source file of the project carries its licence line (issue 23); `python3 tests/spdx.py .`
# adds it to new files.
TEST_STEPS += spdx
spdx:
	@python3 tests/spdx.py . --check
.PHONY: spdx
