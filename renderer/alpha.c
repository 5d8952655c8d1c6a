/* The ray-traced geometry and glTF's alpha (docs/design.md, "Alpha"): triangles whose material
 * can never let a ray through sit in an Embree geometry without filters (Embree's fast path);
 * those whose alpha varies sit in a second one whose intersection and occlusion filters test it,
 * so camera rays, bounces, shadow rays and light paths all see the same cut-outs; triangles no
 * ray can see are left out. MASK cuts out below its cutoff; BLEND lets a ray through with
 * probability 1 - alpha, decided by a hash of the ray and the triangle: threads and runs agree,
 * and over random rays the transmission is 1 - alpha on average. Glass that shadow rays may pass
 * (smooth, unbent: docs/design.md, "Transmission and volume") sits in the second geometry too:
 * its occlusion filter records the hit for scene_transmittance and lets the ray on. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"
#include "scene_parts.h"

enum { ALPHA_CLASS_OPAQUE = 0, ALPHA_CLASS_TESTED, ALPHA_CLASS_INVISIBLE, ALPHA_CLASS_MASK = 3 };
/* Beside the class: the material's glass may let shadow rays through (in the tested geometry). */
enum { ALPHA_PASSES_SHADOWS = 4 };

/* Glass whose transmission may be smooth and unbent somewhere: not metal and its roughness at the
 * floor, by its factors or somewhere in its metallic-roughness texture (which only lowers them),
 * and no refracting volume (material_layers' eta). bsdf_pass_through decides at each hit. */
static int may_pass_shadows(const material *m) {
    int textured = m->metal_rough_tex.texture >= 0;
    if (m->model != MATERIAL_GLTF || !(m->ext.transmission > 0.0f)) return 0;
    if (!textured && (!(m->metallic < 1.0f) || !(m->roughness * m->roughness <= BSDF_MIN_ALPHA))) return 0;
    return !material_is_volume(m) || m->ext.ior < 1.0f || fabsf(m->ext.ior - 1.0f) < 1e-3f;
}

int scene_material_passes_shadows(const scene *s, int m) {
    return s->alpha_class && (s->alpha_class[m] & ALPHA_PASSES_SHADOWS);
}

vec3 material_pass_through(const scene *s, const surface_hit *h, const bsdf *b, vec3 wo) {
    return scene_material_passes_shadows(s, h->material) ? bsdf_pass_through(b, wo) : v3s(0.0f);
}

float material_alpha(const scene *s, const material *m, vec2 uv0, vec2 uv1) {
    float a = m->base_alpha;
    if (m->base_color_tex.texture >= 0) a *= texture_lookup(s, m->base_color_tex, uv0, uv1, 0).w;
    return a;
}

/* Whether a surface of alpha a is there for a ray whose hash is u in [0, 1). */
static int alpha_keeps(const material *m, float a, float u) {
    return m->alpha == ALPHA_MASK ? a >= m->alpha_cutoff : u < a;
}

float material_coverage(const scene *s, const surface_hit *h) {
    const material *m = &s->materials[h->material];
    if (m->alpha == ALPHA_OPAQUE) return 1.0f;
    float a = material_alpha(s, m, h->uv0, h->uv1);
    return m->alpha == ALPHA_MASK ? (a >= m->alpha_cutoff ? 1.0f : 0.0f) : clampf(a, 0.0f, 1.0f);
}

/* The range of alpha an image holds, [lo, hi] in 0..255 (scanned once per image, however many
 * materials use it). */
static void image_alpha_range(const scene_image *img, unsigned char range[2]) {
    int amin = 255, amax = 0;
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n && (amin > 0 || amax < 255); i++) {
        int a = img->rgba[4 * i + 3];
        amin = a < amin ? a : amin;
        amax = a > amax ? a : amax;
    }
    range[0] = (unsigned char)amin;
    range[1] = (unsigned char)amax;
}

/* Opaque: every ray stops; invisible: none does; tested: the filter decides per hit. ranges:
 * per image its alpha range, once known (range[0] > range[1]: not scanned yet). */
