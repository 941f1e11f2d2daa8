/* SPDX-License-Identifier: BSD-3-Clause */
/* run_config.c - `occmap run --config FILE`: sensor mounts and options as key = value lines,
 * turned into command-line options placed before the real ones (see run.h). */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "run.h"

#define LINE_MAX_LEN 1024

static char *trim(char *s)
{
    while (isspace((unsigned char)*s)) {
        s++;
    }
    size_t n = strlen(s);
    while (n > 0u && isspace((unsigned char)s[n - 1u])) {
        s[--n] = '\0';
    }
    return s;
}

static char *dup_opt(const char *prefix, const char *s)
{
    char *const d = malloc(strlen(prefix) + strlen(s) + 1u);
    if (d != NULL) {
        strcpy(d, prefix);
        strcat(d, s);
    }
    return d;
}

static bool push(char ***v, int *n, int *cap, char *s)
{
    if (s == NULL) {
        return false;
    }
    if (*n == *cap) {
        const int c = *cap == 0 ? 32 : 2 * *cap;
        char **const p = realloc(*v, (size_t)c * sizeof *p);
        if (p == NULL) {
            return false;
        }
        *v = p;
        *cap = c;
    }
    (*v)[(*n)++] = s;
    return true;
}

static bool is_true(const char *v)
{
    return strcmp(v, "true") == 0 || strcmp(v, "yes") == 0 || strcmp(v, "1") == 0;
}

/* One line into options; 0, or 2 after a message. */
static int take_line(const char *path, int lineno, char *line, char ***v, int *n, int *cap)
{
    char *const hash = strchr(line, '#');
    if (hash != NULL) {
        *hash = '\0';
    }
    char *const s = trim(line);
    if (*s == '\0') {
        return 0;
    }
    char *const eq = strchr(s, '=');
    if (eq == NULL) {
        cli_error("run", "%s:%d: want key = value", path, lineno);
        return 2;
    }
    *eq = '\0';
    const char *const key = trim(s);
    const char *const val = trim(eq + 1);
    char *const opt = dup_opt(strlen(key) == 1u ? "-" : "--", key); /* o = FILE is -o FILE */
    if (*key == '\0' || opt == NULL || strcmp(key, "config") == 0) {
        cli_error("run", "%s:%d: bad key '%s'", path, lineno, key);
        free(opt);
        return 2;
    }
    if (run_args_is_flag(opt)) {
        if (!is_true(val) && strcmp(val, "false") != 0 && strcmp(val, "no") != 0 &&
            strcmp(val, "0") != 0) {
            cli_error("run", "%s:%d: %s wants true or false", path, lineno, key);
            free(opt);
            return 2;
        }
        if (!is_true(val)) {
            free(opt);
            return 0;
        }
        return push(v, n, cap, opt) ? 0 : 2;
    }
    if (*val == '\0') {
        cli_error("run", "%s:%d: %s has no value", path, lineno, key);
        free(opt);
        return 2;
    }
    return push(v, n, cap, opt) && push(v, n, cap, dup_opt("", val)) ? 0 : 2;
}

static int read_file(const char *path, char ***v, int *n, int *cap)
{
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        cli_error("run", "cannot read --config %s", path);
        return 2;
    }
    char line[LINE_MAX_LEN];
    int status = 0;
    for (int lineno = 1; status == 0 && fgets(line, sizeof line, f) != NULL; lineno++) {
        if (strchr(line, '\n') == NULL && !feof(f)) {
            cli_error("run", "%s:%d: line too long", path, lineno);
            status = 2;
        } else {
            status = take_line(path, lineno, line, v, n, cap);
        }
    }
    (void)fclose(f);
    return status;
}

int run_config_expand(int argc, char **argv, int *out_argc, char ***out_argv)
{
    static char **v; /* kept until exit: the options point into it */
    int n = 0;
    int cap = 0;
    *out_argc = argc;
    *out_argv = argv;
    if (argc < 1 || !push(&v, &n, &cap, argv[0])) {
        return argc < 1 ? 0 : 2;
    }
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0) {
            if (i + 1 >= argc) {
                cli_error("run", "--config needs a value");
                return 2;
            }
            const int status = read_file(argv[++i], &v, &n, &cap);
            if (status != 0) {
                return status;
            }
        }
    }
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0) {
            i++;
        } else if (!push(&v, &n, &cap, argv[i])) {
            return 2;
        }
    }
    *out_argc = n;
    *out_argv = v;
    return 0;
}
