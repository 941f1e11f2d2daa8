/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shared_internal.h - the hooks every write path calls for the single-writer / many-reader mode
 * (occ_shared.h), and the atomics port: the only place the library touches atomics.
 */
#ifndef OCC_SHARED_INTERNAL_H_INCLUDED
#define OCC_SHARED_INTERNAL_H_INCLUDED

#include "occmap/occ_shared.h"

/* Atomics: 32-bit loads and stores only (no read-modify-write, so no libatomic and nothing an
 * ARMv6-M core lacks). seq_cst, because the reader's store-then-load of its slot and the
 * published index must not be reordered (store-load ordering needs a full fence). */
#if !defined(OCC_SHARED_SINGLE_CORE)
#if defined(__GNUC__) || defined(__clang__)
#define OCC_SHARED_SINGLE_CORE 0
#else
#define OCC_SHARED_SINGLE_CORE 1
#endif
#endif

static inline uint32_t occi_atomic_load(const uint32_t *const p)
{
#if OCC_SHARED_SINGLE_CORE
    /* One core: an interrupt sees the writer's stores in program order; only the compiler may
     * reorder them, and the barriers stop it. */
    __asm__ __volatile__("" ::: "memory");
    const uint32_t v = *(const volatile uint32_t *)p;
    __asm__ __volatile__("" ::: "memory");
    return v;
#else
    return __atomic_load_n(p, __ATOMIC_SEQ_CST);
#endif
}

static inline void occi_atomic_store(uint32_t *const p, const uint32_t v)
{
#if OCC_SHARED_SINGLE_CORE
    __asm__ __volatile__("" ::: "memory");
    *(volatile uint32_t *)p = v;
    __asm__ __volatile__("" ::: "memory");
#else
    __atomic_store_n(p, v, __ATOMIC_SEQ_CST);
#endif
}

/* A write call changed the writer's content (call after success only): publish it as a version
 * unless a write section is open. The test is all a map that is not shared pays. */
void occi_shared_commit(occ_map_t *m);

static inline void occi_shared_written(occ_map_t *const m)
{
#if OCC_SHARED
    if (m->priv.shared != NULL) {
        occi_shared_commit(m);
    }
#else
    (void)m;
#endif
}

/* The writer wrote `bytes` at `p` (inside a block; pointers outside the arena, the root's
 * fields, are ignored): the snapshots get those 16-byte granules at their next publish. */
void occi_shared_mark(occ_map_t *m, const void *p, size_t bytes);

static inline void occi_shared_touch(occ_map_t *const m, const void *const p, const size_t bytes)
{
#if OCC_SHARED
    if (m->priv.shared != NULL) {
        occi_shared_mark(m, p, bytes);
    }
#else
    (void)m;
    (void)p;
    (void)bytes;
#endif
}

/* The content was rebuilt without marks (a loader built it on an unshared copy): the next
 * publish of each snapshot copies every carved block. Then publishes like occi_shared_written. */
void occi_shared_rebuilt(occ_map_t *m);

/* Replace the writer's map by `src` (a map built on the side: the loaders) without writing the
 * field readers read concurrently (priv.shared); keeps `dst` shared. */
void occi_map_replace(occ_map_t *dst, const occ_map_t *src);

#endif /* OCC_SHARED_INTERNAL_H_INCLUDED */
