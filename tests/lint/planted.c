/* SPDX-License-Identifier: BSD-3-Clause */
/* planted.c - a defect `make lint` must report (tests/lint.mk checks that both cppcheck and
 * gcc -fanalyzer fail on it, so a lint step that silently checks nothing cannot pass). Never
 * built into anything. */
#include <stddef.h>

int occ_lint_planted(int c);

static int g_value = 1;

int occ_lint_planted(const int c)
{
    const int *p = NULL;
    if (c > 0) {
        p = &g_value;
    }
    return *p; /* NULL when c <= 0 */
}
