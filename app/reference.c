/* glint — reference descriptions: content hashes, the JSON in a reference EXR's header (or, from
 * older glint, beside it), the noise of a progressive mean from two halves, and the match check
 * glint bench runs. */
#define _POSIX_C_SOURCE 200809L
#include "reference.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camera.h"
#include "image_io.h"
#include "metrics.h"

static int fail(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(char *err, size_t errlen, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

static uint64_t fnv1a64(uint64_t h, const unsigned char *p, size_t n) {
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}
#define FNV_OFFSET 0xcbf29ce484222325ull

int reference_hash_file(const char *path, char out[64], char *err, size_t errlen) {
    if (scene_builtin_name(path)) {
        const builtin_scene *b = scene_builtin_find(scene_builtin_name(path));
        if (!b) return fail(err, errlen, "%s: no such built-in scene", path);
        uint64_t h = fnv1a64(FNV_OFFSET, b->gltf, *b->size);
        snprintf(out, 64, "%s:fnv1a64:%016llx", path, (unsigned long long)h);
        return 0;
    }
    FILE *f = open_regular_file(path);
    if (!f) return fail(err, errlen, "%s: cannot open: %s", path, open_regular_problem(errno));
    uint64_t h = FNV_OFFSET;
    unsigned char buf[1 << 16];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = fnv1a64(h, buf, n);
    int bad = ferror(f);
    fclose(f);
    if (bad) return fail(err, errlen, "%s: read error", path);
    snprintf(out, 64, "fnv1a64:%016llx", (unsigned long long)h);
    return 0;
}

int reference_describe(reference_info *r, const char *scene_path, const char *env_path, double env_rotation_deg,
                       const scene *s, int camera_index, const render_params *p, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    snprintf(r->model, sizeof r->model, "%s", BSDF_MODEL_STAMP);
    /* Without a path, the scene is the default built-in, which knows its name. */
    snprintf(r->scene, sizeof r->scene, "%s", scene_path ? scene_path : s->path);
    if (reference_hash_file(r->scene, r->scene_hash, err, errlen)) return -1;
    if (env_path) {
        snprintf(r->env, sizeof r->env, "%s", env_path);
        if (reference_hash_file(env_path, r->env_hash, err, errlen)) return -1;
        r->env_rotation = env_rotation_deg;
    }
    if (scene_variant(s) >= 0) snprintf(r->variant, sizeof r->variant, "%s", scene_variant_name(s, scene_variant(s)));
    /* -1 renders the first camera when there is one: record that, so both spellings match. */
    r->camera_index = camera_index < 0 && s->num_cameras > 0 ? 0 : camera_index;
    r->cam = scene_camera(s, camera_index, (float)p->width / (float)p->height);
    r->scene_diag = s->diag;
    r->width = p->width;
    r->height = p->height;
    r->max_depth = p->max_depth > 0 ? p->max_depth : DEFAULT_MAX_DEPTH;
    r->seed = p->seed;
    r->threads = p->threads;
    snprintf(r->method, sizeof r->method, "%s", method_name(p->method));
    r->highlights_layer = p->pt_highlights || p->method == METHOD_VSL_HL;
    reference_params_text(p, r->params, sizeof r->params);
    if (p->shard_count > 0) {
        r->shard_count = p->shard_count;
        reference_add_shard(r, p->shard_index);
    }
    return 0;
}

void reference_params_text(const render_params *p, char *out, size_t n) {
    const render_params r = render_params_resolve(p);
    size_t len = 0;
    len += (size_t)snprintf(out, n, "plan=%s", r.plan == PLAN_FULL ? "full" : "auto");
    if (r.method == METHOD_PT) return; /* whole paths: nothing else shapes them */
    char only[64] = "";
    for (int c = 0; c < COMP_COUNT; c++)
        if (!r.only || r.only & (1u << c))
            snprintf(only + strlen(only), sizeof only - strlen(only), "%s%s", only[0] ? "," : "",
                     film_component_names[c]);
    len += (size_t)snprintf(out + len, len < n ? n - len : 0, " only=%s", only);
    int count = 0;
    const param_desc *table = params_table(&count);
    for (int k = 0; k < count; k++) {
        if (!(PARAM_GROUPS_VL >> table[k].group & 1u)) continue; /* the method, size...: fields of their own */
        char v[64];
        param_format(&table[k], &r, v, sizeof v);
        len += (size_t)snprintf(out + len, len < n ? n - len : 0, " %s=%s", table[k].name, v);
    }
}

/* The sidecar path of an EXR as older glint wrote it: "OUT.exr.json". */
static int reference_sidecar_path(const char *exr_path, char *out, size_t outlen) {
    int n = snprintf(out, outlen, "%s.json", exr_path);
    return n < 0 || (size_t)n >= outlen ? -1 : 0;
}

/* ---- writing --------------------------------------------------------------------------------- */

void reference_json_string(FILE *f, const char *s) {
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void json_vec3(FILE *f, const char *key, vec3 v) {
    fprintf(f, "\"%s\": [%.9g, %.9g, %.9g]", key, (double)v.x, (double)v.y, (double)v.z);
}

/* One string attribute holding the same JSON as the old sidecar, rather than typed attributes:
 * one schema and one parser (cJSON) for both, and EXR has no 64-bit integer attribute for the
 * seed nor nesting for the camera. */
char *reference_json(const reference_info *r) {
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return NULL;
    fprintf(f, "{\n  \"glint_reference\": 1,\n  \"model\": ");
    reference_json_string(f, r->model);
    fputs(",\n  \"scene\": ", f);
    reference_json_string(f, r->scene);
    /* Every string escaped, the hashes too: a description read from a file holds what it held. */
    fputs(",\n  \"scene_hash\": ", f);
    reference_json_string(f, r->scene_hash);
    fputs(",\n  \"env\": ", f);
    reference_json_string(f, r->env);
    fputs(",\n  \"env_hash\": ", f);
    reference_json_string(f, r->env_hash);
    /* The rotation reads back exactly, however large, for reference_check's comparison. */
    char rot[32];
    snprintf(rot, sizeof rot, "%.15g", r->env_rotation);
    if (strtod(rot, NULL) != r->env_rotation) snprintf(rot, sizeof rot, "%.17g", r->env_rotation);
    fprintf(f, ",\n  \"env_rotation\": %s,\n", rot);
    if (r->variant[0]) { /* older references have none: the default materials */
        fputs("  \"variant\": ", f);
        reference_json_string(f, r->variant);
        fputs(",\n", f);
    }
    fprintf(f, "  \"camera\": {\"index\": %d, ", r->camera_index);
    json_vec3(f, "position", r->cam.position);
    fputs(", ", f);
    json_vec3(f, "right", r->cam.right);
    fputs(", ", f);
    json_vec3(f, "up", r->cam.up);
    fputs(", ", f);
    json_vec3(f, "forward", r->cam.forward);
    fprintf(f, ", \"yfov\": %.9g},\n", (double)r->cam.yfov);
    if (r->scene_diag > 0.0f) fprintf(f, "  \"scene_diagonal\": %.9g,\n", (double)r->scene_diag);
    fputs("  \"lights\": ", f);
    reference_json_string(f, r->lights);
    fputs(",\n", f);
    fprintf(f, "  \"width\": %d,\n  \"height\": %d,\n  \"method\": ", r->width, r->height);
    reference_json_string(f, r->method);
    fprintf(f, ",\n  \"highlights_layer\": %s,\n", r->highlights_layer ? "true" : "false");
    fprintf(f, "  \"spp\": %lld,\n  \"frames\": %lld,\n  \"seconds\": %.6f,\n  \"max_depth\": %d,\n", r->spp, r->spp,
            r->seconds, r->max_depth);
    fprintf(f, "  \"seed\": %llu,\n  \"threads\": %d,\n", (unsigned long long)r->seed, r->threads);
    fputs("  \"params\": ", f);
    reference_json_string(f, r->params);
    fputs(",\n", f);
    if (r->shard_count > 0) {
        fprintf(f, "  \"shards\": {\"count\": %d, \"spp_total\": %lld, \"indices\": [", r->shard_count, r->spp_total);
        for (int i = 0, first = 1; i < r->shard_count; i++)
            if (reference_has_shard(r, i)) fprintf(f, "%s%d", first ? "" : ", ", i), first = 0;
        fputs("]},\n", f);
    }
    if (r->capture)
        fprintf(f,
                "  \"capture\": {\"since_change\": %.6f, \"since_start\": %.6f, \"image_age\": %.6f, "
                "\"preview\": %s, \"image_size\": [%d, %d], \"latest\": %s},\n",
                r->since_change, r->since_start, r->image_age, r->preview ? "true" : "false", r->image_width,
                r->image_height, r->latest ? "true" : "false");
    if (r->has_noise)
        fprintf(f,
                "  \"variance\": {\"mean_pixel_variance\": %.9g, \"rel_l2_noise\": %.9g, "
                "\"estimate\": \"%s\"}\n}\n",
                r->mean_variance, r->rel_l2_noise, r->shard_count > 0 ? "pixel variances" : "two halves of the frames");
    else
        fprintf(f, "  \"variance\": null\n}\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* ---- reading: cJSON parses, then every field is checked for its type and range ---------------- */

/* obj's member key, a string that fits out. */
static int json_str(const cJSON *obj, const char *key, char *out, size_t outlen) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsString(v) || strlen(v->valuestring) >= outlen) return -1;
    memcpy(out, v->valuestring, strlen(v->valuestring) + 1);
    return 0;
}

/* A finite number: cJSON reads 1e999 as infinity. */
static int finite_number(const cJSON *v, double *out) {
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble)) return -1;
    *out = v->valuedouble;
    return 0;
}

static int json_number(const cJSON *obj, const char *key, double *out) {
    return finite_number(cJSON_GetObjectItemCaseSensitive(obj, key), out);
}

static int json_int(const cJSON *obj, const char *key, long long lo, long long hi, long long *out) {
    double x;
    if (json_number(obj, key, &x) || x != floor(x) || x < (double)lo || x > (double)hi) return -1;
    *out = (long long)x;
    return 0;
}

/* A float of the camera: beyond FLT_MAX it would become infinite. */
static int json_float(const cJSON *v, float *out) {
    double x;
    if (finite_number(v, &x) || fabs(x) > (double)FLT_MAX) return -1;
    *out = (float)x;
    return 0;
}

static int json_vec(const cJSON *obj, const char *key, vec3 *out) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    float c[3];
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) return -1;
    for (int k = 0; k < 3; k++)
        if (json_float(cJSON_GetArrayItem(v, k), &c[k])) return -1;
    *out = (vec3){c[0], c[1], c[2]};
    return 0;
}

