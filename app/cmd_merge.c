/* glint merge: shards of one render (glint render --shard I/N) combined into the image the whole
 * render gives: per pixel and channel, the means weighted by the samples each shard kept, and the
 * variances combined with the spread of the shards' means about the whole (Chan et al.'s
 * pairwise update), so a merge is a shard again and merges further. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "film.h"
#include "image_io.h"
#include "reference.h"

typedef struct {
    const char **parts;
    int num_parts;
    const char *out;
    int allow_partial, quiet;
} merge_options;

static void print_merge_help(void) {
    printf("usage: glint merge PART.exr... --out REF.exr [--allow-partial] [--quiet]\n"
           "\n"
           "Combines the shards of one render (glint render --shard I/N --out PART.exr, or earlier\n"
           "merges of them) into REF.exr: the image one render of all their samples gives, with its\n"
           "noise estimate and the moments to merge it further. Refuses parts of another scene,\n"
           "environment, camera, size, method, seed or parameters, a shard given twice, and a set\n"
           "that misses shards.\n"
           "\n"
           "  --out REF.exr     the merged reference (replaced when it exists)\n"
           "  --allow-partial   merge the shards given though some are missing; REF.exr records\n"
           "                    which it holds and its true sample count, and merges with the rest\n"
           "                    later\n"
           "  --quiet           no summary line\n");
}

/* 0 to merge, 1 after --help, -1 on a usage error (reported). */
static int parse_merge_options(int argc, char **argv, merge_options *o) {
    memset(o, 0, sizeof *o);
    o->parts = calloc((size_t)(argc > 0 ? argc : 1), sizeof *o->parts);
    if (!o->parts) return cli_error("out of memory"), -1;
    const cli_opt opts[] = {
        {.name = "--out", .kind = CLI_TEXT, .out = &o->out},
        {.name = "--allow-partial", .kind = CLI_FLAG, .out = &o->allow_partial},
        {.name = "--quiet", .kind = CLI_FLAG, .out = &o->quiet},
    };
    for (int i = 0; i < argc; i++) {
        int r;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            print_merge_help();
            return 1;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0) {
            if (r < 0) return -1;
        } else if (argv[i][0] == '-') {
            return cli_error("merge: unknown option '%s' (see glint merge --help)", argv[i]), -1;
        } else {
            o->parts[o->num_parts++] = argv[i];
        }
    }
    if (o->num_parts == 0) return cli_error("merge: no parts given (see glint merge --help)"), -1;
    if (!o->out) return cli_error("merge: --out REF.exr is required"), -1;
    return 0;
}

/* The descriptions of the parts, checked against the first and against each other: same render,
 * no shard twice, each with the frames its shards own. The union of their shards into *all.
 * 0, or -1 after the error. */
static int check_parts(const merge_options *o, reference_info *infos, reference_info *all) {
    char err[8192];
    for (int p = 0; p < o->num_parts; p++) {
        reference_info *r = &infos[p];
        int st = reference_load(o->parts[p], r, err, sizeof err);
        if (st < 0) return cli_error("%s", err), -1;
        if (st > 0 || r->shard_count == 0)
            return cli_error("%s: not a shard (render one with glint render --shard I/N --out FILE.exr)", o->parts[p]),
                   -1;
        if (p > 0 && reference_check_shard(o->parts[p], r, o->parts[0], &infos[0], err, sizeof err) != 0)
            return cli_error("%s", err), -1;
        long long share = 0;
        for (int i = 0; i < r->shard_count; i++) {
            if (!reference_has_shard(r, i)) continue;
            share += shard_share(r->spp_total, i, r->shard_count);
            for (int q = 0; q < p; q++)
                if (reference_has_shard(&infos[q], i))
                    return cli_error("%s: shard %d of %d is in %s too: merging it twice would count its samples "
                                     "twice",
                                     o->parts[p], i, r->shard_count, o->parts[q]),
                           -1;
        }
        if (r->spp_total > 0 && r->spp != share)
            return cli_error("%s: holds %lld spp, its shards of a %lld spp render hold %lld", o->parts[p], r->spp,
                             r->spp_total, share),
                   -1;
    }
    *all = infos[0];
    memset(all->shards, 0, sizeof all->shards);
    all->spp = 0;
    all->seconds = 0.0;
    char missing[1024] = "";
    int num_missing = 0;
    for (int i = 0; i < infos[0].shard_count; i++) {
        for (int p = 0; p < o->num_parts; p++)
            if (reference_has_shard(&infos[p], i)) reference_add_shard(all, i);
        if (reference_has_shard(all, i)) continue;
        size_t len = strlen(missing);
        if (num_missing++ < 20) snprintf(missing + len, sizeof missing - len, "%s%d", len ? ", " : "", i);
    }
    for (int p = 0; p < o->num_parts; p++) all->spp += infos[p].spp, all->seconds += infos[p].seconds;
    if (num_missing && !o->allow_partial)
        return cli_error("%s: shard%s %s%s of %d missing (give every part, or --allow-partial to merge these)", o->out,
                         num_missing > 1 ? "s" : "", missing, num_missing > 20 ? ", ..." : "", infos[0].shard_count),
               -1;
    if (num_missing)
        cli_warning("%s: shard%s %s%s of %d missing: merging %lld spp, not the whole render's", o->out,
                    num_missing > 1 ? "s" : "", missing, num_missing > 20 ? ", ..." : "", infos[0].shard_count,
                    all->spp);
    return 0;
}

