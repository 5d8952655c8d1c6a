/* glint tests — the parameter table (params.h): every entry is accepted by the command line's
 * parser and by the script's `set` (both through the table), listed in the help, complete for the
 * panel; its default is what render_params_resolve gives; every vl_params field has an entry, and
 * so have the method and the path depth; the option list in docs/methods.md is the help's. The counters' list (RENDER_COUNTERS) is all of
 * render_stats and all of it is summed. With the glint program as argument, each entry is also
 * given to `glint render` as a user would, and --stats reports every counter. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli.h"
#include "cli_harness.h"
#include "params.h"

/* A value for d other than its default, as text, and the number it is stored as. */
static double example(const param_desc *d, char *text, size_t n) {
    if (d->type == PARAM_CHOICE) {
        for (int c = 0; c < d->num_choices; c++)
            if (d->choices[c].name && d->choices[c].value != (int)d->def) {
                snprintf(text, n, "%s", d->choices[c].name);
                return d->choices[c].value;
            }
        return snprintf(text, n, "?"), 0.0;
    }
    if (d->type == PARAM_U64) return snprintf(text, n, "7"), 7.0;
    if (d->type == PARAM_SIZE) return snprintf(text, n, "32x18"), 32.0 * 65536.0 + 18.0;
    if (d->type == PARAM_INT) {
        int v = (int)d->lo != (int)d->def ? (int)d->lo : (int)d->lo + 1;
        snprintf(text, n, "%d", v);
        return v;
    }
    double v = d->lo > 0.0 ? 2.0 * d->lo : 0.5 * d->hi;
    snprintf(text, n, "%.17g", v);
    return (float)v;
}