/* The seed, any uint64. cJSON keeps numbers as doubles, exact to 2^53 only, and the bench must
 * know the reference's seed exactly (not to replay its samples); so a larger seed is read again
 * from the digits after a "seed": in the text, taken when they are the number cJSON read. */
static int json_seed(const cJSON *obj, const char *text, uint64_t *out) {
    double x;
    /* 2^64 - 1 rounds to 2^64: that far the digits decide */
    if (json_number(obj, "seed", &x) || x != floor(x) || x < 0.0 || x > 18446744073709551616.0) return -1;
    if (x < 9007199254740992.0) { /* 2^53 itself may be 2^53 + 1 rounded */
        *out = (uint64_t)x;
        return 0;
    }
    for (const char *p = strstr(text, "\"seed\""); p; p = strstr(p + 1, "\"seed\"")) {
        const char *q = p + 6 + strspn(p + 6, " \t\r\n");
        if (*q != ':') continue;
        q += 1 + strspn(q + 1, " \t\r\n");
        errno = 0;
        unsigned long long v = *q >= '0' && *q <= '9' ? strtoull(q, NULL, 10) : 0;
        if (errno == 0 && (double)v == x) {
            *out = v;
            return 0;
        }
    }
    return -1;
}

/* "shards": {"count": N, "spp_total": T, "indices": [i, ...]}: distinct indices below N. */
static int parse_shards(const cJSON *obj, reference_info *r) {
    long long count, total, i;
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(obj, "indices");
    if (json_int(obj, "count", 1, REFERENCE_MAX_SHARDS, &count) ||
        json_int(obj, "spp_total", 0, (long long)1 << 50, &total) || !cJSON_IsArray(list) ||
        cJSON_GetArraySize(list) < 1)
        return -1;
    r->shard_count = (int)count;
    r->spp_total = total;
    const cJSON *v;
    cJSON_ArrayForEach(v, list) {
        double x;
        if (finite_number(v, &x) || x != floor(x) || x < 0.0 || x >= (double)count) return -1;
        i = (long long)x;
        if (reference_has_shard(r, (int)i)) return -1;
        reference_add_shard(r, (int)i);
    }
    return 0;
}

