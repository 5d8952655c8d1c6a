#include "params.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const ray_kind_names[RAY_KIND_COUNT] = {"camera", "shadow", "bounce"};
const char *const pass_names[PASS_COUNT] = {"paths", "direct", "virtual_lights", "gather", "highlights"};

/* ---- defaults ---------------------------------------------------------------------------------- */

static int int_or(int v, int def, int max) { return v > 0 ? (v < max ? v : max) : def; }
/* 0 is the default; a negative value is "off" and stays. */
static float float_or(float v, float def) { return v != 0.0f ? v : def; }

vl_params vl_params_resolve(const vl_params *vp) {
    vl_params r = *vp;
    r.count = int_or(vp->count, VL_DEFAULT_COUNT, INT32_MAX);
    r.clamp_value = vp->clamp_value > 0.0f ? vp->clamp_value : VL_DEFAULT_CLAMP;
    r.clamp_growth = float_or(vp->clamp_growth, VL_DEFAULT_CLAMP_GROWTH);
    r.radius_mult = vp->radius_mult > 0.0f ? vp->radius_mult : VL_DEFAULT_RADIUS_MULT;
    r.radius_shrink = float_or(vp->radius_shrink, VL_DEFAULT_RADIUS_SHRINK);
    r.rows = int_or(vp->rows, VL_DEFAULT_ROWS, INT32_MAX);
    if (vp->per_pixel == 0) r.per_pixel = vp->columns > 0 ? -1 : VL_DEFAULT_PER_PIXEL;
    r.candidates = int_or(vp->candidates, VL_DEFAULT_CANDIDATES, VL_MAX_CANDIDATES);
    if (vp->select == VL_SELECT_DEFAULT) r.select = VL_SELECT_POWER;
    r.trace_glossy = float_or(vp->trace_glossy, VL_DEFAULT_TRACE_GLOSSY);
    r.regularize = float_or(vp->regularize, VL_DEFAULT_REGULARIZE);
    r.reg_image = float_or(vp->reg_image, VL_DEFAULT_REGULARIZE_IMAGE);
    r.glossy_rays = int_or(vp->glossy_rays, VL_DEFAULT_GLOSSY_RAYS, VL_MAX_GLOSSY_RAYS);
    if (vp->adapt == VL_ADAPT_DEFAULT) r.adapt = VL_ADAPT_ON;
    r.secondary_rays = int_or(vp->secondary_rays, HL_DEFAULT_SECONDARY_RAYS, HL_MAX_SECONDARY_RAYS);
    r.clusters = int_or(vp->clusters, HL_DEFAULT_CLUSTERS, HL_MAX_CLUSTERS);
    if (vp->merge == HL_MERGE_DEFAULT) r.merge = HL_MERGE_AUTO;
    if (vp->share == HL_SHARE_DEFAULT) r.share = HL_SHARE_OFF;
    r.dim_share = float_or(vp->dim_share, HL_DEFAULT_DIM_SHARE);
    r.check_share = float_or(vp->check_share, HL_DEFAULT_CHECK_SHARE);
    return r;
}

render_params render_params_resolve_frame(const render_params *p) {
    render_params r = *p;
    if (r.width <= 0) r.width = DEFAULT_WIDTH;
    if (r.height <= 0) r.height = DEFAULT_HEIGHT;
    if (r.max_depth <= 0) r.max_depth = DEFAULT_MAX_DEPTH;
    if ((unsigned)r.method >= METHOD_COUNT) r.method = METHOD_PT;
    return r;
}

render_params render_params_resolve(const render_params *p) {
    render_params r = render_params_resolve_frame(p);
    r.vl = vl_params_resolve(&p->vl);
    if (r.vl.clamp == VL_CLAMP_DEFAULT) r.vl.clamp = r.method == METHOD_VPL ? VL_CLAMP_ON : VL_CLAMP_OFF;
    return r;
}

int vl_frame_per_pixel(const vl_params *vp, int clustering) {
    return vp->per_pixel > 0 ? vp->per_pixel : (clustering || vp->per_pixel < 0 ? 0 : VL_DEFAULT_PER_PIXEL);
}

/* ---- the table --------------------------------------------------------------------------------- */

#define STR_(x) #x
#define STR(x) STR_(x)
#define F(field) offsetof(render_params, vl.field)
_Static_assert(sizeof(render_method) == sizeof(int), "a method is stored as a choice, an int");
_Static_assert(offsetof(render_params, height) == offsetof(render_params, width) + sizeof(int),
               "a size is two ints, width then height");