static void test_entry(const param_desc *d, const char *help) {
    char text[64], err[256];
    double want = example(d, text, sizeof text);
    const render_params zero = {0};
    const unsigned all = PARAM_GROUPS_ALL;

    /* The script's `set` (params_set) and the command line (cli_set_param, cli_param_option). */
    render_params a = zero, b = zero, c = zero;
    CHECK(params_set(&a, all, d->name, text, err, sizeof err) == 1, "set %s %s: %s", d->name, text, err);
    CHECK(param_get(d, &a) == want, "set %s %s stored %g", d->name, text, param_get(d, &a));
    render_params other = a;
    param_put(d, &other, 0.0);
    CHECK(memcmp(&other, &zero, sizeof zero) == 0, "set %s changed another field", d->name);
    /* what a viewer sends again: a change of this entry, seen in its group and no other */
    unsigned mine = 1u << d->group;
    CHECK(params_differ(&a, &zero, mine) && !params_differ(&a, &zero, PARAM_GROUPS_ALL & ~mine),
          "params_differ misses set %s %s, or sees it in another group", d->name, text);
    CHECK(cli_set_param(d->name, text, &b, all) == 1 && memcmp(&a, &b, sizeof a) == 0, "--%s %s", d->name, text);
    /* a command that does not take the entry's group (bench's methods and depth are its own) */
    unsigned others = all & ~(1u << d->group);
    CHECK(params_set(&b, others, d->name, text, err, sizeof err) == 0, "%s taken outside its group", d->name);
    char option[80];
    snprintf(option, sizeof option, "--%s", d->name);
    char *argv[] = {option, d->flag ? (char *)"--next" : text, NULL};
    int i = 0;
    CHECK(cli_param_option(2, argv, &i, &c, all) == 1, "cli_param_option %s", option);
    CHECK(i == (d->flag ? 0 : 1), "%s took %d arguments", option, i);
    if (d->flag) {
        CHECK(param_get(d, &c) == 1.0, "%s alone is not on", option);
        char *with[] = {option, (char *)"off", NULL}; /* ... and takes a choice that follows it */
        render_params off = c;
        i = 0;
        CHECK(cli_param_option(2, with, &i, &off, all) == 1 && i == 1 && param_get(d, &off) == 0.0,
              "%s off: took %d arguments, stored %g", option, i, param_get(d, &off));
    } else
        CHECK(memcmp(&a, &c, sizeof a) == 0, "cli_param_option %s %s differs from set", option, text);
    /* the many-light sections list their own; each command lists the method, depth... (test_program) */
    int many_light = (PARAM_GROUPS_VL >> d->group & 1u) != 0;
    CHECK((strstr(help, option) != NULL) == many_light,
          "the help does not list %s (or lists it among the many-light options)", option);

    /* A bad value is refused with a message and changes nothing; the off word is -1. */
    render_params bad = a;
    CHECK(params_set(&bad, all, d->name, "banana", err, sizeof err) == -1 && memcmp(&bad, &a, sizeof a) == 0,
          "set %s banana accepted", d->name);
    if (d->off_word) {
        CHECK(params_set(&bad, all, d->name, d->off_word, err, sizeof err) == 1 && param_get(d, &bad) == -1.0,
              "set %s %s is not -1", d->name, d->off_word);
    }
    if (d->zero_is_off)
        CHECK(params_set(&bad, all, d->name, "0", err, sizeof err) == 1 && param_get(d, &bad) == -1.0,
              "%s 0 is not off", d->name);

    /* The default is what the renderer resolves a zero field to (the clamp's, the method's choice,
     * left open: vl_params_resolve), and what is set reads back. */
    render_params r = render_params_resolve_frame(&zero);
    r.vl = vl_params_resolve(&zero.vl);
    CHECK(param_get(d, &r) == (double)(d->type == PARAM_FLOAT ? (float)d->def : d->def),
          "%s: table default %g, resolved %g", d->name, d->def, param_get(d, &r));
    param_format(d, &a, text, sizeof text);
    render_params back = zero;
    CHECK(params_set(&back, all, d->name, text, err, sizeof err) == 1 && param_get(d, &back) == param_get(d, &a),
          "%s: '%s' does not read back", d->name, text);

    /* The panel's widget. */
    CHECK(d->label && d->label[0] && d->help && d->help[0], "%s: no label or help", d->name);
    if (d->type == PARAM_CHOICE) {
        for (int k = 0; k < d->num_choices; k++)
            CHECK(d->choices[k].label != NULL, "%s: a choice without a label", d->name);
    } else if (!d->no_panel) {
        CHECK(d->panel_lo < d->panel_hi && d->panel_format, "%s: no slider range", d->name);
        CHECK(d->panel_hi <= d->hi, "%s: the slider goes past the accepted range", d->name);
        CHECK(d->unit && d->unit[0], "%s: no unit for a sweep plot's axis", d->name);
    }
}

static void test_table(void) {
    int n;
    const param_desc *t = params_table(&n);
    const char *help = cli_vl_help();
    CHECK(n > 0, "an empty table");
    size_t covered = 0;
    for (int i = 0; i < n; i++) {
        test_entry(&t[i], help);
        CHECK(param_find(t[i].name) == &t[i], "%s: not found by name (or named twice)", t[i].name);
        for (int j = 0; j < i; j++)
            CHECK(strcmp(t[i].label, t[j].label) != 0 && t[i].offset != t[j].offset, "%s and %s share a label or field",
                  t[i].name, t[j].name);
        size_t vl_at = offsetof(render_params, vl);
        int in_vl = t[i].offset >= vl_at && t[i].offset < vl_at + sizeof(vl_params);
        CHECK(in_vl == ((PARAM_GROUPS_VL >> t[i].group & 1u) != 0), "%s: a field outside its group's struct",
              t[i].name);
        if (in_vl) covered += t[i].type == PARAM_FLOAT ? sizeof(float) : sizeof(int);
    }
    /* A vl_params field without an entry would be out of reach of every front end. */
    CHECK(covered == sizeof(vl_params), "the table covers %zu of vl_params' %zu bytes", covered, sizeof(vl_params));
    const param_desc *method = param_find("method"), *depth = param_find("max-depth");
    CHECK(method && method->offset == offsetof(render_params, method) && depth &&
              depth->offset == offsetof(render_params, max_depth) && depth->hi == MAX_DEPTH_LIMIT,
          "the method and the path depth are not the table's");
    render_params v = {0};
    char err[64];
    CHECK(params_set(&v, PARAM_GROUPS_ALL, "no-such-parameter", "1", err, sizeof err) == 0,
          "an unknown name was taken");
    /* a seed keeps all of its 64 bits, which a double would round */
    char text[32];
    CHECK(params_set(&v, PARAM_GROUPS_ALL, "seed", "18446744073709551615", err, sizeof err) == 1 &&
              v.seed == UINT64_MAX && (param_format(param_find("seed"), &v, text, sizeof text), 1) &&
              strcmp(text, "18446744073709551615") == 0,
          "seed 2^64 - 1: stored %llu", (unsigned long long)v.seed);
    CHECK(params_set(&v, PARAM_GROUPS_ALL, "seed", "-1", err, sizeof err) == -1 &&
              params_set(&v, PARAM_GROUPS_ALL, "seed", "18446744073709551616", err, sizeof err) == -1 &&
              v.seed == UINT64_MAX,
          "seeds out of range taken");
}

