/* test_sectors.c - occ_sectors_compute() against a brute-force reference: every voxel column
 * in the search box, each footprint clipped against each sector's wedge (polygon clipping in
 * double), on random maps and poses; plus hand-computed cases (behind = +-180 degrees, yaw wrap,
 * the vehicle in unknown space, the edges of the map volume) and argument checks. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_sectors.h"
#include "support/leak_check.h"

#define ARENA_BYTES (8u << 20)
static uint8_t arena[ARENA_BYTES];
static occ_map_t map;
static occ_sectors_t sect; /* large: static */
static unsigned seed;

/* The vehicle level at (x, y, z) with heading yaw (map frame): the pose the sectors take. */
static occ_pose_t at_yaw(float x, float y, float z, float yaw)
{
    occ_pose_t p;
    p.p.x = x;
    p.p.y = y;
    p.p.z = z;
    p.q = occ_quat_from_euler(0.0f, 0.0f, yaw);
    return p;
}

static void set_yaw(occ_pose_t *p, float yaw)
{
    p->q = occ_quat_from_euler(0.0f, 0.0f, yaw);
}

/* The heading of the body x axis, in double for the reference (ZYX yaw). */
static double yaw_of(const occ_pose_t *p)
{
    const double w = p->q.w, x = p->q.x, y = p->q.y, z = p->q.z;
    return atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

static int setup(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return leak_check(&map);
}

static void reinit(float res, unsigned depth)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.depth_levels = (uint8_t)depth;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
}

static double urand(void)
{
    return (double)rand() / ((double)RAND_MAX + 1.0);
}

/* ---- the reference ------------------------------------------------------------------------- */

typedef struct { double x, y; } pt_t;

/* Keep the part of polygon `in` (n points) where cross(d, p) * sign >= 0. */
static int clip(const pt_t *in, int n, double dx, double dy, double sign, pt_t *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const pt_t a = in[i];
        const pt_t b = in[(i + 1) % n];
        const double fa = sign * (dx * a.y - dy * a.x);
        const double fb = sign * (dx * b.y - dy * b.x);
        if (fa >= 0.0) {
            out[m++] = a;
        }
        if ((fa >= 0.0) != (fb >= 0.0)) {
            const double t = fa / (fa - fb);
            out[m].x = a.x + t * (b.x - a.x);
            out[m].y = a.y + t * (b.y - a.y);
            m++;
        }
    }
    return m;
}

static double seg_dist(pt_t a, pt_t b)
{
    const double vx = b.x - a.x, vy = b.y - a.y;
    const double l2 = vx * vx + vy * vy;
    double t = l2 > 0.0 ? -(a.x * vx + a.y * vy) / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double px = a.x + t * vx, py = a.y + t * vy;
    return sqrt(px * px + py * py);
}

/* Distance from the origin to square [x0,x1]x[y0,y1] clipped to the wedge between map angles
 * lo and lo + inc (inc <= 90 deg); < 0 when the intersection is empty. */
static double wedge_dist(double x0, double y0, double x1, double y1, double lo, double inc)
{
    pt_t p0[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    pt_t p1[12], p2[16];
    int n = clip(p0, 4, cos(lo), sin(lo), 1.0, p1);
    if (n == 0) {
        return -1.0;
    }
    n = clip(p1, n, cos(lo + inc), sin(lo + inc), -1.0, p2);
    if (n == 0) {
        return -1.0;
    }
    if (x0 <= 0.0 && x1 >= 0.0 && y0 <= 0.0 && y1 >= 0.0) {
        return 0.0;
    }
    double best = 1e300;
    for (int i = 0; i < n; i++) {
        const double d = seg_dist(p2[i], p2[(i + 1) % n]);
        best = d < best ? d : best;
    }
    return best;
}

/* Column state at voxel column (kx, ky) (int keys, maybe outside the volume): bit0 occupied,
 * bit1 unknown, over the voxels whose z extent overlaps [za, zb). */
static unsigned column_state(int64_t kx, int64_t ky, double za, double zb)
{
    const double res = map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (map.cfg.depth_levels - 1);
    const int64_t kmax = ((int64_t)1 << map.cfg.depth_levels) - 1;
    unsigned st = 0;
    for (int64_t kz = (int64_t)floor(za / res) + half - 1; kz <= (int64_t)ceil(zb / res) + half;
         kz++) {
        const double z0 = (double)(kz - half) * res;
        if (!(z0 < zb && z0 + res > za)) {
            continue;
        }
        if (kx < 0 || ky < 0 || kz < 0 || kx > kmax || ky > kmax || kz > kmax) {
            st |= 2u;
            continue;
        }
        occ_key_t k = {{(uint32_t)kx, (uint32_t)ky, (uint32_t)kz}};
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&map, k, 0, &info), OCC_OK);
        if (!info.observed || info.state == OCC_STATE_UNKNOWN) {
            st |= 2u;
        } else if (info.state == OCC_STATE_OCCUPIED) {
            st |= 1u;
        }
    }
    return st;
}

