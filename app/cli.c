#define _XOPEN_SOURCE 700 /* realpath */
#include "cli.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* One line on stderr, written at once so lines from two threads do not interleave. */
static void message(const char *kind, const char *fmt, va_list ap) {
    char text[2048];
    vsnprintf(text, sizeof text, fmt, ap);
    fprintf(stderr, "glint: %s: %s\n", kind, text);
}

void cli_error(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    message("error", fmt, ap);
    va_end(ap);
}

void cli_warning(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    message("warning", fmt, ap);
    va_end(ap);
}

void cli_print_warning(void *user, const char *message) {
    (void)user;
    cli_warning("%s", message);
}

int cli_parse_int(const char *option, const char *text, long long lo, long long hi, long long *out) {
    char *end = NULL;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (errno || end == text || *end != '\0' || v < lo || v > hi) {
        cli_error("%s: expected an integer in [%lld, %lld], got '%s'", option, lo, hi, text);
        return -1;
    }
    *out = v;
    return 0;
}

int cli_parse_u64(const char *option, const char *text, uint64_t *out) {
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || end == text || *end != '\0' || text[0] == '-') {
        cli_error("%s: expected a non-negative integer, got '%s'", option, text);
        return -1;
    }
    *out = v;
    return 0;
}

int cli_parse_float(const char *option, const char *text, double lo, double hi, double *out) {
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || end == text || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        cli_error("%s: expected a number in [%g, %g], got '%s'", option, lo, hi, text);
        return -1;
    }
    *out = v;
    return 0;
}

int cli_parse_plan(const char *option, const char *text, int *plan) {
    render_params p = {0};
    char err[256];
    if (param_parse(param_find("plan"), text, &p, err, sizeof err) != 0) return cli_error("%s: %s", option, err), -1;
    *plan = p.plan;
    return 0;
}

int cli_parse_size(const char *option, const char *text, int *width, int *height) {
    char err[256];
    if (params_parse_size(text, width, height, err, sizeof err) == 0) return 0;
    cli_error("%s: %s", option, err);
    return -1;
}

int cli_scene_argument(const char *command, const char *arg, const char **scene_path) {
    if (arg[0] == '-') return cli_error("unknown option '%s' (see glint %s --help)", arg, command), -1;
    if (*scene_path) return cli_error("more than one scene given ('%s' and '%s')", *scene_path, arg), -1;
    *scene_path = arg;
    return 0;
}

void cli_print_scenes(void) {
    int n;
    const builtin_scene *b = scene_builtins(&n);
    printf("SCENE is a glTF 2.0 file (.gltf or .glb) or builtin:NAME, one of the scenes compiled into\n"
           "the program; without one, builtin:%s. The built-in scenes:\n",
           b[0].name);
    for (int i = 0; i < n; i++) printf("  %-10s %s\n", b[i].name, b[i].description);
}

const char *cli_value(int argc, char **argv, int *i) {
    if (*i + 1 >= argc) {
        cli_error("%s needs a value (see --help)", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

int cli_table_option(int argc, char **argv, int *i, const cli_opt *opts, int n) {
    const char *a = argv[*i];
    const cli_opt *o = NULL;
    for (int k = 0; k < n && !o; k++)
        if (strcmp(a, opts[k].name) == 0) o = &opts[k];
    if (!o) return 0;
    if (o->given) *o->given = 1;
    if (o->kind == CLI_FLAG) return *(int *)o->out = 1, 1;
    const char *v = cli_value(argc, argv, i);
    if (!v) return -1;
    long long n_ll;
    switch (o->kind) {
    case CLI_INT:
        if (cli_parse_int(a, v, (long long)o->lo, (long long)o->hi, &n_ll)) return -1;
        *(int *)o->out = (int)n_ll;
        return 1;
    case CLI_LONG: return cli_parse_int(a, v, (long long)o->lo, (long long)o->hi, o->out) ? -1 : 1;
    case CLI_U64: return cli_parse_u64(a, v, o->out) ? -1 : 1;
    case CLI_FLOAT: return cli_parse_float(a, v, o->lo, o->hi, o->out) ? -1 : 1;
    case CLI_SIZE: return cli_parse_size(a, v, o->out, o->out2) ? -1 : 1;
    case CLI_TEXT: return *(const char **)o->out = v, 1;
    case CLI_PLAN: return cli_parse_plan(a, v, o->out) ? -1 : 1;
    case CLI_PARAM: return cli_set_param(a + 2, v, o->out, PARAM_GROUPS_ALL);
    case CLI_FLAG: break;
    }
    return 0;
}

double cli_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cli_check_output_dir(const char *option, const char *path) {
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (access(dir, W_OK | X_OK) != 0) {
        cli_error("%s: %s: cannot write into directory '%s' (%s)", option, path, dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* The file path names, as "DIR-resolved/NAME" when the directory exists (out: PATH_MAX). */
static void file_identity(const char *path, char *out, size_t outlen) {
    char dir[4096], resolved[PATH_MAX];
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    if (realpath(dir, resolved))
        snprintf(out, outlen, "%s/%s", resolved, name);
    else
        snprintf(out, outlen, "%s", path);
}

static int same_file(const char *a, const char *b) {
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char ia[PATH_MAX + 256], ib[PATH_MAX + 256];
    file_identity(a, ia, sizeof ia);
    file_identity(b, ib, sizeof ib);
    return strcmp(ia, ib) == 0;
}

int cli_check_roles(const cli_file *outputs, int num_outputs, const cli_file *inputs, int num_inputs) {
    for (int i = 0; i < num_outputs; i++) {
        if (!outputs[i].path) continue;
        for (int j = i + 1; j < num_outputs; j++)
            if (outputs[j].path && same_file(outputs[i].path, outputs[j].path))
                return cli_error("%s and %s name the same file '%s'", outputs[i].role, outputs[j].role,
                                 outputs[i].path),
                       -1;
        for (int j = 0; j < num_inputs; j++)
            if (inputs[j].path && same_file(outputs[i].path, inputs[j].path))
                return cli_error("%s '%s' is %s: it would be replaced", outputs[i].role, outputs[i].path,
                                 inputs[j].role),
                       -1;
    }
    return 0;
}

/* ---- render parameters: the table in params.c ------------------------------------------------ */

const char *cli_vl_help(void) { return params_help(); }

int cli_set_param(const char *name, const char *value, render_params *p, unsigned groups) {
    char err[256];
    int r = params_set(p, groups, name, value, err, sizeof err);
    if (r < 0) cli_error("--%s: %s", name, err);
    return r;
}

int cli_param_option(int argc, char **argv, int *i, render_params *p, unsigned groups) {
    const char *a = argv[*i];
    if (strncmp(a, "--", 2) != 0) return 0;
    const param_desc *d = param_find(a + 2);
    if (!d || !(groups >> d->group & 1u)) return 0;
    if (d->flag) { /* alone it is on; a choice of its own may follow (--denoise off) */
        const char *next = *i + 1 < argc ? argv[*i + 1] : NULL;
        for (int c = 0; next && c < d->num_choices; c++)
            if (d->choices[c].name && strcmp(next, d->choices[c].name) == 0)
                return cli_set_param(d->name, argv[++*i], p, groups);
        return cli_set_param(d->name, "on", p, groups);
    }
    const char *v = cli_value(argc, argv, i);
    if (!v) return -1;
    return cli_set_param(d->name, v, p, groups);
}