/* A parameter whose memory grows with it is refused beyond PARAM_MAX_BYTES, at once and saying what
 * it would take: the most lights that fit are taken, one more is not. */
static void test_memory_rule(void) {
    const param_desc *d = param_find("vsl-count");
    render_params v = {0};
    char err[256], text[32];
    long long most = (long long)(PARAM_MAX_BYTES / d->bytes_each);
    snprintf(text, sizeof text, "%lld", most);
    CHECK(d->bytes_each > 0.0 && params_set(&v, PARAM_GROUPS_VL, "vsl-count", text, err, sizeof err) == 1 &&
              v.vl.count == most,
          "vsl-count %s: %s", text, err);
    snprintf(text, sizeof text, "%lld", most + 1);
    CHECK(params_set(&v, PARAM_GROUPS_VL, "vsl-count", text, err, sizeof err) == -1 && v.vl.count == most &&
              strstr(err, "GiB") && strstr(err, "over the limit of 4 GiB"),
          "vsl-count %s: %s", text, err);
    /* clustering's matrix, rows x lights floats, under the same limit whichever option comes last */
    render_params m = {0};
    CHECK(params_set(&m, PARAM_GROUPS_VL, "rows", "100000", err, sizeof err) == 1 &&
              params_set(&m, PARAM_GROUPS_VL, "vsl-count", "8000000", err, sizeof err) == 1,
          "rows and lights alone: %s", err);
    CHECK(params_set(&m, PARAM_GROUPS_VL, "columns", "100", err, sizeof err) == -1 && m.vl.columns == 0 &&
              strstr(err, "matrix"),
          "columns 100 with a 100000 x 8000000 matrix: %s", err);
    CHECK(params_set(&m, PARAM_GROUPS_VL, "rows", "30", err, sizeof err) == 1 &&
              params_set(&m, PARAM_GROUPS_VL, "columns", "100", err, sizeof err) == 1,
          "a matrix of 30 rows: %s", err);
    CHECK(params_set(&m, PARAM_GROUPS_VL, "rows", "100000", err, sizeof err) == -1 && m.vl.rows == 30,
          "rows back to 100000: %s", err);
}

/* Resolving is idempotent, leaves explicit values and "off" alone, and decides the clamp by method. */
static void test_resolve(void) {
    const vl_params zero = {0};
    vl_params r = vl_params_resolve(&zero), rr = vl_params_resolve(&r);
    CHECK(memcmp(&r, &rr, sizeof r) == 0, "resolving twice changes the parameters");
    vl_params set = {.count = 77, .radius_shrink = -1.0f, .trace_glossy = -1.0f, .per_pixel = -1, .candidates = 100000};
    r = vl_params_resolve(&set);
    CHECK(r.count == 77 && r.radius_shrink < 0.0f && r.trace_glossy < 0.0f && r.per_pixel == -1,
          "explicit values changed");
    CHECK(r.candidates == VL_MAX_CANDIDATES, "candidates not capped: %d", r.candidates);
    vl_params clustered = {.columns = 100};
    CHECK(vl_params_resolve(&clustered).per_pixel == -1, "with columns every representative is shaded");
    CHECK(vl_frame_per_pixel(&clustered, 0) == VL_DEFAULT_PER_PIXEL && vl_frame_per_pixel(&clustered, 1) == 0,
          "a frame's lights per pixel");
    for (int m = 0; m < METHOD_COUNT; m++) {
        render_params p = render_params_resolve(&(render_params){.method = (render_method)m});
        CHECK(p.vl.clamp == (m == METHOD_VPL ? VL_CLAMP_ON : VL_CLAMP_OFF), "%s: clamp %d", method_name(p.method),
              p.vl.clamp);
        CHECK(p.max_depth == DEFAULT_MAX_DEPTH && p.width > 0 && p.height > 0, "%s: size or depth",
              method_name(p.method));
    }
}

