/* SPDX-License-Identifier: BSD-3-Clause */
/* can_hooks.c - weak defaults of the bare-metal CAN hooks (see occ_bm_can.h). */
#include "occ_bm_can.h"

__attribute__((weak)) occ_err_t occ_bm_can_tx(const occ_can_frame_t *frame)
{
    (void)frame;
    return OCC_ERR_IO;
}

__attribute__((weak)) uint32_t occ_bm_can_tx_space(void)
{
    return 0u;
}

__attribute__((weak)) bool occ_bm_can_rx(occ_can_frame_t *frame)
{
    (void)frame;
    return false;
}

__attribute__((weak)) uint64_t occ_bm_micros(void)
{
    static uint64_t calls;
    return ++calls;
}

static occ_err_t bm_tx(void *user, const occ_can_frame_t *frame)
{
    (void)user;
    return occ_bm_can_tx(frame);
}

static uint32_t bm_space(void *user)
{
    (void)user;
    return occ_bm_can_tx_space();
}

occ_can_iface_t occ_bm_can_iface(void)
{
    occ_can_iface_t i = {bm_tx, bm_space, NULL};
    return i;
}
