#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

void cli_error(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fputs("glint: error: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void cli_warning(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fputs("glint: warning: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
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
    if (strcmp(text, "auto") == 0) *plan = PLAN_AUTO;
    else if (strcmp(text, "full") == 0) *plan = PLAN_FULL;
    else return cli_error("%s: expected auto or full, got '%s'", option, text), -1;
    return 0;
}

int cli_parse_size(const char *option, const char *text, int *width, int *height) {
    char *end = NULL;
    errno = 0;
    long w = strtol(text, &end, 10);
    long h = 0;
    int ok = !errno && end != text && (*end == 'x' || *end == 'X');
    if (ok) {
        const char *hs = end + 1;
        h = strtol(hs, &end, 10);
        ok = !errno && end != hs && *end == '\0';
    }
    if (!ok || w < 1 || h < 1 || w > 16384 || h > 16384) {
        cli_error("%s: expected WIDTHxHEIGHT (1..16384 each), got '%s'", option, text);
        return -1;
    }
    *width = (int)w;
    *height = (int)h;
    return 0;
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
           "the program; without one, builtin:%s. The built-in scenes:\n", b[0].name);
    for (int i = 0; i < n; i++) printf("  %-10s %s\n", b[i].name, b[i].description);
}

const char *cli_value(int argc, char **argv, int *i) {
    if (*i + 1 >= argc) {
        cli_error("%s needs a value (see --help)", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

double cli_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cli_check_output_dir(const char *option, const char *path) {
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == path) snprintf(dir, sizeof dir, "/");
    else snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (access(dir, W_OK | X_OK) != 0) {
        cli_error("%s: %s: cannot write into directory '%s' (%s)", option, path, dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* ---- many-light parameters ------------------------------------------------------------------- */

const char *cli_vl_help(void) {
    static char text[4096];
    snprintf(text, sizeof text,
             "many-light methods (vpl, vsl):\n"
             "  --vsl-count N        virtual lights traced per frame [%d]\n"
             "  --clamp on|off       clamp each light's contribution [on for vpl, off for vsl]\n"
             "  --clamp-value C      the clamp bound, in radiance [%g]\n"
             "  --clamp-growth A|off the bound grows as C * frame^A, so clamped VPLs converge [%g]\n"
             "  --vpl-glossy         VPLs reflect with their full BSDF, not only its diffuse part\n"
             "  --radius-mult M      VSL radius: M x distance to the 10th nearest light [%g]\n"
             "  --radius-shrink A|off  0 < A < 1: M shrinks over frames (progressive photon mapping's\n"
             "                       schedule), so VSLs converge to the path-traced answer [%g]\n"
             "  --rows R             matrix row-column sampling: sampled rows (pixels) [%d]\n"
             "  --columns C          ... and clusters; 0 = no clustering [0]\n"
             "  --per-pixel N|all    lights (cluster representatives) each pixel shades per frame,\n"
             "                       picked by power (cluster norm) [%d; all with --columns]\n"
             "  --light-select power|tree  where a pixel's light draws come from: by power, or\n"
             "                       through a light tree by an estimate of what each sends there [power]\n"
             "  --candidates M       draws per pixel, from which its lights are resampled by that\n"
             "                       estimate; 1 = the draws are shaded as they come [%d]\n"
             "  --trace-glossy A|off receivers' glossy lobes with roughness alpha below A are not\n"
             "                       gathered from the lights: the path goes on through them [%g]\n"
             "  --glossy-rays N      directions traced through such a lobe at the camera hit, 1..%d [%d]\n"
             "indirect highlights (vsl+hl):\n"
             "  --secondary-rays N   rays sampled from a camera hit's glossy lobe, 1..%d [%d]\n"
             "  --clusters K         merged vMF lobes per camera hit, 1..%d [%d]\n"
             "  --merge on|off|trace off: every secondary hit's own vMF lobe is lit by itself (the\n"
             "                       paper's comparison); trace: no vMFs, each hit's true glossy lobe\n"
             "                       (the path tracer's answer for the same paths) [on]\n",
             VL_DEFAULT_COUNT, (double)VL_DEFAULT_CLAMP, (double)VL_DEFAULT_CLAMP_GROWTH, (double)VL_DEFAULT_RADIUS_MULT,
             (double)VL_DEFAULT_RADIUS_SHRINK, VL_DEFAULT_ROWS,
             VL_DEFAULT_PER_PIXEL, VL_DEFAULT_CANDIDATES, (double)VL_DEFAULT_TRACE_GLOSSY, VL_MAX_GLOSSY_RAYS, VL_DEFAULT_GLOSSY_RAYS,
             HL_MAX_SECONDARY_RAYS, HL_DEFAULT_SECONDARY_RAYS, HL_MAX_CLUSTERS, HL_DEFAULT_CLUSTERS);
    return text;
}

static int on_off(const char *option, const char *value, int *out) {
    if (strcmp(value, "on") == 0) *out = 1;
    else if (strcmp(value, "off") == 0) *out = 0;
    else return cli_error("%s: expected on or off, got '%s'", option, value), -1;
    return 0;
}

int cli_set_vl_param(const char *name, const char *value, vl_params *vl) {
    char option[64];
    snprintf(option, sizeof option, "--%s", name);
    long long n;
    double x;
    int b;
    if (strcmp(name, "vsl-count") == 0) {
        if (cli_parse_int(option, value, 1, 50000000, &n)) return -1;
        vl->count = (int)n;
    } else if (strcmp(name, "clamp") == 0) {
        if (on_off(option, value, &b)) return -1;
        vl->clamp = b ? VL_CLAMP_ON : VL_CLAMP_OFF;
    } else if (strcmp(name, "clamp-value") == 0) {
        if (cli_parse_float(option, value, 1e-12, 1e30, &x)) return -1;
        vl->clamp_value = (float)x;
    } else if (strcmp(name, "clamp-growth") == 0) {
        if (strcmp(value, "off") == 0) x = 0.0;
        else if (cli_parse_float(option, value, 0.0, 10.0, &x)) return -1;
        vl->clamp_growth = x > 0.0 ? (float)x : -1.0f; /* 0 is off too, not the default */
    } else if (strcmp(name, "vpl-glossy") == 0) {
        if (on_off(option, value, &b)) return -1;
        vl->vpl_glossy = b;
    } else if (strcmp(name, "radius-mult") == 0) {
        if (cli_parse_float(option, value, 1e-6, 1e6, &x)) return -1;
        vl->radius_mult = (float)x;
    } else if (strcmp(name, "radius-shrink") == 0) {
        if (strcmp(value, "off") == 0) x = 0.0;
        else if (cli_parse_float(option, value, 0.0, 1.0, &x)) return -1;
        if (x >= 1.0) return cli_error("%s: must be below 1 (0 or off turns it off), got '%s'", option, value), -1;
        vl->radius_shrink = x > 0.0 ? (float)x : -1.0f;
    } else if (strcmp(name, "rows") == 0) {
        if (cli_parse_int(option, value, 1, 100000, &n)) return -1;
        vl->rows = (int)n;
    } else if (strcmp(name, "columns") == 0) {
        if (cli_parse_int(option, value, 0, 10000000, &n)) return -1;
        vl->columns = (int)n;
    } else if (strcmp(name, "per-pixel") == 0) {
        if (strcmp(value, "all") == 0) vl->per_pixel = -1;
        else if (cli_parse_int(option, value, 1, 1000000, &n)) return -1;
        else vl->per_pixel = (int)n;
    } else if (strcmp(name, "light-select") == 0) {
        if (strcmp(value, "tree") == 0) vl->select = VL_SELECT_TREE;
        else if (strcmp(value, "power") == 0) vl->select = VL_SELECT_POWER;
        else return cli_error("%s: expected tree or power, got '%s'", option, value), -1;
    } else if (strcmp(name, "candidates") == 0) {
        if (cli_parse_int(option, value, 1, VL_MAX_CANDIDATES, &n)) return -1;
        vl->candidates = (int)n;
    } else if (strcmp(name, "trace-glossy") == 0) {
        if (strcmp(value, "off") == 0) vl->trace_glossy = -1.0f;
        else if (cli_parse_float(option, value, 0.0, 10.0, &x)) return -1;
        else vl->trace_glossy = x > 0.0 ? (float)x : -1.0f; /* 0 is off too, not the default */
    } else if (strcmp(name, "glossy-rays") == 0) {
        if (cli_parse_int(option, value, 1, VL_MAX_GLOSSY_RAYS, &n)) return -1;
        vl->glossy_rays = (int)n;
    } else if (strcmp(name, "secondary-rays") == 0) {
        if (cli_parse_int(option, value, 1, HL_MAX_SECONDARY_RAYS, &n)) return -1;
        vl->secondary_rays = (int)n;
    } else if (strcmp(name, "clusters") == 0) {
        if (cli_parse_int(option, value, 1, HL_MAX_CLUSTERS, &n)) return -1;
        vl->clusters = (int)n;
    } else if (strcmp(name, "merge") == 0) {
        if (strcmp(value, "trace") == 0) vl->merge = HL_MERGE_TRACE;
        else if (on_off(option, value, &b)) return -1;
        else vl->merge = b ? HL_MERGE_ON : HL_MERGE_OFF;
    } else {
        return 0;
    }
    return 1;
}

int cli_vl_option(int argc, char **argv, int *i, vl_params *vl) {
    const char *a = argv[*i];
    if (strncmp(a, "--", 2) != 0) return 0;
    if (strcmp(a, "--vpl-glossy") == 0) return cli_set_vl_param("vpl-glossy", "on", vl);
    static const char *const names[] = {"vsl-count", "clamp", "clamp-value", "clamp-growth", "radius-mult",
                                         "radius-shrink", "rows", "columns", "per-pixel", "light-select", "candidates",
                                         "trace-glossy", "glossy-rays", "secondary-rays", "clusters", "merge"};
    int ours = 0;
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) ours |= strcmp(a + 2, names[k]) == 0;
    if (!ours) return 0;
    const char *v = cli_value(argc, argv, i);
    if (!v) return -1;
    return cli_set_vl_param(a + 2, v, vl);
}
