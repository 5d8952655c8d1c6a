/* Tangents for meshes that come without them, as MikkTSpace computes them (docs/design.md,
 * "Normal maps"): per triangle the direction of increasing u, from the uv derivatives;
 * per vertex the sum of its triangles' directions, each projected onto the vertex's tangent
 * plane and weighted by the triangle's angle there; triangles of opposite uv orientation at a
 * vertex (mirrored uvs) kept apart; vertices with equal position, normal and uv treated as one. */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "scene_parts.h"

static vec3 load3(const float *p, uint32_t i) { return v3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); }

/* What identifies a vertex for welding: position, normal, uv (as MikkTSpace compares them). */
typedef struct {
    float k[8];
} weld_key;

static uint32_t key_hash(const weld_key *a) {
    uint32_t h = 2166136261u;
    for (int i = 0; i < 8; i++) {
        float f = a->k[i] == 0.0f ? 0.0f : a->k[i]; /* -0 and +0 weld */
        uint32_t b;
        memcpy(&b, &f, 4);
        h = (h ^ b) * 16777619u;
        h ^= h >> 15;
    }
    return h;
}

static int key_equal(const weld_key *a, const weld_key *b) {
    for (int i = 0; i < 8; i++)
        if (a->k[i] != b->k[i]) return 0;
    return 1;
}

/* Welds n keys: id[i] is the first index with key i's value. Returns 0, or -1 out of memory. */
static int weld(const weld_key *keys, int n, int *id) {
    size_t cap = 16;
    while (cap < 2 * (size_t)n) cap *= 2;
    int *table = malloc(cap * sizeof(int));
    if (!table) return -1;
    memset(table, 0xff, cap * sizeof(int));
    for (int i = 0; i < n; i++) {
        size_t slot = key_hash(&keys[i]) & (cap - 1);
        while (table[slot] >= 0 && !key_equal(&keys[table[slot]], &keys[i])) slot = (slot + 1) & (cap - 1);
        if (table[slot] < 0) table[slot] = i;
        id[i] = table[slot];
    }
    free(table);
    return 0;
}

/* The unit vector along v's part perpendicular to unit n, or zero. */
static vec3 project_unit(vec3 v, vec3 n) {
    vec3 p = sub3(v, scale3(n, dot3(n, v)));
    float l2 = length_sq3(p);
    return l2 > 0.0f && isfinite(l2) ? scale3(p, 1.0f / sqrtf(l2)) : v3(0, 0, 0);
}

void tangent_mesh_free(tangent_mesh *t) {
    free(t->positions);
    free(t->normals);
    free(t->tangents);
    free(t->uv0);
    free(t->uv1);
    free(t->indices);
    memset(t, 0, sizeof *t);
}