/* One row per parameter reads better than one line per field. */
/* clang-format off */
static const param_choice methods[METHOD_COUNT] = {{"pt", METHOD_PT, "pt"}, {"vpl", METHOD_VPL, "vpl"},
                                                  {"vsl", METHOD_VSL, "vsl"}, {"vsl+hl", METHOD_VSL_HL, "vsl+hl"},
                                                  {"auto", METHOD_AUTO, "auto"}};
/* clang-format on */

/* The method's names are the table's. */
const char *method_name(render_method m) { return (unsigned)m < METHOD_COUNT ? methods[m].name : "?"; }

int method_from_name(const char *name) {
    for (int i = 0; i < METHOD_COUNT; i++)
        if (strcmp(name, methods[i].name) == 0) return methods[i].value;
    return -1;
}

/* clang-format off */
static const param_choice plans[] = {{"auto", PLAN_AUTO, "auto"}, {"full", PLAN_FULL, "full"}};
static const param_choice tonemaps[] = {{"reinhard", TONEMAP_REINHARD, "reinhard"},
                                        {"clamp", TONEMAP_CLAMP, "clamp"},
                                        {"exponential", TONEMAP_EXPONENTIAL, "exponential"}};
static const param_choice on_off[] = {{"on", 1, "on"}, {"off", 0, "off"}};
static const param_choice clamps[] = {{NULL, VL_CLAMP_DEFAULT, "method default"}, {"on", VL_CLAMP_ON, "on"},
                                      {"off", VL_CLAMP_OFF, "off"}};
static const param_choice selects[] = {{"power", VL_SELECT_POWER, "by power"}, {"tree", VL_SELECT_TREE, "light tree"}};
static const param_choice adapts[] = {{"on", VL_ADAPT_ON, "on"}, {"off", VL_ADAPT_OFF, "off"}};
static const param_choice shares[] = {{"on", HL_SHARE_ON, "on"}, {"off", HL_SHARE_OFF, "off"}};
static const param_choice merges[] = {{"on", HL_MERGE_ON, "on"}, {"off", HL_MERGE_OFF, "off"},
                                      {"trace", HL_MERGE_TRACE, "trace"},
                                      {"auto", HL_MERGE_AUTO, "auto"}};

/* In the help's order. Numbers' ranges are what the command line accepts; the panel's sliders span
 * the useful part of them. */
