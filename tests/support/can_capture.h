/* SPDX-License-Identifier: BSD-3-Clause */
/* can_capture.h - DroneCAN test fixtures shared by test_dronecan.c (the transfer layer and
 * messages) and test_dronecan_node.c (the node): a capturing transmit hook with a settable queue
 * limit, its CMocka setup, and exact float equality. One capture per test binary (static). */
#ifndef OCC_TEST_CAN_CAPTURE_H_INCLUDED
#define OCC_TEST_CAN_CAPTURE_H_INCLUDED

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "occmap/occ_dronecan.h"

/* ---- A capturing transmit hook with a settable queue limit ---------------------------------- */
#define CAP_MAX 512
typedef struct {
    occ_can_frame_t frames[CAP_MAX];
    size_t n;
    size_t limit;         /* frames accepted before "queue full" */
    bool report_space;    /* offer tx_space */
    bool fail_io;
} capture_t;

static inline occ_err_t cap_tx(void *user, const occ_can_frame_t *f)
{
    capture_t *c = user;
    if (c->fail_io) {
        return OCC_ERR_IO;
    }
    if (c->n >= c->limit || c->n >= CAP_MAX) {
        return OCC_ERR_NOMEM;
    }
    c->frames[c->n++] = *f;
    return OCC_OK;
}

static inline uint32_t cap_space(void *user)
{
    const capture_t *c = user;
    return (uint32_t)(c->limit > c->n ? c->limit - c->n : 0u);
}

static capture_t cap;

static inline occ_can_iface_t cap_iface(void)
{
    occ_can_iface_t i = {cap_tx, cap.report_space ? cap_space : NULL, &cap};
    return i;
}

static inline int setup(void **state)
{
    (void)state;
    memset(&cap, 0, sizeof cap);
    cap.limit = CAP_MAX;
    return 0;
}

/* Exact float equality without -Wfloat-equal noise: same bits. */
static inline bool same_float(float a, float b)
{
    uint32_t ua, ub;
    memcpy(&ua, &a, 4);
    memcpy(&ub, &b, 4);
    return ua == ub;
}

#endif
