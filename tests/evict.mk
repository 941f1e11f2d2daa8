# SPDX-License-Identifier: BSD-3-Clause
# evict.mk - bounded memory in flight (issue 9): the eviction tests are tests/test_evict.c
# (auto-discovered); the soak run lives in tests/soak.mk.