/* The counters' list (RENDER_COUNTERS) is the whole of render_stats beside the rays and the passes,
 * and render_stats_add sums every one of them. */
static void test_counters(void) {
    int listed = 0;
#define COUNT_ONE(field, name, section, scale) listed++;
    RENDER_COUNTERS(COUNT_ONE)
#undef COUNT_ONE
    CHECK(sizeof(render_stats) == sizeof(uint64_t) * (size_t)(RAY_KIND_COUNT + listed + PASS_COUNT),
          "render_stats has a field outside the list");
    render_stats a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    uint64_t v = 1;
    for (int k = 0; k < RAY_KIND_COUNT; k++) b.rays[k] = v++;
#define SET_ONE(field, name, section, scale) b.field = v++;
    RENDER_COUNTERS(SET_ONE)
#undef SET_ONE
    for (int k = 0; k < PASS_COUNT; k++) b.pass_ns[k] = v++;
    render_stats_add(&a, &b);
    render_stats_add(&a, &b);
    v = 1;
    for (int k = 0; k < RAY_KIND_COUNT; k++, v++) CHECK(a.rays[k] == 2 * v, "rays[%d] not summed", k);
#define CHECK_ONE(field, name, section, scale)                                                                         \
    CHECK(a.field == 2 * v, "render_stats_add does not sum %s", name);                                                 \
    v++;
    RENDER_COUNTERS(CHECK_ONE)
#undef CHECK_ONE
    for (int k = 0; k < PASS_COUNT; k++, v++) CHECK(a.pass_ns[k] == 2 * v, "pass_ns[%d] not summed", k);
}

/* docs/methods.md lists the options as --help prints them. */
static void test_options_doc(void) {
    static char text[1 << 20];
    FILE *f = fopen(GLINT_OPTIONS_DOC, "rb");
    CHECK(f != NULL, "cannot open %s", GLINT_OPTIONS_DOC);
    if (!f) return;
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = 0;
    fclose(f);
    CHECK(strstr(text, cli_vl_help()) != NULL, "%s: the option list differs from --help's:\n%s", GLINT_OPTIONS_DOC,
          cli_vl_help());
}