static uint16_t ref_cm(double d, const occ_sectors_config_t *cfg)
{
    const double cm = floor(d * 100.0);
    if (cm <= cfg->min_distance_cm) {
        return cfg->min_distance_cm;
    }
    if (cm >= cfg->max_distance_cm) {
        return cfg->max_distance_cm;
    }
    return (uint16_t)cm;
}

typedef struct {
    double d_occ[OCC_SECTORS_MAX], d_unk[OCC_SECTORS_MAX];
    uint16_t cm[OCC_SECTORS_MAX];
} ref_t;

/* The ground rule of occ_sectors.h, in double: the first occupied voxel down the vehicle's column
 * (from its own voxel while the voxel reaches above za) lifts za to its top + clearance. */
static double ref_band_lo(const occ_pose_t *p, const occ_sectors_config_t *cfg, double za,
                          double zb)
{
    if (!cfg->ignore_ground) {
        return za;
    }
    const double res = map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (map.cfg.depth_levels - 1);
    const int64_t kx = (int64_t)floor((double)p->p.x / res) + half;
    const int64_t ky = (int64_t)floor((double)p->p.y / res) + half;
    for (int64_t kz = (int64_t)floor((double)p->p.z / res) + half; kz >= 0; kz--) {
        const double top = (double)(kz - half + 1) * res;
        if (!(top > za)) {
            break;
        }
        occ_key_t k = {{(uint32_t)kx, (uint32_t)ky, (uint32_t)kz}};
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&map, k, 0, &info), OCC_OK);
        if (info.observed && info.state == OCC_STATE_OCCUPIED) {
            const double lifted = top + (double)cfg->ground_clearance_m;
            return lifted > za && lifted < zb ? lifted : za;
        }
    }
    return za;
}

static void reference(const occ_pose_t *p, const occ_sectors_config_t *cfg, ref_t *r)
{
    const double res = map.cfg.resolution_m;
    const int64_t half = (int64_t)1 << (map.cfg.depth_levels - 1);
    const double R = cfg->max_distance_cm * 0.01;
    const double px = p->p.x, py = p->p.y, pz = p->p.z, yaw = yaw_of(p);
    const double zb = pz + (double)cfg->band_above_m;
    const double za = ref_band_lo(p, cfg, pz - (double)cfg->band_below_m, zb);
    const double inc = (double)cfg->increment_deg * M_PI / 180.0;
    const double off = (double)cfg->angle_offset_deg * M_PI / 180.0;
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        r->d_occ[s] = r->d_unk[s] = 1e300;
    }
    const int64_t kx0 = (int64_t)floor((px - R) / res) + half - 1;
    const int64_t kx1 = (int64_t)floor((px + R) / res) + half + 1;
    const int64_t ky0 = (int64_t)floor((py - R) / res) + half - 1;
    const int64_t ky1 = (int64_t)floor((py + R) / res) + half + 1;
    for (int64_t kx = kx0; kx <= kx1; kx++) {
        for (int64_t ky = ky0; ky <= ky1; ky++) {
            const unsigned st = column_state(kx, ky, za, zb);
            if (st == 0u) {
                continue;
            }
            const double x0 = (double)(kx - half) * res - px;
            const double y0 = (double)(ky - half) * res - py;
            for (unsigned s = 0; s < cfg->n_sectors; s++) {
                /* Body [c - inc/2, c + inc/2) clockwise -> map angles from yaw - c - inc/2. */
                const double lo = yaw - (off + s * inc) - inc / 2.0;
                const double d = wedge_dist(x0, y0, x0 + res, y0 + res, lo, inc);
                if (d < 0.0) {
                    continue;
                }
                if ((st & 1u) && d < r->d_occ[s]) {
                    r->d_occ[s] = d;
                }
                if ((st & 2u) && d < r->d_unk[s]) {
                    r->d_unk[s] = d;
                }
            }
        }
    }
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        if (r->d_occ[s] <= r->d_unk[s] && r->d_occ[s] < R) {
            r->cm[s] = ref_cm(r->d_occ[s], cfg);
        } else if (r->d_unk[s] < R) {
            r->cm[s] = cfg->unknown_as_distance ? ref_cm(r->d_unk[s], cfg) : UINT16_MAX;
        } else {
            r->cm[s] = (uint16_t)(cfg->max_distance_cm + 1u); /* "no obstacle" */
        }
    }
}