static const param_desc table[] = {
    {.name = "method", .type = PARAM_CHOICE, .group = PARAM_RENDER, .offset = offsetof(render_params, method),
     .choices = methods, .num_choices = METHOD_COUNT, .def = METHOD_PT, .value_name = "NAME",
     .help = "estimator: pt (path tracing, the reference), vpl (clamped virtual\n"
             "point lights), vsl (virtual spherical lights), vsl+hl (VSLs plus\n"
             "vMF-merged indirect highlights), auto (pt or vsl, per 16x16 tile,\n"
             "whichever measures the less error for its time there)",
     .label = "method"},
    {.name = "max-depth", .type = PARAM_INT, .group = PARAM_RENDER, .offset = offsetof(render_params, max_depth),
     .lo = 1, .hi = MAX_DEPTH_LIMIT, .def = DEFAULT_MAX_DEPTH, .value_name = "D",
     .help = "scattering events per path; 1 = direct light only", .label = "max depth",
     .unit = "scattering events per path", .panel_lo = 1, .panel_hi = 64, .panel_format = "%d"},
    {.name = "plan", .type = PARAM_CHOICE, .group = PARAM_RENDER, .offset = offsetof(render_params, plan),
     .choices = plans, .num_choices = 2, .def = PLAN_AUTO,
     .help = "auto: only the passes the scene calls for (glint info shows\n"
             "them); full: every pass, for comparison",
     .label = "effect plan"},
    {.name = "size", .type = PARAM_SIZE, .group = PARAM_SETUP, .offset = offsetof(render_params, width), .lo = 1,
     .hi = PARAM_MAX_SIDE, .def = DEFAULT_WIDTH * 65536.0 + DEFAULT_HEIGHT,
     .def_text = STR(DEFAULT_WIDTH) "x" STR(DEFAULT_HEIGHT), .value_name = "WxH",
     .help = "the image's size in pixels (the viewer opens its window at it)", .label = "size", .no_panel = 1},
    {.name = "seed", .type = PARAM_U64, .group = PARAM_RENDER, .offset = offsetof(render_params, seed), .lo = 0,
     .hi = 18446744073709551615.0, .def = 0, .value_name = "S", .help = "random seed; runs with the same seed reproduce",
     .label = "seed", .no_panel = 1},
    {.name = "exposure", .type = PARAM_FLOAT, .group = PARAM_DISPLAY, .offset = offsetof(render_params, look.exposure),
     .lo = -50, .hi = 50, .def = 0, .value_name = "STOPS", .help = "exposure of the image shown and of the PNG",
     .label = "exposure", .unit = "stops", .panel_lo = -8, .panel_hi = 8, .panel_format = "%.1f stops"},
    {.name = "tonemap", .type = PARAM_CHOICE, .group = PARAM_DISPLAY, .offset = offsetof(render_params, look.tonemap),
     .choices = tonemaps, .num_choices = 3, .def = TONEMAP_REINHARD, .value_name = "NAME",
     .help = "tone mapper of the image shown and of the PNG: reinhard (to the\n"
             "image's log-average), clamp, exponential (a soft shoulder)",
     .label = "tone mapper"},
    {.name = "denoise", .type = PARAM_CHOICE, .group = PARAM_DISPLAY, .offset = offsetof(render_params, look.denoise),
     .choices = on_off, .num_choices = 2, .flag = 1, .def = 0,
     .help = "the image shown filtered while it is young and sampled more where\n"
             "it errs most (the viewer's N toggles both); glint render: that\n"
             "image as the EXR's layer denoised.*; the estimate, exports and\n"
             "the error never see either",
     .label = "denoise (N)"},
    {.name = "vsl-count", .type = PARAM_INT, .offset = F(count), .lo = 1, .hi = 50000000,
     .bytes_each = VL_BYTES_PER_LIGHT, .def = VL_DEFAULT_COUNT,
     .value_name = "N", .help = "virtual lights traced per frame", .label = "lights/frame",
     .unit = "lights per frame", .panel_lo = 16,
     .panel_hi = 1 << 20, .panel_log = 1, .panel_format = "%d"},
    {.name = "clamp", .type = PARAM_CHOICE, .offset = F(clamp), .choices = clamps, .num_choices = 3,
     .def = VL_CLAMP_DEFAULT, .def_text = "on for vpl, off for vsl", .help = "clamp each light's contribution",
     .label = "clamping"},
    {.name = "clamp-value", .type = PARAM_FLOAT, .offset = F(clamp_value), .lo = 1e-12, .hi = 1e30,
     .def = VL_DEFAULT_CLAMP, .value_name = "C", .help = "the clamp bound, in radiance", .label = "clamp value",
     .unit = "radiance",
     .panel_lo = 1e-3, .panel_hi = 100, .panel_log = 1, .panel_format = "%.3g"},
    {.name = "clamp-growth", .type = PARAM_FLOAT, .offset = F(clamp_growth), .lo = 0, .hi = 10, .off_word = "off",
     .zero_is_off = 1, .def = VL_DEFAULT_CLAMP_GROWTH, .value_name = "A",
     .help = "the bound grows as C * frame^A, so clamped VPLs converge", .label = "clamp growth",
     .unit = "exponent of the frame count", .panel_lo = 0,
     .panel_hi = 2, .panel_format = "%.2f", .panel_lo_text = "off"},
    {.name = "vpl-glossy", .type = PARAM_CHOICE, .offset = F(vpl_glossy), .choices = on_off, .num_choices = 2,
     .flag = 1, .def = 0, .help = "VPLs reflect with their full BSDF, not only its diffuse part",
     .label = "vpl glossy"},
    {.name = "radius-mult", .type = PARAM_FLOAT, .offset = F(radius_mult), .lo = 1e-6, .hi = 1e6,
     .def = VL_DEFAULT_RADIUS_MULT, .value_name = "M", .help = "VSL radius: M x distance to the 10th nearest light",
     .label = "radius mult", .unit = "× distance to the 10th nearest light", .panel_lo = 0.05, .panel_hi = 32,
     .panel_log = 1, .panel_format = "%.2f"},
    {.name = "radius-shrink", .type = PARAM_FLOAT, .offset = F(radius_shrink), .lo = 0, .hi = 1, .below_hi = 1,
     .off_word = "off", .zero_is_off = 1, .def = VL_DEFAULT_RADIUS_SHRINK, .value_name = "A",
     .help = "0 < A < 1: M shrinks over frames (progressive photon mapping's\n"
             "schedule), so VSLs converge to the path-traced answer",
     .label = "radius shrink", .unit = "exponent, 0 to 1", .panel_lo = 0, .panel_hi = 0.99, .panel_format = "%.2f",
     .panel_lo_text = "off"},
    {.name = "rows", .type = PARAM_INT, .offset = F(rows), .lo = 1, .hi = 100000, .def = VL_DEFAULT_ROWS,
     .value_name = "R", .help = "matrix row-column sampling: sampled rows (pixels)", .label = "rows",
     .unit = "pixels", .panel_lo = 16,
     .panel_hi = 4096, .panel_log = 1, .panel_format = "%d"},
    {.name = "columns", .type = PARAM_INT, .offset = F(columns), .lo = 0, .hi = 10000000, .def = 0,
     .value_name = "C", .help = "... and clusters; 0 = no clustering", .label = "clusters", .unit = "clusters",
     .panel_lo = 0,
     .panel_hi = 1 << 14, .panel_log = 1, .panel_format = "%d", .panel_lo_text = "none"},
    {.name = "per-pixel", .type = PARAM_INT, .offset = F(per_pixel), .lo = 1, .hi = 1000000, .off_word = "all",
     .def = VL_DEFAULT_PER_PIXEL, .value_name = "N",
     .help = "lights (cluster representatives) each pixel shades per frame,\n"
             "picked by power (cluster norm); all by default with --columns",
     .label = "lights/pixel", .unit = "lights per pixel and frame", .panel_lo = -1, .panel_hi = 256,
     .panel_format = "%d", .panel_lo_text = "all"},
    {.name = "light-select", .type = PARAM_CHOICE, .offset = F(select), .choices = selects, .num_choices = 2,
     .def = VL_SELECT_POWER,
     .help = "where a pixel's light draws come from: by power, or\n"
             "through a light tree by an estimate of what each sends there",
     .label = "light draws"},
    {.name = "candidates", .type = PARAM_INT, .offset = F(candidates), .lo = 1, .hi = VL_MAX_CANDIDATES,
     .def = VL_DEFAULT_CANDIDATES, .value_name = "M",
     .help = "draws per pixel, from which its lights are resampled by that\n"
             "estimate (a quarter at later hits); 1 = shaded as drawn",
     .label = "candidates", .unit = "draws per pixel", .panel_lo = 1, .panel_hi = 128, .panel_log = 1,
     .panel_format = "%d",
     .panel_lo_text = "1 (as drawn)"},
    {.name = "trace-glossy", .type = PARAM_FLOAT, .offset = F(trace_glossy), .lo = 0, .hi = 10, .off_word = "off",
     .zero_is_off = 1, .def = VL_DEFAULT_TRACE_GLOSSY, .value_name = "A",
     .help = "receivers' glossy lobes with roughness alpha below A are not\n"
             "gathered from the lights: the path goes on through them",
     .label = "trace glossy below", .unit = "roughness alpha", .panel_lo = 0, .panel_hi = 1,
     .panel_format = "alpha %.2f",
     .panel_lo_text = "never"},
    {.name = "glossy-rays", .type = PARAM_INT, .offset = F(glossy_rays), .lo = 1, .hi = VL_MAX_GLOSSY_RAYS,
     .def = VL_DEFAULT_GLOSSY_RAYS, .value_name = "N",
     .help = "directions traced through such a lobe at the camera hit, 1.." STR(VL_MAX_GLOSSY_RAYS),
     .label = "glossy rays", .unit = "rays per camera hit", .panel_lo = 1, .panel_hi = VL_MAX_GLOSSY_RAYS,
     .panel_format = "%d"},
    {.name = "regularize", .type = PARAM_FLOAT, .offset = F(regularize), .lo = 0, .hi = 1, .off_word = "off",
     .zero_is_off = 1, .def = VL_DEFAULT_REGULARIZE, .value_name = "A",
     .help = "past two traced lobes, the next hit's lobes sharper than\n"
             "alpha A are widened to A for its direct light; A shrinks as M",
     .label = "regularize below", .unit = "roughness alpha", .panel_lo = 0, .panel_hi = 1,
     .panel_format = "alpha %.2f", .panel_lo_text = "never"},
    {.name = "regularize-image", .type = PARAM_FLOAT, .offset = F(reg_image), .lo = 0, .hi = 2,
     .off_word = "off", .zero_is_off = 1, .def = VL_DEFAULT_REGULARIZE_IMAGE, .value_name = "C",
     .help = "a traced direction's hit sees lights through lobes at least C x\n"
             "the sending lobe's roughness wide, a point or spot light at d\n"
             "through C x that x (1 + t / d), t the ray's length; C shrinks as M",
     .label = "regularize images", .unit = "x the sending lobe", .panel_lo = 0, .panel_hi = 2,
     .panel_format = "%.2f", .panel_lo_text = "never"},
    {.name = "adapt", .type = PARAM_CHOICE, .offset = F(adapt), .choices = adapts, .num_choices = 2,
     .def = VL_ADAPT_ON,
     .help = "on: each pixel's glossy rays (N on average) and direct-light\n"
             "samples (4) follow how much one sample's light varied there in\n"
             "earlier frames; off: the same at every pixel",
     .label = "adapt samples"},
    {.name = "secondary-rays", .type = PARAM_INT, .group = PARAM_HIGHLIGHTS, .offset = F(secondary_rays), .lo = 1,
     .hi = HL_MAX_SECONDARY_RAYS, .def = HL_DEFAULT_SECONDARY_RAYS, .value_name = "N",
     .help = "rays sampled from a camera hit's glossy lobe, 1.." STR(HL_MAX_SECONDARY_RAYS),
     .label = "secondary rays", .unit = "rays per camera hit", .panel_lo = 1, .panel_hi = HL_MAX_SECONDARY_RAYS,
     .panel_log = 1,
     .panel_format = "%d"},
    {.name = "clusters", .type = PARAM_INT, .group = PARAM_HIGHLIGHTS, .offset = F(clusters), .lo = 1,
     .hi = HL_MAX_CLUSTERS, .def = HL_DEFAULT_CLUSTERS, .value_name = "K",
     .help = "merged vMF lobes per camera hit, 1.." STR(HL_MAX_CLUSTERS), .label = "clusters (K)",
     .unit = "lobes per camera hit", .panel_lo = 1,
     .panel_hi = HL_MAX_CLUSTERS, .panel_format = "%d"},
    {.name = "merge", .type = PARAM_CHOICE, .group = PARAM_HIGHLIGHTS, .offset = F(merge), .choices = merges,
     .num_choices = 4, .def = HL_MERGE_AUTO,
     .help = "auto: merged, and with --adapt on a pixel takes the trace from\n"
             "when the merge's bias there (against the trace at the same hits)\n"
             "outweighs the trace's extra noise, judged as the frames double;\n"
             "on: merged everywhere; off: every secondary hit's own vMF lobe\n"
             "is lit by itself (the paper's comparison); trace: no vMFs, each\n"
             "hit's true glossy lobe (the path tracer's answer for the paths)",
     .label = "merge"},
    {.name = "share", .type = PARAM_CHOICE, .group = PARAM_HIGHLIGHTS, .offset = F(share), .choices = shares,
     .num_choices = 2, .def = HL_SHARE_OFF,
     .help = "on: 2x2 blocks of pixels whose lobes are not sharp share their\n"
             "secondary hits, each pixel merging the block's into 2K lobes\n"
             "(N up to " STR(HL_SHARE_MAX_RAYS) "); off: each pixel its own",
     .label = "share hits"},
    {.name = "dim-highlights", .type = PARAM_FLOAT, .group = PARAM_HIGHLIGHTS, .offset = F(dim_share), .lo = 0,
     .hi = 1, .off_word = "off", .zero_is_off = 1, .def = HL_DEFAULT_DIM_SHARE, .value_name = "S",
     .help = "with --adapt on: a pixel whose highlights, and theirs within " STR(HL_DIM_RADIUS) "\n"
             "pixels, came to at most S of their light in its first " STR(HL_DIM_FRAMES) " frames\n"
             "leaves them to the virtual lights (no secondary rays), judged\n"
             "again as the frames double; the others take " STR(HL_BRIGHT_RAY_FACTOR) "N rays and 2K\n"
             "clusters; off: N and K everywhere",
     .label = "dim highlights below", .unit = "of the pixel's light", .panel_lo = 0, .panel_hi = 0.1,
     .panel_format = "%.3f", .panel_lo_text = "never"},
    {.name = "check-merge", .type = PARAM_FLOAT, .group = PARAM_HIGHLIGHTS, .offset = F(check_share), .lo = 0,
     .hi = 1, .off_word = "off", .zero_is_off = 1, .def = HL_DEFAULT_CHECK_SHARE, .def_text = "off", .value_name = "Q",
     .help = "merged: in a share Q of its frames a pixel's merged\n"
             "lobes are checked against its hits lit through their own lobes,\n"
             "adding (traced - merged) / Q: unbiased; off: never",
     .label = "check the merge", .unit = "of the frames", .panel_lo = 0, .panel_hi = 1,
     .panel_format = "%.2f", .panel_lo_text = "never"},
};
/* clang-format on */

