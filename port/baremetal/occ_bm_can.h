/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_bm_can.h - bare-metal hooks for the CAN front end (port/baremetal/can_hooks.c).
 * Every hook is a weak function: a board file defines the real one with the same name and the
 * linker takes it. The defaults do nothing useful (no driver): tx refuses with OCC_ERR_IO, rx
 * never has a frame, the clock is a call counter. All are called from the main loop only (not
 * from interrupts); a driver that fills its RX FIFO in an ISR must hand frames over safely.
 */
#ifndef OCC_BM_CAN_H_INCLUDED
#define OCC_BM_CAN_H_INCLUDED

#include "occmap/occ_dronecan.h"

/* Queue one frame in the CAN peripheral (mailbox or software FIFO). Never blocks: OCC_OK,
 * OCC_ERR_NOMEM when full, OCC_ERR_IO without a driver. */
occ_err_t occ_bm_can_tx(const occ_can_frame_t *frame);
/* Free transmit slots now (the node sends a multi-frame transfer only when all of it fits). */
uint32_t occ_bm_can_tx_space(void);
/* Take one received frame; false when none. */
bool occ_bm_can_rx(occ_can_frame_t *frame);
/* Monotonic microseconds (a timer). */
uint64_t occ_bm_micros(void);
/* The node's transmit interface on top of occ_bm_can_tx / occ_bm_can_tx_space. */
occ_can_iface_t occ_bm_can_iface(void);

#endif
