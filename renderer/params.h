/* glint — what a render is asked to do: the method, its parameters and their defaults, and the
 * statistics a session reports. Every estimator and front end includes this header (not
 * session.h) for these types. Every setting of a render (the method, the path depth, the plan,
 * the seed, the size, the many-light parameters, the look) is described once, in a table
 * (params_table) that the command line, the viewer's script `set`, its panel and the help text all
 * read, so a new parameter is one render_params field and one entry (docs/design.md,
 * "Parameters"). */
#ifndef GLINT_PARAMS_H
#define GLINT_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    METHOD_PT = 0, /* unbiased path tracing: the reference */
    METHOD_VPL,    /* virtual point lights (instant radiosity), clamped */
    METHOD_VSL,    /* virtual spherical lights */
    METHOD_VSL_HL, /* virtual spherical lights plus vMF-merged indirect highlights */
    METHOD_AUTO,   /* per tile, path tracing or the virtual spherical lights, by what each measured there */
    METHOD_COUNT
} render_method;

/* "pt", "vpl", "vsl", "vsl+hl"; method_from_name returns -1 for an unknown name. */
const char *method_name(render_method m);
int method_from_name(const char *name);

/* The method the viewer and glint info start with: vsl, the estimator that converges fastest on
 * the default scene (docs/benchmarks.md). glint render keeps path tracing, its references'
 * unbiased method, unless told otherwise. */
#define DEFAULT_METHOD METHOD_VSL
#define DEFAULT_METHOD_NAME "vsl" /* its name, for help texts (test_params checks it) */
#define DEFAULT_MAX_DEPTH 16
#define MAX_DEPTH_LIMIT 10000 /* the deepest path any front end accepts */
#define DEFAULT_WIDTH 960
#define DEFAULT_HEIGHT 540

/* The many-light methods (vpl, vsl, vsl+hl). Zero means default for every field but the switches. */
typedef struct {
    int count;           /* virtual lights per frame [VL_DEFAULT_COUNT] */
    int clamp;           /* VL_CLAMP_*: clamp each light's contribution [on for vpl, off for vsl] */
    float clamp_value;   /* the bound on one light's contribution [VL_DEFAULT_CLAMP] */
    float clamp_growth;  /* > 0: the bound grows as c * frame^growth (consistent VPLs); < 0: a fixed
                          * bound [VL_DEFAULT_CLAMP_GROWTH] */
    int vpl_glossy;      /* vpl: the light's full BSDF instead of its diffuse lobe */
    float radius_mult;   /* vsl: radius = mult x distance to the 10th nearest light [VL_DEFAULT_RADIUS_MULT] */
    float radius_shrink; /* vsl, in (0,1): mult shrinks as r_{i+1} = r_i sqrt((i + a) / (i + 1)), so
                          * VSLs converge to the path-traced answer; < 0: a fixed radius
                          * [VL_DEFAULT_RADIUS_SHRINK] */
    int rows, columns;   /* matrix row-column sampling; columns 0: no clustering [rows 300] */
    int per_pixel;       /* lights (or cluster representatives) sampled per pixel per frame, by
                          * power (or cluster norm); -1: every one; 0: the default, which is
                          * VL_DEFAULT_PER_PIXEL without clustering and every representative with */
    int candidates;      /* per pixel: lights drawn (by power, cluster norm or the tree) from which
                          * the pixel's per_pixel lights are resampled in proportion to an estimate
                          * of what each sends there; 1: the draws are shaded as they come. At the
                          * camera hit; a path's later hits draw a quarter [VL_DEFAULT_CANDIDATES] */
    int select;          /* VL_SELECT_*: where a pixel's light draws come from (without clustering) [power] */
    float trace_glossy;  /* a receiver's glossy lobe with roughness alpha below this is not
                          * gathered from the lights: the camera path goes on through it (BSDF
                          * sampling, direct light at the next hit, gathering there); < 0: never
                          * [VL_DEFAULT_TRACE_GLOSSY] */
    float regularize;    /* where a traced path has gone through two such lobes or more, the glossy
                          * lobes at the next hit, whose direct light it takes, are widened to this
                          * roughness alpha at least, shrinking as the VSL radius does; < 0: never
                          * [VL_DEFAULT_REGULARIZE] */
    float reg_image;     /* --regularize-image: at a hit a traced direction reaches, a light's image
                          * in the glossy lobes is made at least this share of the sending lobe's
                          * width (docs/design.md, "Regularised images"), shrinking as the VSL
                          * radius does; < 0: never [VL_DEFAULT_REGULARIZE_IMAGE] */
    int glossy_rays;     /* directions traced through such a lobe at the camera hit, each taking the
                          * direct light at its next hit, one carrying the path on; with
                          * adapt, their mean over the pixels [VL_DEFAULT_GLOSSY_RAYS] */
    int adapt;           /* VL_ADAPT_*: each pixel's number of those directions follows how much one
                          * direction's light varied there in earlier frames [on] */
    /* vsl+hl: the highlight estimator (which owns the camera - glossy - glossy - light paths) */
    int secondary_rays; /* rays sampled from the camera hit's glossy lobe [HL_DEFAULT_SECONDARY_RAYS] */
    int clusters;       /* merged lobes per camera hit, 1..HL_MAX_CLUSTERS [HL_DEFAULT_CLUSTERS] */
    int merge;          /* HL_MERGE_*: merged, traced, either per pixel (auto), or each hit's own vMF [auto] */
    int share;          /* HL_SHARE_*: 2x2 blocks of pixels with broad lobes share their secondary hits [off] */
    float dim_share;    /* with adapt: a pixel whose highlights, and its neighbours', were at most this
                         * share of their light in its first HL_DIM_FRAMES frames leaves them to the
                         * virtual lights' paths (hl_judge_dim); < 0: never [HL_DEFAULT_DIM_SHARE] */
    float check_share;  /* merged: the share of a pixel's frames whose merged lobes are checked against
                         * the same hits lit through their own lobes (then unbiased); < 0: none
                         * [HL_DEFAULT_CHECK_SHARE] */
} vl_params;