const param_desc *params_table(int *count) {
    *count = (int)(sizeof table / sizeof table[0]);
    return table;
}

const param_desc *param_find(const char *name) {
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strcmp(name, table[i].name) == 0) return &table[i];
    return NULL;
}

double param_get(const param_desc *d, const render_params *p) {
    const char *field = (const char *)p + d->offset;
    if (d->type == PARAM_U64) {
        uint64_t v;
        memcpy(&v, field, sizeof v);
        return (double)v;
    }
    if (d->type == PARAM_SIZE) {
        int wh[2];
        memcpy(wh, field, sizeof wh);
        return wh[0] * 65536.0 + wh[1];
    }
    if (d->type == PARAM_FLOAT) {
        float v;
        memcpy(&v, field, sizeof v);
        return v;
    }
    int v;
    memcpy(&v, field, sizeof v);
    return v;
}

void param_put(const param_desc *d, render_params *p, double v) {
    char *field = (char *)p + d->offset;
    if (d->type == PARAM_U64) {
        uint64_t u = v > 0.0 ? (v < 18446744073709551615.0 ? (uint64_t)v : UINT64_MAX) : 0;
        memcpy(field, &u, sizeof u);
    } else if (d->type == PARAM_SIZE) {
        int wh[2] = {(int)(v / 65536.0), (int)fmod(v, 65536.0)};
        memcpy(field, wh, sizeof wh);
    } else if (d->type == PARAM_FLOAT) {
        float f = (float)v;
        memcpy(field, &f, sizeof f);
    } else {
        int i = (int)v;
        memcpy(field, &i, sizeof i);
    }
}