/* Compare with 1 cm of slack for float vs double; a kind may differ only on a (near) tie or at
 * the edge of the search radius. Returns the number of mismatching sectors. */
static unsigned compare(const occ_pose_t *p, const occ_sectors_config_t *cfg, const char *what)
{
    static ref_t r;
    reference(p, cfg, &r);
    assert_int_equal(occ_sectors_compute(&map, p, cfg, &sect), OCC_OK);
    assert_int_equal(sect.n, cfg->n_sectors);
    const double R = cfg->max_distance_cm * 0.01;
    unsigned bad = 0;
    for (unsigned s = 0; s < cfg->n_sectors; s++) {
        const int a = sect.distance_cm[s], b = r.cm[s];
        assert_true(a != 0);
        bool ok = abs(a - b) <= 1;
        if (!ok && (a == UINT16_MAX || b == UINT16_MAX)) {
            const double dd = fabs(r.d_occ[s] - r.d_unk[s]);
            ok = dd < 0.01 || fabs(r.d_unk[s] - R) < 0.01 || fabs(r.d_occ[s] - R) < 0.01;
        }
        if (!ok) {
            bad++;
            fprintf(stderr,
                    "%s seed %u: pose (%.3f %.3f %.3f yaw %.4f) n %u inc %.2f off %.2f: sector %u "
                    "got %d want %d (ref occ %.4f unk %.4f; got occ %.4f unk %.4f)\n",
                    what, seed, (double)p->p.x, (double)p->p.y, (double)p->p.z, yaw_of(p),
                    cfg->n_sectors, (double)cfg->increment_deg, (double)cfg->angle_offset_deg, s,
                    a, b, r.d_occ[s], r.d_unk[s], (double)sect.d_occ_m[s],
                    (double)sect.d_unk_m[s]);
        }
    }
    return bad;
}

/* ---- random maps ------------------------------------------------------------------------------ */

static void key_at(double x, double y, double z, occ_key_t *k)
{
    occ_vec3_t v = {(float)x, (float)y, (float)z};
    assert_int_equal(occ_map_key(&map, v, k), OCC_OK);
}

/* A room-sized random map around the origin: mostly free, pruned blocks, holes of unknown,
 * occupied boxes and walls. */