/* The layers a part holds: the image ("") and its components, as glint render wrote them. */
typedef struct {
    const char *prefix[1 + COMP_COUNT];
    int n;
} layer_set;

static layer_set part_layers(const reference_info *r) {
    layer_set ls = {{"", "direct", "indirect"}, 3};
    if (r->highlights_layer) ls.prefix[ls.n++] = "highlights";
    return ls;
}

/* Per layer and channel: the sum of count x mean and of count x (variance + mean^2) over the parts
 * (the sums of the samples and of their squares), and per pixel the count. */
typedef struct {
    size_t pixels;
    double *sum[1 + COMP_COUNT][3], *sumsq[1 + COMP_COUNT][3];
    double *count, *rejected;
} accumulator;

static void accumulator_free(accumulator *a, int layers) {
    for (int l = 0; l < layers; l++)
        for (int k = 0; k < 3; k++) free(a->sum[l][k]), free(a->sumsq[l][k]);
    free(a->count);
    free(a->rejected);
}

static int accumulator_init(accumulator *a, size_t pixels, int layers) {
    memset(a, 0, sizeof *a);
    a->pixels = pixels;
    int ok = (a->count = calloc(pixels, sizeof(double))) && (a->rejected = calloc(pixels, sizeof(double)));
    for (int l = 0; l < layers; l++)
        for (int k = 0; k < 3; k++)
            ok = ok && (a->sum[l][k] = calloc(pixels, sizeof(double))) &&
                 (a->sumsq[l][k] = calloc(pixels, sizeof(double)));
    if (!ok) accumulator_free(a, layers);
    return ok ? 0 : -1;
}

/* The plane of channel "PREFIX.C" (or "C") of the layer's means (var 0) or variances (var 1). */
static const float *layer_channel(const exr_image *ex, const char *prefix, int var, int k) {
    char layer[96], name[128];
    if (var)
        film_moments_var_layer(prefix, layer, sizeof layer);
    else
        snprintf(layer, sizeof layer, "%s", prefix);
    snprintf(name, sizeof name, "%s%s%c", layer, layer[0] ? "." : "", "RGB"[k]);
    return exr_image_channel(ex, name);
}

/* Adds part p's pixels. 0, or -1 after the error. */
static int accumulate_part(accumulator *a, const char *path, const reference_info *r, const layer_set *ls) {
    char err[4400];
    exr_image ex;
    if (exr_image_load(path, &ex, err, sizeof err) != 0) return cli_error("%s", err), -1;
    int status = -1;
    if ((size_t)ex.width * (size_t)ex.height != a->pixels || ex.width != r->width) {
        cli_error("%s: %dx%d pixels, its description says %dx%d", path, ex.width, ex.height, r->width, r->height);
        goto done;
    }
    const float *rejected = exr_image_channel(&ex, MOMENTS_REJECTED ".R");
    if (!rejected) {
        cli_error("%s: no channel %s.R: not a shard's EXR", path, MOMENTS_REJECTED);
        goto done;
    }
    for (size_t i = 0; i < a->pixels; i++) {
        if (!(rejected[i] >= 0.0f && rejected[i] <= (float)r->spp && rejected[i] == floorf(rejected[i]))) {
            cli_error("%s: pixel %zu: %g samples dropped of %lld", path, i, (double)rejected[i], r->spp);
            goto done;
        }
    }
    for (int l = 0; l < ls->n; l++)
        for (int k = 0; k < 3; k++) {
            const float *mean = layer_channel(&ex, ls->prefix[l], 0, k), *var = layer_channel(&ex, ls->prefix[l], 1, k);
            if (!mean || !var) {
                cli_error("%s: no %s channel %s%s%c: not a shard's EXR", path, mean ? "variance" : "mean",
                          ls->prefix[l], ls->prefix[l][0] ? "." : "", "RGB"[k]);
                goto done;
            }
            for (size_t i = 0; i < a->pixels; i++) {
                double n = (double)r->spp - (double)rejected[i], m = (double)mean[i], v = (double)var[i];
                if (!isfinite(m) || !isfinite(v) || v < 0.0) {
                    cli_error("%s: pixel %zu: mean %g, variance %g", path, i, m, v);
                    goto done;
                }
                a->sum[l][k][i] += n * m;
                a->sumsq[l][k][i] += n * (v + m * m);
            }
        }
    for (size_t i = 0; i < a->pixels; i++) {
        a->count[i] += (double)r->spp - (double)rejected[i];
        a->rejected[i] += (double)rejected[i];
    }
    status = 0;
done:
    exr_image_free(&ex);
    return status;
}