/* The accepted values in words, for messages and the help: "on|off", "A|off"; a choice's names,
 * or its placeholder (value_name) where it has one and `placeholder` is set (the help's NAME). */
static void value_words(const param_desc *d, const char *sep, int placeholder, char *out, size_t n) {
    out[0] = 0;
    size_t len = 0;
    if (d->type == PARAM_CHOICE && !(placeholder && d->value_name)) {
        for (int c = 0; c < d->num_choices; c++) {
            if (!d->choices[c].name) continue;
            len += (size_t)snprintf(out + len, n - len, "%s%s", len ? sep : "", d->choices[c].name);
            if (len >= n) return;
        }
    } else {
        snprintf(out, n, "%s%s%s", d->value_name ? d->value_name : "X", d->off_word ? sep : "",
                 d->off_word ? d->off_word : "");
    }
}

int param_parse(const param_desc *d, const char *text, render_params *p, char *err, size_t errlen) {
    if (d->type == PARAM_CHOICE) {
        for (int c = 0; c < d->num_choices; c++)
            if (d->choices[c].name && strcmp(text, d->choices[c].name) == 0)
                return param_put(d, p, d->choices[c].value), 0;
        char words[128];
        value_words(d, ", ", 0, words, sizeof words);
        return snprintf(err, errlen, "expected one of %s, got '%s'", words, text), -1;
    }
    if (d->off_word && strcmp(text, d->off_word) == 0) return param_put(d, p, -1.0), 0;
    if (d->type == PARAM_SIZE) {
        int *wh = (int *)((char *)p + d->offset);
        return params_parse_size(text, &wh[0], &wh[1], err, errlen);
    }
    if (d->type == PARAM_U64) { /* all 64 bits: not through a double */
        char *end = NULL;
        errno = 0;
        unsigned long long u = text[0] >= '0' && text[0] <= '9' ? strtoull(text, &end, 10) : 0;
        if (!end || errno || *end != '\0')
            return snprintf(err, errlen, "expected an integer in [0, %llu], got '%s'", (unsigned long long)UINT64_MAX,
                            text),
                   -1;
        uint64_t v = (uint64_t)u;
        memcpy((char *)p + d->offset, &v, sizeof v);
        return 0;
    }
    char *end = NULL;
    errno = 0;
    double v = d->type == PARAM_INT ? (double)strtoll(text, &end, 10) : strtod(text, &end);
    int ok =
        !errno && end != text && *end == '\0' && isfinite(v) && v >= d->lo && (d->below_hi ? v < d->hi : v <= d->hi);
    if (!ok) {
        char off[64] = "";
        if (d->off_word) snprintf(off, sizeof off, " or %s", d->off_word);
        return snprintf(err, errlen, "expected %s in [%.15g, %.15g%s%s, got '%s'",
                        d->type == PARAM_INT ? "an integer" : "a number", d->lo, d->hi, d->below_hi ? ")" : "]", off,
                        text),
               -1;
    }
    return param_set_value(d, p, d->zero_is_off && v == 0.0 ? -1.0 : v, text, err, errlen);
}