enum { VL_CLAMP_DEFAULT = 0, VL_CLAMP_ON, VL_CLAMP_OFF };
/* Where a pixel's light draws come from: VL_SELECT_POWER by power (or cluster norm); VL_SELECT_TREE
 * through the light tree (lighttree.h), by an estimate of each group's contribution there. */
enum { VL_SELECT_DEFAULT = 0, VL_SELECT_TREE, VL_SELECT_POWER };
enum { VL_ADAPT_DEFAULT = 0, VL_ADAPT_ON, VL_ADAPT_OFF };
#define VL_DEFAULT_COUNT 1024
#define VL_DEFAULT_CLAMP 1.0f
/* The paper's multipliers (4-12) go with 10^5 lights in one set; radii scale as mult/sqrt(count),
 * so with ~10^3 fresh lights a frame a multiplier of 1 gives the same radii as 8 at 6.4 10^4. */
#define VL_DEFAULT_RADIUS_MULT 1.0f
/* The consistent schedules are on by default: progressive rendering should converge to the
 * answer, not to the answer at one radius (docs/design.md; the values measured in
 * docs/benchmarks.md). */
#define VL_DEFAULT_RADIUS_SHRINK 0.9f
#define VL_DEFAULT_CLAMP_GROWTH 0.5f
#define VL_DEFAULT_ROWS 300
#define VL_DEFAULT_PER_PIXEL 2
#define VL_DEFAULT_CANDIDATES 32
#define VL_MAX_CANDIDATES 256 /* they live on the stack */
#define VL_DEFAULT_TRACE_GLOSSY 0.35f
#define VL_DEFAULT_REGULARIZE 0.15f
#define VL_DEFAULT_REGULARIZE_IMAGE 0.25f
#define VL_DEFAULT_GLOSSY_RAYS 4
#define VL_MAX_GLOSSY_RAYS 64
/* HL_MERGE_TRACE: no vMF at all, every secondary hit lit through its own glossy BSDF lobe (the
 * path tracer's estimate of the same paths, to see what the approximation costs). HL_MERGE_AUTO:
 * the merge, and each pixel judged as the frames double (hl_judge_trace) takes the trace from then
 * on where the merge's bias outweighs the trace's extra noise. */