/* The merged EXR: means, variances and dropped samples, as film_save_exr_attrs writes a shard's. */
static int write_merged(const char *path, const accumulator *a, const layer_set *ls, reference_info *all) {
    size_t n = a->pixels;
    enum { MAX_LAYERS = 2 * (1 + COMP_COUNT) + 1 };
    float *planes[MAX_LAYERS] = {0};
    exr_layer layers[MAX_LAYERS];
    char names[1 + COMP_COUNT][64];
    int nl = 0, status = -1;
    for (int l = 0; l < 2 * ls->n + 1; l++)
        if (!(planes[l] = malloc(sizeof(float) * 3 * n))) {
            cli_error("%s: out of memory", path);
            goto done;
        }
    for (int l = 0; l < ls->n; l++) {
        float *mean = planes[l], *var = planes[ls->n + l];
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) {
                double c = a->count[i], m = c > 0.0 ? a->sum[l][k][i] / c : 0.0;
                double v = c > 0.0 ? a->sumsq[l][k][i] / c - m * m : 0.0;
                /* each shard's numbers are finite floats; the spread of their means need not be */
                const double most = (double)FLT_MAX;
                if (!(fabs(m) <= most && v <= most)) {
                    cli_error("%s: pixel %zu: the merged %s %g does not fit in a float (the shards' means lie too "
                              "far apart)",
                              path, i, fabs(m) <= most ? "variance" : "mean", fabs(m) <= most ? v : m);
                    goto done;
                }
                mean[3 * i + (size_t)k] = (float)m;
                var[3 * i + (size_t)k] = v > 0.0 ? (float)v : 0.0f; /* rounding takes a constant pixel's below 0 */
            }
        layers[l] = (exr_layer){ls->prefix[l], mean};
        film_moments_var_layer(ls->prefix[l], names[l], sizeof names[l]);
        layers[ls->n + l] = (exr_layer){names[l], var};
    }
    nl = 2 * ls->n;
    for (size_t i = 0; i < 3 * n; i++) planes[nl][i] = (float)a->rejected[i / 3];
    layers[nl] = (exr_layer){MOMENTS_REJECTED, planes[nl]};
    nl++;
    const float *const m[3] = {planes[0], planes[0] + 1, planes[0] + 2};
    const float *const v[3] = {planes[ls->n], planes[ls->n] + 1, planes[ls->n] + 2};
    reference_noise_from_variance(m, v, 3, a->count, n, all);
    char *json = reference_json(all);
    if (!json) {
        cli_error("%s: out of memory", path);
        goto done;
    }
    char err[4400];
    exr_text_attr attr = {REFERENCE_ATTR, json};
    status = exr_save_layers_attrs(path, all->width, all->height, layers, nl, &attr, 1, WRITE_REPLACE, err, sizeof err);
    if (status != 0) cli_error("%s", err);
    free(json);
done:
    for (int l = 0; l < MAX_LAYERS; l++) free(planes[l]);
    return status;
}

int cmd_merge(int argc, char **argv) {
    merge_options o;
    int parsed = parse_merge_options(argc, argv, &o);
    if (parsed != 0) {
        free(o.parts);
        return parsed > 0 ? EXIT_OK : EXIT_USAGE;
    }
    int status = EXIT_FAILURE_;
    reference_info *infos = calloc((size_t)o.num_parts, sizeof *infos);
    cli_file *inputs = calloc((size_t)o.num_parts, sizeof *inputs);
    reference_info all;
    accumulator acc;
    const cli_file output = {"--out", o.out};
    if (!infos || !inputs) {
        cli_error("out of memory");
        goto done;
    }
    for (int p = 0; p < o.num_parts; p++) inputs[p] = (cli_file){"a part", o.parts[p]};
    if (cli_check_roles(&output, 1, inputs, o.num_parts) != 0) {
        status = EXIT_USAGE;
        goto done;
    }
    if (cli_check_output_dir("--out", o.out) != 0 || check_parts(&o, infos, &all) != 0) goto done;
    const layer_set ls = part_layers(&all);
    if (accumulator_init(&acc, (size_t)all.width * (size_t)all.height, ls.n) != 0) {
        cli_error("%s: out of memory for a %dx%d image", o.out, all.width, all.height);
        goto done;
    }
    int ok = 1;
    for (int p = 0; p < o.num_parts && ok; p++) ok = accumulate_part(&acc, o.parts[p], &infos[p], &ls) == 0;
    if (ok && write_merged(o.out, &acc, &ls, &all) == 0) {
        status = EXIT_OK;
        if (!o.quiet)
            printf("merged %d part%s (%lld spp) into %s; noise: relative L2 %.4g\n", o.num_parts,
                   o.num_parts > 1 ? "s" : "", all.spp, o.out, all.rel_l2_noise);
    }
    accumulator_free(&acc, ls.n);
done:
    free(infos);
    free(inputs);
    free(o.parts);
    return status;
}