/* "capture": {"since_change": S, "since_start": S, "image_age": S, "preview": B, "image_size": [W, H],
 * "latest": B}. */
static int parse_capture(const cJSON *obj, reference_info *r) {
    const cJSON *size = cJSON_GetObjectItemCaseSensitive(obj, "image_size");
    const cJSON *preview = cJSON_GetObjectItemCaseSensitive(obj, "preview");
    const cJSON *latest = cJSON_GetObjectItemCaseSensitive(obj, "latest");
    double w, h;
    if (!cJSON_IsObject(obj) || json_number(obj, "since_change", &r->since_change) ||
        json_number(obj, "since_start", &r->since_start) || json_number(obj, "image_age", &r->image_age) ||
        !cJSON_IsBool(preview) || !cJSON_IsBool(latest) || !cJSON_IsArray(size) || cJSON_GetArraySize(size) != 2 ||
        finite_number(cJSON_GetArrayItem(size, 0), &w) || finite_number(cJSON_GetArrayItem(size, 1), &h) ||
        w != floor(w) || h != floor(h) || w < 1 || h < 1 || w > 16384 || h > 16384)
        return -1;
    r->capture = 1;
    r->preview = cJSON_IsTrue(preview);
    r->latest = cJSON_IsTrue(latest);
    r->image_width = (int)w;
    r->image_height = (int)h;
    return 0;
}