enum { HL_MERGE_DEFAULT = 0, HL_MERGE_ON, HL_MERGE_OFF, HL_MERGE_TRACE, HL_MERGE_AUTO };
enum { HL_SHARE_DEFAULT = 0, HL_SHARE_ON, HL_SHARE_OFF };
#define HL_DEFAULT_SECONDARY_RAYS 8
#define HL_DEFAULT_CLUSTERS 4
#define HL_MAX_CLUSTERS 8
#define HL_MAX_SECONDARY_RAYS 256 /* the paper uses 32-64; per-hit records live on the stack */
#define HL_SHARE_MAX_RAYS 16      /* N beyond this: no sharing (a block's pool lives on the stack) */
/* Most pixels whose camera hit has a highlight lobe see hardly any highlight: on the built-in rooms
 * the highlight pass reaches 42-53 k pixels a frame, of which 7-35 k get any highlight, many of
 * those under 0.3% of their light (docs/benchmarks.md, 2026-11-28). */
#define HL_DEFAULT_DIM_SHARE 0.01f
#define HL_DEFAULT_CHECK_SHARE -1.0f /* off (docs/benchmarks.md, 2026-11-28, ninth entry) */
#define HL_DIM_FRAMES 2              /* the frames a pixel's highlights are estimated before it is judged */
/* A pixel stays bright when one within this many pixels is: a small sharp highlight (a curved
 * mirror's image of a lit speck) that its own first frames missed is seldom missed by all 25
 * (docs/benchmarks.md, 2026-11-28, ninth entry). */
#define HL_DIM_RADIUS 2
/* A pixel judged bright (not dim) takes N times this many secondary rays, and twice the clusters
 * (up to HL_MAX_CLUSTERS), from then on (docs/benchmarks.md, 2026-11-28). */
#define HL_BRIGHT_RAY_FACTOR 2

/* Frames a --time shard takes in a row before the other shards' runs (shard_frame_index). */
#define SHARD_TIME_BLOCK 65536

/* Frame k of shard index of count, in the whole render's sequence. Each shard's frames follow on
 * without a gap: a pixel's low-discrepancy runs index their points by the frame, and every N-th
 * point of a run is no run at all (every other point of the Sobol sequence covers half of its first
 * dimension), so a shard taking frames i, i + N, ... converged, alone, to a wrong image. With --spp
 * T the shards take consecutive blocks of T (shard i's share: the frames of i, i + N, ... below
 * T); with --time (total 0), blocks of SHARD_TIME_BLOCK frames in turn. */
/* Shard index's share of a render of total frames: as many frames as index, index + count, ...
 * below total. */
static inline long long shard_share(long long total, int index, int count) {
    return total > index ? (total - index + count - 1) / count : 0;
}
static inline uint64_t shard_frame_index(long long total, int index, int count, uint64_t k) {
    const uint64_t i = (uint64_t)index, n = (uint64_t)count, b = SHARD_TIME_BLOCK;
    /* after the shares of shards 0 .. index - 1: total / count each, one more for the first total % count */
    if (total > 0) return i * ((uint64_t)total / n) + (i < (uint64_t)total % n ? i : (uint64_t)total % n) + k;
    return (k / b) * n * b + i * b + k % b;
}

/* Global tone operators, all followed by the sRGB transfer function to 8 bits (film.h applies them). */
typedef enum {
    TONEMAP_REINHARD = 0, /* Reinhard et al. 2002: key / log-average luminance, L/(1+L), hue kept */
    TONEMAP_CLAMP,        /* radiance x 2^exposure, clipped at 1: what the numbers say */
    TONEMAP_EXPONENTIAL,  /* 1 - exp(-radiance x 2^exposure) per channel: a soft shoulder, no
                           * image statistics, so brightness never shifts while noise settles */
    TONEMAP_COUNT
} tonemap_op;

/* How the image is shown and written, never the estimate: a change of these restarts no
 * accumulation (PARAM_DISPLAY). The viewer's look; glint render's PNG and filtered layer. */
typedef struct {
    float exposure; /* stops */
    int tonemap;    /* tonemap_op */
    int denoise;    /* 1: the image shown filtered while young and sampled more where it errs most
                     * (the viewer's default); glint render: that image as an extra layer */
} look_params;

/* The effect plan's modes (render_params.plan; plan.h makes the plan). */
enum { PLAN_AUTO = 0, PLAN_FULL };

