/* The scene: building from meshes, finalizing (normals, tangents, lights, BVH), ray queries and
 * material evaluation at hits. */
#include "scene.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_import.h"
#include "lights.h"
#include "scene_parts.h"

typedef struct {
    scene_warn_fn fn;
    void *user;
} warn_sink;

/* The warning sink and the light edits live beside the scene; kept out of the public struct. */
typedef struct {
    scene s;
    warn_sink warn;
    /* Per light group, made on the first change of intensity: the multiplier and what it
     * multiplies (the colour or emission as loaded), so gains are exact, never compounded. */
    int num_gains;
    float *gains;
    vec3 *gain_bases;
} scene_box;

scene *scene_create(scene_warn_fn warn, void *warn_user) {
    scene_box *box = calloc(1, sizeof(scene_box));
    if (!box) return NULL;
    box->warn = (warn_sink){warn, warn_user};
    box->s.env_light = -1;
    box->s.bounds = bounds_empty();
    return &box->s;
}

void scene_warn(scene *s, const char *fmt, ...) {
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* One line, whatever a file's names hold. */
    for (char *c = msg; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
    /* Embree reports its errors from whichever thread hit them. */
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    pthread_mutex_lock(&lock);
    /* Keep the first few for display, and do not repeat the same warning. */
    int kept = s->num_warnings < 8 ? s->num_warnings : 8;
    for (int i = 0; i < kept; i++)
        if (strncmp(s->warnings[i], msg, sizeof s->warnings[i] - 1) == 0) goto done;
    if (s->num_warnings < 8) snprintf(s->warnings[s->num_warnings], sizeof s->warnings[0], "%.255s", msg);
    s->num_warnings++;
    scene_box *box = (scene_box *)s;
    if (box->warn.fn) box->warn.fn(box->warn.user, msg);
done:
    pthread_mutex_unlock(&lock);
}

void scene_destroy(scene *s) {
    if (!s) return;
    scene_bvh_free(s);
    if (s->device) rtcReleaseDevice(s->device);
    free(s->positions);
    free(s->normals);
    free(s->tangents);
    free(s->uv0);
    free(s->uv1);
    free(s->indices);
    free(s->tri_material);
    free(s->tri_normal);
    free(s->tri_light);
    free(s->tri_emit_tex);
    scene_variants_free(s);
    free(s->materials);
    for (int i = 0; i < s->num_images; i++) free(s->images[i].rgba);
    free(s->images);
    free(s->textures);
    free(s->lights);
    free(s->cameras);
    env_map_destroy(s->env);
    dist1d_deinit(&s->light_dist);
    dist1d_deinit(&s->nee_dist);
    free(((scene_box *)s)->gains);
    free(((scene_box *)s)->gain_bases);
    free((scene_box *)s);
}

/* Grows *arr (elements of size elem) to hold at least need; cap doubles. */
static int grow(void **arr, int *cap, int need, size_t elem) {
    if (need <= *cap) return 0;
    long long c = *cap ? *cap : 16;
    while (c < need) c *= 2;
    if (c > (1LL << 30)) return -1;
    void *n = realloc(*arr, elem * (size_t)c);
    if (!n) return -1;
    *arr = n;
    *cap = (int)c;
    return 0;
}

#define GROW(s, arr, cap, need) grow((void **)&(s)->arr, &(s)->cap, (need), sizeof(*(s)->arr))

static int realloc_to(void **arr, size_t elem, long long count) {
    void *n = realloc(*arr, elem * (size_t)count);
    if (!n) return -1;
    *arr = n;
    return 0;
}

/* The vertex arrays are parallel and share one capacity; positions keep one spare element of
 * padding because Embree reads vertices 16 bytes at a time. */
static int reserve_vertices(scene *s, int need) {
    if (need <= s->cap_vertices) return 0;
    long long c = s->cap_vertices ? s->cap_vertices : 1024;
    while (c < need) c *= 2;
    if (realloc_to((void **)&s->positions, sizeof(vec3), c + 1) || realloc_to((void **)&s->normals, sizeof(vec3), c) ||
        realloc_to((void **)&s->tangents, sizeof(vec4), c) || realloc_to((void **)&s->uv0, sizeof(vec2), c) ||
        realloc_to((void **)&s->uv1, sizeof(vec2), c))
        return -1;
    s->cap_vertices = (int)c;
    return 0;
}

static int reserve_triangles(scene *s, int need) {
    if (need <= s->cap_triangles) return 0;
    long long c = s->cap_triangles ? s->cap_triangles : 1024;
    while (c < need) c *= 2;
    if (realloc_to((void **)&s->indices, 3 * sizeof(uint32_t), c) ||
        realloc_to((void **)&s->tri_material, sizeof(int32_t), c) ||
        realloc_to((void **)&s->tri_light, sizeof(int32_t), c))
        return -1;
    s->cap_triangles = (int)c;
    return 0;
}

int scene_add_texture(scene *s, scene_texture t) {
    if (GROW(s, textures, cap_textures, s->num_textures + 1)) return -1;
    s->textures[s->num_textures] = t;
    return s->num_textures++;
}

int scene_add_material(scene *s, const material *m) {
    if (GROW(s, materials, cap_materials, s->num_materials + 1)) return -1;
    s->materials[s->num_materials] = *m;
    return s->num_materials++;
}

int scene_add_light(scene *s, const light *l) {
    if (GROW(s, lights, cap_lights, s->num_lights + 1)) return -1;
    s->lights[s->num_lights] = *l;
    return s->num_lights++;
}

int scene_add_camera(scene *s, const camera *c) {
    if (GROW(s, cameras, cap_cameras, s->num_cameras + 1)) return -1;
    s->cameras[s->num_cameras] = *c;
    return s->num_cameras++;
}

material material_default(void) {
    material m;
    memset(&m, 0, sizeof m);
    snprintf(m.name, sizeof m.name, "default");
    m.normal_tex = (texture_slot){.texture = -1};
    m.normal_scale = 1.0f;
    m.alpha_cutoff = 0.5f;
    m.base_alpha = 1.0f;
    m.model = MATERIAL_GLTF;
    m.base_color = v3s(1.0f);
    m.metallic = 1.0f;
    m.roughness = 1.0f;
    m.base_color_tex = m.metal_rough_tex = m.anisotropy_tex = m.emissive_tex = (texture_slot){.texture = -1};
    m.ext = material_ext_default();
    return m;
}

/* Upper 3x3 cofactor matrix: det(M) M^-T, the normal transform up to scale. */
static void cofactor3(const mat4 *m, float c[3][3], float *det) {
    const float(*a)[4] = m->m;
    c[0][0] = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    c[0][1] = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    c[0][2] = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    c[1][0] = a[0][2] * a[2][1] - a[0][1] * a[2][2];
    c[1][1] = a[0][0] * a[2][2] - a[0][2] * a[2][0];
    c[1][2] = a[0][1] * a[2][0] - a[0][0] * a[2][1];
    c[2][0] = a[0][1] * a[1][2] - a[0][2] * a[1][1];
    c[2][1] = a[0][2] * a[1][0] - a[0][0] * a[1][2];
    c[2][2] = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    *det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
}

static vec3 load3(const float *p, int i) { return v3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); }

