/*
 * io_header.c - OctoMap's text header: parsed as AbstractOcTree::readHeader does (whitespace
 * tokens, '#' comments, unknown keywords skipped to the end of the line, "data" ends it), and
 * written byte for byte as OctoMap writes it (resolution as iostream's default %g, 6 digits),
 * without stdio or double arithmetic.
 */
#include <string.h>

#include "io_internal.h"

static const char magic_bt[] = "# Octomap OcTree binary file";
static const char magic_ot[] = "# Octomap OcTree file";
static const char comment[] = "# (feel free to add / change comments, but leave the first line "
                              "as it is!)\n#\n";

static bool is_ws(const uint8_t ch)
{
    return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\v' || ch == '\f' || ch == '\r';
}

static void skip_ws(occ_cursor_t *const c)
{
    while (c->pos < c->len && is_ws(c->buf[c->pos])) {
        c->pos++;
    }
}

/* Past the next '\n'; false when there is none. */
static bool skip_line(occ_cursor_t *const c)
{
    while (c->pos < c->len) {
        if (c->buf[c->pos++] == '\n') {
            return true;
        }
    }
    return false;
}

static size_t token_len(const occ_cursor_t *const c)
{
    size_t n = 0u;
    while (c->pos + n < c->len && !is_ws(c->buf[c->pos + n])) {
        n++;
    }
    return n;
}

static bool token_is(const occ_cursor_t *const c, const size_t n, const char *const word)
{
    return n == strlen(word) && memcmp(c->buf + c->pos, word, n) == 0;
}

static bool is_digit(const uint8_t ch)
{
    return ch >= '0' && ch <= '9';
}

static const float pow10f_exact[11] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f,
                                       1e6f, 1e7f, 1e8f, 1e9f, 1e10f};

/* A decimal number as istream >> double reads it; float result. */
static bool parse_real(occ_cursor_t *const c, float *const out)
{
    size_t p = c->pos;
    bool neg = false;
    if (p < c->len && (c->buf[p] == '+' || c->buf[p] == '-')) {
        neg = c->buf[p] == '-';
        p++;
    }
    uint64_t mant = 0u;
    int32_t exp10 = 0;
    unsigned digits = 0u;
    bool any = false;
    while (p < c->len && is_digit(c->buf[p])) {
        any = true;
        if (digits < 19u) {
            mant = mant * 10u + (uint64_t)(c->buf[p] - '0');
            if (mant != 0u) {
                digits++;
            }
        } else if (exp10 < 100000) { /* an int32_t that a 2 GiB run of digits cannot wrap */
            exp10++;
        }
        p++;
    }
    if (p < c->len && c->buf[p] == '.') {
        p++;
        while (p < c->len && is_digit(c->buf[p])) {
            any = true;
            if (digits < 19u && exp10 > -100000) {
                mant = mant * 10u + (uint64_t)(c->buf[p] - '0');
                exp10--;
                if (mant != 0u) {
                    digits++;
                }
            }
            p++;
        }
    }
    if (!any) {
        return false;
    }
    if (p < c->len && (c->buf[p] == 'e' || c->buf[p] == 'E')) {
        size_t q = p + 1u;
        bool eneg = false;
        if (q < c->len && (c->buf[q] == '+' || c->buf[q] == '-')) {
            eneg = c->buf[q] == '-';
            q++;
        }
        if (q < c->len && is_digit(c->buf[q])) {
            int32_t e = 0;
            while (q < c->len && is_digit(c->buf[q])) {
                if (e < 10000) {
                    e = e * 10 + (int32_t)(c->buf[q] - '0');
                }
                q++;
            }
            exp10 += eneg ? -e : e;
            p = q;
        }
    }
    c->pos = p;
    float v = (float)mant;
    /* One correctly rounded step when both parts are exact, else stepwise. */
    while (exp10 > 10 && v < 1e30f) {
        v *= 1e10f;
        exp10 -= 10;
    }
    while (exp10 < -10 && v > 1e-30f) {
        v /= 1e10f;
        exp10 += 10;
    }
    if (exp10 > 10 || exp10 < -10) {
        v = exp10 > 0 ? 3.0e38f * 10.0f : 0.0f;  /* saturates: rejected by the range check */
    } else if (exp10 >= 0) {
        v *= pow10f_exact[exp10];
    } else {
        v /= pow10f_exact[-exp10];
    }
    *out = neg ? -v : v;
    return true;
}

