/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_test_config.h - the OCC_CONFIG_HEADER of the test build of the core (ASAN_CFLAGS in the
 * Makefile): OCC_ASSERT is live and reports through CMocka's mock_assert(), so a broken internal
 * invariant fails the running test, and expect_assert_failure() can prove an assert fires.
 * src/ never includes cmocka.h: mock_assert's prototype (as in cmocka.h 1.1.5) is declared here.
 * A CMocka test gets mock_assert from libcmocka; any other program linking a test build of the
 * core (the soak, the fuzz harnesses) includes tests/support/occ_assert_abort.h in one file,
 * which defines a mock_assert that prints and aborts (libcmocka's would exit 255 silently).
 */
#ifndef OCC_TEST_CONFIG_H_INCLUDED
#define OCC_TEST_CONFIG_H_INCLUDED

void mock_assert(const int result, const char *const expression, const char *const file,
                 const int line);

/* Calls CMocka only when the check fails: a passing assert costs one compare. */
#define OCC_ASSERT(x) ((x) ? (void)0 : mock_assert(0, #x, __FILE__, __LINE__))

#endif /* OCC_TEST_CONFIG_H_INCLUDED */
