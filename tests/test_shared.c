/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_shared.c - one writer, many readers (issue 20, occ_shared.h), single-threaded: versions
 * (a view keeps its version's answers after later writes; a new view has the new ones), every
 * write path publishes exactly its end state (the view serializes to the writer's bytes), NOMEM
 * publishes nothing, snapshots are reused only once views close, sections, API errors, and
 * occ_map_check() on every view. The threaded stress is test_shared_stress.c.
 * Built with -DOCC_SHARED=0 (tests/foundation.mk's noshared variant, the library built the same
 * way) it checks instead that the mode is gone as the header promises: occ_map_share() answers
 * OCC_ERR_UNSUPPORTED and changes nothing, the reader and writer-side calls refuse, and the map
 * works as a plain map.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occmap.h"

#define ARENA_BYTES OCC_ARENA_BYTES(2048, 4096)
static uint8_t arena[ARENA_BYTES];
static uint8_t shmem[3u * ARENA_BYTES + 4096u];
static uint8_t buf_a[1u << 18], buf_b[1u << 18];
static occ_map_t map;

static occ_vec3_t v3(float x, float y, float z)
{
    occ_vec3_t v = {x, y, z};
    return v;
}

static int setup(void **state)
{
    (void)state;
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    return 0;
}

/* Snapshot bytes of a map: equal bytes mean equal trees (values, structure, config). */
static size_t serialize(const occ_map_t *m, uint8_t *buf, size_t cap)
{
    occ_io_buf_t b = {buf, cap, 0u};
    assert_int_equal(occ_io_write(m, OCC_FORMAT_SNAPSHOT, occ_io_buf_write, &b, NULL), OCC_OK);
    return b.len;
}

static occ_state_t state_in(const occ_view_t *v, occ_vec3_t p)
{
    return occ_map_state_at(occ_view_map(v), p);
}

#if OCC_SHARED
/* The view answers exactly as the writer's map (serialized trees equal, checks hold). */
static void assert_view_equals(const occ_view_t *view, const occ_map_t *m)
{
    const occ_map_t *const vm = occ_view_map(view);
    assert_int_equal(occ_map_check(vm), OCC_OK);
    const size_t na = serialize(vm, buf_a, sizeof buf_a);
    const size_t nb = serialize(m, buf_b, sizeof buf_b);
    assert_int_equal(na, nb);
    assert_memory_equal(buf_a, buf_b, na);
}

static void share(unsigned n_readers)
{
    const size_t need = occ_shared_bytes(&map, n_readers);
    assert_true(need > 0u && need <= sizeof shmem);
    assert_int_equal(occ_map_share(&map, shmem + 3, need, n_readers), OCC_OK);
}


static void test_errors(void **state)
{
    (void)state;
    assert_int_equal(occ_shared_bytes(NULL, 1u), 0u);
    assert_int_equal(occ_shared_bytes(&map, 0u), 0u);
    assert_int_equal(occ_shared_bytes(&map, OCC_SHARED_MAX_READERS + 1u), 0u);
    const size_t need = occ_shared_bytes(&map, 2u);
    assert_true(need >= OCC_SHARED_SNAPSHOTS * map.arena_bytes);
    assert_true(need <= OCC_SHARED_BYTES(sizeof arena)); /* the static bound holds */
    assert_int_equal(occ_shared_bytes(&map, OCC_SHARED_MAX_READERS), need); /* slots are fixed */
    occ_view_t v;
    assert_int_equal(occ_shared_latest_version(NULL), 0u);
    assert_int_equal(occ_shared_latest_version(&map), 0u); /* not shared */
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_ERR_STATE); /* not shared yet */
    assert_int_equal(occ_map_state_at(occ_view_map(&v), v3(0, 0, 0)), OCC_STATE_UNKNOWN);
    assert_int_equal(occ_map_write_begin(&map), OCC_ERR_STATE);
    assert_int_equal(occ_map_write_end(NULL), OCC_ERR_ARG);
    assert_false(occ_map_publish(&map));
    assert_int_equal(occ_map_share(NULL, shmem, need, 2u), OCC_ERR_ARG);
    assert_int_equal(occ_map_share(&map, NULL, need, 2u), OCC_ERR_ARG);
    assert_int_equal(occ_map_share(&map, shmem, need, 0u), OCC_ERR_ARG);
    assert_int_equal(occ_map_share(&map, shmem, need, 17u), OCC_ERR_ARG);
    assert_int_equal(occ_map_share(&map, shmem, need - 1u, 2u), OCC_ERR_SCRATCH);
    assert_null(map.priv.shared); /* refused: nothing changed */
    assert_int_equal(occ_map_share(&map, shmem, need, 2u), OCC_OK);
    assert_int_equal(occ_map_share(&map, shmem, need, 2u), OCC_ERR_STATE);
    assert_int_equal(occ_read_begin(NULL, 0u, &v), OCC_ERR_ARG);
    assert_int_equal(occ_read_begin(&map, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_read_begin(&map, 2u, &v), OCC_ERR_ARG);
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_OK);
    assert_int_equal(v.version, 0u);
    occ_view_t w;
    assert_int_equal(occ_read_begin(&map, 0u, &w), OCC_ERR_STATE); /* slot already open */
    assert_int_equal(occ_map_write_end(&map), OCC_ERR_STATE);       /* no section open */
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_int_equal(info.open_views, 1u);
    occ_read_end(&map, &v);
    occ_read_end(&map, &v); /* closed already: nothing */
    occ_read_end(NULL, &v);
    assert_null(occ_view_map(NULL));
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_int_equal(info.open_views, 0u);
}

/* A view opened before a write keeps the old answers; one opened after has the new ones. */
static void test_versions(void **state)
{
    (void)state;
    const occ_vec3_t p = v3(1.05f, 0.05f, 0.05f);
    assert_int_equal(occ_map_update(&map, p, -1.0f), OCC_OK); /* FREE before sharing */
    share(2u);
    occ_view_t old;
    assert_int_equal(occ_read_begin(&map, 0u, &old), OCC_OK);
    assert_int_equal(state_in(&old, p), OCC_STATE_FREE);
    assert_int_equal(occ_map_update(&map, p, 3.0f), OCC_OK);
    assert_int_equal(occ_map_state_at(&map, p), OCC_STATE_OCCUPIED);
    assert_int_equal(state_in(&old, p), OCC_STATE_FREE); /* still its version */
    occ_view_t cur;
    assert_int_equal(occ_read_begin(&map, 1u, &cur), OCC_OK);
    assert_int_equal(state_in(&cur, p), OCC_STATE_OCCUPIED);
    assert_int_equal(cur.version, old.version + 1u);
    assert_int_equal(occ_map_version(&map), cur.version);
    assert_view_equals(&cur, &map);
    assert_int_equal(occ_map_check(occ_view_map(&old)), OCC_OK);
    occ_read_end(&map, &old);
    /* A closed view fails closed: UNKNOWN everywhere. */
    assert_int_equal(state_in(&old, p), OCC_STATE_UNKNOWN);
    occ_read_end(&map, &cur);
}

/* With both spare snapshots pinned, a version waits (deferred) and the pinned ones stay intact;
 * once a view closes the next publish goes out. */
static void test_reuse_after_close(void **state)
{
    (void)state;
    const occ_vec3_t p = v3(-0.55f, 0.35f, 0.15f);
    share(2u);
    occ_view_t v0, v1, v2;
    assert_int_equal(occ_read_begin(&map, 0u, &v0), OCC_OK); /* pins version 0 */
    assert_int_equal(occ_map_update(&map, p, 1.0f), OCC_OK);  /* version 1 -> other snapshot */
    assert_int_equal(occ_read_begin(&map, 1u, &v1), OCC_OK);  /* pins version 1 */
    assert_int_equal(v1.version, 1u);
    assert_int_equal(occ_map_update(&map, p, -3.0f), OCC_OK); /* version 2: nowhere to go */
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_int_equal(info.version, 2u);
    assert_int_equal(info.published_version, 1u);
    assert_int_equal(info.deferred, 1u);
    assert_false(occ_map_publish(&map));
    assert_int_equal(state_in(&v0, p), OCC_STATE_UNKNOWN);  /* untouched by the deferral */
    assert_int_equal(state_in(&v1, p), OCC_STATE_OCCUPIED);
    occ_read_end(&map, &v1);
    assert_int_equal(occ_read_begin(&map, 1u, &v1), OCC_OK);
    assert_int_equal(v1.version, 1u); /* still the published one */
    occ_read_end(&map, &v1);
    occ_read_end(&map, &v0); /* frees snapshot 0 */
    assert_true(occ_map_publish(&map));
    assert_true(occ_map_publish(&map)); /* nothing pending: true, no copy */
    assert_int_equal(occ_read_begin(&map, 0u, &v2), OCC_OK);
    assert_int_equal(v2.version, 2u);
    assert_int_equal(state_in(&v2, p), OCC_STATE_FREE);
    assert_view_equals(&v2, &map);
    occ_read_end(&map, &v2);
}

/* The freshness rule: while a view opened before the last publish stays open, every new version
 * is deferred (no bound in number) and new views get the last published one; a reader sees how
 * far behind it is from occ_shared_latest_version(); once that view closes the writer's next
 * call publishes the latest. */
static void test_freshness(void **state)
{
    (void)state;
    share(2u);
    occ_view_t old, cur;
    assert_int_equal(occ_read_begin(&map, 0u, &old), OCC_OK); /* version 0, kept open */
    assert_int_equal(occ_map_update(&map, v3(0.05f, 0.05f, 0.05f), 1.0f), OCC_OK); /* 1: out */
    assert_int_equal(occ_shared_latest_version(&map), 1u);
    for (unsigned i = 0; i < 40u; i++) { /* versions 2..41: the spare snapshot is pinned */
        assert_int_equal(occ_map_update(&map, v3(0.05f + 0.1f * (float)i, 1.0f, 0.0f), 1.0f),
                         OCC_OK);
        assert_int_equal(occ_read_begin(&map, 1u, &cur), OCC_OK);
        assert_int_equal(cur.version, 1u);
        assert_int_equal(occ_shared_latest_version(&map) - cur.version, i + 1u); /* its age */
        occ_read_end(&map, &cur);
    }
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_int_equal(info.version, 41u);
    assert_int_equal(info.published_version, 1u);
    assert_int_equal(info.deferred, 40u);
    assert_int_equal(occ_shared_latest_version(&map) - old.version, 41u);
    occ_read_end(&map, &old);
    /* The first write call after the pinning view closed publishes (its own version). */
    assert_int_equal(occ_map_update(&map, v3(-1.0f, -1.0f, 0.5f), -1.0f), OCC_OK);
    assert_int_equal(occ_read_begin(&map, 1u, &cur), OCC_OK);
    assert_int_equal(cur.version, 42u);
    assert_int_equal(occ_shared_latest_version(&map), cur.version);
    assert_view_equals(&cur, &map);
    occ_read_end(&map, &cur);
    /* Inside a section the latest completed version does not move until its end. */
    assert_int_equal(occ_map_write_begin(&map), OCC_OK);
    assert_int_equal(occ_map_update(&map, v3(2.0f, 2.0f, 0.5f), 1.0f), OCC_OK);
    assert_int_equal(occ_shared_latest_version(&map), 42u);
    assert_int_equal(occ_map_version(&map), 43u); /* what the section will publish as */
    assert_int_equal(occ_map_write_end(&map), OCC_OK);
    assert_int_equal(occ_shared_latest_version(&map), 43u);
}

/* A refused write publishes nothing: views and the published version stay as they were. */
static void test_nomem(void **state)
{
    (void)state;
    static uint8_t small[OCC_ARENA_BYTES(16, 4)];
    static uint8_t smem[3u * sizeof small + 4096u];
    const occ_map_config_t cfg = occ_map_config_default();
    occ_map_t m;
    assert_int_equal(occ_map_init(&m, &cfg, small, sizeof small), OCC_OK);
    assert_int_equal(occ_map_share(&m, smem, occ_shared_bytes(&m, 1u), 1u), OCC_OK);
    assert_int_equal(occ_map_update(&m, v3(0.05f, 0.05f, 0.05f), 1.0f), OCC_OK);
    const uint32_t before = occ_map_version(&m);
    occ_err_t e = OCC_OK;
    float x = 1.0f;
    for (int i = 0; i < 64 && e == OCC_OK; i++, x += 3.0f) {
        e = occ_map_update(&m, v3(x, -x, 0.5f * x), 1.0f);
    }
    assert_int_equal(e, OCC_ERR_NOMEM);
    const uint32_t ok_versions = occ_map_version(&m);
    assert_true(ok_versions >= before);
    occ_view_t v;
    assert_int_equal(occ_read_begin(&m, 0u, &v), OCC_OK);
    assert_int_equal(v.version, ok_versions); /* the refused call made no version */
    assert_int_equal(occ_map_state_at(occ_view_map(&v), v3(x - 3.0f, 3.0f - x, 0.5f * (x - 3.0f))),
                     OCC_STATE_UNKNOWN);
    assert_view_equals(&v, &m);
    occ_read_end(&m, &v);
    /* A file too big for the small arena: occ_io_read refuses and publishes nothing. */
    for (float y = -2.0f; y < 2.0f; y += 0.7f) {
        assert_int_equal(occ_map_update(&map, v3(3.0f, y, -y), 1.0f), OCC_OK);
    }
    const size_t n = serialize(&map, buf_b, sizeof buf_b);
    occ_shared_info_t info, after;
    assert_int_equal(occ_shared_info(&m, &info), OCC_OK);
    assert_int_equal(occ_io_read(&m, buf_b, n, NULL), OCC_ERR_NOMEM);
    assert_int_equal(occ_shared_info(&m, &after), OCC_OK);
    assert_int_equal(after.publishes, info.publishes);
    assert_int_equal(after.version, info.version);
    assert_int_equal(occ_read_begin(&m, 0u, &v), OCC_OK);
    assert_view_equals(&v, &m);
    occ_read_end(&m, &v);
}

/* A section is one version: a view in the middle sees none of it. */
static void test_section(void **state)
{
    (void)state;
    const occ_vec3_t a = v3(0.25f, 0.25f, 0.25f), b = v3(-3.0f, 2.0f, 1.0f);
    share(1u);
    assert_int_equal(occ_map_write_begin(&map), OCC_OK);
    assert_int_equal(occ_map_write_begin(&map), OCC_OK); /* nests */
    assert_int_equal(occ_map_update(&map, a, 2.0f), OCC_OK);
    assert_int_equal(occ_map_write_end(&map), OCC_OK);
    assert_int_equal(occ_map_update(&map, b, 2.0f), OCC_OK);
    assert_false(occ_map_publish(&map)); /* a section is open */
    occ_view_t v;
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_OK);
    assert_int_equal(v.version, 0u);
    assert_int_equal(state_in(&v, a), OCC_STATE_UNKNOWN);
    occ_read_end(&map, &v);
    assert_int_equal(occ_map_version(&map), 1u); /* what the section will publish as */
    assert_int_equal(occ_map_write_end(&map), OCC_OK);
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_OK);
    assert_int_equal(v.version, 1u);
    assert_int_equal(state_in(&v, a), OCC_STATE_OCCUPIED);
    assert_int_equal(state_in(&v, b), OCC_STATE_OCCUPIED);
    occ_read_end(&map, &v);
    /* A section that changed nothing (a refused write) publishes nothing. */
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_int_equal(occ_map_write_begin(&map), OCC_OK);
    assert_int_equal(occ_map_update(&map, b, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_map_write_end(&map), OCC_OK);
    occ_shared_info_t after;
    assert_int_equal(occ_shared_info(&map, &after), OCC_OK);
    assert_int_equal(after.version, 1u);
    assert_int_equal(after.publishes, info.publishes);
}