int param_set_value(const param_desc *d, render_params *p, double v, const char *text, char *err, size_t errlen) {
    double gib = 1024.0 * 1024.0 * 1024.0;
    if (v * d->bytes_each > PARAM_MAX_BYTES)
        return snprintf(err, errlen, "%s would take %.1f GiB (%.0f bytes each), over the limit of %.0f GiB", text,
                        v * d->bytes_each / gib, d->bytes_each, PARAM_MAX_BYTES / gib),
               -1;
    render_params was = *p;
    param_put(d, p, v);
    /* Clustering's matrix is rows x lights floats: the two together under the same limit. */
    vl_params r = vl_params_resolve(&p->vl);
    double matrix = r.columns > 0 ? (double)r.rows * (double)r.count * sizeof(float) : 0.0;
    if (matrix > PARAM_MAX_BYTES) {
        *p = was;
        return snprintf(err, errlen,
                        "%s: clustering's matrix of %d rows by %d lights would take %.1f GiB, over the limit of "
                        "%.0f GiB",
                        text, r.rows, r.count, matrix / gib, PARAM_MAX_BYTES / gib),
               -1;
    }
    return 0;
}

int params_parse_size(const char *text, int *width, int *height, char *err, size_t errlen) {
    char *end = NULL;
    errno = 0;
    long w = strtol(text, &end, 10), h = 0;
    int ok = !errno && end != text && (*end == 'x' || *end == 'X');
    if (ok) {
        const char *hs = end + 1;
        h = strtol(hs, &end, 10);
        ok = !errno && end != hs && *end == '\0';
    }
    if (!ok || w < 1 || h < 1 || w > PARAM_MAX_SIDE || h > PARAM_MAX_SIDE)
        return snprintf(err, errlen, "expected WIDTHxHEIGHT (1..%d each), got '%s'", PARAM_MAX_SIDE, text), -1;
    /* what the film and the per-pixel records take grows with the pixels: refused at once, as a
     * many-light parameter's memory is */
    double bytes = (double)w * (double)h * PARAM_PIXEL_BYTES, gib = 1024.0 * 1024.0 * 1024.0;
    if (bytes > PARAM_MAX_IMAGE_BYTES)
        return snprintf(err, errlen, "%s would take %.1f GiB (%.0f bytes a pixel), over the limit of %.0f GiB", text,
                        bytes / gib, PARAM_PIXEL_BYTES, PARAM_MAX_IMAGE_BYTES / gib),
               -1;
    *width = (int)w;
    *height = (int)h;
    return 0;
}