/* Zero means default for every field. */
typedef struct {
    int width, height; /* 0: DEFAULT_WIDTH x DEFAULT_HEIGHT */
    render_method method;
    int max_depth; /* scattering events per path; 0: DEFAULT_MAX_DEPTH; 1 is direct light only */
    uint64_t seed;
    int threads;       /* 0: one per core */
    int pt_highlights; /* pt: camera - glossy - glossy - light paths in their own component */
    int plan;          /* PLAN_AUTO: only the passes the scene calls for; PLAN_FULL: all (plan.h) */
    unsigned only;     /* many-light methods: render only these film components (a mask of
                        * 1 << COMP_*), skipping the others' passes, to time one estimator alone;
                        * the path tracer renders whole paths regardless; 0: all */
    /* A shard of a render split over machines: its frames are one run of the whole render's
     * sequence (shard_frame_index), so the shards' samples are disjoint and together those of one
     * render; the film keeps the moments merging needs. 0: not a shard. shard_spp_total: the
     * whole render's frames (--spp), 0 with --time. */
    int shard_index, shard_count;
    long long shard_spp_total;
    vl_params vl;
    look_params look;
} render_params;

/* Work done, by kind of ray; summed over the frames since the last reset. */
typedef enum { RAY_CAMERA = 0, RAY_SHADOW, RAY_BOUNCE, RAY_KIND_COUNT } ray_kind;
extern const char *const ray_kind_names[RAY_KIND_COUNT];

/* The passes a frame runs, each timed (thread time; the virtual lights' preparation wall time):
 * path tracing (pt), or the camera rays with the direct light, the virtual lights' tracing and
 * clustering, gathering from them, and the highlights. */
typedef enum { PASS_PATHS = 0, PASS_DIRECT, PASS_VIRTUAL_LIGHTS, PASS_GATHER, PASS_HIGHLIGHTS, PASS_COUNT } pass_kind;
extern const char *const pass_names[PASS_COUNT];

/* The counters a session keeps, declared once: X(field, name, section, scale), the field of
 * render_stats, its name in `glint render --stats` (inside its "highlights" object for
 * STATS_HIGHLIGHTS, "auto" for STATS_AUTO), the methods that report it (STATS_ALL every one,
 * STATS_MANY_LIGHT vpl, vsl, vsl+hl and auto, STATS_HIGHLIGHTS vsl+hl, STATS_AUTO auto) and what the JSON multiplies it by (1: a count; 1e-9: nanoseconds
 * as seconds). render_stats, its sum (render_stats_add: over threads, over rows) and the JSON's
 * counters are made from this list: a counter added here is summed and reported with nothing else
 * to change. */
typedef enum { STATS_ALL, STATS_MANY_LIGHT, STATS_HIGHLIGHTS, STATS_AUTO } stats_section;
#define RENDER_COUNTERS(X)                                                                                             \
    X(rejected_samples, "rejected_samples", STATS_ALL, 1.0)             /* samples dropped: NaN or Inf */              \
    X(virtual_lights, "virtual_lights_total", STATS_MANY_LIGHT, 1.0)    /* deposited, over frames */                   \
    X(light_paths, "light_paths_total", STATS_MANY_LIGHT, 1.0)          /* traced to deposit them */                   \
    X(vl_connections, "connections", STATS_MANY_LIGHT, 1.0)             /* shading point - virtual light */            \
    X(vsl_samples, "vsl_samples", STATS_MANY_LIGHT, 1.0)                /* integration samples of the VSL integrals */ \
    X(clamped, "clamped", STATS_MANY_LIGHT, 1.0)                        /* contributions the clamp cut down */         \
    X(glossy_bounces, "glossy_bounces", STATS_MANY_LIGHT, 1.0)          /* camera paths on through a sharp lobe */     \
    X(pixel_points, "pixel_points", STATS_MANY_LIGHT, 1.0)              /* camera rays past a pixel's one a frame */   \
    X(hl_points, "points", STATS_HIGHLIGHTS, 1.0)                       /* camera hits the highlights worked at */     \
    X(hl_secondary_rays, "secondary_rays_total", STATS_HIGHLIGHTS, 1.0) /* rays from their glossy lobes */             \
    X(hl_lobes, "lobes_lit", STATS_HIGHLIGHTS, 1.0)                     /* merged, or one per secondary hit */         \
    X(hl_merge_ns, "merge_seconds", STATS_HIGHLIGHTS, 1e-9)             /* clustering and merging (thread time) */     \
    X(hl_traced_pixels, "traced_pixels", STATS_HIGHLIGHTS, 1.0)         /* --merge auto: at the last judgement */      \
    X(env_filter_bytes, "env_filter_bytes", STATS_HIGHLIGHTS, 1.0)      /* the prefiltered map's memory */             \
    X(auto_pt_paths, "pt_paths", STATS_AUTO, 1.0)                       /* auto: path-traced samples */                \
    X(auto_vl_samples, "vl_samples", STATS_AUTO, 1.0)                   /* ... virtual lights' samples */              \
    X(auto_vl_tiles, "vl_tiles", STATS_AUTO, 1.0)                       /* ... tiles of them, last judged */