static void view_matches_after(void (*write)(void))
{
    occ_view_t v;
    write();
    assert_int_equal(occ_map_check(&map), OCC_OK);
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_OK);
    assert_int_equal(v.version, occ_map_version(&map));
    assert_view_equals(&v, &map);
    occ_read_end(&map, &v);
}

static uint8_t scratch[1u << 22];
static occ_vec3_t cloud[2000];

static void w_insert(void)
{
    for (unsigned i = 0; i < 2000u; i++) {
        const float t = (float)i * 0.0031f;
        cloud[i] = v3(4.0f + (float)(i % 40u) * 0.05f, -2.0f + t, 0.3f + (float)(i % 7u) * 0.1f);
    }
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_FAST_DISCRETE; /* coarse pass + voxel batch: one version */
    ip.fast_d = 2u;
    ip.fast_n = 1u;
    const occ_vec3_t o = v3(0.0f, 0.0f, 0.5f);
    const uint32_t before = occ_map_version(&map);
    assert_int_equal(occ_map_insert_cloud(&map, &o, cloud, 2000u, &ip, scratch, sizeof scratch,
                                          NULL), OCC_OK);
    assert_int_equal(occ_map_version(&map), before + 1u);
}

static void w_set(void)
{
    occ_key_t k;
    assert_int_equal(occ_map_key(&map, v3(1.0f, 1.0f, 1.0f), &k), OCC_OK);
    assert_int_equal(occ_map_set_key(&map, k, 3u, -1.5f), OCC_OK);
}