static int alpha_class(const scene *s, const material *m, unsigned char (*ranges)[2]) {
    if (m->alpha == ALPHA_OPAQUE) return ALPHA_CLASS_OPAQUE;
    float lo = m->base_alpha, hi = m->base_alpha; /* bilinear lookups stay between the texels */
    if (m->base_color_tex.texture >= 0) {
        int img = s->textures[m->base_color_tex.texture].image;
        if (ranges[img][0] > ranges[img][1]) image_alpha_range(&s->images[img], ranges[img]);
        lo *= (float)ranges[img][0] / 255.0f;
        hi *= (float)ranges[img][1] / 255.0f;
    }
    float threshold = m->alpha == ALPHA_MASK ? m->alpha_cutoff : 1.0f;
    if (lo >= threshold) return ALPHA_CLASS_OPAQUE;
    if (m->alpha == ALPHA_MASK ? hi < threshold : !(hi > 0.0f)) return ALPHA_CLASS_INVISIBLE;
    return ALPHA_CLASS_TESTED;
}

/* Embree's ray and hit packets in C: structure-of-arrays of N lanes (rtcore_ray.h's RTCRayN_*
 * and RTCHitN_* accessors, which are C++ only). */
static float ray_f(const struct RTCRayN *r, unsigned n, unsigned k, unsigned i) {
    return ((const float *)r)[k * n + i];
}
static float hit_f(const struct RTCHitN *h, unsigned n, unsigned k, unsigned i) {
    return ((const float *)h)[k * n + i];
}
static unsigned hit_u(const struct RTCHitN *h, unsigned n, unsigned k, unsigned i) {
    return ((const unsigned *)h)[k * n + i];
}

/* A number in [0, 1) from a ray (origin, direction) and a triangle: the same ray meets the same
 * decision wherever and however often it is traced. */
static float ray_hash(const float org_dir[6], unsigned tri) {
    uint64_t h = 0x616c706861ULL + tri;
    for (int k = 0; k < 6; k++) {
        uint32_t b;
        memcpy(&b, &org_dir[k], 4);
        h = rng_hash64(h ^ b);
    }
    return (float)(h >> 40) * 0x1p-24f;
}

float alpha_ray_hash(vec3 o, vec3 d, int tri) {
    const float od[6] = {o.x, o.y, o.z, d.x, d.y, d.z};
    return ray_hash(od, (unsigned)tri);
}

/* Whether lane i's hit on triangle t (barycentrics b1, b2) stands by its material's alpha. */
static int alpha_hit_stands(const scene *s, const struct RTCFilterFunctionNArguments *args, unsigned i, int t, float b1,
                            float b2) {
    const material *m = &s->materials[s->tri_material[t]];
    if (m->alpha == ALPHA_OPAQUE) return 1; /* glass in this geometry for its shadows */
    unsigned n = args->N;
    float a = material_alpha(s, m, triangle_uv(s, s->uv0, t, b1, b2), triangle_uv(s, s->uv1, t, b1, b2));
    float u = 0.0f;
    if (m->alpha == ALPHA_BLEND) {
        float od[6]; /* org_x, org_y, org_z, then dir_x, dir_y, dir_z after tnear */
        for (unsigned k = 0; k < 3; k++) od[k] = ray_f(args->ray, n, k, i), od[3 + k] = ray_f(args->ray, n, 4 + k, i);
        u = ray_hash(od, (unsigned)t);
    }
    return alpha_keeps(m, a, u);
}

/* The hit's triangle and barycentrics (NaN barycentrics, a ray in the triangle's plane: a corner). */
static int filter_hit(const scene *s, const struct RTCFilterFunctionNArguments *args, unsigned i, float *b1,
                      float *b2) {
    unsigned n = args->N;
    *b1 = hit_f(args->hit, n, 3, i), *b2 = hit_f(args->hit, n, 4, i);
    if (!isfinite(*b1) || !isfinite(*b2)) *b1 = *b2 = 0.0f;
    return s->bvh_tri[1][hit_u(args->hit, n, 5, i)]; /* primID */
}