/* Each entry given to glint render as a user would: a tiny vsl image. */
static void test_program(void) {
    int n;
    const param_desc *t = params_table(&n);
    /* One zero too many is one line at once, naming the option and the memory. */
    CHECK(run("render --method vsl --vsl-count 50000000 --size 8x6 --spp 1 --png p.png") == 2 &&
              strstr(err_text, "glint: error: --vsl-count: 50000000 would take 23.8 GiB") &&
              strchr(err_text, '\n') == err_text + strlen(err_text) - 1,
          "--vsl-count 50000000: %s", err_text);
    /* --stats reports every counter of the list (vsl+hl every section but auto's, auto its own) */
    static char json[16384];
    CHECK(run("render builtin:showcase --method vsl+hl --size 16x12 --spp 1 --vsl-count 16 --quiet --png p.png "
              "--stats s.json") == 0 &&
              read_file("s.json", json, sizeof json) > 0,
          "vsl+hl --stats: %s", err_text);
#define IN_JSON(field, name, section, scale)                                                                           \
    if ((section) != STATS_AUTO) CHECK(strstr(json, "\"" name "\": ") != NULL, "--stats lacks %s", name);
    RENDER_COUNTERS(IN_JSON)
#undef IN_JSON
    CHECK(run("render builtin:showcase --method auto --size 16x12 --spp 1 --vsl-count 16 --quiet --png p.png "
              "--stats s.json") == 0 &&
              read_file("s.json", json, sizeof json) > 0,
          "auto --stats: %s", err_text);
#define IN_JSON(field, name, section, scale)                                                                           \
    if ((section) == STATS_AUTO) CHECK(strstr(json, "\"" name "\": ") != NULL, "auto's --stats lacks %s", name);
    RENDER_COUNTERS(IN_JSON)
#undef IN_JSON
    for (int i = 0; i < n; i++) {
        char text[64], args[512];
        example(&t[i], text, sizeof text);
        snprintf(args, sizeof args,
                 "render --method %s --size 8x6 --spp 1 --vsl-count 16 --quiet --png p.png --out p.exr --%s %s",
                 t[i].group == PARAM_HIGHLIGHTS ? "vsl+hl" : "vsl", t[i].name, t[i].flag ? "" : text);
        int rc = run(args);
        CHECK(rc == 0, "glint %s: exit %d: %s", args, rc, err_text);
    }
    /* Each command's help lists the entries of every method that it takes as the table words them,
     * in blocks where they fit its own options, with its own defaults (the viewer opens on vsl, its
     * image filtered); every entry of those groups is taken by some command. */
    static const struct {
        const char *args, *blocks[2], *defaults;
    } helps[] = {
        {"render --help", {"method max-depth seed size plan", "exposure tonemap denoise"}, NULL},
        {"view --help",
         {"size method max-depth seed plan exposure tonemap denoise", NULL},
         "method=" DEFAULT_METHOD_NAME " denoise=on"},
        {"info --help", {"method max-depth plan", NULL}, "method=" DEFAULT_METHOD_NAME},
    };
    CHECK(strcmp(method_name(DEFAULT_METHOD), DEFAULT_METHOD_NAME) == 0, "DEFAULT_METHOD_NAME is not its name");
    int taken[64] = {0};
    for (int k = 0; k < 3; k++) {
        CHECK(run(helps[k].args) == 0, "glint %s: %s", helps[k].args, err_text);
        for (int b = 0; b < 2 && helps[k].blocks[b]; b++) {
            const char *lines = params_render_help(helps[k].blocks[b], helps[k].defaults);
            CHECK(lines[0] && strstr(out_text, lines) != NULL, "glint %s does not list these as:\n%s", helps[k].args,
                  lines);
            for (int i = 0; i < n && i < 64; i++) {
                char option[80];
                snprintf(option, sizeof option, "  --%s ", t[i].name);
                taken[i] |= strstr(lines, option) != NULL;
            }
        }
    }
    for (int i = 0; i < n && i < 64; i++)
        CHECK((PARAM_GROUPS_VL >> t[i].group & 1u) || taken[i], "no command's help lists --%s", t[i].name);
    /* a flag alone is on; one of its choices may follow it (glint view --denoise off) */
    CHECK(run("render --size 8x6 --spp 1 --quiet --png p.png --vpl-glossy off --denoise off") == 0,
          "--vpl-glossy off --denoise off: %s", err_text);
    /* the seed, all 64 bits of it, as glint render takes it */
    CHECK(run("render --size 8x6 --spp 1 --quiet --png p.png --seed 18446744073709551615") == 0, "--seed 2^64 - 1: %s",
          err_text);
    CHECK(run("render --size 8x6 --spp 1 --quiet --png p.png --seed -1") == 2 &&
              strstr(err_text, "glint: error: --seed: expected an integer"),
          "--seed -1: %s", err_text);
}

int main(int argc, char **argv) {
    test_table();
    test_resolve();
    test_memory_rule();
    test_options_doc();
    test_counters();
    if (argc >= 2 && harness_start(argc, argv, "params") == 0) test_program();
    return check_exit("test_params");
}
