// SPDX-License-Identifier: BSD-3-Clause
// oracle_res.hpp - the resolution an OctoMap oracle is built with: the decimal a user writes.
// A C test holds the resolution as the float cfg.resolution_m (0.1f); the user who wrote 0.1f
// writes OcTree(0.1), not OcTree((double)0.1f). This is the shortest "%.*g" text that reads
// back as that float, found by printing (an implementation apart from the library's geom.c).
#ifndef OCC_ORACLE_RES_HPP_INCLUDED
#define OCC_ORACLE_RES_HPP_INCLUDED

#include <cstdio>
#include <cstdlib>

static inline double oracle_user_resolution(double res)
{
    const float f = static_cast<float>(res);
    char text[40];
    for (int digits = 1; digits <= 9; digits++) {
        std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(f));
        const double d = std::strtod(text, nullptr);
        if (static_cast<float>(d) == f) {
            return d;
        }
    }
    return static_cast<double>(f);
}

#endif
