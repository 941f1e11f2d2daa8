/* SPDX-License-Identifier: BSD-3-Clause */
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

/* A decimal mantissa: up to 19 significant digits, the rest only counted in the exponent. */
typedef struct {
    uint64_t mant;
    int32_t exp10;
    unsigned digits; /* significant digits in mant */
    bool any;        /* a digit was seen */
} decimal_t;

/* The digits of "123.456" from p into *d; returns the position after them. */
static size_t scan_mantissa(const occ_cursor_t *const c, size_t p, decimal_t *const d)
{
    while (p < c->len && is_digit(c->buf[p])) {
        d->any = true;
        if (d->digits < 19u) {
            d->mant = d->mant * 10u + (uint64_t)(c->buf[p] - '0');
            if (d->mant != 0u) {
                d->digits++;
            }
        } else if (d->exp10 < 100000) { /* an int32_t that a 2 GiB run of digits cannot wrap */
            d->exp10++;
        }
        p++;
    }
    if (p < c->len && c->buf[p] == '.') {
        p++;
        while (p < c->len && is_digit(c->buf[p])) {
            d->any = true;
            if (d->digits < 19u && d->exp10 > -100000) {
                d->mant = d->mant * 10u + (uint64_t)(c->buf[p] - '0');
                d->exp10--;
                if (d->mant != 0u) {
                    d->digits++;
                }
            }
            p++;
        }
    }
    return p;
}

/* An exponent "e-12" at p added to *exp10; returns the position after it (p itself when there
 * is none: "1e" reads as 1). */
static size_t scan_exponent(const occ_cursor_t *const c, const size_t p, int32_t *const exp10)
{
    if (!(p < c->len && (c->buf[p] == 'e' || c->buf[p] == 'E'))) {
        return p;
    }
    size_t q = p + 1u;
    bool eneg = false;
    if (q < c->len && (c->buf[q] == '+' || c->buf[q] == '-')) {
        eneg = c->buf[q] == '-';
        q++;
    }
    if (!(q < c->len && is_digit(c->buf[q]))) {
        return p;
    }
    int32_t e = 0;
    while (q < c->len && is_digit(c->buf[q])) {
        if (e < 10000) {
            e = e * 10 + (int32_t)(c->buf[q] - '0');
        }
        q++;
    }
    *exp10 += eneg ? -e : e;
    return q;
}

/* mant * 10^exp10 in float: one correctly rounded step when both parts are exact, else
 * stepwise. */
static float scale_pow10(const uint64_t mant, int32_t exp10)
{
    float v = (float)mant;
    while (exp10 > 10 && v < 1e30f) {
        v *= 1e10f;
        exp10 -= 10;
    }
    while (exp10 < -10 && v > 1e-30f) {
        v /= 1e10f;
        exp10 += 10;
    }
    if (exp10 > 10 || exp10 < -10) {
        return exp10 > 0 ? 3.0e38f * 10.0f : 0.0f;  /* saturates: rejected by the range check */
    }
    return exp10 >= 0 ? v * pow10f_exact[exp10] : v / pow10f_exact[-exp10];
}