static void w_forget(void)
{
    occ_key_t k;
    assert_int_equal(occ_map_key(&map, v3(4.5f, -1.0f, 0.5f), &k), OCC_OK);
    assert_int_equal(occ_map_forget_key(&map, k, 4u), OCC_OK);
}

static void w_evict(void)
{
    occ_evict_policy_t pol = occ_evict_policy_default();
    pol.keep_radius_m = 2.0f;
    occ_evict_out_t out;
    occ_evict_out_init(&out);
    const occ_vec3_t c = v3(0.0f, 0.0f, 0.0f);
    /* A target no arena meets: evict everything outside the kept ball. */
    assert_int_equal(occ_map_evict(&map, &c, &pol, 1u << 30, &out), OCC_OK);
    assert_true(out.evictions > 0u);
}

static void w_io_read(void)
{
    occ_map_t copy = map;
    const size_t n = serialize(&copy, buf_b, sizeof buf_b);
    static uint8_t file[sizeof buf_b];
    memcpy(file, buf_b, n);
    assert_int_equal(occ_map_update(&map, v3(-6.0f, -6.0f, 0.0f), 2.0f), OCC_OK);
    const uint32_t before = occ_map_version(&map);
    assert_int_equal(occ_io_read(&map, file, n, NULL), OCC_OK);
    assert_int_equal(occ_map_version(&map), before + 1u); /* clear + build: one version */
    assert_int_equal(occ_map_state_at(&map, v3(-6.0f, -6.0f, 0.0f)), OCC_STATE_UNKNOWN);
}