/* A description is small; this bounds what a damaged or hostile file can make the parser do. */
enum { MAX_DESCRIPTION = 1 << 20 };

int reference_parse(const char *text, size_t n, const char *label, reference_info *r, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    if (n > MAX_DESCRIPTION) return fail(err, errlen, "%s (too large: more than 1 MiB)", label);
    if (memchr(text, '\0', n)) return fail(err, errlen, "%s (binary data)", label);
    /* cJSON refuses nesting deeper than CJSON_NESTING_LIMIT (1000), so no input exhausts the stack. */
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        int line = 1;
        for (const char *p = text; end && p < end; p++) line += *p == '\n';
        return fail(err, errlen, "%s (not JSON, line %d)", label, line);
    }
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return fail(err, errlen, "%s (not a JSON object)", label);
    }
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    const char *missing = NULL;
    long long ll = 0;
#define NEED(ok, key)                                                                                                  \
    if (!missing && !(ok)) missing = key
    NEED(cJSON_GetObjectItemCaseSensitive(root, "glint_reference") != NULL, "glint_reference");
    /* Older references have no model: read as "", which reference_check refuses as stale. */
    NEED(!cJSON_GetObjectItemCaseSensitive(root, "model") || json_str(root, "model", r->model, sizeof r->model) == 0,
         "model");
    NEED(json_str(root, "scene", r->scene, sizeof r->scene) == 0, "scene");
    NEED(json_str(root, "scene_hash", r->scene_hash, sizeof r->scene_hash) == 0, "scene_hash");
    /* Before there were several, the built-in scene showcase was spelt builtin:default. */
    static const char legacy[] = "builtin:default:";
    if (strncmp(r->scene_hash, legacy, strlen(legacy)) == 0) {
        char rest[sizeof r->scene_hash];
        snprintf(rest, sizeof rest, "%s", r->scene_hash + strlen(legacy));
        snprintf(r->scene_hash, sizeof r->scene_hash, "builtin:showcase:%.40s", rest); /* fnv1a64: + 16 digits */
    }
    NEED(json_str(root, "env", r->env, sizeof r->env) == 0, "env");
    NEED(json_str(root, "env_hash", r->env_hash, sizeof r->env_hash) == 0, "env_hash");
    NEED(json_number(root, "env_rotation", &r->env_rotation) == 0, "env_rotation");
    NEED(!cJSON_GetObjectItemCaseSensitive(root, "variant") ||
             json_str(root, "variant", r->variant, sizeof r->variant) == 0,
         "variant");
    NEED(json_int(cam, "index", -1, 1000000, &ll) == 0, "camera index");
    r->camera_index = (int)ll;
    NEED(json_vec(cam, "position", &r->cam.position) == 0, "camera position");
    NEED(json_vec(cam, "right", &r->cam.right) == 0, "camera right");
    NEED(json_vec(cam, "up", &r->cam.up) == 0, "camera up");
    NEED(json_vec(cam, "forward", &r->cam.forward) == 0, "camera forward");
    NEED(json_float(cJSON_GetObjectItemCaseSensitive(cam, "yfov"), &r->cam.yfov) == 0, "camera yfov");
    NEED(json_int(root, "width", 1, 16384, &ll) == 0, "width");
    r->width = (int)ll;
    NEED(json_int(root, "height", 1, 16384, &ll) == 0, "height");
    r->height = (int)ll;
    NEED(json_str(root, "method", r->method, sizeof r->method) == 0, "method");
    const cJSON *hl = cJSON_GetObjectItemCaseSensitive(root, "highlights_layer");
    NEED(cJSON_IsBool(hl), "highlights_layer");
    r->highlights_layer = cJSON_IsTrue(hl);
    NEED(json_int(root, "spp", 0, (long long)1 << 50, &r->spp) == 0, "spp");
    NEED(json_number(root, "seconds", &r->seconds) == 0, "seconds");
    NEED(json_int(root, "max_depth", 1, MAX_DEPTH_LIMIT, &ll) == 0, "max_depth");
    r->max_depth = (int)ll;
    NEED(json_seed(root, text, &r->seed) == 0, "seed");
    NEED(!cJSON_GetObjectItemCaseSensitive(root, "params") ||
             json_str(root, "params", r->params, sizeof r->params) == 0,
         "params");
    /* Newer fields, absent from older descriptions: no scale known, no light edits, not a capture. */
    const cJSON *diag = cJSON_GetObjectItemCaseSensitive(root, "scene_diagonal");
    NEED(!diag || (json_float(diag, &r->scene_diag) == 0 && r->scene_diag > 0.0f), "scene_diagonal");
    light_edit edits[REFERENCE_MAX_LIGHT_EDITS];
    char why[256];
    NEED(!cJSON_GetObjectItemCaseSensitive(root, "lights") ||
             (json_str(root, "lights", r->lights, sizeof r->lights) == 0 &&
              reference_lights_parse(r->lights, edits, REFERENCE_MAX_LIGHT_EDITS, why, sizeof why) >= 0),
         "lights");
    const cJSON *capture = cJSON_GetObjectItemCaseSensitive(root, "capture");
    NEED(!capture || parse_capture(capture, r) == 0, "capture");
    const cJSON *shards = cJSON_GetObjectItemCaseSensitive(root, "shards");
    NEED(!shards || parse_shards(shards, r) == 0, "shards");
    /* "variance": null when the reference rendered a single frame. */
    const cJSON *var = cJSON_GetObjectItemCaseSensitive(root, "variance");
    r->has_noise = json_number(var, "mean_pixel_variance", &r->mean_variance) == 0 &&
                   json_number(var, "rel_l2_noise", &r->rel_l2_noise) == 0;