static void random_map(void)
{
    occ_map_clear(&map);
    occ_key_t k;
    for (double x = -3.2; x < 3.2; x += 0.8) {
        for (double y = -3.2; y < 3.2; y += 0.8) {
            for (double z = -0.8; z < 0.8; z += 0.8) {
                if (urand() < 0.85) {
                    key_at(x + 0.05, y + 0.05, z + 0.05, &k);
                    assert_int_equal(occ_map_set_key(&map, k, 3, -2.0f), OCC_OK);
                }
            }
        }
    }
    const int holes = 3 + rand() % 6;
    for (int i = 0; i < holes; i++) {
        key_at(urand() * 6.0 - 3.0, urand() * 6.0 - 3.0, urand() * 1.2 - 0.6, &k);
        assert_int_equal(occ_map_forget_key(&map, k, (unsigned)(rand() % 3)), OCC_OK);
    }
    const int boxes = 4 + rand() % 10;
    for (int i = 0; i < boxes; i++) {
        const double cx = urand() * 6.0 - 3.0, cy = urand() * 6.0 - 3.0, cz = urand() * 1.2 - 0.6;
        const int sx = 1 + rand() % 6, sy = 1 + rand() % 6, sz = 1 + rand() % 5;
        for (int a = 0; a < sx; a++) {
            for (int b = 0; b < sy; b++) {
                for (int c = 0; c < sz; c++) {
                    key_at(cx + a * 0.1, cy + b * 0.1, cz + c * 0.1, &k);
                    assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
                }
            }
        }
    }
    /* A wall segment and a few isolated voxels. */
    const double wy = urand() * 4.0 - 2.0;
    for (double x = -2.5; x < 1.0; x += 0.1) {
        for (double z = -0.5; z < 0.5; z += 0.1) {
            key_at(x, wy, z, &k);
            assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
        }
    }
    for (int i = 0; i < 40; i++) {
        key_at(urand() * 6.0 - 3.0, urand() * 6.0 - 3.0, urand() * 1.2 - 0.6, &k);
        assert_int_equal(occ_map_update_key(&map, k, urand() < 0.7 ? 1.0f : -1.0f), OCC_OK);
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static void random_config(occ_sectors_config_t *cfg)
{
    static const struct { uint8_t n; float inc; } shapes[] = {
        {72, 5.0f}, {36, 10.0f}, {8, 45.0f}, {16, 22.5f}, {12, 7.5f}, {4, 90.0f}};
    *cfg = occ_sectors_config_default();
    const unsigned i = (unsigned)rand() % (sizeof shapes / sizeof shapes[0]);
    cfg->n_sectors = shapes[i].n;
    cfg->increment_deg = shapes[i].inc;
    cfg->angle_offset_deg = (float)(urand() * 20.0 - 10.0);
    cfg->band_below_m = (float)(0.05 + urand() * 0.5);
    cfg->band_above_m = (float)(0.05 + urand() * 0.5);
    cfg->min_distance_cm = (uint16_t)(5 + rand() % 30);
    cfg->max_distance_cm = (uint16_t)(150 + rand() % 200);
    cfg->unknown_as_distance = (rand() & 1) != 0;
    cfg->ignore_ground = (rand() & 3) != 0;
    cfg->ground_clearance_m = (float)(urand() * 0.3);
}

static void test_random_maps(void **state)
{
    (void)state;
    unsigned bad = 0;
    for (int m = 0; m < 6; m++) {
        random_map();
        for (int i = 0; i < 8; i++) {
            occ_pose_t p = occ_pose_identity();
            p.p.x = (float)(urand() * 5.0 - 2.5);
            p.p.y = (float)(urand() * 5.0 - 2.5);
            p.p.z = (float)(urand() * 1.0 - 0.5);
            set_yaw(&p, (float)(urand() * 4.0 * M_PI - 2.0 * M_PI));
            occ_sectors_config_t cfg;
            random_config(&cfg);
            bad += compare(&p, &cfg, "random");
        }
    }
    assert_int_equal(bad, 0);
}

/* Yaw and yaw + 2 pi give the same sectors; so do +-pi. */
static void test_yaw_wrap(void **state)
{
    (void)state;
    random_map();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300;
    static occ_sectors_t a;
    const float yaws[] = {(float)M_PI, (float)-M_PI, 0.0f, 3.0f, -3.1f, 6.2f};
    for (unsigned i = 0; i < sizeof yaws / sizeof yaws[0]; i++) {
        occ_pose_t p = at_yaw(0.33f, -0.71f, 0.05f, yaws[i]);
        assert_int_equal(compare(&p, &cfg, "yaw"), 0);
        memcpy(&a, &sect, sizeof a);
        set_yaw(&p, yaws[i] + 2.0f * (float)M_PI);
        assert_int_equal(compare(&p, &cfg, "yaw+2pi"), 0);
        for (unsigned s = 0; s < cfg.n_sectors; s++) {
            assert_true(abs((int)a.distance_cm[s] - (int)sect.distance_cm[s]) <= 1);
        }
    }
}

/* Hand-computed: free room, one wall behind the vehicle (body 180 deg = sector 36 of 72). */
static void test_behind_180(void **state)
{
    (void)state;
    occ_key_t k;
    /* Observe free space: the eight level-7 nodes (12.8 m cubes) around the origin. */
    for (int i = 0; i < 8; i++) {
        key_at((i & 1) ? 0.05 : -0.05, (i & 2) ? 0.05 : -0.05, (i & 4) ? 0.05 : -0.05, &k);
        assert_int_equal(occ_map_set_key(&map, k, 7, -2.0f), OCC_OK);
    }
    /* Wall x in [-1.0, -0.9), all y in [-3, 3), z in [-0.5, 0.5). */
    for (double y = -2.95; y < 3.0; y += 0.1) {
        for (double z = -0.45; z < 0.5; z += 0.1) {
            key_at(-0.95, y, z, &k);
            assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
        }
    }
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 250;
    occ_pose_t p = at_yaw(0.05f, 0.05f, 0.0f, 0.0f); /* facing east: wall behind */
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    /* Nearest wall point (-0.9, 0.05): 0.95 m. */
    assert_int_equal(sect.distance_cm[36], 95);
    assert_int_equal(sect.distance_cm[0], 251);   /* ahead: free up to 2.5 m: max + 1 */
    assert_int_equal(sect.distance_cm[18], 251);  /* right (south) */
    assert_int_equal(compare(&p, &cfg, "behind"), 0);
    /* Facing west (yaw pi): the wall is ahead, sector 0; yaw -pi the same. */
    set_yaw(&p, (float)M_PI);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sect.distance_cm[0], 95);
    assert_int_equal(sect.distance_cm[36], 251);
    set_yaw(&p, -(float)M_PI);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sect.distance_cm[0], 95);
    /* Facing north (yaw pi/2): the wall is on the left, body 270 deg = sector 54. */
    set_yaw(&p, (float)(M_PI / 2.0));
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sect.distance_cm[54], 95);
    assert_int_equal(compare(&p, &cfg, "left"), 0);
}

