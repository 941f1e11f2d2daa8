/* SPDX-License-Identifier: BSD-3-Clause */
/* shared_replay.h - the real-data writer and the probe set the shared-map stress test
 * (tests/test_shared_stress.c) and bench (bench/shared.c) share (tests/support/shared_replay.c):
 * the 10 TUM depth frames and OctoMap's scan.dat replayed along a path in a small arena with
 * eviction, and a fixed set of reader queries (voxel states, sphere and capsule checks, ray
 * casts, sectors) whose answers a version's writer records and its readers must reproduce. */
#ifndef OCC_SHARED_REPLAY_H_INCLUDED
#define OCC_SHARED_REPLAY_H_INCLUDED

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "occmap/occmap.h"
#include "occmap/occ_sectors.h"

#define SR_TUM_DIR "../shared/data/depth/tum_fr2_pioneer_slam2"
#define SR_LASER "build/data/scan.dat"

typedef struct {
    occ_vec3_t *rel[16]; /* points relative to the sensor, per source (malloc'd) */
    size_t n[16];
    size_t n_src;
    occ_vec3_t *pts;     /* one placed scan */
    size_t max_n;
    void *scratch;
    size_t scratch_bytes;
    occ_evict_policy_t pol;
    occ_evict_out_t ev;
    occ_insert_params_t ip;
    size_t k;            /* scans written */
    occ_vec3_t origin;   /* of the last scan */
} sr_writer_t;

/* Load the sources (TUM stride `stride`, every `laser_step`-th laser point). False (with a
 * message on stdout) when the data is absent. */
bool sr_writer_init(sr_writer_t *w, unsigned stride, size_t laser_step);
void sr_writer_free(sr_writer_t *w);
/* One scan: source k mod n along a 30 m circle, an eviction slice, the insert with automatic
 * eviction. The insert's error code (OCC_OK normally). */
occ_err_t sr_writer_step(sr_writer_t *w, occ_map_t *map);

/* The probe set: fixed in the map frame around the path. */
#define SR_POINTS 96u
#define SR_SPHERES 12u
#define SR_CAPSULES 12u
#define SR_RAYS 12u
#define SR_SECTORS 2u
typedef struct {
    uint8_t state[SR_POINTS];
    uint8_t sphere[SR_SPHERES];  /* err + 4 * (safe + 2 * outside) */
    uint8_t capsule[SR_CAPSULES];
    uint32_t ray[SR_RAYS][4];    /* err/hit/stop, key x, y, z */
    uint16_t sector[SR_SECTORS][OCC_SECTORS_MAX];
} sr_answers_t;

/* The kinds of queries a reader runs (bit mask) and all of them. */
#define SR_Q_LOOKUP 1u
#define SR_Q_COLLIDE 2u
#define SR_Q_RAYS 4u
#define SR_Q_SECTORS 8u
#define SR_Q_ALL 15u

/* Answer the probes (the kinds in `mask`; the rest zeroed) on `map`. `sec` is work space. */
void sr_answer(const occ_map_t *map, unsigned mask, occ_sectors_t *sec, sr_answers_t *out);
/* Number of probe answers of the kinds in `mask` that differ. */
unsigned sr_diff(const sr_answers_t *a, const sr_answers_t *b, unsigned mask);

#endif