#undef NEED
    cJSON_Delete(root);
    if (missing) return fail(err, errlen, "%s (missing or bad \"%s\")", label, missing);
    return 0;
}

/* An older reference's sidecar: 1 when there is none. */
static int load_sidecar(const char *exr_path, reference_info *r, char *err, size_t errlen) {
    char path[4200], label[4300];
    if (reference_sidecar_path(exr_path, path, sizeof path) != 0)
        return fail(err, errlen, "%s: name too long", exr_path);
    FILE *f = open_regular_file(path);
    if (!f) {
        if (errno == ENOENT) return 1;
        return fail(err, errlen, "%s: cannot open: %s", path, open_regular_problem(errno));
    }
    char *text = malloc(MAX_DESCRIPTION + 2);
    if (!text) {
        fclose(f);
        return fail(err, errlen, "%s: out of memory", path);
    }
    size_t n = fread(text, 1, MAX_DESCRIPTION + 1, f);
    int bad_read = ferror(f);
    fclose(f);
    text[n] = '\0';
    snprintf(label, sizeof label, "%s: not a glint reference sidecar", path);
    int status = bad_read ? fail(err, errlen, "%s: read error", path) : reference_parse(text, n, label, r, err, errlen);
    free(text);
    return status;
}

int reference_load(const char *exr_path, reference_info *r, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    char *text = NULL, label[4300];
    size_t n = 0;
    int st = exr_header_string(exr_path, REFERENCE_ATTR, &text, &n, err, errlen);
    if (st < 0) return -1;
    if (st > 0) return load_sidecar(exr_path, r, err, errlen);
    snprintf(label, sizeof label, "%s: bad %s header attribute", exr_path, REFERENCE_ATTR);
    int status = reference_parse(text, n, label, r, err, errlen);
    free(text);
    return status;
}

/* ---- noise of the reference ------------------------------------------------------------------ */