static void test_unknown_space(void **state)
{
    (void)state;
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = at_yaw(1.0f, 2.0f, 0.3f, 0.4f);
    /* Empty map: the vehicle stands in unknown space. */
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sect.distance_cm[s], UINT16_MAX);
    }
    cfg.unknown_as_distance = true;
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sect.distance_cm[s], cfg.min_distance_cm);
    }
    /* A free bubble of 0.8 m around a voxel-aligned spot: unknown beyond it. */
    random_map();
    occ_key_t k;
    key_at(0.05, 0.05, 0.05, &k);
    assert_int_equal(occ_map_forget_key(&map, k, 4), OCC_OK);
    assert_int_equal(occ_map_set_key(&map, k, 0, -1.0f), OCC_OK);
    occ_pose_t q = at_yaw(0.05f, 0.05f, 0.05f, 1.0f);
    cfg.unknown_as_distance = false;
    assert_int_equal(compare(&q, &cfg, "bubble"), 0);
    cfg.unknown_as_distance = true;
    cfg.max_distance_cm = 300;
    assert_int_equal(compare(&q, &cfg, "bubble-dist"), 0);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sect.distance_cm[s], cfg.min_distance_cm); /* unknown above/below */
    }
}

/* The edges of the map volume: depth 5 at 0.1 m spans [-1.6, 1.6) per axis. */
static void test_map_edges(void **state)
{
    (void)state;
    reinit(0.1f, 5);
    occ_key_t root = {{0, 0, 0}};
    assert_int_equal(occ_map_set_key(&map, root, 5, -2.0f), OCC_OK);
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300;
    cfg.unknown_as_distance = true;
    cfg.band_below_m = cfg.band_above_m = 0.3f;
    occ_pose_t p = at_yaw(1.0f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sect.distance_cm[0], 60);   /* volume edge 0.6 m ahead */
    assert_int_equal(sect.distance_cm[36], 260); /* 2.6 m behind */
    assert_int_equal(compare(&p, &cfg, "edge"), 0);
    for (int i = 0; i < 20; i++) {
        occ_pose_t q = occ_pose_identity();
        q.p.x = (float)(urand() * 3.1 - 1.55);
        q.p.y = (float)(urand() * 3.1 - 1.55);
        q.p.z = (float)(urand() * 3.0 - 1.5);
        set_yaw(&q, (float)(urand() * 7.0 - 3.5));
        occ_sectors_config_t c2;
        random_config(&c2);
        assert_int_equal(compare(&q, &c2, "edges-random"), 0);
    }
    occ_pose_t out = at_yaw(1.7f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_compute(&map, &out, &cfg, &sect), OCC_ERR_RANGE);
    assert_int_equal(sect.n, 0);
    occ_map_clear(&map);
    setup(NULL);
}