static void w_clear(void)
{
    occ_map_clear(&map);
}

/* Every write path publishes its end state (the view's tree is the writer's, byte for byte). */
static void test_write_paths(void **state)
{
    (void)state;
    share(1u);
    view_matches_after(w_insert);
    view_matches_after(w_set);
    view_matches_after(w_forget);
    view_matches_after(w_io_read);
    view_matches_after(w_evict);
    view_matches_after(w_clear);
}

/* Publishes copy only what was written since a snapshot was last refreshed: after each of many
 * mixed writes (voxel updates, whole-node sets and forgets, evictions, a clear) a fresh view is
 * the writer's tree byte for byte, and an old view kept open across a deferral still checks. */
static void test_incremental(void **state)
{
    (void)state;
    share(2u);
    uint32_t seed = 7u;
    for (unsigned i = 0; i < 300u; i++) {
        seed = seed * 1103515245u + 12345u;
        const float x = (float)((seed >> 8) % 200u) * 0.05f - 5.0f;
        const float y = (float)((seed >> 16) % 100u) * 0.05f - 2.5f;
        occ_key_t k;
        assert_int_equal(occ_map_key(&map, v3(x, y, 0.3f), &k), OCC_OK);
        const unsigned op = (seed >> 28) % 8u;
        if (op < 5u) {
            assert_int_equal(occ_map_update_key(&map, k, op < 3u ? 0.9f : -0.4f), OCC_OK);
        } else if (op == 5u) {
            assert_int_equal(occ_map_set_key(&map, k, 2u, -1.0f), OCC_OK);
        } else if (op == 6u) {
            assert_int_equal(occ_map_forget_key(&map, k, 3u), OCC_OK);
        } else if (i % 50u == 48u) {
            occ_map_clear(&map);
        } else {
            occ_evict_policy_t pol = occ_evict_policy_default();
            pol.keep_radius_m = 2.0f;
            occ_evict_out_t out;
            occ_evict_out_init(&out);
            const occ_vec3_t c = v3(x, y, 0.0f);
            assert_int_equal(occ_map_evict(&map, &c, &pol, 1u << 30, &out), OCC_OK);
        }
        occ_view_t v;
        assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_OK);
        assert_int_equal(v.version, occ_map_version(&map));
        assert_view_equals(&v, &map);
        occ_read_end(&map, &v);
    }
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_OK);
    assert_true(info.copied_bytes_last < (size_t)map.leaf.hwm * OCC_LEAF_BLOCK_BYTES +
                                             (size_t)map.inner.hwm * OCC_INNER_BLOCK_BYTES);
}