static bool parse_uint(occ_cursor_t *const c, uint64_t *const out)
{
    size_t p = c->pos;
    if (p < c->len && c->buf[p] == '+') {
        p++;
    }
    if (p >= c->len || !is_digit(c->buf[p])) {
        return false;
    }
    uint64_t v = 0u;
    while (p < c->len && is_digit(c->buf[p])) {
        if (v > UINT32_MAX) {
            return false;  /* OctoMap reads an unsigned: this fails there too */
        }
        v = v * 10u + (uint64_t)(c->buf[p] - '0');
        p++;
    }
    if (v > UINT32_MAX) {
        return false;
    }
    c->pos = p;
    *out = v;
    return true;
}

occ_err_t occi_om_header_parse(occ_cursor_t *const c, occ_om_header_t *const h)
{
    memset(h, 0, sizeof *h);
    const size_t nb = sizeof magic_bt - 1u, no = sizeof magic_ot - 1u;
    if (c->len >= nb && memcmp(c->buf, magic_bt, nb) == 0) {
        h->format = OCC_FORMAT_BT;
    } else if (c->len >= no && memcmp(c->buf, magic_ot, no) == 0) {
        h->format = OCC_FORMAT_OT;
    } else {
        return occ_cursor_fail(c, 0u, "wrong magic: not an OctoMap .bt/.ot header");
    }
    c->pos = 0u;
    if (!skip_line(c)) {
        return occ_cursor_fail(c, c->len, "truncated header");
    }
    bool have_res = false;
    for (;;) {
        skip_ws(c);
        if (c->pos >= c->len) {
            return occ_cursor_fail(c, c->pos, "truncated header: no 'data' line");
        }
        const size_t at = c->pos;
        const size_t n = token_len(c);
        if (token_is(c, n, "data")) {
            c->pos += n;
            if (!skip_line(c)) {
                return occ_cursor_fail(c, c->len, "truncated header after 'data'");
            }
            break;
        }
        if (c->buf[c->pos] == '#') {
            c->pos += n;
            if (!skip_line(c)) {
                return occ_cursor_fail(c, c->len, "truncated header comment");
            }
        } else if (token_is(c, n, "id")) {
            c->pos += n;
            skip_ws(c);
            const size_t k = token_len(c);
            if (k == 0u) {
                return occ_cursor_fail(c, c->pos, "truncated header: empty id");
            }
            if (k >= sizeof h->id) {
                return occ_cursor_fail(c, c->pos, "tree id too long");
            }
            memcpy(h->id, c->buf + c->pos, k);
            h->id[k] = '\0';
            c->pos += k;
        } else if (token_is(c, n, "res")) {
            c->pos += n;
            skip_ws(c);
            if (!parse_real(c, &h->res)) {
                return occ_cursor_fail(c, c->pos, "malformed res");
            }
            have_res = true;
        } else if (token_is(c, n, "size")) {
            c->pos += n;
            skip_ws(c);
            if (!parse_uint(c, &h->size)) {
                return occ_cursor_fail(c, c->pos, "malformed or absurd size");
            }
        } else {
            h->warnings |= OCC_IO_WARN_UNKNOWN_KEY;
            c->pos += n;
            if (!skip_line(c)) {
                return occ_cursor_fail(c, c->len, "truncated header");
            }
        }
        (void)at;
    }
    h->data_offset = c->pos;
    if (h->id[0] == '\0') {
        return occ_cursor_fail(c, c->pos, "header without id");
    }
    if (!have_res || !occ_finite(h->res) || !(h->res > 0.0f)) {
        return occ_cursor_fail(c, c->pos, "header without a positive res");
    }
    if (h->res < 1e-6f || h->res >= 1e6f) {
        return occ_cursor_fail(c, c->pos, "absurd resolution (outside [1e-6, 1e6) m)");
    }
    if (strcmp(h->id, "1") == 0) {
        h->warnings |= OCC_IO_WARN_LEGACY_ID;
        memcpy(h->id, "OcTree", 7u);
    }
    return OCC_OK;
}

