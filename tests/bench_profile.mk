# SPDX-License-Identifier: BSD-3-Clause
# bench_profile.mk - `make test-bench-profile`: bench/callgrind_phases.py (make bench's
# "where the time goes" rows) on hand-written callgrind_annotate text: the lines it reads, the
# phases adding up to the call with hand-computed values, a missing (inlined) function, rows the
# bench table accepts (tests/bench_profile_check.py). No valgrind run.
test-bench-profile:
	@python3 tests/bench_profile_check.py
TEST_STEPS += test-bench-profile
.PHONY: test-bench-profile