/* A NED map is the ENU map mirrored (x <-> y, z -> -z): the same pose gives the same sectors. */
static uint8_t arena2[ARENA_BYTES];
static void test_ned_mirror(void **state)
{
    (void)state;
    static occ_map_t ned;
    static occ_sectors_t a;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    for (int m = 0; m < 2; m++) {
        random_map();
        assert_int_equal(occ_map_init(&ned, &cfg, arena2, sizeof arena2), OCC_OK);
        const uint32_t top = (uint32_t)1 << map.cfg.depth_levels;
        occ_walk_t w;
        occ_walk_node_t nd;
        occ_walk_begin(&w, &map);
        while (occ_walk_next(&w, &nd)) {
            if (nd.has_children || !nd.observed) {
                continue;
            }
            const uint32_t size = (uint32_t)1 << nd.level;
            occ_key_t k = {{nd.key.k[1], nd.key.k[0], top - nd.key.k[2] - size}};
            assert_int_equal(occ_map_set_key(&ned, k, nd.level, occ_value_to_logodds(nd.value)),
                             OCC_OK);
        }
        for (int i = 0; i < 6; i++) {
            occ_pose_t p = occ_pose_identity();
            p.p.x = (float)(urand() * 5.0 - 2.5);
            p.p.y = (float)(urand() * 5.0 - 2.5);
            p.p.z = (float)(urand() * 1.0 - 0.5);
            const float yaw = (float)(urand() * 6.0 - 3.0);
            set_yaw(&p, yaw);
            occ_sectors_config_t sc;
            random_config(&sc);
            assert_int_equal(occ_sectors_compute(&map, &p, &sc, &a), OCC_OK);
            occ_pose_t q = p;
            q.p.x = p.p.y;
            q.p.y = p.p.x;
            q.p.z = -p.p.z;
            set_yaw(&q, (float)(M_PI / 2.0) - yaw); /* NED <- FRD: heading from north */
            sc.map_ned = true;
            assert_int_equal(occ_sectors_compute(&ned, &q, &sc, &sect), OCC_OK);
            for (unsigned s = 0; s < sc.n_sectors; s++) {
                const int da = a.distance_cm[s], db = sect.distance_cm[s];
                if (abs(da - db) > 1) {
                    fprintf(stderr, "ned mirror seed %u sector %u: enu %d ned %d\n", seed, s, da, db);
                }
                assert_true(abs(da - db) <= 1);
            }
        }
        assert_int_equal(occ_map_check(&ned), OCC_OK);
    }
}

/* A room on a floor: observed free space z in [0, 1.6) over [-3.2, 3.2)^2, the floor voxels
 * z in [-0.1, 0) occupied (unknown below), a wall x in [2.0, 2.1) up to 1.6 m. */
static void floor_room(void)
{
    occ_key_t k;
    for (double x = -3.2; x < 3.2; x += 1.6) {
        for (double y = -3.2; y < 3.2; y += 1.6) {
            key_at(x + 0.05, y + 0.05, 0.05, &k);
            assert_int_equal(occ_map_set_key(&map, k, 4, -2.0f), OCC_OK);
        }
    }
    for (double x = -2.95; x < 3.0; x += 0.1) {
        for (double y = -2.95; y < 3.0; y += 0.1) {
            key_at(x, y, -0.05, &k);
            assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
        }
    }
    for (double y = -2.95; y < 3.0; y += 0.1) {
        for (double z = -0.05; z < 1.6; z += 0.1) {
            key_at(2.05, y, z, &k);
            assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
        }
    }
}