int reference_noise_init(reference_noise *rn, int width, int height) {
    memset(rn, 0, sizeof *rn);
    rn->n = (size_t)width * (size_t)height * 3;
    rn->snap[0] = malloc(sizeof(float) * rn->n);
    rn->snap[1] = malloc(sizeof(float) * rn->n);
    rn->scratch = malloc(sizeof(float) * rn->n);
    if (!rn->snap[0] || !rn->snap[1] || !rn->scratch) {
        reference_noise_deinit(rn);
        return -1;
    }
    return 0;
}

void reference_noise_deinit(reference_noise *rn) {
    free(rn->snap[0]);
    free(rn->snap[1]);
    free(rn->scratch);
    memset(rn, 0, sizeof *rn);
}

void reference_noise_frame(reference_noise *rn, const render_session *rs) {
    long long frames = session_frames(rs);
    if (!rn->scratch || frames <= 0 || (frames & (frames - 1)) != 0) return;
    float *t = rn->snap[0];
    rn->snap[0] = rn->snap[1];
    rn->snap_frames[0] = rn->snap_frames[1];
    rn->snap[1] = t;
    rn->snap_frames[1] = frames;
    film_resolve(session_film(rs), COMP_MASK_ALL, t);
}

void reference_noise_from_variance(const float *const mean[3], const float *const var[3], size_t stride,
                                   const double *count, size_t pixels, reference_info *info) {
    /* The variance of a pixel's mean is one sample's over the count (var, the squared deviations
     * over the count, over count - 1 is its unbiased estimate): summed, it is the expected squared
     * L2 distance of the image from the truth, as the two halves estimate it. */
    double sum = 0.0, norm = 0.0;
    for (size_t i = 0; i < pixels; i++)
        for (int k = 0; k < 3; k++) {
            double m = (double)mean[k][i * stride];
            norm += m * m;
            if (count[i] > 1.0) sum += (double)var[k][i * stride] / (count[i] - 1.0);
        }
    info->has_noise = pixels > 0;
    info->mean_variance = pixels > 0 ? sum / (3.0 * (double)pixels) : 0.0;
    info->rel_l2_noise = norm > 0.0 ? sqrt(sum / norm) : 0.0;
}

/* A shard's noise, from its film's moments. -1 out of memory. */
static int noise_from_moments(const film *f, reference_info *info) {
    size_t n = (size_t)f->width * (size_t)f->height;
    float *mean = malloc(sizeof(float) * 3 * n), *var = malloc(sizeof(float) * 3 * n);
    double *count = malloc(sizeof(double) * n);
    int status = -1;
    if (mean && var && count) {
        film_resolve(f, COMP_MASK_ALL, mean);
        film_resolve_variance(f, COMP_MASK_ALL, var);
        for (size_t i = 0; i < n; i++) count[i] = (double)(f->passes - (long long)f->rejected[i]);
        const float *const m[3] = {mean, mean + 1, mean + 2}, *const v[3] = {var, var + 1, var + 2};
        reference_noise_from_variance(m, v, 3, count, n, info);
        status = 0;
    }
    free(mean);
    free(var);
    free(count);
    return status;
}

void reference_noise_finish(reference_noise *rn, const render_session *rs, reference_info *info) {
    info->has_noise = 0;
    long long total = session_frames(rs);
    if (session_film(rs)->sumsq[0] && total >= 2 && noise_from_moments(session_film(rs), info) == 0) return;
    if (!rn->scratch || total < 2) return;
    /* Of the snapshots taken before the end, the one whose split is closest to even. */
    int best = -1;
    for (int k = 0; k < 2; k++) {
        long long m = rn->snap_frames[k];
        if (m <= 0 || m >= total) continue;
        if (best < 0 || llabs(2 * m - total) < llabs(2 * rn->snap_frames[best] - total)) best = k;
    }
    if (best < 0) return;
    film_resolve(session_film(rs), COMP_MASK_ALL, rn->scratch);
    info->mean_variance = metric_mean_variance_halves(rn->snap[best], rn->scratch, rn->n, rn->snap_frames[best], total,
                                                      &info->rel_l2_noise);
    info->has_noise = 1;
}

/* ---- light edits ----------------------------------------------------------------------------- */

static int by_group(const void *a, const void *b) {
    int x = ((const light_edit *)a)->group, y = ((const light_edit *)b)->group;
    return (x > y) - (x < y);
}