#else /* OCC_SHARED == 0 */

/* Built without the mode: share refuses with OCC_ERR_UNSUPPORTED and leaves the map as it was;
 * every other call of occ_shared.h answers as on a map that is not shared; writes work. */
static void test_unsupported(void **state)
{
    (void)state;
    const occ_vec3_t p = v3(0.35f, -0.45f, 0.15f);
    assert_int_equal(occ_map_update(&map, p, 2.0f), OCC_OK);
    const size_t n = serialize(&map, buf_a, sizeof buf_a);
    const size_t need = occ_shared_bytes(&map, 2u);
    assert_true(need > 0u && need <= sizeof shmem); /* the size formula stays */
    assert_int_equal(occ_map_share(&map, shmem, need, 2u), OCC_ERR_UNSUPPORTED);
    assert_int_equal(occ_map_share(&map, shmem, sizeof shmem, 1u), OCC_ERR_UNSUPPORTED);
    assert_null(map.priv.shared);
    assert_int_equal(serialize(&map, buf_b, sizeof buf_b), n);
    assert_memory_equal(buf_a, buf_b, n);
    occ_view_t v;
    assert_int_equal(occ_read_begin(&map, 0u, &v), OCC_ERR_STATE);
    assert_int_equal(state_in(&v, p), OCC_STATE_UNKNOWN); /* a refused view fails closed */
    occ_read_end(&map, &v);
    assert_int_equal(occ_map_write_begin(&map), OCC_ERR_STATE);
    assert_int_equal(occ_map_write_end(&map), OCC_ERR_STATE);
    assert_false(occ_map_publish(&map));
    assert_int_equal(occ_map_version(&map), 0u);
    assert_int_equal(occ_shared_latest_version(&map), 0u);
    occ_shared_info_t info;
    assert_int_equal(occ_shared_info(&map, &info), OCC_ERR_STATE);
    assert_int_equal(occ_map_update(&map, p, -4.0f), OCC_OK);
    assert_int_equal(occ_map_state_at(&map, p), OCC_STATE_FREE);
    occ_map_clear(&map);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
#if !OCC_SHARED
        cmocka_unit_test_setup(test_unsupported, setup),
#else
        cmocka_unit_test_setup(test_errors, setup),
        cmocka_unit_test_setup(test_versions, setup),
        cmocka_unit_test_setup(test_reuse_after_close, setup),
        cmocka_unit_test_setup(test_freshness, setup),
        cmocka_unit_test_setup(test_nomem, setup),
        cmocka_unit_test_setup(test_section, setup),
        cmocka_unit_test_setup(test_write_paths, setup),
        cmocka_unit_test_setup(test_incremental, setup),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
