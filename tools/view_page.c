/* SPDX-License-Identifier: BSD-3-Clause */
/* view_page.c - the HTML page of `occmap view`: one file that opens offline. The rendering
 * library (three.js, pinned and fetched by tools/view.mk) and the page's script (view_app.js)
 * are inlined; the voxels are a base64 array per kind, decoded by view_app.js. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "view.h"
#include "occmap/host/occ_file.h"

/* The scripts inlined, in order, from the assets folder. */
static const char *const asset_names[] = {"three.min.js", "OrbitControls.js", "view_app.js"};

/* Copy a script into the page; "</script" inside it would end the element, so it is written
 * "<\/script" (the same text for JavaScript inside a string, where it can only occur). */
static void put_script(FILE *f, const uint8_t *js, const size_t len)
{
    static const char end_tag[] = "</script";
    const size_t tag_len = sizeof end_tag - 1u;
    size_t from = 0;
    fputs("<script>\n", f);
    for (size_t i = 0; i + tag_len <= len; i++) {
        if (memcmp(js + i, end_tag, tag_len) == 0) {
            fwrite(js + from, 1, i - from, f);
            fputs("<\\/script", f);
            from = i + tag_len;
            i += tag_len - 1u;
        }
    }
    fwrite(js + from, 1, len - from, f);
    fputs("\n</script>\n", f);
}

static void put_escaped(FILE *f, const char *s)
{
    for (; *s != '\0'; s++) {
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\\': fputs("&#92;", f); break;
        default: fputc(*s, f); break;
        }
    }
}

/* One kind of node as {"n":..,"kw":..,"min":[..],"b64":".."}: keys relative to the set's
 * minimum, little-endian in kw = 2 or 4 bytes, laid out x[n] y[n] z[n] level[n]. */
static int put_set(FILE *f, const char *name, const view_set_t *s)
{
    uint32_t lo[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < s->n; i++) {
        for (size_t a = 0; a < 3u; a++) {
            const uint32_t k = s->key[3u * i + a];
            lo[a] = k < lo[a] ? k : lo[a];
            hi[a] = k > hi[a] ? k : hi[a];
        }
    }
    unsigned kw = 2;
    for (size_t a = 0; a < 3u && s->n > 0u; a++) {
        kw = hi[a] - lo[a] > 0xFFFFu ? 4u : kw;
    }
    const size_t bytes = s->n * (3u * kw + 1u);
    uint8_t *buf = malloc(bytes > 0u ? bytes : 1u);
    if (buf == NULL) {
        return -1;
    }
    for (size_t a = 0; a < 3u; a++) {
        for (size_t i = 0; i < s->n; i++) {
            const uint32_t d = s->key[3u * i + a] - lo[a];
            for (unsigned b = 0; b < kw; b++) {
                buf[(a * s->n + i) * kw + b] = (uint8_t)(d >> (8u * b));
            }
        }
    }
    if (s->n > 0u) {
        memcpy(buf + 3u * kw * s->n, s->level, s->n);
    }
    fprintf(f, "\"%s\": {\"n\": %zu, \"kw\": %u, \"min\": [%lu, %lu, %lu], \"b64\": \"", name,
            s->n, kw, (unsigned long)(s->n > 0u ? lo[0] : 0u),
            (unsigned long)(s->n > 0u ? lo[1] : 0u), (unsigned long)(s->n > 0u ? lo[2] : 0u));
    view_base64(f, buf, bytes);
    fputs("\"}", f);
    free(buf);
    return 0;
}

/* The map's facts and the three sets as one global, OCC_MAP. */
static int put_data(FILE *f, const occ_map_t *map, const view_sets_t *sets)
{
    const occ_map_stats_t *st = &sets->stats;
    char b[7][CLI_NUM_CHARS];
    fprintf(f, "<script>\nvar OCC_MAP = {\"res\": %s, \"depth\": %u, \"has_known\": %s, "
               "\"bbox_min\": [%s, %s, %s], \"bbox_max\": [%s, %s, %s], "
               "\"occupied_leaves\": %llu, \"free_leaves\": %llu,\n",
            cli_json_float(b[6], map->cfg.resolution_m), (unsigned)map->cfg.depth_levels,
            st->has_known ? "true" : "false", cli_json_float(b[0], st->bbox_min.x),
            cli_json_float(b[1], st->bbox_min.y), cli_json_float(b[2], st->bbox_min.z),
            cli_json_float(b[3], st->bbox_max.x), cli_json_float(b[4], st->bbox_max.y),
            cli_json_float(b[5], st->bbox_max.z), (unsigned long long)st->occupied_leaves,
            (unsigned long long)st->free_leaves);
    if (put_set(f, "occupied", &sets->occupied) != 0 || fputs(",\n", f) < 0 ||
        put_set(f, "free", &sets->free) != 0 || fputs(",\n", f) < 0 ||
        put_set(f, "unknown", &sets->unknown) != 0) {
        return -1;
    }
    fputs("};\n</script>\n", f);
    return 0;
}

static const char page_head[] =
    "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    "<meta name=\"generator\" content=\"occmap view\">\n<title>occmap: ";
static const char page_style[] =
    "</title>\n<style>\n"
    "html, body { margin: 0; height: 100%; overflow: hidden; background: #1b1e23; "
    "font: 13px sans-serif; color: #e6e6e6; }\n"
    "#view { position: absolute; inset: 0; }\n"
    "#panel { position: absolute; top: 8px; left: 8px; padding: 8px 10px; "
    "background: rgba(0,0,0,0.55); border-radius: 4px; line-height: 1.6; }\n"
    "#panel label { display: block; cursor: pointer; }\n"
    "#status { color: #9aa; font-size: 12px; }\n"
    "</style>\n</head>\n<body>\n<div id=\"view\"></div>\n<div id=\"panel\">\n<b>occmap</b> ";
static const char page_panel[] =
    "\n<label><input type=\"checkbox\" id=\"show-occupied\" checked> occupied</label>\n"
    "<label><input type=\"checkbox\" id=\"show-free\"> free</label>\n"
    "<label><input type=\"checkbox\" id=\"show-unknown\"> unknown</label>\n"
    "<label><input type=\"checkbox\" id=\"show-bbox\" checked> bounding box</label>\n"
    "<div id=\"status\" data-drawn=\"-1\">loading</div>\n</div>\n";

int view_write_page(FILE *f, const occ_map_t *map, const view_sets_t *sets, const char *assets_dir,
                    const char *title, char *msg, const size_t msg_len)
{
    uint8_t *js[3] = {NULL, NULL, NULL};
    size_t js_len[3] = {0, 0, 0};
    int rc = 0;
    for (size_t i = 0; i < 3u && rc == 0; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", assets_dir, asset_names[i]);
        if (occ_file_read_all(path, &js[i], &js_len[i], msg, msg_len) != OCC_OK) {
            rc = -1;
        }
    }
    if (rc == 0) {
        fputs(page_head, f);
        put_escaped(f, title);
        fputs(page_style, f);
        put_escaped(f, title);
        fputs(page_panel, f);
        put_script(f, js[0], js_len[0]);
        put_script(f, js[1], js_len[1]);
        if (put_data(f, map, sets) != 0) {
            snprintf(msg, msg_len, "out of memory");
            rc = -1;
        } else {
            put_script(f, js[2], js_len[2]);
            fputs("</body>\n</html>\n", f);
        }
    }
    for (size_t i = 0; i < 3u; i++) {
        free(js[i]);
    }
    return rc;
}