static void alpha_filter(const struct RTCFilterFunctionNArguments *args) {
    const scene *s = args->geometryUserPtr;
    for (unsigned i = 0; i < args->N; i++) {
        if (args->valid[i] == 0) continue;
        float b1, b2;
        int t = filter_hit(s, args, i, &b1, &b2);
        if (!alpha_hit_stands(s, args, i, t, b1, b2)) args->valid[i] = 0;
    }
}

/* Whether glass that may pass shadow rays is smooth at barycentrics (b1, b2) of triangle t by its
 * metallic-roughness texture (glTF's factor times texel; bsdf_pass_through has the last word):
 * rough texels block the ray here, at once, rather than after the query. */
static int smooth_here(const scene *s, const material *m, int t, float b1, float b2) {
    if (m->metal_rough_tex.texture < 0) return 1;
    vec4 mr =
        texture_lookup(s, m->metal_rough_tex, triangle_uv(s, s->uv0, t, b1, b2), triangle_uv(s, s->uv1, t, b1, b2), 0);
    float r = m->roughness * mr.y;
    return m->metallic * mr.z < 1.0f && r * r <= BSDF_MIN_ALPHA;
}

/* Occlusion: alpha as above; then glass that shadow rays may pass, smooth at the hit, when the
 * query records it (scene_transmittance), is recorded once per triangle (Embree may report a hit
 * twice) and passed. More glass than the record holds blocks the ray. */
static void occlusion_filter(const struct RTCFilterFunctionNArguments *args) {
    const scene *s = args->geometryUserPtr;
    shadow_context *ctx = (shadow_context *)args->context;
    for (unsigned i = 0; i < args->N; i++) {
        if (args->valid[i] == 0) continue;
        float b1, b2;
        int t = filter_hit(s, args, i, &b1, &b2);
        if (!alpha_hit_stands(s, args, i, t, b1, b2)) {
            args->valid[i] = 0;
            continue;
        }
        if (!ctx->record || !scene_material_passes_shadows(s, s->tri_material[t]) ||
            !smooth_here(s, &s->materials[s->tri_material[t]], t, b1, b2))
            continue;
        int k = 0;
        while (k < ctx->count && ctx->hit[k].tri != t) k++;
        if (k == ctx->count) {
            if (k == SCENE_MAX_GLASS) continue;
            ctx->hit[k].tri = t, ctx->hit[k].b1 = b1, ctx->hit[k].b2 = b2;
            ctx->count++;
        }
        args->valid[i] = 0;
    }
}

static void free_bvh(scene *s) {
    if (s->rtc) rtcReleaseScene(s->rtc);
    s->rtc = NULL;
    for (int g = 0; g < 2; g++) {
        free(s->bvh_indices[g]);
        free(s->bvh_tri[g]);
        s->bvh_indices[g] = NULL;
        s->bvh_tri[g] = NULL;
        s->bvh_count[g] = 0;
    }
}

void scene_bvh_free(scene *s) {
    free_bvh(s);
    free(s->alpha_class);
    s->alpha_class = NULL;
}

/* Embree's own errors go where the scene's warnings go: the library does not print. */
static void embree_error(void *user, enum RTCError code, const char *str) {
    scene_warn(user, "embree: %s (code %d)", str ? str : "unknown error", (int)code);
}

static RTCGeometry add_geometry(scene *s, const uint32_t *indices, int count) {
    RTCGeometry geom = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s->positions, 0, sizeof(vec3),
                               (size_t)s->num_vertices);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0, 3 * sizeof(uint32_t),
                               (size_t)count);
    return geom;
}