/* Any unit vector perpendicular to n. */
static vec3 any_tangent(vec3 n) { return frame_from_normal(n).t; }

int scene_add_mesh(scene *s, const mesh_desc *mesh, const mat4 *xform, char *err, size_t errlen) {
    int nv = mesh->num_vertices;
    int ni = mesh->num_indices ? mesh->num_indices : nv;
    if (nv <= 0 || !mesh->positions) return snprintf(err, errlen, "mesh without vertices"), -1;
    if (ni % 3 != 0) return snprintf(err, errlen, "index count %d is not a multiple of 3", ni), -1;
    if (mesh->material < -1 || mesh->material >= s->num_materials)
        return snprintf(err, errlen, "material %d out of range", mesh->material), -1;
    for (int i = 0; mesh->indices && i < ni; i++)
        if (mesh->indices[i] >= (uint32_t)nv)
            return snprintf(err, errlen, "vertex index %u out of range (%d vertices)", mesh->indices[i], nv), -1;

    int mat_index = mesh->material;
    if (mat_index < 0) {
        /* One shared default material, created on first use. */
        int found = -1;
        for (int i = 0; i < s->num_materials; i++)
            if (strcmp(s->materials[i].name, "<glint default>") == 0) found = i;
        if (found < 0) {
            material m = material_default();
            snprintf(m.name, sizeof m.name, "<glint default>");
            found = scene_add_material(s, &m);
            if (found < 0) return snprintf(err, errlen, "out of memory"), -1;
        }
        mat_index = found;
    }

    /* Tangents (normal maps, anisotropy) from the file, else as MikkTSpace makes them from the
     * normal map's uv set; glTF ignores the file's when it has no normals. */
    const material *mat = &s->materials[mat_index];
    int tangent_uv = mat->normal_tex.texture >= 0 ? mat->normal_tex.texcoord : 0;
    if ((mesh->uv0 || mesh->uv1) && (!mesh->tangents || !mesh->normals)) {
        tangent_mesh tm;
        if (tangents_generate(mesh, tangent_uv, &tm) != 0) goto oom;
        tm.mesh.material = mat_index;
        int status = scene_add_mesh(s, &tm.mesh, xform, err, errlen);
        tangent_mesh_free(&tm);
        return status;
    }

    /* Without normals, glTF asks for flat shading: every triangle gets its own vertices. */
    int flat = mesh->normals == NULL;
    int out_vertices = flat ? ni : nv;
    long long total_v = (long long)s->num_vertices + out_vertices;
    long long total_t = (long long)s->num_triangles + ni / 3;
    if (total_t > SCENE_MAX_TRIANGLES || total_v > 3LL * SCENE_MAX_TRIANGLES)
        return snprintf(err, errlen, "the scene would have more than %d triangles (the limit)", SCENE_MAX_TRIANGLES),
               -1;
    /* Far beyond the limit Embree refuses rays; non-finite vertices have no place at all. */
    for (int k = 0; k < nv; k++) {
        vec3 p = xform_point(xform, load3(mesh->positions, k));
        if (!(fabsf(p.x) < SCENE_MAX_COORD && fabsf(p.y) < SCENE_MAX_COORD && fabsf(p.z) < SCENE_MAX_COORD))
            return snprintf(err, errlen,
                            "vertex %d lies at (%g, %g, %g) after its transforms; coordinates must be finite and "
                            "within +-%g",
                            k, (double)p.x, (double)p.y, (double)p.z, (double)SCENE_MAX_COORD),
                   -1;
    }
    if (reserve_vertices(s, (int)total_v) || reserve_triangles(s, (int)total_t)) goto oom;

    float cof[3][3], det;
    cofactor3(xform, cof, &det);
    float det_sign = det < 0.0f ? -1.0f : 1.0f;
    int base = s->num_vertices;

    /* Vertices: transform to world space. */
    for (int k = 0; k < out_vertices; k++) {
        int src = flat ? (mesh->indices ? (int)mesh->indices[k] : k) : k;
        vec3 p = xform_point(xform, load3(mesh->positions, src));
        s->positions[base + k] = p;
        vec3 n = v3(0, 0, 0);
        if (mesh->normals) {
            vec3 on = load3(mesh->normals, src);
            n = v3(cof[0][0] * on.x + cof[0][1] * on.y + cof[0][2] * on.z,
                   cof[1][0] * on.x + cof[1][1] * on.y + cof[1][2] * on.z,
                   cof[2][0] * on.x + cof[2][1] * on.y + cof[2][2] * on.z);
            n = normalize3(scale3(n, det_sign));
        }
        s->normals[base + k] = n;
        s->uv0[base + k] = mesh->uv0 ? v2(mesh->uv0[2 * src], mesh->uv0[2 * src + 1]) : v2(0, 0);
        s->uv1[base + k] = mesh->uv1 ? v2(mesh->uv1[2 * src], mesh->uv1[2 * src + 1]) : s->uv0[base + k];
        vec4 t = {0, 0, 0, 0};
        if (mesh->tangents && !flat) {
            const float *tp = mesh->tangents + 4 * src;
            vec3 tw = normalize3(xform_vector(xform, v3(tp[0], tp[1], tp[2])));
            t = (vec4){tw.x, tw.y, tw.z, (tp[3] < 0.0f ? -1.0f : 1.0f) * det_sign};
        }
        s->tangents[base + k] = t;
    }

    /* Triangles: skip degenerate ones (they cannot be hit and would only produce NaN normals). */
    int tri_base = s->num_triangles, kept = 0, skipped = 0;
    for (int f = 0; f < ni / 3; f++) {
        uint32_t v[3];
        for (int c = 0; c < 3; c++) {
            int k = 3 * f + c;
            v[c] = (uint32_t)base + (flat ? (uint32_t)k : (mesh->indices ? mesh->indices[k] : (uint32_t)k));
        }
        if (det < 0.0f) { /* a mirroring transform flips winding; swap to keep the front face */
            uint32_t tmp = v[1];
            v[1] = v[2];
            v[2] = tmp;
        }
        vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
        vec3 ng = cross3(sub3(p1, p0), sub3(p2, p0));
        float a2 = length_sq3(ng);
        if (!(a2 > 0.0f) || !isfinite(a2) || !is_finite3(p0) || !is_finite3(p1) || !is_finite3(p2)) {
            skipped++;
            continue;
        }
        int t = tri_base + kept++;
        memcpy(&s->indices[3 * t], v, sizeof v);
        s->tri_material[t] = mat_index;
        s->tri_light[t] = -1;
        if (flat) {
            vec3 n = normalize3(ng);
            for (int c = 0; c < 3; c++) s->normals[v[c]] = n;
        }
    }
    if (skipped)
        scene_warn(s, "skipped %d triangle%s with no area, or too large for float's squares (edges beyond ~1e9)",
                   skipped, skipped > 1 ? "s" : "");

    /* No uvs to derive tangents from (tangents_generate had them otherwise): any frame. */
    if (!mesh->tangents || flat)
        for (int k = 0; k < out_vertices; k++) {
            vec3 n = s->normals[base + k];
            vec3 t = length_sq3(n) > 0.0f ? any_tangent(n) : v3(1, 0, 0);
            s->tangents[base + k] = (vec4){t.x, t.y, t.z, 1.0f};
        }

    s->num_vertices += out_vertices;
    s->num_triangles += kept;
    return 0;
oom:
    snprintf(err, errlen, "out of memory");
    return -1;
}