static unsigned sectors_below(unsigned cm)
{
    unsigned n = 0;
    for (unsigned s = 0; s < sect.n; s++) {
        n += sect.distance_cm[s] < cm ? 1u : 0u;
    }
    return n;
}

/* The vehicle standing on the floor can arm (ArduPilot wants > 0.6 m in every face): the ground
 * rule keeps the floor out of the band, the wall stays in; without it the floor is everywhere. */
static void test_floor_standing(void **state)
{
    (void)state;
    floor_room();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300; /* the free room reaches 3.15 m */
    occ_pose_t p = at_yaw(0.05f, 0.05f, 0.05f, 0.0f); /* 5 cm above the floor, facing east */
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sectors_below(61), 0);
    assert_int_equal(sect.distance_cm[0], 195);   /* the wall ahead */
    assert_int_equal(sect.distance_cm[36], 301);  /* behind: free (floor ignored) */
    assert_int_equal(compare(&p, &cfg, "floor-standing"), 0);
    /* Flying over it at 0.3 m and at 1.2 m: the same. */
    p.p.z = 0.3f;
    assert_int_equal(compare(&p, &cfg, "floor-0.3"), 0);
    assert_int_equal(sectors_below(61), 0);
    p.p.z = 1.2f;
    assert_int_equal(compare(&p, &cfg, "floor-1.2"), 0);
    assert_int_equal(sectors_below(61), 0);
    /* The old band: the floor is an obstacle at 0 m in every sector (min_distance). */
    cfg.ignore_ground = false;
    p.p.z = 0.05f;
    assert_int_equal(compare(&p, &cfg, "floor-kept"), 0);
    assert_int_equal(sectors_below(21), 72);
    /* A box on the floor (z 0..0.3) taller than the clearance is an obstacle (west, 1.05 m). */
    occ_key_t k;
    for (double z = 0.05; z < 0.3; z += 0.1) {
        key_at(-1.05, 0.05, z, &k);
        assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
    }
    cfg.ignore_ground = true;
    assert_int_equal(compare(&p, &cfg, "floor-box"), 0);
    assert_true(sect.distance_cm[36] >= 104 && sect.distance_cm[36] <= 105);
    /* With a clearance above its top it is not. */
    cfg.ground_clearance_m = 0.35f;
    assert_int_equal(compare(&p, &cfg, "floor-box-low"), 0);
    assert_int_equal(sect.distance_cm[36], 301);
}

/* Separate settings below and above: a shelf at 0.8..0.9 m north, a low box south. */
static void test_band_below_above(void **state)
{
    (void)state;
    floor_room();
    occ_key_t k;
    for (double x = -0.45; x < 0.5; x += 0.1) {
        key_at(x, 1.05, 0.85, &k); /* shelf: 1.0 m north, z 0.8..0.9 */
        assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
        key_at(x, -1.55, 0.25, &k); /* box top: 1.5 m south, z 0.2..0.3 */
        assert_int_equal(occ_map_update_key(&map, k, 2.0f), OCC_OK);
    }
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300; /* the free room reaches 3.15 m */
    occ_pose_t p = at_yaw(0.05f, 0.05f, 0.6f, (float)(M_PI / 2.0)); /* facing north */
    cfg.band_below_m = 0.2f;
    cfg.band_above_m = 0.1f; /* [0.4, 0.7): neither */
    assert_int_equal(compare(&p, &cfg, "band-none"), 0);
    assert_int_equal(sect.distance_cm[0], 301);
    assert_int_equal(sect.distance_cm[36], 301);
    cfg.band_above_m = 0.3f; /* [0.4, 0.9): the shelf ahead */
    assert_int_equal(compare(&p, &cfg, "band-above"), 0);
    assert_int_equal(sect.distance_cm[0], 95);
    assert_int_equal(sect.distance_cm[36], 301);
    cfg.band_above_m = 0.1f;
    cfg.band_below_m = 0.35f; /* [0.25, 0.7): the box behind */
    assert_int_equal(compare(&p, &cfg, "band-below"), 0);
    assert_int_equal(sect.distance_cm[0], 301);
    assert_int_equal(sect.distance_cm[36], 155);
}

