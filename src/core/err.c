/* SPDX-License-Identifier: BSD-3-Clause */
/* err.c - error code texts. */
#include "occmap/occmap.h"

const char *occ_err_str(const occ_err_t err)
{
    switch (err) {
    case OCC_OK: return "ok";
    case OCC_ERR_ARG: return "invalid argument";
    case OCC_ERR_RANGE: return "outside the map volume";
    case OCC_ERR_NOMEM: return "out of memory (pool or buffer)";
    case OCC_ERR_FORMAT: return "malformed input";
    case OCC_ERR_IO: return "i/o error";
    case OCC_ERR_STATE: return "invalid state";
    case OCC_ERR_UNSUPPORTED: return "unsupported";
    case OCC_ERR_CORRUPT: return "map invariants broken";
    case OCC_ERR_SCRATCH: return "scratch buffer too small";
    case OCC_ERR_TIME: return "no pose for that time, or out of time order";
    default: return "unknown error";
    }
}