static int unedited(const light_edit *e) { return is_black3(e->offset) && e->gain == 1.0f; }

int reference_lights_text(const light_edit *edits, int n, char *out, size_t outlen) {
    light_edit sorted[REFERENCE_MAX_LIGHT_EDITS];
    int m = 0;
    for (int i = 0; i < n; i++)
        if (!unedited(&edits[i])) {
            if (m == REFERENCE_MAX_LIGHT_EDITS) return -1;
            sorted[m++] = edits[i];
        }
    qsort(sorted, (size_t)m, sizeof sorted[0], by_group);
    size_t len = 0;
    if (outlen) out[0] = 0;
    for (int i = 0; i < m; i++) {
        /* + 0.0f: a -0 offset prints as 0, so equal edits have one text; %.9g reads back exactly */
        const light_edit *e = &sorted[i];
        int k = snprintf(out + len, outlen - len, "%s%d:%.9g,%.9g,%.9g*%.9g", i ? ";" : "", e->group,
                         (double)(e->offset.x + 0.0f), (double)(e->offset.y + 0.0f), (double)(e->offset.z + 0.0f),
                         (double)e->gain);
        if (k < 0 || (size_t)k >= outlen - len) return -1;
        len += (size_t)k;
    }
    return 0;
}

int reference_lights_parse(const char *text, light_edit *out, int max, char *err, size_t errlen) {
    int n = 0;
    for (const char *p = text; *p;) {
        const char *end = strchr(p, ';');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char item[160], tail;
        if (len >= sizeof item) return fail(err, errlen, "light edit '%.40s...' too long", p);
        memcpy(item, p, len);
        item[len] = 0;
        int g;
        float x, y, z, gain;
        if (sscanf(item, "%d:%f,%f,%f*%f%c", &g, &x, &y, &z, &gain, &tail) != 5 || g < 0 || g >= 1000000 ||
            !isfinite(x) || !isfinite(y) || !isfinite(z) || !(gain >= 1e-6f && gain <= 1e6f))
            return fail(err, errlen, "light edit '%s' is not GROUP:DX,DY,DZ*GAIN", item);
        for (int i = 0; i < n; i++)
            if (out[i].group == g) return fail(err, errlen, "light %d edited twice", g);
        if (n == max) return fail(err, errlen, "more than %d light edits", max);
        out[n++] = (light_edit){g, v3(x, y, z), gain};
        p += len + (end ? 1 : 0);
        if (end && !*p) return fail(err, errlen, "a light edit list ends in ';'");
    }
    return n;
}

static int near(float a, float b) { return fabsf(a - b) <= 1e-5f * (1.0f + fmaxf(fabsf(a), fabsf(b))); }
static int near3(vec3 a, vec3 b) { return near(a.x, b.x) && near(a.y, b.y) && near(a.z, b.z); }

/* The edit of group g among n (unedited when absent). */
static light_edit edit_of(const light_edit *e, int n, int g) {
    for (int i = 0; i < n; i++)
        if (e[i].group == g) return e[i];
    return (light_edit){g, v3(0, 0, 0), 1.0f};
}

int reference_lights_same(const char *a, const char *b) {
    light_edit ea[REFERENCE_MAX_LIGHT_EDITS], eb[REFERENCE_MAX_LIGHT_EDITS];
    char why[256];
    int na = reference_lights_parse(a, ea, REFERENCE_MAX_LIGHT_EDITS, why, sizeof why);
    int nb = reference_lights_parse(b, eb, REFERENCE_MAX_LIGHT_EDITS, why, sizeof why);
    if (na < 0 || nb < 0) return 0;
    for (int pass = 0; pass < 2; pass++) /* every group either edits, against the other's */
        for (int i = 0; i < (pass ? nb : na); i++) {
            int g = pass ? eb[i].group : ea[i].group;
            light_edit x = edit_of(ea, na, g), y = edit_of(eb, nb, g);
            if (!near3(x.offset, y.offset) || !near(x.gain, y.gain)) return 0;
        }
    return 1;
}

/* ---- matching -------------------------------------------------------------------------------- */