static void assert_unsafe(uint16_t want)
{
    assert_int_equal(sect.n, 0);
    for (unsigned s = 0; s < OCC_SECTORS_MAX; s++) {
        assert_int_equal(sect.distance_cm[s], want);
        assert_true(fabsf(sect.d_occ_m[s]) + fabsf(sect.d_unk_m[s]) < 1e-30f);
    }
}

/* Every error leaves the unsafe answer (an obstacle at min_distance) in all 72 values, also
 * over the values of an earlier good call. */
static void test_fail_closed(void **state)
{
    (void)state;
    floor_room();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = at_yaw(0.05f, 0.05f, 0.05f, 0.0f);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_true(sect.distance_cm[36] > cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(NULL, &p, &cfg, &sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(occ_sectors_compute(&map, NULL, &cfg, &sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(&map, &p, NULL, &sect), OCC_ERR_ARG);
    assert_unsafe(1);
    occ_sectors_config_t bad = cfg;
    bad.n_sectors = 0;
    bad.min_distance_cm = 35;
    assert_int_equal(occ_sectors_compute(&map, &p, &bad, &sect), OCC_ERR_ARG);
    assert_unsafe(35);
    set_yaw(&p, NAN);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    set_yaw(&p, 0.0f);
    p.p.x = 1e7f;
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_RANGE);
    assert_unsafe(cfg.min_distance_cm);
    bad = cfg;
    bad.ground_clearance_m = -0.1f;
    p.p.x = 0.05f;
    assert_int_equal(occ_sectors_compute(&map, &p, &bad, &sect), OCC_ERR_ARG);
    bad.ground_clearance_m = NAN;
    assert_int_equal(occ_sectors_config_check(&bad), OCC_ERR_ARG);
    bad = cfg;
    bad.max_distance_cm = OCC_SECTORS_MAX_DISTANCE_CM + 1u; /* max + 1 would read "unknown" */
    assert_int_equal(occ_sectors_config_check(&bad), OCC_ERR_ARG);
    bad.max_distance_cm = OCC_SECTORS_MAX_DISTANCE_CM;
    assert_int_equal(occ_sectors_config_check(&bad), OCC_OK);
}

static void test_args(void **state)
{
    (void)state;
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = at_yaw(0.0f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_config_check(&cfg), OCC_OK);
    assert_int_equal(occ_sectors_compute(NULL, &p, &cfg, &sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&map, NULL, &cfg, &sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&map, &p, NULL, &sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, NULL), OCC_ERR_ARG);
    occ_sectors_config_t c = cfg;
    c.n_sectors = 0;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.n_sectors = 73;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.increment_deg = 6.0f; /* 72 x 6 > 360 */
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.n_sectors = 2;
    c.increment_deg = 120.0f;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.min_distance_cm = 0;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.min_distance_cm = c.max_distance_cm;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.max_distance_cm = 65535;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.band_below_m = c.band_above_m = 0.0f;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.angle_offset_deg = NAN;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    set_yaw(&p, NAN);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_ARG);
    set_yaw(&p, 0.0f);
    p.p.x = INFINITY;
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_ARG);
    p.p.x = 1e7f;
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_RANGE);
}

int main(void)
{
    const char *env = getenv("OCC_SEED");
    seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : 12345u;
    printf("test_sectors: OCC_SEED=%u\n", seed);
    srand(seed);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_args, setup, teardown),
        cmocka_unit_test_setup_teardown(test_behind_180, setup, teardown),
        cmocka_unit_test_setup_teardown(test_unknown_space, setup, teardown),
        cmocka_unit_test_setup_teardown(test_yaw_wrap, setup, teardown),
        cmocka_unit_test_setup_teardown(test_map_edges, setup, teardown),
        cmocka_unit_test_setup_teardown(test_random_maps, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ned_mirror, setup, teardown),
        cmocka_unit_test_setup_teardown(test_floor_standing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_band_below_above, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fail_closed, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