/* ---- finalize ------------------------------------------------------------------------------ */

/* The scene's size from its triangles: bounds, diagonal, and the ray offset that scales with it.
 * Returns 0, or -1 when the scene has no (finite) extent. */
static int update_extent(scene *s) {
    bounds3 b = bounds_empty();
    for (int t = 0; t < s->num_triangles; t++)
        for (int c = 0; c < 3; c++) b = bounds_add(b, s->positions[s->indices[3 * t + c]]);
    float diag = bounds_diagonal(b);
    if (!(diag > 0.0f) || !isfinite(diag)) return -1;
    s->bounds = b;
    s->diag = diag;
    s->ray_eps = 1e-5f * diag;
    return 0;
}

static void warn_if_unlit(scene *s) {
    if (s->num_lights == 0)
        scene_warn(s,
                   "%s: no light (no punctual light, no emissive material): the image is black without an "
                   "environment map",
                   s->path);
}

int scene_finalize(scene *s, char *err, size_t errlen) {
    if (s->num_triangles == 0) return snprintf(err, errlen, "%s: no triangles to render", s->path), -1;
    if (update_extent(s) != 0) return snprintf(err, errlen, "%s: scene has no extent", s->path), -1;

    /* Pad the vertex array for Embree (the slot exists: positions has one spare element). */
    s->positions[s->num_vertices] = v3(0, 0, 0);

    /* Hits need the geometric normal, which moving a light (a translation) never changes. */
    free(s->tri_normal);
    if (!(s->tri_normal = malloc((size_t)s->num_triangles * sizeof(vec3))))
        return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    for (int t = 0; t < s->num_triangles; t++) {
        const uint32_t *v = &s->indices[3 * t];
        vec3 p0 = s->positions[v[0]];
        s->tri_normal[t] = normalize3(cross3(sub3(s->positions[v[1]], p0), sub3(s->positions[v[2]], p0)));
    }

    s->coincident = scene_count_coincident(s);
    if (s->coincident < 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    if (s->coincident > 0)
        scene_warn(s,
                   "%s: %ld triangles repeat another's three corners: they add nothing to the image and slow "
                   "every ray through them",
                   s->path, s->coincident);
    /* The BVH first: it decides which triangles no ray can see (alpha), and those emit nothing. */
    if (scene_build_bvh(s, err, errlen) != 0 || scene_emissive_analyse(s, err, errlen) != 0 ||
        scene_build_lights(s, err, errlen) != 0)
        return -1;
    /* A material variant may bring its own: scene_set_variant warns then. */
    if (!scene_variants_emit(s)) warn_if_unlit(s);
    return 0;
}

/* ---- editing lights ------------------------------------------------------------------------ */

static int is_punctual(light_type t) { return t == LIGHT_POINT || t == LIGHT_SPOT || t == LIGHT_DIRECTIONAL; }

static float group_gain(const scene *s, int g) {
    const scene_box *box = (const scene_box *)s;
    return g < box->num_gains ? box->gains[g] : 1.0f;
}

int scene_light_groups(const scene *s, light_group *out, int max) {
    int n = 0;
    for (int i = 0; i < s->num_lights; i++) {
        const light *l = &s->lights[i];
        if (!is_punctual(l->type)) continue;
        if (n < max) {
            light_group *g = &out[n];
            memset(g, 0, sizeof *g);
            if (l->name[0])
                snprintf(g->name, sizeof g->name, "%s", l->name);
            else
                snprintf(g->name, sizeof g->name, "light %d", i);
            g->type = l->type;
            g->index = i;
            g->center = l->type == LIGHT_DIRECTIONAL ? v3(0, 0, 0) : l->position;
            g->gain = group_gain(s, n);
        }
        n++;
    }
    /* Emissive materials with triangles, with their area-weighted centroids, from one scan of the
     * triangles: per material its area, then centroid x area. */
    double *acc = calloc(4 * (size_t)s->num_materials + 1, sizeof(double));
    if (!acc) return -1;
    for (int t = 0; t < s->num_triangles; t++) {
        int m = s->tri_material[t];
        if (!(max_comp3(s->materials[m].emission) > 0.0f)) continue;
        const uint32_t *v = &s->indices[3 * t];
        vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
        double a = 0.5 * (double)length3(cross3(sub3(p1, p0), sub3(p2, p0)));
        vec3 mid = scale3(add3(add3(p0, p1), p2), 1.0f / 3.0f);
        double *k = acc + 4 * (size_t)m;
        k[0] += a;
        k[1] += a * (double)mid.x;
        k[2] += a * (double)mid.y;
        k[3] += a * (double)mid.z;
    }
    for (int m = 0; m < s->num_materials; m++) {
        const double *k = acc + 4 * (size_t)m;
        if (!(k[0] > 0.0)) continue;
        if (n < max) {
            light_group *g = &out[n];
            memset(g, 0, sizeof *g);
            if (s->materials[m].name[0])
                snprintf(g->name, sizeof g->name, "%s", s->materials[m].name);
            else
                snprintf(g->name, sizeof g->name, "emissive material %d", m);
            g->type = LIGHT_TRIANGLE;
            g->index = m;
            g->center = v3((float)(k[1] / k[0]), (float)(k[2] / k[0]), (float)(k[3] / k[0]));
            g->gain = group_gain(s, n);
        }
        n++;
    }
    free(acc);
    return n;
}

/* Group g, or -1 with err set. */
static int find_group(const scene *s, int g, light_group *out, char *err, size_t errlen) {
    int n = scene_light_groups(s, NULL, 0);
    if (n < 0) return snprintf(err, errlen, "out of memory"), -1;
    if (g < 0 || g >= n) return snprintf(err, errlen, "no light %d (the scene has %d)", g, n), -1;
    /* Punctual groups come first and are cheap; an area group needs the list up to it. */
    light_group *all = malloc(sizeof(light_group) * (size_t)(g + 1));
    int status = all && scene_light_groups(s, all, g + 1) > g ? 0 : -1;
    if (status == 0)
        *out = all[g];
    else
        snprintf(err, errlen, "out of memory");
    free(all);
    return status;
}

int scene_move_light(scene *s, int g, vec3 delta, char *err, size_t errlen) {
    light_group lg;
    if (find_group(s, g, &lg, err, errlen) != 0) return -1;
    /* Beyond a thousand scene sizes, float positions lose the scene's detail: a typo, not a move. */
    if (!is_finite3(delta) || length3(delta) > 1e3f * s->diag)
        return snprintf(err, errlen, "light %d: move too large or not finite", g), -1;
    if (lg.type == LIGHT_DIRECTIONAL)
        return snprintf(err, errlen, "light %d (%s) is directional: it has no position", g, lg.name), -1;
    if (lg.type != LIGHT_TRIANGLE) {
        s->lights[lg.index].position = add3(s->lights[lg.index].position, delta);
        return 0; /* a punctual light's power does not depend on where it is */
    }
    /* The material's vertices, each once (triangles share them). No other material's triangle
     * uses them: every mesh brings its own vertices and has one material. */
    uint8_t *moved = calloc((size_t)s->num_vertices, 1);
    if (!moved) return snprintf(err, errlen, "out of memory"), -1;
    for (int t = 0; t < s->num_triangles; t++) {
        if (s->tri_material[t] != lg.index) continue;
        for (int c = 0; c < 3; c++) {
            uint32_t v = s->indices[3 * t + c];
            if (!moved[v]) s->positions[v] = add3(s->positions[v], delta);
            moved[v] = 1;
        }
    }
    free(moved);
    update_extent(s); /* cannot fail: the moved triangles keep their (non-zero) areas */
    /* The vertex buffer is shared with Embree: mark it changed and rebuild the BVH. */
    if (scene_bvh_vertices_moved(s) != 0) return snprintf(err, errlen, "rebuilding the BVH failed"), -1;
    /* Bounds feed the directional and environment powers: the selection distribution follows. */
    return scene_build_lights(s, err, errlen);
}

int scene_set_light_gain(scene *s, int g, float gain, char *err, size_t errlen) {
    light_group lg;
    if (find_group(s, g, &lg, err, errlen) != 0) return -1;
    if (!(gain >= 1e-6f && gain <= 1e6f))
        return snprintf(err, errlen, "light %d: intensity %g out of range", g, (double)gain), -1;
    scene_box *box = (scene_box *)s;
    if (!box->gains) {
        int n = scene_light_groups(s, NULL, 0); /* more than g (find_group found it), or -1 */
        light_group *all = n > g ? malloc(sizeof(light_group) * (size_t)n) : NULL;
        box->gains = n > g ? malloc(sizeof(float) * (size_t)n) : NULL;
        box->gain_bases = n > g ? malloc(sizeof(vec3) * (size_t)n) : NULL;
        if (!all || !box->gains || !box->gain_bases || scene_light_groups(s, all, n) != n) {
            free(all);
            free(box->gains);
            free(box->gain_bases);
            box->gains = NULL;
            box->gain_bases = NULL;
            return snprintf(err, errlen, "out of memory"), -1;
        }
        for (int i = 0; i < n; i++) {
            box->gains[i] = 1.0f;
            const light_group *gi = &all[i];
            box->gain_bases[i] =
                gi->type == LIGHT_TRIANGLE ? s->materials[gi->index].emission : s->lights[gi->index].color;
        }
        box->num_gains = n;
        free(all);
    }
    vec3 value = scale3(box->gain_bases[g], gain);
    if (lg.type == LIGHT_TRIANGLE)
        s->materials[lg.index].emission = value;
    else
        s->lights[lg.index].color = value;
    box->gains[g] = gain;
    /* Powers and the selection distribution follow the new intensity. */
    return scene_build_lights(s, err, errlen);
}

int scene_set_variant(scene *s, int v, char *err, size_t errlen) {
    if (v < -1 || v >= scene_num_variants(s))
        return snprintf(err, errlen, "%s: no material variant %d (the scene has %d)", s->path, v,
                        scene_num_variants(s)),
               -1;
    /* Light groups follow the materials: intensities go back to the file's before they change. */
    scene_box *box = (scene_box *)s;
    for (int g = 0; g < box->num_gains; g++)
        if (box->gains[g] != 1.0f && scene_set_light_gain(s, g, 1.0f, err, errlen) != 0) return -1;
    if (scene_apply_variant(s, v) != 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    free(box->gains);
    free(box->gain_bases);
    box->gains = NULL;
    box->gain_bases = NULL;
    box->num_gains = 0;
    if (!s->rtc) return 0; /* not finalized yet: scene_finalize builds the rest */
    if (scene_build_bvh(s, err, errlen) != 0 || scene_emissive_analyse(s, err, errlen) != 0 ||
        scene_build_lights(s, err, errlen) != 0)
        return -1;
    warn_if_unlit(s);
    return 0;
}

/* ---- loading ------------------------------------------------------------------------------- */

static scene *finish_load(scene *s, int status, char *err, size_t errlen) {
    if (status == 0 && scene_finalize(s, err, errlen) == 0) return s;
    scene_destroy(s);
    return NULL;
}

static scene *load_builtin(const char *path, scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    const builtin_scene *b = scene_builtin_find(scene_builtin_name(path));
    if (b) return scene_load_memory(b->gltf, *b->size, "", path, warn, warn_user, err, errlen);
    char names[256] = "";
    int n;
    const builtin_scene *all = scene_builtins(&n);
    for (int i = 0; i < n; i++) {
        if (i) strncat(names, ", ", sizeof names - strlen(names) - 1);
        strncat(names, all[i].name, sizeof names - strlen(names) - 1);
    }
    snprintf(err, errlen, "%s: no such built-in scene (have: %s)", path, names);
    return NULL;
}

scene *scene_load(const char *path, scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    if (scene_builtin_name(path)) return load_builtin(path, warn, warn_user, err, errlen);
    scene *s = scene_create(warn, warn_user);
    if (!s) return snprintf(err, errlen, "%s: out of memory", path), NULL;
    snprintf(s->path, sizeof s->path, "%s", path);
    return finish_load(s, gltf_import_file(s, path, err, errlen), err, errlen);
}

scene *scene_load_memory(const void *data, size_t size, const char *base_dir, const char *name, scene_warn_fn warn,
                         void *warn_user, char *err, size_t errlen) {
    scene *s = scene_create(warn, warn_user);
    if (!s) return snprintf(err, errlen, "%s: out of memory", name), NULL;
    snprintf(s->path, sizeof s->path, "%s", name);
    return finish_load(s, gltf_import_memory(s, data, size, base_dir, name, err, errlen), err, errlen);
}

scene *scene_load_default(scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    int n;
    char path[64];
    snprintf(path, sizeof path, "builtin:%s", scene_builtins(&n)[0].name);
    return scene_load(path, warn, warn_user, err, errlen);
}

/* ---- ray queries --------------------------------------------------------------------------- */

static void init_ray(struct RTCRay *r, vec3 o, vec3 d, float tmax) {
    r->org_x = o.x;
    r->org_y = o.y;
    r->org_z = o.z;
    r->tnear = 0.0f;
    r->dir_x = d.x;
    r->dir_y = d.y;
    r->dir_z = d.z;
    r->time = 0.0f;
    r->tfar = tmax;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

/* Fills h from Embree's hit (triangle t, barycentrics b1 b2, distance tfar) of the ray along d. */
static void complete_hit(const scene *s, vec3 d, int t, float b1, float b2, float tfar, surface_hit *h) {
    const uint32_t *v = &s->indices[3 * t];
    /* A ray in the triangle's plane through one of its corners can come back with NaN
     * barycentrics: the hit is that triangle, so keep the point on it. */
    if (!isfinite(b1) || !isfinite(b2)) b1 = b2 = 0.0f;
    float b0 = 1.0f - b1 - b2;
    vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
    h->t = tfar;
    h->tri = t;
    h->material = s->tri_material[t];
    /* Barycentric interpolation is more accurate than o + t d far from the origin. */
    h->p = add3(add3(scale3(p0, b0), scale3(p1, b1)), scale3(p2, b2));
    vec3 ng = s->tri_normal[t];
    h->backface = dot3(ng, d) > 0.0f;
    if (h->backface) ng = neg3(ng);
    h->ng = ng;
    h->uv0 = triangle_uv(s, s->uv0, t, b1, b2);
    h->uv1 = triangle_uv(s, s->uv1, t, b1, b2);

    shading_frame_at_hit(s, h, b1, b2, d);
}

int scene_intersect(const scene *s, vec3 o, vec3 d, float tmax, surface_hit *h) {
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    init_ray(&rh.ray, o, d, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s->rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    complete_hit(s, d, scene_hit_triangle(s, rh.hit.geomID, rh.hit.primID), rh.hit.u, rh.hit.v, rh.ray.tfar, h);
    return 1;
}

_Static_assert(SCENE_PACKET == 16, "scene_intersect_packet traces one RTCRayHit16");

unsigned scene_intersect_packet(const scene *s, vec3 o, const vec3 *d, int n, surface_hit *h) {
    /* One 16-wide packet: Embree traverses the BVH once for rays that go the same way. */
    RTC_ALIGN(64) int valid[SCENE_PACKET]; /* Embree reads the mask and packet as aligned vectors */
    RTC_ALIGN(64) struct RTCRayHit16 rh;
    for (int i = 0; i < SCENE_PACKET; i++) {
        int live = i < n;
        valid[i] = live ? -1 : 0;
        vec3 di = live ? d[i] : v3(0, 0, 1);
        rh.ray.org_x[i] = o.x;
        rh.ray.org_y[i] = o.y;
        rh.ray.org_z[i] = o.z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.dir_x[i] = di.x;
        rh.ray.dir_y[i] = di.y;
        rh.ray.dir_z[i] = di.z;
        rh.ray.time[i] = 0.0f;
        rh.ray.tfar[i] = INFINITY;
        rh.ray.mask[i] = 0xFFFFFFFFu;
        rh.ray.id[i] = (unsigned)i;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect16(valid, s->rtc, &ctx, &rh);
    unsigned hits = 0;
    for (int i = 0; i < n; i++) {
        if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
        complete_hit(s, d[i], scene_hit_triangle(s, rh.hit.geomID[i], rh.hit.primID[i]), rh.hit.u[i], rh.hit.v[i],
                     rh.ray.tfar[i], &h[i]);
        hits |= 1u << i;
    }
    return hits;
}

/* One occlusion query; with record, the glass passed is in ctx. */
static int occluded(const scene *s, vec3 o, vec3 d, float tmax, int record, shadow_context *ctx) {
    rtcInitIntersectContext(&ctx->rtc);
    ctx->record = record;
    ctx->count = 0;
    struct RTCRay r;
    init_ray(&r, o, d, tmax);
    rtcOccluded1(s->rtc, &ctx->rtc, &r);
    return r.tfar < 0.0f; /* Embree sets tfar to -inf on a hit */
}

int scene_occluded(const scene *s, vec3 o, vec3 d, float tmax) {
    shadow_context ctx;
    return occluded(s, o, d, tmax, 0, &ctx);
}

/* The glass a shadow ray recorded (ctx), in order along the ray (the filter saw it in the BVH's
 * order): each surface's pass and Beer-Lambert between. Apart, so that shadow rays meeting no
 * glass keep a small frame. */
static vec3 glass_transmittance(const scene *s, const shadow_context *ctx, vec3 o, vec3 d, float tmax, vec3 sigma) {
    surface_hit h[SCENE_MAX_GLASS];
    for (int k = 0; k < ctx->count; k++) {
        complete_hit(s, d, ctx->hit[k].tri, ctx->hit[k].b1, ctx->hit[k].b2, 0.0f, &h[k]);
        h[k].t = dot3(sub3(h[k].p, o), d);
        for (int j = k; j > 0 && h[j].t < h[j - 1].t; j--) {
            surface_hit tmp = h[j];
            h[j] = h[j - 1], h[j - 1] = tmp;
        }
    }
    vec3 tr = v3s(1.0f);
    float t0 = 0.0f;
    for (int k = 0; k < ctx->count && !is_black3(tr); k++) {
        /* A ray through an edge or a corner meets each triangle there: one crossing. */
        if (k > 0 && h[k].material == h[k - 1].material && h[k].t - h[k - 1].t <= scene_offset_eps(s, h[k].p)) continue;
        tr = mul3(tr, medium_transmittance(sigma, h[k].t - t0));
        tr = mul3(tr, scene_glass_pass(s, &h[k], d, &sigma));
        t0 = h[k].t;
    }
    return mul3(tr, medium_transmittance(sigma, tmax - t0));
}

vec3 scene_transmittance(const scene *s, vec3 o, vec3 d, float tmax, vec3 sigma) {
    shadow_context ctx;
    if (occluded(s, o, d, tmax, 1, &ctx)) return v3s(0.0f);
    return ctx.count ? glass_transmittance(s, &ctx, o, d, tmax, sigma) : medium_transmittance(sigma, tmax);
}

vec3 scene_glass_pass(const scene *s, const surface_hit *h, vec3 d, vec3 *sigma) {
    if (!scene_material_passes_shadows(s, h->material)) return v3s(0.0f);
    frame3 fr;
    bsdf b = material_bsdf(s, h, &fr);
    *sigma = material_medium_after(&s->materials[h->material], h->backface, BSDF_TRANSMIT, *sigma);
    return material_pass_through(s, h, &b, to_local(fr, neg3(d)));
}

/* ---- materials at hits --------------------------------------------------------------------- */

/* Rotates the frame's tangent by angle about n (toward b for positive angles). */
static void rotate_tangent(frame3 *f, float c, float sn) {
    vec3 t = add3(scale3(f->t, c), scale3(f->b, sn));
    vec3 b = sub3(scale3(f->b, c), scale3(f->t, sn));
    f->t = t;
    f->b = b;
}

bsdf material_bsdf(const scene *s, const surface_hit *h, frame3 *frame) {
    const material *m = &s->materials[h->material];
    *frame = h->shading;
    vec3 tint = v3s(1.0f);
    if (m->base_color_tex.texture >= 0) {
        vec4 c = texture_lookup(s, m->base_color_tex, h->uv0, h->uv1, 1);
        tint = v3(c.x, c.y, c.z);
    }
    switch (m->model) {
    case MATERIAL_PHONG: return make_bsdf_phong(mul3(m->kd, tint), m->ks, m->exponent);
    case MATERIAL_WARD:
        if (m->anisotropy_rotation != 0.0f)
            rotate_tangent(frame, cosf(m->anisotropy_rotation), sinf(m->anisotropy_rotation));
        return make_bsdf_ward(mul3(m->kd, tint), m->ks, m->alpha_x, m->alpha_y);
    case MATERIAL_GLTF:
    default: {
        float metallic = m->metallic, roughness = m->roughness;
        if (m->metal_rough_tex.texture >= 0) {
            vec4 mr = texture_lookup(s, m->metal_rough_tex, h->uv0, h->uv1, 0);
            roughness *= mr.y;
            metallic *= mr.z;
        }
        float aniso = m->anisotropy_strength;
        if (aniso > 0.0f) {
            float dx = 1.0f, dy = 0.0f;
            if (m->anisotropy_tex.texture >= 0) {
                vec4 a = texture_lookup(s, m->anisotropy_tex, h->uv0, h->uv1, 0);
                dx = 2.0f * a.x - 1.0f;
                dy = 2.0f * a.y - 1.0f;
                aniso *= a.z;
            }
            float c = cosf(m->anisotropy_rotation), sn = sinf(m->anisotropy_rotation);
            float rx = c * dx - sn * dy, ry = sn * dx + c * dy;
            float len = sqrtf(rx * rx + ry * ry);
            if (len > 1e-6f) rotate_tangent(frame, rx / len, ry / len);
        }
        gltf_layers layers = material_layers(s, m, h);
        bsdf b = make_bsdf_gltf_layered(mul3(m->base_color, tint), metallic, roughness, aniso, &layers);
        if (b.coat > 0.0f) b.coat_n = to_local(*frame, h->coat_n);
        return b;
    }
    }
}

vec3 material_emission(const scene *s, const surface_hit *h) {
    const material *m = &s->materials[h->material];
    if (is_black3(m->emission) || (h->backface && !m->double_sided)) return v3(0, 0, 0);
    vec3 e = m->emission;
    if (m->emissive_tex.texture >= 0) {
        vec4 c = texture_lookup(s, m->emissive_tex, h->uv0, h->uv1, 1);
        e = mul3(e, v3(c.x, c.y, c.z));
    }
    return e;
}
