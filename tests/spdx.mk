# SPDX-License-Identifier: BSD-3-Clause
# Every source and build file of the project carries its licence line (issue 23); `python3
# tests/spdx.py .` adds it to new files. The step first proves the checker on a scratch
# repository holding a file of every kind it knows (--self-test), then checks this tree.
TEST_STEPS += spdx
spdx:
	@python3 tests/spdx.py --self-test
	@python3 tests/spdx.py . --check
.PHONY: spdx
