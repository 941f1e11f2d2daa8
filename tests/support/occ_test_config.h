/*
 * occ_test_config.h - the OCC_CONFIG_HEADER of the test build of the core (ASAN_CFLAGS in the
 * Makefile): OCC_ASSERT is live and reports through CMocka's mock_assert(), so a broken internal
 * invariant fails the running test, and expect_assert_failure() can prove an assert fires.
 * src/ never includes cmocka.h: mock_assert's prototype (as in cmocka.h 1.1.5) is declared here.
 * A program that links the test build of the core links libcmocka (outside a CMocka test, a
 * failed mock_assert prints "file:line: error: Failure!" and exits with status 255).
 */
#ifndef OCC_TEST_CONFIG_H_INCLUDED
#define OCC_TEST_CONFIG_H_INCLUDED

void mock_assert(const int result, const char *const expression, const char *const file,
                 const int line);

/* Calls CMocka only when the check fails: a passing assert costs one compare. */
#define OCC_ASSERT(x) ((x) ? (void)0 : mock_assert(0, #x, __FILE__, __LINE__))

#endif /* OCC_TEST_CONFIG_H_INCLUDED */
