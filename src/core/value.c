/* SPDX-License-Identifier: BSD-3-Clause */
/* value.c - log-odds <-> node values, states, and OctoMap's clamped update rule. */
#include "tree_internal.h"

#if OCC_VALUE_FLOAT
float occ_value_to_logodds(const occ_value_t v)
{
    return occ_is_observed(v) ? v : 0.0f;
}

occ_value_t occ_value_from_logodds(const float logodds)
{
    if (!(logodds > OCC_VALUE_MIN)) {  /* also NaN */
        return OCC_VALUE_MIN;
    }
    return logodds < OCC_VALUE_MAX ? logodds : OCC_VALUE_MAX;
}
#else
float occ_value_to_logodds(const occ_value_t v)
{
    return occ_is_observed(v) ? (float)v / (float)OCC_FIXED_ONE : 0.0f;
}

/* Round to nearest and saturate to the observed range (never yields the unobserved value). */
occ_value_t occ_value_from_logodds(const float logodds)
{
    const float scaled = logodds * (float)OCC_FIXED_ONE;
    if (!(scaled > (float)OCC_VALUE_MIN)) {  /* also NaN */
        return (occ_value_t)OCC_VALUE_MIN;
    }
    if (scaled >= (float)OCC_VALUE_MAX) {
        return (occ_value_t)OCC_VALUE_MAX;
    }
    const float r = scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f;
    return (occ_value_t)(int32_t)r;
}
#endif

#if !OCC_VALUE_FLOAT && OCC_VALUE_BITS == 8
/* A delta in value steps, rounded to nearest, saturated to +-INT16_MAX (NaN: the bottom). */
occ_delta_t occi_delta_from_logodds(const float logodds)
{
    const float scaled = logodds * (float)OCC_FIXED_ONE;
    if (!(scaled > (float)-INT16_MAX)) {
        return (occ_delta_t)-INT16_MAX;
    }
    if (scaled >= (float)INT16_MAX) {
        return (occ_delta_t)INT16_MAX;
    }
    const float r = scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f;
    return (occ_delta_t)(int32_t)r;
}
#else
occ_delta_t occi_delta_from_logodds(const float logodds)
{
    return occ_value_from_logodds(logodds);
}
#endif

bool occ_value_observed(const occ_value_t v)
{
    return occ_is_observed(v);
}

occ_state_t occ_map_state_of(const occ_map_t *const map, const float logodds)
{
    if (map == NULL || !(logodds - logodds < 1.0f)) {
        return OCC_STATE_UNKNOWN; /* NaN / Inf evidence is never FREE */
    }
    return occ_value_state(map, occ_value_from_logodds(logodds));
}
