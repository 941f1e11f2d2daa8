/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_assert_abort.h - OCC_ASSERT's hook for a program that links a test build of the core (live
 * asserts: tests/support/occ_test_config.h) but is not a CMocka test: the soak, the fuzz
 * harnesses. Include it in exactly one file of the program: it defines mock_assert(), which
 * then takes the place of libcmocka's (that one ends a program outside a CMocka test with exit
 * status 255 and no message). A failed invariant prints where and what, then aborts: the
 * sanitizers and libFuzzer report the abort with its stack and keep the input.
 * (A header, not a .c file in tests/support: those are linked into every CMocka test, where
 * libcmocka's mock_assert must stay for expect_assert_failure.)
 */
#ifndef OCC_ASSERT_ABORT_H_INCLUDED
#define OCC_ASSERT_ABORT_H_INCLUDED

#include <stdio.h>
#include <stdlib.h>

void mock_assert(const int result, const char *const expression, const char *const file,
                 const int line);

void mock_assert(const int result, const char *const expression, const char *const file,
                 const int line)
{
    if (!result) {
        fprintf(stderr, "%s:%d: OCC_ASSERT(%s) failed\n", file, line, expression);
        abort();
    }
}

#endif /* OCC_ASSERT_ABORT_H_INCLUDED */