int params_set(render_params *p, unsigned groups, const char *name, const char *text, char *err, size_t errlen) {
    const param_desc *d = param_find(name);
    if (!d || !(groups >> d->group & 1u)) return 0;
    return param_parse(d, text, p, err, errlen) == 0 ? 1 : -1;
}

int params_differ(const render_params *a, const render_params *b, unsigned groups) {
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        const param_desc *d = &table[i];
        size_t size = d->type == PARAM_U64 || d->type == PARAM_SIZE ? 8 : 4; /* two ints, or one of 64 bits */
        if (groups >> d->group & 1u && memcmp((const char *)a + d->offset, (const char *)b + d->offset, size) != 0)
            return 1;
    }
    return 0;
}

void param_format(const param_desc *d, const render_params *p, char *out, size_t n) {
    double v = param_get(d, p);
    if (d->type == PARAM_U64) {
        uint64_t u;
        memcpy(&u, (const char *)p + d->offset, sizeof u);
        snprintf(out, n, "%llu", (unsigned long long)u);
    } else if (d->type == PARAM_SIZE) {
        int wh[2];
        memcpy(wh, (const char *)p + d->offset, sizeof wh);
        snprintf(out, n, "%dx%d", wh[0], wh[1]);
    } else if (d->type == PARAM_CHOICE) {
        for (int c = 0; c < d->num_choices; c++)
            if (d->choices[c].value == (int)v) {
                snprintf(out, n, "%s", d->choices[c].name ? d->choices[c].name : "default");
                return;
            }
        snprintf(out, n, "%d", (int)v);
    } else if (v < 0.0 && d->off_word) {
        snprintf(out, n, "%s", d->off_word);
    } else {
        snprintf(out, n, "%g", v);
    }
}