int scene_build_bvh(scene *s, char *err, size_t errlen) {
    if (!s->device) {
        s->device = rtcNewDevice(NULL);
        if (!s->device) return snprintf(err, errlen, "%s: cannot create an Embree device", s->path), -1;
        rtcSetDeviceErrorFunction(s->device, embree_error, s);
    }
    free_bvh(s);
    unsigned char *cls = realloc(s->alpha_class, (size_t)s->num_materials + 1);
    if (!cls) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    s->alpha_class = cls;
    int filters = (int)rtcGetDeviceProperty(s->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED);
    int counts[3] = {0, 0, 0};
    unsigned char(*ranges)[2] = malloc(2 * (size_t)s->num_images + 2);
    if (!ranges) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    for (int i = 0; i < s->num_images; i++) ranges[i][0] = 255, ranges[i][1] = 0;
    s->has_glass = 0;
    for (int m = 0; m < s->num_materials; m++) {
        s->has_glass |= s->materials[m].ext.transmission > 0.0f;
        cls[m] = (unsigned char)alpha_class(s, &s->materials[m], ranges);
        if (cls[m] != ALPHA_CLASS_INVISIBLE && filters && may_pass_shadows(&s->materials[m]))
            cls[m] = ALPHA_CLASS_TESTED | ALPHA_PASSES_SHADOWS;
    }
    free(ranges);
    for (int t = 0; t < s->num_triangles; t++) counts[cls[s->tri_material[t]] & ALPHA_CLASS_MASK]++;
    if (counts[ALPHA_CLASS_TESTED] && !filters) {
        scene_warn(s, "%s: this Embree has no filter functions: alpha modes are drawn opaque", s->path);
        for (int m = 0; m < s->num_materials; m++) cls[m] = ALPHA_CLASS_OPAQUE;
        counts[0] = s->num_triangles, counts[1] = counts[2] = 0;
    }

    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    if (counts[ALPHA_CLASS_OPAQUE] == s->num_triangles) {
        /* The common case: one geometry over the scene's own index buffer, triangles in order. */
        RTCGeometry geom = add_geometry(s, s->indices, s->num_triangles);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(s->rtc, geom, 0);
        rtcReleaseGeometry(geom);
        s->bvh_count[0] = s->num_triangles;
    } else {
        for (int g = 0; g < 2; g++) {
            s->bvh_indices[g] = malloc(3 * sizeof(uint32_t) * (size_t)(counts[g] + 1));
            s->bvh_tri[g] = malloc(sizeof(int32_t) * (size_t)(counts[g] + 1));
            if (!s->bvh_indices[g] || !s->bvh_tri[g]) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
        }
        for (int t = 0; t < s->num_triangles; t++) {
            int g = cls[s->tri_material[t]] & ALPHA_CLASS_MASK;
            if (g == ALPHA_CLASS_INVISIBLE) continue;
            memcpy(&s->bvh_indices[g][3 * s->bvh_count[g]], &s->indices[3 * t], 3 * sizeof(uint32_t));
            s->bvh_tri[g][s->bvh_count[g]++] = t;
        }
        for (unsigned g = 0; g < 2; g++) {
            if (s->bvh_count[g] == 0) continue;
            RTCGeometry geom = add_geometry(s, s->bvh_indices[g], s->bvh_count[g]);
            if (g == 1) {
                rtcSetGeometryUserData(geom, s);
                rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
                rtcSetGeometryOccludedFilterFunction(geom, occlusion_filter);
            }
            rtcCommitGeometry(geom);
            rtcAttachGeometryByID(s->rtc, geom, g);
            rtcReleaseGeometry(geom);
        }
    }
    rtcCommitScene(s->rtc);
    if (rtcGetDeviceError(s->device) != RTC_ERROR_NONE)
        return snprintf(err, errlen, "%s: building the BVH failed", s->path), -1;
    return 0;
}

int scene_bvh_vertices_moved(scene *s) {
    for (unsigned g = 0; g < 2; g++) {
        if (s->bvh_count[g] == 0) continue;
        RTCGeometry geom = rtcGetGeometry(s->rtc, g);
        rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
        rtcCommitGeometry(geom);
    }
    rtcCommitScene(s->rtc);
    return rtcGetDeviceError(s->device) == RTC_ERROR_NONE ? 0 : -1;
}

int scene_triangle_invisible(const scene *s, int t) {
    return s->alpha_class && (s->alpha_class[s->tri_material[t]] & ALPHA_CLASS_MASK) == ALPHA_CLASS_INVISIBLE;
}
