/* SPDX-License-Identifier: BSD-3-Clause */
/* pose_history.c - a caller-owned ring of timestamped poses, answered at any sample's time. */
#include "occmap/occ_pose.h"

/* i-th sample from the oldest (i < count_). */
static const occ_pose_sample_t *sample(const occ_pose_history_t *h, const size_t i)
{
    size_t j = h->head_ + i;
    if (j >= h->cap_) {
        j -= h->cap_;
    }
    return &h->ring_[j];
}

occ_err_t occ_pose_history_init(occ_pose_history_t *const h, occ_pose_sample_t *const storage,
                                const size_t cap, const occ_pose_history_cfg_t *const cfg)
{
    if (h == NULL || storage == NULL || cfg == NULL || cap < 2u || cfg->max_gap_us == 0u) {
        return OCC_ERR_ARG;
    }
    const occ_pose_history_t empty = {0};
    *h = empty;
    h->ring_ = storage;
    h->cap_ = cap;
    h->cfg_ = *cfg;
    return OCC_OK;
}

occ_err_t occ_pose_history_push(occ_pose_history_t *const h, const uint64_t t_us,
                                const occ_pose_t *const pose)
{
    if (h == NULL) {
        return OCC_ERR_ARG;
    }
    if (occ_pose_check(pose) != OCC_OK) {
        h->rejected_bad++;
        return OCC_ERR_ARG;
    }
    if (h->count_ > 0u && t_us <= sample(h, h->count_ - 1u)->t_us) {
        h->rejected_order++;
        return OCC_ERR_TIME;
    }
    if (h->count_ == h->cap_) { /* full: the oldest goes */
        h->head_ = h->head_ + 1u == h->cap_ ? 0u : h->head_ + 1u;
        h->count_--;
    }
    size_t j = h->head_ + h->count_;
    if (j >= h->cap_) {
        j -= h->cap_;
    }
    h->ring_[j].t_us = t_us;
    h->ring_[j].pose = *pose;
    h->count_++;
    h->pushed++;
    return OCC_OK;
}

/* Index of the last sample with time <= t (count_ > 0, t >= the oldest time). */
static size_t last_at_or_before(const occ_pose_history_t *h, const uint64_t t_us)
{
    size_t lo = 0u, hi = h->count_ - 1u;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo + 1u) / 2u;
        if (sample(h, mid)->t_us <= t_us) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

/* Fraction of t between a and b, a < b; > 1 past b (extrapolation). */
static float fraction(const uint64_t a_us, const uint64_t b_us, const uint64_t t_us)
{
    return (float)(t_us - a_us) / (float)(b_us - a_us);
}

/* The pose at or after the newest sample, t - newest <= max_extrapolate_us. */
static occ_pose_t extrapolate(const occ_pose_history_t *h, const uint64_t t_us)
{
    const occ_pose_sample_t *const last = sample(h, h->count_ - 1u);
    if (h->count_ < 2u || t_us == last->t_us) {
        return last->pose;
    }
    const occ_pose_sample_t *const prev = sample(h, h->count_ - 2u);
    if (last->t_us - prev->t_us > h->cfg_.max_gap_us) {
        return last->pose; /* too far apart to trust their motion: hold the newest */
    }
    return occ_pose_interpolate(&prev->pose, &last->pose, fraction(prev->t_us, last->t_us, t_us));
}

static occ_pose_refusal_t lookup(const occ_pose_history_t *h, const uint64_t t_us, occ_pose_t *out)
{
    if (h->count_ == 0u) {
        return OCC_POSE_EMPTY;
    }
    const uint64_t newest = sample(h, h->count_ - 1u)->t_us;
    if (t_us < sample(h, 0u)->t_us) {
        return OCC_POSE_TOO_OLD;
    }
    if (t_us >= newest) {
        if (t_us - newest > h->cfg_.max_extrapolate_us) {
            return OCC_POSE_TOO_NEW;
        }
        *out = extrapolate(h, t_us);
        return OCC_POSE_OK;
    }
    const size_t i = last_at_or_before(h, t_us);
    const occ_pose_sample_t *const a = sample(h, i), *const b = sample(h, i + 1u);
    if (t_us == a->t_us) {
        *out = a->pose;
        return OCC_POSE_OK;
    }
    if (b->t_us - a->t_us > h->cfg_.max_gap_us) {
        return OCC_POSE_GAP;
    }
    *out = occ_pose_interpolate(&a->pose, &b->pose, fraction(a->t_us, b->t_us, t_us));
    return OCC_POSE_OK;
}

occ_err_t occ_pose_history_at(occ_pose_history_t *const h, const uint64_t t_us,
                              occ_pose_t *const out, occ_pose_refusal_t *const why)
{
    if (h == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    const occ_pose_refusal_t r = lookup(h, t_us, out);
    if (why != NULL) {
        *why = r;
    }
    if (r != OCC_POSE_OK) {
        h->refused[r]++;
        return OCC_ERR_TIME;
    }
    return OCC_OK;
}

size_t occ_pose_history_count(const occ_pose_history_t *const h)
{
    return h == NULL ? 0u : h->count_;
}

occ_err_t occ_pose_history_span(const occ_pose_history_t *const h, uint64_t *const oldest_us,
                                uint64_t *const newest_us)
{
    if (h == NULL || oldest_us == NULL || newest_us == NULL) {
        return OCC_ERR_ARG;
    }
    if (h->count_ == 0u) {
        return OCC_ERR_STATE;
    }
    *oldest_us = sample(h, 0u)->t_us;
    *newest_us = sample(h, h->count_ - 1u)->t_us;
    return OCC_OK;
}
