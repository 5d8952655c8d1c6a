/* The scene as data: meshes, materials, textures, lights and cameras as the file gives them, added
 * one by one, and the light groups they make. What rendering needs is built from it above this file
 * (scene_make.c: the BVH, the light distributions, emissive powers), and nothing here calls up. */
#include "scene.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_parts.h"

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

material_ext material_ext_default(void) {
    material_ext x = {0};
    x.ior = 1.5f;
    x.specular = 1.0f;
    x.specular_color = v3s(1.0f);
    x.specular_tex = x.specular_color_tex = x.sheen_color_tex = x.sheen_roughness_tex = x.clearcoat_tex =
        x.clearcoat_roughness_tex = x.clearcoat_normal_tex = x.transmission_tex = (texture_slot){.texture = -1};
    x.clearcoat_normal_scale = 1.0f;
    x.attenuation_distance = INFINITY;
    x.attenuation_color = v3s(1.0f);
    return x;
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

/* ---- light groups -------------------------------------------------------------------------- */

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