int reference_check(const char *ref, const reference_info *have, const reference_info *want, char *err, size_t errlen) {
    if (strcmp(have->model, want->model) != 0)
        return fail(err, errlen,
                    "%s: rendered by %s%s%s, not this glint's material model '%s': its values are stale; "
                    "re-render the reference",
                    ref, have->model[0] ? "material model '" : "an older glint (no material model recorded)",
                    have->model, have->model[0] ? "'" : "", want->model);
    if (strcmp(have->scene_hash, want->scene_hash) != 0)
        return fail(err, errlen, "%s: rendered from another scene ('%s', %s), not '%s' (%s)", ref, have->scene,
                    have->scene_hash, want->scene, want->scene_hash);
    if (strcmp(have->env_hash, want->env_hash) != 0)
        return fail(err, errlen, "%s: rendered with environment %s%s%s, not %s%s%s", ref, have->env[0] ? "'" : "",
                    have->env[0] ? have->env : "none", have->env[0] ? "'" : "", want->env[0] ? "'" : "",
                    want->env[0] ? want->env : "none", want->env[0] ? "'" : "");
    if (fabs(have->env_rotation - want->env_rotation) > 1e-6)
        return fail(err, errlen, "%s: rendered with --env-rotation %g, not %g", ref, have->env_rotation,
                    want->env_rotation);
    if (strcmp(have->variant, want->variant) != 0)
        return fail(err, errlen, "%s: rendered with %s%s%s, not %s%s%s", ref,
                    have->variant[0] ? "material variant '" : "",
                    have->variant[0] ? have->variant : "the default materials", have->variant[0] ? "'" : "",
                    want->variant[0] ? "material variant '" : "",
                    want->variant[0] ? want->variant : "the default materials", want->variant[0] ? "'" : "");
    if (!reference_lights_same(have->lights, want->lights))
        return fail(err, errlen, "%s: rendered with %s%s%s, not %s%s%s", ref,
                    have->lights[0] ? "lights edited '" : "the lights as loaded", have->lights,
                    have->lights[0] ? "'" : "", want->lights[0] ? "lights edited '" : "the lights as loaded",
                    want->lights, want->lights[0] ? "'" : "");
    if (have->width != want->width || have->height != want->height)
        return fail(err, errlen, "%s: rendered at %dx%d, not %dx%d", ref, have->width, have->height, want->width,
                    want->height);
    if (have->camera_index != want->camera_index)
        return fail(err, errlen, "%s: rendered from camera %d, not %d", ref, have->camera_index, want->camera_index);
    const camera *a = &have->cam, *b = &want->cam;
    if (!near3(a->position, b->position) || !near3(a->right, b->right) || !near3(a->up, b->up) ||
        !near3(a->forward, b->forward) || !near(a->yfov, b->yfov))
        return fail(err, errlen,
                    "%s: camera %d has moved since the reference was rendered (position %g %g %g, "
                    "now %g %g %g)",
                    ref, have->camera_index, (double)a->position.x, (double)a->position.y, (double)a->position.z,
                    (double)b->position.x, (double)b->position.y, (double)b->position.z);
    return 0;
}

int reference_check_shard(const char *path, const reference_info *have, const char *want_path,
                          const reference_info *want, char *err, size_t errlen) {
    if (reference_check(path, have, want, err, errlen) != 0) return -1;
    if (strcmp(have->method, want->method) != 0)
        return fail(err, errlen, "%s: rendered with --method %s, %s with %s", path, have->method, want_path,
                    want->method);
    if (have->max_depth != want->max_depth)
        return fail(err, errlen, "%s: rendered with --max-depth %d, %s with %d", path, have->max_depth, want_path,
                    want->max_depth);
    if (have->seed != want->seed)
        return fail(err, errlen, "%s: rendered with --seed %llu, %s with %llu: not shards of one render", path,
                    (unsigned long long)have->seed, want_path, (unsigned long long)want->seed);
    if (have->highlights_layer != want->highlights_layer)
        return fail(err, errlen, "%s: %s a highlights layer, %s %s", path, have->highlights_layer ? "has" : "has no",
                    want_path, want->highlights_layer ? "has" : "has none");
    if (strcmp(have->params, want->params) != 0)
        return fail(err, errlen, "%s: rendered with parameters '%s', %s with '%s'", path, have->params, want_path,
                    want->params);
    if (have->shard_count != want->shard_count || have->spp_total != want->spp_total)
        return fail(err, errlen, "%s: a shard of %d of %lld spp%s, %s of %d of %lld spp%s", path, have->shard_count,
                    have->spp_total, have->spp_total ? "" : " (--time)", want_path, want->shard_count, want->spp_total,
                    want->spp_total ? "" : " (--time)");
    return 0;
}