int tangents_generate(const mesh_desc *mesh, int uv_set, tangent_mesh *out) {
    memset(out, 0, sizeof *out);
    const float *uv = (uv_set == 1 && mesh->uv1) || !mesh->uv0 ? mesh->uv1 : mesh->uv0;
    int nc = mesh->num_indices ? mesh->num_indices : mesh->num_vertices - mesh->num_vertices % 3;
    int nt = nc / 3;
    int flat = mesh->normals == NULL;
    /* Welding units: vertices, or corners when every triangle has its own (flat) normal. */
    int units = flat ? nc : mesh->num_vertices;
    weld_key *keys = malloc(sizeof(weld_key) * (size_t)(units > 0 ? units : 1));
    vec3 *unit_n = malloc(sizeof(vec3) * (size_t)(units > 0 ? units : 1));
    int *wid = malloc(sizeof(int) * (size_t)(units > 0 ? units : 1));
    /* Per group (welded unit x uv orientation): summed tangent, and whether anything was added. */
    vec3 *acc = calloc(2 * (size_t)units + 1, sizeof(vec3));
    unsigned char *used = calloc(2 * (size_t)units + 1, 1);
    vec3 *tri_t = malloc(sizeof(vec3) * (size_t)(nt > 0 ? nt : 1)); /* unit, signed by orientation */
    unsigned char *tri_o = malloc((size_t)(nt > 0 ? nt : 1));       /* 1: uv orientation preserved */
    int *corner_group = malloc(sizeof(int) * (size_t)(nc > 0 ? nc : 1));
    int status = -1;
    if (!keys || !unit_n || !wid || !acc || !used || !tri_t || !tri_o || !corner_group) goto done;

#define VI(c) (mesh->indices ? mesh->indices[(c)] : (uint32_t)(c))
#define UNIT(c) (flat ? (c) : (int)VI(c))
    for (int u = 0; u < units; u++) {
        uint32_t v = flat ? VI(u) : (uint32_t)u;
        vec3 n;
        if (flat) {
            int f = u / 3;
            vec3 p0 = load3(mesh->positions, VI(3 * f)), p1 = load3(mesh->positions, VI(3 * f + 1)),
                 p2 = load3(mesh->positions, VI(3 * f + 2));
            n = normalize3(cross3(sub3(p1, p0), sub3(p2, p0)));
        } else {
            n = load3(mesh->normals, v);
        }
        vec3 p = load3(mesh->positions, v);
        keys[u] = (weld_key){{p.x, p.y, p.z, n.x, n.y, n.z, uv[2 * v], uv[2 * v + 1]}};
        float l2 = length_sq3(n);
        unit_n[u] = l2 > 0.0f && isfinite(l2) ? scale3(n, 1.0f / sqrtf(l2)) : v3(0, 0, 0);
    }
    if (weld(keys, units, wid) != 0) goto done;

    /* Per triangle: the direction of increasing u and the uv orientation (MikkTSpace's vOs). */
    for (int f = 0; f < nt; f++) {
        uint32_t i0 = VI(3 * f), i1 = VI(3 * f + 1), i2 = VI(3 * f + 2);
        vec3 p0 = load3(mesh->positions, i0);
        vec3 d1 = sub3(load3(mesh->positions, i1), p0), d2 = sub3(load3(mesh->positions, i2), p0);
        float t21x = uv[2 * i1] - uv[2 * i0], t21y = uv[2 * i1 + 1] - uv[2 * i0 + 1];
        float t31x = uv[2 * i2] - uv[2 * i0], t31y = uv[2 * i2 + 1] - uv[2 * i0 + 1];
        float area = t21x * t31y - t21y * t31x;
        vec3 os = sub3(scale3(d1, t31y), scale3(d2, t21y));
        float len = length3(os);
        tri_o[f] = area > 0.0f;
        tri_t[f] = fabsf(area) > FLT_MIN && len > 0.0f && isfinite(len) ? scale3(os, (area > 0.0f ? 1.0f : -1.0f) / len)
                                                                        : v3(0, 0, 0);
    }

    /* Each corner adds its triangle's direction, in its vertex's tangent plane, weighted by the
     * triangle's angle at the corner. Triangles without a uv direction join a group after. */
    for (int pass = 0; pass < 2; pass++)
        for (int c = 0; c < nc; c++) {
            int f = c / 3, k = c % 3;
            int degenerate = is_black3(tri_t[f]);
            if (degenerate != pass) continue;
            int w = wid[UNIT(c)];
            if (degenerate) {
                corner_group[c] = used[2 * w + 1] ? 2 * w + 1 : used[2 * w] ? 2 * w : 2 * w + tri_o[f];
                continue;
            }
            int g = corner_group[c] = 2 * w + tri_o[f];
            vec3 n = unit_n[UNIT(c)];
            vec3 p = load3(mesh->positions, VI(c));
            vec3 e1 = project_unit(sub3(load3(mesh->positions, VI(3 * f + (k + 2) % 3)), p), n);
            vec3 e2 = project_unit(sub3(load3(mesh->positions, VI(3 * f + (k + 1) % 3)), p), n);
            float angle = acosf(clampf(dot3(e1, e2), -1.0f, 1.0f));
            acc[g] = madd3(acc[g], project_unit(tri_t[f], n), angle);
            used[g] = 1;
        }

    /* Output vertices: one per corner for flat meshes, else one per (vertex, orientation). */
    int *out_of = malloc(sizeof(int) * (flat ? 1 : 2 * (size_t)units + 1));
    if (!out_of) goto done;
    int nout = 0;
    if (!flat) {
        for (int i = 0; i < 2 * units; i++) out_of[i] = -1;
        for (int c = 0; c < nc; c++) {
            int key = 2 * (int)VI(c) + (corner_group[c] & 1);
            if (out_of[key] < 0) out_of[key] = nout++;
        }
    } else {
        nout = nc;
    }
    out->positions = malloc(sizeof(float) * 3 * (size_t)nout + 1);
    out->normals = malloc(sizeof(float) * 3 * (size_t)nout + 1);
    out->tangents = malloc(sizeof(float) * 4 * (size_t)nout + 1);
    out->uv0 = mesh->uv0 ? malloc(sizeof(float) * 2 * (size_t)nout + 1) : NULL;
    out->uv1 = mesh->uv1 ? malloc(sizeof(float) * 2 * (size_t)nout + 1) : NULL;
    out->indices = malloc(sizeof(uint32_t) * (size_t)nc + 1);
    if (!out->positions || !out->normals || !out->tangents || (mesh->uv0 && !out->uv0) || (mesh->uv1 && !out->uv1) ||
        !out->indices) {
        free(out_of);
        tangent_mesh_free(out);
        goto done;
    }
    for (int c = 0; c < nc; c++) {
        uint32_t v = VI(c);
        int g = corner_group[c];
        int o = flat ? c : out_of[2 * (int)v + (g & 1)];
        out->indices[c] = (uint32_t)o;
        vec3 n = unit_n[UNIT(c)];
        vec3 t = project_unit(acc[g], n);
        if (is_black3(t)) t = length_sq3(n) > 0.0f ? frame_from_normal(n).t : v3(1, 0, 0);
        /* glTF's bitangent, cross(n, t) w, points up the image, toward decreasing v: the opposite
         * of MikkTSpace's on the file's uvs (it takes v upward), so preserved orientation is -1. */
        float w = used[g] && (g & 1) ? -1.0f : 1.0f;
        memcpy(out->positions + 3 * o, mesh->positions + 3 * v, 3 * sizeof(float));
        vec3 nn = flat ? n : load3(mesh->normals, v);
        memcpy(out->normals + 3 * o, &nn, 3 * sizeof(float));
        float tw[4] = {t.x, t.y, t.z, w};
        memcpy(out->tangents + 4 * o, tw, sizeof tw);
        if (out->uv0) memcpy(out->uv0 + 2 * o, mesh->uv0 + 2 * v, 2 * sizeof(float));
        if (out->uv1) memcpy(out->uv1 + 2 * o, mesh->uv1 + 2 * v, 2 * sizeof(float));
    }
    free(out_of);
    out->mesh = (mesh_desc){.num_vertices = nout,
                            .positions = out->positions,
                            .normals = out->normals,
                            .tangents = out->tangents,
                            .uv0 = out->uv0,
                            .uv1 = out->uv1,
                            .num_indices = nc,
                            .indices = out->indices,
                            .material = mesh->material};
    status = 0;
#undef VI
#undef UNIT
done:
    free(keys);
    free(unit_n);
    free(wid);
    free(acc);
    free(used);
    free(tri_t);
    free(tri_o);
    free(corner_group);
    return status;
}