/* Rays by kind, the list's counters and each pass's time; summed over the frames since the last reset. */
typedef struct {
    uint64_t rays[RAY_KIND_COUNT];
#define RENDER_COUNTER_FIELD(field, name, section, scale) uint64_t field;
    RENDER_COUNTERS(RENDER_COUNTER_FIELD)
#undef RENDER_COUNTER_FIELD
    uint64_t pass_ns[PASS_COUNT];
} render_stats;

/* from's counts added to to's, every one of them. */
void render_stats_add(render_stats *to, const render_stats *from);

/* ---- defaults ---------------------------------------------------------------------------------- */

/* vp with every default made explicit, as the renderer uses it: zero fields get their defaults,
 * counts are capped at their maxima, "off" stays negative (so resolving twice changes nothing).
 * Two fields stay open: clamp keeps VL_CLAMP_DEFAULT (the method's choice, render_params_resolve)
 * and per_pixel 0 becomes -1 (every representative) with columns, VL_DEFAULT_PER_PIXEL without;
 * a frame with fewer lights than columns does not cluster and then takes the default
 * (vl_frame_per_pixel). */
vl_params vl_params_resolve(const vl_params *vp);
/* p with its size, depth and method resolved, vl as given: what a session keeps (its estimators
 * resolve vl themselves, with the frame's light count at hand). */
render_params render_params_resolve_frame(const render_params *p);
/* p with its size, depth, method and vl resolved, clamp included (on for vpl, off otherwise). */
render_params render_params_resolve(const render_params *p);
/* Lights a pixel shades in a frame from vp as given (unresolved); 0: every one. clustering: the
 * frame clusters its lights (columns below its light count). */
int vl_frame_per_pixel(const vl_params *vp, int clustering);

/* ---- the parameter table --------------------------------------------------------------------- */

/* A parameter whose memory grows with its value (param_desc's bytes_each) is refused beyond this
 * much, at once, with what it would take: one zero too many must not run the machine out of
 * memory before anything says no. */
#define PARAM_MAX_BYTES (4.0 * 1024 * 1024 * 1024)
/* What one virtual light takes over a frame, measured: the light, its k-nearest-neighbour tree,
 * light tree and selection entries (1,000,000 lights: 559 MB at peak, 100,000: 70 MB). */
#define VL_BYTES_PER_LIGHT 512.0
/* A render's memory per pixel, measured (the film's sums and moments and the per-pixel records:
 * vsl at 2000x1000 122 bytes a pixel, pt 80), and the most an image may take: an 8K render
 * fits, 16384x16384 (32 GiB) does not. */
#define PARAM_PIXEL_BYTES 128.0
#define PARAM_MAX_IMAGE_BYTES (16.0 * 1024 * 1024 * 1024)
#define PARAM_MAX_SIDE 16384
/* "WxH", each 1..PARAM_MAX_SIDE, within PARAM_MAX_IMAGE_BYTES: 0, or -1 with err set and the size
 * unchanged. */
int params_parse_size(const char *text, int *width, int *height, char *err, size_t errlen);

typedef enum { PARAM_INT, PARAM_FLOAT, PARAM_CHOICE, PARAM_U64, PARAM_SIZE } param_type;
/* Which methods read a parameter: the panel shows it with them, the help groups by it. PARAM_RENDER:
 * every method (the method itself, the path depth, the plan, the seed), which each command's help
 * lists with its own options and default (params_render_help), not in params_help's sections;
 * PARAM_SETUP the same, but given when a render is set up, never changed while it runs (the
 * image's size); PARAM_DISPLAY the look (look_params), which never changes the estimate. */
typedef enum { PARAM_MANY_LIGHT, PARAM_HIGHLIGHTS, PARAM_RENDER, PARAM_SETUP, PARAM_DISPLAY } param_group;
/* Masks of groups (1 << group) a front end takes: the many-light ones, those that restart a
 * running render when they change, the look (which restarts nothing), all (a command line). */