/* One option's help into text (a line, or lines, each ending in a newline), def_given its default
 * (NULL: the table's). Returns the length written (clipped to n). */
static size_t help_line(const param_desc *d, const char *def_given, char *text, size_t n) {
    char option[64], words[64], def[64];
    value_words(d, "|", 1, words, sizeof words);
    int olen = d->flag ? snprintf(option, sizeof option, "  --%s [%s]", d->name, words)
                       : snprintf(option, sizeof option, "  --%s %s", d->name, words);
    if (def_given || d->def_text)
        snprintf(def, sizeof def, "%s", def_given ? def_given : d->def_text);
    else if (d->type == PARAM_INT)
        snprintf(def, sizeof def, "%d", (int)d->def);
    else if (d->type == PARAM_FLOAT)
        snprintf(def, sizeof def, "%g", d->def);
    else if (d->type == PARAM_U64)
        snprintf(def, sizeof def, "%.0f", d->def);
    else {
        render_params v = {0};
        param_put(d, &v, d->def);
        param_format(d, &v, def, sizeof def);
    }
    /* Options in a column of 23, the help beside them; its later lines under its first. */
    size_t len = (size_t)snprintf(text, n, "%s%*s", option, olen < 22 ? 23 - olen : olen == 22 ? 1 : 2, "");
    for (const char *h = d->help; *h && len < n;) {
        const char *nl = strchr(h, '\n');
        int k = nl ? (int)(nl - h) : (int)strlen(h);
        len += (size_t)snprintf(text + len, n - len, "%.*s", k, h);
        if (!nl) break;
        h = nl + 1;
        if (len < n) len += (size_t)snprintf(text + len, n - len, "\n%23s", "");
    }
    if (len < n) len += (size_t)snprintf(text + len, n - len, " [%s]\n", def);
    return len < n ? len : n;
}

/* Whether name is one of the space-separated words of list. */
static int listed(const char *list, const char *name) {
    size_t n = strlen(name);
    for (const char *w = list; *w;) {
        size_t k = strcspn(w, " ");
        if (k == n && strncmp(w, name, n) == 0) return 1;
        w += k;
        w += strspn(w, " ");
    }
    return 0;
}

/* name's value in a list of "name=value" words, into out (n bytes); NULL when not there. */
static const char *listed_value(const char *list, const char *name, char *out, size_t n) {
    size_t k = strlen(name);
    for (const char *w = list ? list : ""; *w;) {
        size_t len = strcspn(w, " ");
        if (len > k && strncmp(w, name, k) == 0 && w[k] == '=') {
            snprintf(out, n, "%.*s", (int)(len - k - 1), w + k + 1);
            return out;
        }
        w += len;
        w += strspn(w, " ");
    }
    return NULL;
}

const char *params_render_help(const char *names, const char *defaults) {
    static char text[4096];
    size_t len = 0;
    text[0] = '\0';
    for (size_t i = 0; i < sizeof table / sizeof table[0] && len < sizeof text; i++) {
        char own[64];
        if (!(PARAM_GROUPS_VL >> table[i].group & 1u) && listed(names, table[i].name))
            len += help_line(&table[i], listed_value(defaults, table[i].name, own, sizeof own), text + len,
                             sizeof text - len);
    }
    return text;
}

const char *params_help(void) {
    static char text[8192];
    static const char *const headings[] = {"many-light methods (vpl, vsl):\n", "indirect highlights (vsl+hl):\n"};
    size_t len = 0;
    int group = -1;
    for (size_t i = 0; i < sizeof table / sizeof table[0] && len < sizeof text; i++) {
        const param_desc *d = &table[i];
        if (!(PARAM_GROUPS_VL >> d->group & 1u)) continue; /* each command lists these with its own */
        if ((int)d->group != group) {
            group = (int)d->group;
            len += (size_t)snprintf(text + len, sizeof text - len, "%s", headings[group]);
        }
        if (len < sizeof text) len += help_line(d, NULL, text + len, sizeof text - len);
    }
    return text;
}

void render_stats_add(render_stats *to, const render_stats *from) {
    for (int k = 0; k < RAY_KIND_COUNT; k++) to->rays[k] += from->rays[k];
#define RENDER_COUNTER_ADD(field, name, section, scale) to->field += from->field;
    RENDER_COUNTERS(RENDER_COUNTER_ADD)
#undef RENDER_COUNTER_ADD
    for (int k = 0; k < PASS_COUNT; k++) to->pass_ns[k] += from->pass_ns[k];
}