/* round(m * 10^p / 2^s), halves to even, exact in 64 bits for m < 2^24, p <= 11, s <= 62. */
static uint64_t scaled_round(const uint32_t m, const unsigned p, const unsigned s)
{
    uint64_t num = m;
    for (unsigned i = 0; i < p; i++) {
        num *= 10u;
    }
    if (s == 0u) {
        return num;
    }
    const uint64_t q = num >> s, r = num & ((1ull << s) - 1u), half = 1ull << (s - 1u);
    return (r > half || (r == half && (q & 1u) != 0u)) ? q + 1u : q;
}

occ_err_t occi_om_header_write(occ_sink_t *const s, const occ_format_t format, const uint64_t size,
                               const float res)
{
    if (!occ_finite(res) || !(res >= 1e-6f) || !(res < 1e6f)) {
        return OCC_ERR_UNSUPPORTED;
    }
    uint32_t bits;
    memcpy(&bits, &res, sizeof bits);
    const int32_t bexp = (int32_t)((bits >> 23) & 0xFFu);
    const uint32_t m = (bits & 0x7FFFFFu) | 0x800000u;
    const unsigned shift = (unsigned)(150 - bexp);  /* res = m / 2^shift; 1e-6..1e6 -> 24..63 */
    if (shift > 62u) {
        return OCC_ERR_UNSUPPORTED;
    }
    /* Six significant digits: find e with 10^5 <= round(res * 10^(5-e)) < 10^6. */
    int32_t e = 0;
    uint64_t d = 0u;
    for (unsigned iter = 0; iter < 16u; iter++) {
        if (5 - e < 0 || 5 - e > 11) {
            return OCC_ERR_UNSUPPORTED;
        }
        d = scaled_round(m, (unsigned)(5 - e), shift);
        if (d < 100000u) {
            e--;
        } else if (d >= 1000000u) {
            e++;
        } else {
            break;
        }
    }
    char digits[7];
    for (int i = 5; i >= 0; i--) {
        digits[i] = (char)('0' + (int)(d % 10u));
        d /= 10u;
    }
    unsigned nd = 6u;
    while (nd > 1u && digits[nd - 1u] == '0') {
        nd--;
    }
    char out[24];
    unsigned o = 0u;
    if (e < -4) {  /* %g switches to the exponent form: d.ddddde-0X */
        out[o++] = digits[0];
        if (nd > 1u) {
            out[o++] = '.';
            for (unsigned i = 1; i < nd; i++) {
                out[o++] = digits[i];
            }
        }
        out[o++] = 'e';
        out[o++] = '-';
        out[o++] = '0';
        out[o++] = (char)('0' + -e);
    } else if (e < 0) {
        out[o++] = '0';
        out[o++] = '.';
        for (int i = -1; i > e; i--) {
            out[o++] = '0';
        }
        for (unsigned i = 0; i < nd; i++) {
            out[o++] = digits[i];
        }
    } else {
        const unsigned ip = (unsigned)e + 1u;
        for (unsigned i = 0; i < ip; i++) {
            out[o++] = digits[i];
        }
        if (nd > ip) {
            out[o++] = '.';
            for (unsigned i = ip; i < nd; i++) {
                out[o++] = digits[i];
            }
        }
    }
    occi_sink_str(s, format == OCC_FORMAT_BT ? magic_bt : magic_ot);
    occi_sink_str(s, "\n");
    occi_sink_str(s, comment);
    occi_sink_str(s, "id OcTree\nsize ");
    occi_sink_dec(s, size);
    occi_sink_str(s, "\nres ");
    occi_sink_put(s, out, o);
    occi_sink_str(s, "\ndata\n");
    return s->err;
}