#define PARAM_GROUPS_VL ((1u << PARAM_MANY_LIGHT) | (1u << PARAM_HIGHLIGHTS))
#define PARAM_GROUPS_LIVE (PARAM_GROUPS_VL | (1u << PARAM_RENDER))
#define PARAM_GROUPS_LOOK (1u << PARAM_DISPLAY)
#define PARAM_GROUPS_ALL (PARAM_GROUPS_LIVE | (1u << PARAM_SETUP) | PARAM_GROUPS_LOOK)

typedef struct {
    const char *name; /* the word on the command line and in scripts; NULL: the panel's only */
    int value;
    const char *label; /* the panel's */
} param_choice;

/* One parameter: an int, float or uint64_t field of render_params (a choice is an int field; the
 * many-light ones are in its vl), or a size (two ints, width then height). */
typedef struct {
    const char *name; /* the option without "--", and the script's `set` name */
    param_type type;
    param_group group;
    size_t offset;        /* of the field in render_params */
    double lo, hi;        /* numbers accepted */
    int below_hi;         /* hi itself is refused */
    double bytes_each;    /* the memory each unit of the value takes, if it grows with it (0: none) */
    const char *off_word; /* a word stored as -1 ("off", "all"); NULL: none */
    int zero_is_off;      /* 0 is stored as -1 too (0 in vl_params means the default) */
    const param_choice *choices;
    int num_choices;
    int flag;               /* the command line takes it alone, as "on", or with one of its choices */
    double def;             /* the default, as render_params_resolve gives it */
    const char *def_text;   /* the help's default when it is no one value (or each command's own) */
    const char *value_name; /* the help's name for the value (a choice's: its names, unless set) */
    const char *help;       /* lines for --help, '\n' between them */
    const char *label;      /* the panel's */
    const char *unit;       /* numbers: what the value counts or measures, for plots' axes */
    double panel_lo, panel_hi;
    int panel_log; /* a logarithmic slider */
    const char *panel_format;
    const char *panel_lo_text; /* shown at or below panel_lo (off, none, all) */
    int no_panel;              /* the panel has no widget for it (the seed) */
} param_desc;

const param_desc *params_table(int *count);
/* The entry named name (without "--"), or NULL. */
const param_desc *param_find(const char *name);
/* Sets d's field in p from text. Returns 0, or -1 with err = "NAME: problem" and p unchanged. */
int param_parse(const param_desc *d, const char *text, render_params *p, char *err, size_t errlen);
/* Sets parameter d to v (in range, -1 for off) under the memory rules (bytes_each and
 * clustering's matrix within PARAM_MAX_BYTES): 0, or -1 with p unchanged and err saying what it
 * would take (text: the value as the user gave it). param_parse and the panel both set through it. */
int param_set_value(const param_desc *d, render_params *p, double v, const char *text, char *err, size_t errlen);
/* Like param_parse by name, of the groups in mask (PARAM_GROUPS_*): 1 applied, 0 no such
 * parameter, -1 a bad value (err set). */
int params_set(render_params *p, unsigned groups, const char *name, const char *text, char *err, size_t errlen);
/* Whether a and b differ in an entry of the groups in mask (PARAM_GROUPS_*): what a viewer sends
 * the renderer again, whichever entry of the table changed. */
int params_differ(const render_params *a, const render_params *b, unsigned groups);
/* The field's value as param_parse reads it back (a choice's name, the off word, a number). */
void param_format(const param_desc *d, const render_params *p, char *out, size_t n);
/* The field as a number (choices their value, off -1; a seed beyond 2^53 rounded: param_format
 * gives it exactly; a size as width x 65536 + height). */
double param_get(const param_desc *d, const render_params *p);
void param_put(const param_desc *d, render_params *p, double v);
/* The many-light options' help text, one section per group; the returned text is static. */
const char *params_help(void);
/* The options of every method (every group but the many-light ones) that a command takes, named in
 * `names` (separated by spaces: "method max-depth seed"), as params_help words its own, for the
 * command's help, with the command's own defaults where they are not the table's (`defaults`:
 * "method=vsl denoise=on", or NULL); the text is static until the next call. */
const char *params_render_help(const char *names, const char *defaults);

#ifdef __cplusplus
}
#endif

#endif