/* A decimal number as istream >> double reads it; float result. */
static bool parse_real(occ_cursor_t *const c, float *const out)
{
    size_t p = c->pos;
    bool neg = false;
    if (p < c->len && (c->buf[p] == '+' || c->buf[p] == '-')) {
        neg = c->buf[p] == '-';
        p++;
    }
    decimal_t d = {0u, 0, 0u, false};
    p = scan_mantissa(c, p, &d);
    if (!d.any) {
        return false;
    }
    c->pos = scan_exponent(c, p, &d.exp10);
    const float v = scale_pow10(d.mant, d.exp10);
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

/* The first line: which format's magic it is. */
static occ_err_t read_magic(occ_cursor_t *const c, occ_om_header_t *const h)
{
    const size_t nb = sizeof magic_bt - 1u, no = sizeof magic_ot - 1u;
    if (c->len >= nb && memcmp(c->buf, magic_bt, nb) == 0) {
        h->format = OCC_FORMAT_BT;
    } else if (c->len >= no && memcmp(c->buf, magic_ot, no) == 0) {
        h->format = OCC_FORMAT_OT;
    } else {
        return occ_cursor_fail(c, 0u, "wrong magic: not an OctoMap .bt/.ot header");
    }
    c->pos = 0u;
    return skip_line(c) ? OCC_OK : occ_cursor_fail(c, c->len, "truncated header");
}

/* The id token after "id" (at c->pos, whitespace skipped) into h->id. */
static occ_err_t read_id(occ_cursor_t *const c, occ_om_header_t *const h)
{
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
    return OCC_OK;
}

/* The value after a keyword of length n at c->pos, past the whitespace between them. */
static void skip_keyword(occ_cursor_t *const c, const size_t n)
{
    c->pos += n;
    skip_ws(c);
}

/* One entry: the token of length n at c->pos and what belongs to it - a comment line, "id",
 * "res" or "size" and its value, an unknown keyword (skipped to the end of its line). */
static occ_err_t read_entry(occ_cursor_t *const c, const size_t n, occ_om_header_t *const h,
                            bool *const have_res)
{
    if (c->buf[c->pos] == '#') {
        c->pos += n;
        return skip_line(c) ? OCC_OK : occ_cursor_fail(c, c->len, "truncated header comment");
    }
    if (token_is(c, n, "id")) {
        skip_keyword(c, n);
        return read_id(c, h);
    }
    if (token_is(c, n, "res")) {
        skip_keyword(c, n);
        if (!parse_real(c, &h->res)) {
            return occ_cursor_fail(c, c->pos, "malformed res");
        }
        *have_res = true;
        return OCC_OK;
    }
    if (token_is(c, n, "size")) {
        skip_keyword(c, n);
        return parse_uint(c, &h->size) ? OCC_OK
                                       : occ_cursor_fail(c, c->pos, "malformed or absurd size");
    }
    h->warnings |= OCC_IO_WARN_UNKNOWN_KEY;
    c->pos += n;
    return skip_line(c) ? OCC_OK : occ_cursor_fail(c, c->len, "truncated header");
}

/* After "data": an id and a sane resolution are there; the legacy id "1" reads as "OcTree". */
static occ_err_t finish_header(occ_cursor_t *const c, occ_om_header_t *const h,
                               const bool have_res)
{
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

occ_err_t occi_om_header_parse(occ_cursor_t *const c, occ_om_header_t *const h)
{
    memset(h, 0, sizeof *h);
    occ_err_t e = read_magic(c, h);
    bool have_res = false;
    while (e == OCC_OK) {
        skip_ws(c);
        if (c->pos >= c->len) {
            return occ_cursor_fail(c, c->pos, "truncated header: no 'data' line");
        }
        const size_t n = token_len(c);
        if (token_is(c, n, "data")) {
            c->pos += n;
            if (!skip_line(c)) {
                return occ_cursor_fail(c, c->len, "truncated header after 'data'");
            }
            h->data_offset = c->pos;
            return finish_header(c, h, have_res);
        }
        e = read_entry(c, n, h, &have_res);
    }
    return e;
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

/* res's six significant digits (as %g rounds them) into digits[0..*nd), trailing zeros dropped,
 * and the decimal exponent of the first: res ~ d.ddddd * 10^e. False outside [1e-6, 1e6). */
static bool res_digits(const float res, char digits[6], unsigned *const nd, int32_t *const e_out)
{
    if (!occ_finite(res) || !(res >= 1e-6f) || !(res < 1e6f)) {
        return false;
    }
    uint32_t bits;
    memcpy(&bits, &res, sizeof bits);
    const int32_t bexp = (int32_t)((bits >> 23) & 0xFFu);
    const uint32_t m = (bits & 0x7FFFFFu) | 0x800000u;
    const unsigned shift = (unsigned)(150 - bexp);  /* res = m / 2^shift; 1e-6..1e6 -> 24..63 */
    if (shift > 62u) {
        return false;
    }
    /* Six significant digits: find e with 10^5 <= round(res * 10^(5-e)) < 10^6. */
    int32_t e = 0;
    uint64_t d = 0u;
    for (unsigned iter = 0; iter < 16u; iter++) {
        if (5 - e < 0 || 5 - e > 11) {
            return false;
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
    for (int i = 5; i >= 0; i--) {
        digits[i] = (char)('0' + (int)(d % 10u));
        d /= 10u;
    }
    *nd = 6u;
    while (*nd > 1u && digits[*nd - 1u] == '0') {
        (*nd)--;
    }
    *e_out = e;
    return true;
}

/* Appends digits[from..to) to out at *o. */
static void put_digits(char *const out, unsigned *const o, const char *const digits,
                       const unsigned from, const unsigned to)
{
    for (unsigned i = from; i < to; i++) {
        out[(*o)++] = digits[i];
    }
}

/* %g of d.ddddd * 10^e (nd digits, e >= -6) into out (24 bytes); returns its length. */
static unsigned format_g(const char digits[6], const unsigned nd, const int32_t e,
                         char out[24])
{
    unsigned o = 0u;
    if (e < -4) {  /* %g switches to the exponent form: d.ddddde-0X */
        out[o++] = digits[0];
        if (nd > 1u) {
            out[o++] = '.';
            put_digits(out, &o, digits, 1u, nd);
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
        put_digits(out, &o, digits, 0u, nd);
    } else {
        const unsigned ip = (unsigned)e + 1u;
        put_digits(out, &o, digits, 0u, ip);
        if (nd > ip) {
            out[o++] = '.';
            put_digits(out, &o, digits, ip, nd);
        }
    }
    return o;
}

occ_err_t occi_om_header_write(occ_sink_t *const s, const occ_format_t format, const uint64_t size,
                               const float res)
{
    char digits[6];
    unsigned nd = 0u;
    int32_t e = 0;
    if (!res_digits(res, digits, &nd, &e)) {
        return OCC_ERR_UNSUPPORTED;
    }
    char out[24];
    const unsigned o = format_g(digits, nd, e, out);
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
