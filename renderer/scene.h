/* glint — the scene: world-space triangles, materials, textures, lights, cameras, an environment
 * map, and the Embree BVH over the triangles. Elements refer to each other by index.
 *
 * Life cycle: scene_create() -> scene_add_*() (the glTF importer calls these) ->
 * scene_finalize() (normals, tangents, light list, scale, BVH) -> read-only while rendering ->
 * scene_destroy(). The loaders below do all of it. */
#ifndef GLINT_SCENE_H
#define GLINT_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include <embree3/rtcore.h>

#include "bsdf.h"
#include "envmap.h"
#include "gmath.h"
#include "image_io.h"
#include "sampling.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- textures ------------------------------------------------------------------------------ */

typedef enum { WRAP_REPEAT = 0, WRAP_CLAMP, WRAP_MIRROR } wrap_mode;

typedef struct {
    int width, height;
    uint8_t *rgba; /* owned, 8 bits per channel; colour space is decided by the slot using it */
} scene_image;

typedef struct {
    int image;
    wrap_mode wrap_s, wrap_t;
} scene_texture;

/* A material's reference to a texture: texture < 0 means none. */
typedef struct {
    int texture;
    int texcoord; /* 0 or 1 */
    /* KHR_texture_transform, applied where uv is looked up (texture_lookup): when transformed,
     * u' = uv_xf[0] u + uv_xf[1] v + uv_xf[2], v' = uv_xf[3] u + uv_xf[4] v + uv_xf[5]. */
    int transformed;
    float uv_xf[6];
} texture_slot;

/* ---- materials ----------------------------------------------------------------------------- */

typedef enum {
    MATERIAL_GLTF = 0, /* metallic-roughness: Lambert + GGX */
    MATERIAL_PHONG,    /* extras.glint.model = "phong" */
    MATERIAL_WARD,     /* extras.glint.model = "ward" */
} material_model;

/* The glTF material extensions of the material model (KHR_materials_ior, _specular, _sheen,
 * _clearcoat, _transmission, _volume): factors with their textures, combined at a hit by
 * material_layers. */
typedef struct {
    float ior;                            /* KHR_materials_ior: 1.5; 0 means F0 = 1 (spec-gloss conversions) */
    float specular;                       /* KHR_materials_specular: specularFactor, 1 */
    vec3 specular_color;                  /* specularColorFactor, 1 (may exceed 1; F0 is clamped) */
    texture_slot specular_tex;            /* linear: A strength */
    texture_slot specular_color_tex;      /* sRGB: RGB */
    vec3 sheen_color;                     /* KHR_materials_sheen: 0, no sheen */
    float sheen_roughness;                /* perceptual */
    texture_slot sheen_color_tex;         /* sRGB: RGB */
    texture_slot sheen_roughness_tex;     /* linear: A */
    float clearcoat;                      /* KHR_materials_clearcoat: 0, no coat */
    float clearcoat_roughness;            /* perceptual */
    texture_slot clearcoat_tex;           /* linear: R */
    texture_slot clearcoat_roughness_tex; /* linear: G */
    texture_slot clearcoat_normal_tex;    /* linear: the coat's own normal map, as normalTexture */
    float clearcoat_normal_scale;         /* its scale: multiplies the map's x and y */
    float transmission;                   /* KHR_materials_transmission: transmissionFactor, 0 */
    texture_slot transmission_tex;        /* linear: R */
    /* KHR_materials_volume: thicknessFactor > 0 makes the mesh a closed volume that refracts by
     * the ior; its texture is for rasterisers (a ray measures the real path) and is not read. */
    float thickness;            /* 0: thin-walled */
    float attenuation_distance; /* INFINITY: no absorption */
    vec3 attenuation_color;     /* 1 */
} material_ext;

/* glTF alphaMode. */
typedef enum { ALPHA_OPAQUE = 0, ALPHA_MASK, ALPHA_BLEND } alpha_mode;

typedef struct {
    char name[64];
    material_model model;
    /* Geometry and texturing (docs/design.md, "Surfaces as glTF draws them") */
    texture_slot normal_tex; /* linear: tangent-space normal, glTF's convention */
    float normal_scale;      /* normalTexture.scale: multiplies the map's x and y */
    alpha_mode alpha;        /* MASK: cut out below alpha_cutoff; BLEND: stochastic transparency */
    float alpha_cutoff;      /* MASK */
    float base_alpha;        /* baseColorFactor's alpha; the base colour texture's alpha multiplies it */
    /* glTF metallic-roughness */
    vec3 base_color;
    float metallic, roughness;
    texture_slot base_color_tex;  /* sRGB */
    texture_slot metal_rough_tex; /* linear: G roughness, B metallic */
    float anisotropy_strength;    /* KHR_materials_anisotropy */
    float anisotropy_rotation;    /* radians about the normal, from the tangent (also Ward's) */
    texture_slot anisotropy_tex;  /* linear: RG direction, B strength */
    /* Phong and Ward (the papers' lobes) */
    vec3 kd, ks;
    float exponent;         /* Phong */
    float alpha_x, alpha_y; /* Ward */
    /* emission: radiance = emission * emissive texture */
    vec3 emission;             /* emissiveFactor * KHR_materials_emissive_strength */
    texture_slot emissive_tex; /* sRGB */
    int double_sided;          /* emits from both faces */
    material_ext ext;          /* glTF material extensions (metallic-roughness only) */
} material;

/* ---- lights and cameras -------------------------------------------------------------------- */

typedef enum {
    LIGHT_POINT = 0,
    LIGHT_SPOT,
    LIGHT_DIRECTIONAL,
    LIGHT_TRIANGLE, /* one emissive triangle */
    LIGHT_ENV,      /* the environment map */
} light_type;

typedef struct {
    light_type type;
    char name[64];
    /* Radiometric stand-ins for the glTF units, one consistent scale: candela -> W/sr (point,
     * spot), lux -> W/m^2 (directional). color already includes the intensity. */
    vec3 color;
    vec3 position;   /* point, spot */
    vec3 direction;  /* spot, directional: where the light shines (unit) */
    float cos_inner; /* spot */
    float cos_outer; /* spot */
    float range;     /* point, spot: glTF range (0 = infinite) */
    int triangle;    /* LIGHT_TRIANGLE */
    float power;     /* estimate of emitted power (luminance), for light selection */
} light;

typedef struct {
    char name[64];
    vec3 position;
    vec3 right, up, forward; /* orthonormal */
    float yfov;              /* radians */
} camera;

/* ---- the scene ----------------------------------------------------------------------------- */

typedef struct scene {
    char path[1024]; /* where it came from (builtin:NAME for a built-in scene) */

    /* world-space geometry, flattened: vertex arrays parallel, 3 indices per triangle */
    int num_vertices, cap_vertices;
    vec3 *positions; /* padded by one element for Embree's 16-byte reads */
    vec3 *normals;
    vec4 *tangents; /* xyz tangent, w = bitangent sign */
    vec2 *uv0, *uv1;
    int num_triangles, cap_triangles;
    long coincident; /* triangles that repeat another's three corners (scene_count_coincident) */
    uint32_t *indices;
    int32_t *tri_material;
    int32_t *tri_light; /* light index of an emissive triangle, else -1 */
    vec3 *tri_normal;   /* unit geometric normal (winding order), set by scene_finalize */

    material *materials;
    int num_materials, cap_materials;
    scene_image *images;
    int num_images, cap_images;
    scene_texture *textures;
    int num_textures, cap_textures;
    light *lights; /* punctual lights, then emissive triangles, then the environment */
    int num_lights, cap_lights;
    camera *cameras;
    int num_cameras, cap_cameras;
    env_map *env;  /* NULL without one */
    int env_light; /* index into lights, or -1 */

    dist1d light_dist; /* light selection by power (emission: virtual lights) */
    dist1d nee_dist;   /* next-event estimation's draw by power among the lights it does not take each */
    int nee_each;      /* the punctual lights [0, nee_each) next-event estimation takes each (lights.h) */
    int nee_draws;     /* whether it draws a light from nee_dist too */

    bounds3 bounds;
    float diag;    /* bounding-box diagonal: the scene's size */
    float ray_eps; /* base ray offset, relative to the scene's size */

    int num_warnings;
    char warnings[8][256]; /* the first few warnings, for display; all are printed */

    RTCDevice device;
    RTCScene rtc;

    /* The ray-traced geometry (alpha.c): Embree geometry 0 holds the triangles every ray stops
     * at, geometry 1 those whose alpha a filter tests; each maps its primitives to scene
     * triangles (bvh_tri[0] NULL: geometry 0 is every triangle, in order). Per material its
     * alpha class. */
    uint32_t *bvh_indices[2];
    int32_t *bvh_tri[2];
    int bvh_count[2];
    unsigned char *alpha_class;
    int has_glass; /* some material transmits (KHR_materials_transmission); set with the classes */
    /* Per triangle, for emissive triangles with an emissive texture (emissive.c): the texture's
     * mean over the triangle, 0 in the channels where it is black all over; NULL without such. */
    vec3 *tri_emit_tex;
    /* KHR_materials_variants (variants.c; the accessors below): NULL without variants. */
    struct scene_variants *variants;
} scene;

/* ---- loading ------------------------------------------------------------------------------- */

/* Error messages are one line, "PATH: problem". Warnings (ignored extensions, ...) go to warn_fn
 * (may be NULL) as they happen, without a trailing newline. */
typedef void (*scene_warn_fn)(void *user, const char *message);

/* Loads a .gltf/.glb file, or a built-in scene when path is "builtin:NAME" (the scene's path is
 * then that spelling). Returns a new scene (caller destroys) or NULL with err set. */
scene *scene_load(const char *path, scene_warn_fn warn, void *warn_user, char *err, size_t errlen);
/* Loads the default built-in scene. */
scene *scene_load_default(scene_warn_fn warn, void *warn_user, char *err, size_t errlen);
/* Loads glTF JSON or GLB from memory; base_dir resolves external URIs; name is used in messages. */
scene *scene_load_memory(const void *data, size_t size, const char *base_dir, const char *name, scene_warn_fn warn,
                         void *warn_user, char *err, size_t errlen);

/* The scenes compiled into the program (builtins.c), glTF with embedded buffers. */
typedef struct {
    const char *name;        /* loaded as builtin:NAME */
    const char *description; /* one line, for --help */
    const unsigned char *gltf;
    const size_t *size; /* of gltf, in bytes */
} builtin_scene;
/* All of them, the default first; *count set. */
const builtin_scene *scene_builtins(int *count);
/* The one named name, or NULL. */
const builtin_scene *scene_builtin_find(const char *name);
/* NAME when path is spelt builtin:NAME, else NULL. */
const char *scene_builtin_name(const char *path);
/* Attaches an environment map (.exr or .hdr) to a loaded scene, replacing any previous one. The
 * scene must not be rendering. Returns 0, or -1 with err set (the scene keeps its old map). */
int scene_set_env(scene *s, const char *path, float rotation, char *err, size_t errlen);
/* The same from an image in memory (taken over: *image is emptied, also on failure). */
int scene_set_env_image(scene *s, image_rgb *image, float rotation, char *err, size_t errlen);
void scene_destroy(scene *s);

/* ---- building (used by the importer and by tests that make scenes in code) ---------------- */

scene *scene_create(scene_warn_fn warn, void *warn_user);
void scene_warn(scene *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

typedef struct {
    int num_vertices;
    const float *positions;  /* 3 per vertex (required) */
    const float *normals;    /* 3 per vertex, or NULL: generated (area-weighted, smooth) */
    const float *tangents;   /* 4 per vertex, or NULL: generated from uv0 when it exists */
    const float *uv0, *uv1;  /* 2 per vertex, or NULL */
    int num_indices;         /* 0: non-indexed, every 3 vertices a triangle */
    const uint32_t *indices; /* all < num_vertices (the importer checks) */
    int material;            /* index, or -1 for the default grey material */
} mesh_desc;

/* Limits: every coordinate (vertices after their transforms, lights, cameras) finite and below
 * SCENE_MAX_COORD in magnitude; at most SCENE_MAX_TRIANGLES triangles in all. */
#define SCENE_MAX_COORD 1e15f
#define SCENE_MAX_TRIANGLES (1 << 24)

/* Adds a mesh instance transformed by xform. Returns 0, or -1 on bad input (a coordinate beyond
 * the limit, too many triangles) / out of memory with err set (no "PATH:" prefix; the caller adds
 * context). */
int scene_add_mesh(scene *s, const mesh_desc *mesh, const mat4 *xform, char *err, size_t errlen);
/* Adds an image given as 1-4 channels of 8 or 16 bits; returns its index or -1. */
int scene_add_image(scene *s, int width, int height, int channels, int bits, const void *pixels);
int scene_add_texture(scene *s, scene_texture t);
int scene_add_material(scene *s, const material *m);
int scene_add_light(scene *s, const light *l);
int scene_add_camera(scene *s, const camera *c);
material material_default(void);
/* Builds what rendering needs: light list and selection, scale, the BVH. Returns 0 or -1. */
int scene_finalize(scene *s, char *err, size_t errlen);

/* Material variants (KHR_materials_variants): their number (0 without), names, and the one in
 * use (-1: the file's default materials). */
#define SCENE_MAX_VARIANTS 1024
#define SCENE_MAX_VARIANT_PAIRS (1 << 22) /* (variant, material) mappings over all primitives */
int scene_num_variants(const scene *s);
const char *scene_variant_name(const scene *s, int i);
int scene_variant(const scene *s);
/* The variant called name, or -1. */
int scene_variant_find(const scene *s, const char *name);
/* Gives every primitive its material for variant v (-1: the default ones) and rebuilds what
 * follows from materials (alpha, emitters, the light list); intensity edits start over (light
 * groups follow materials), moved lights stay moved. Between frames. Returns 0, or -1 with err
 * set (no such variant, out of memory). */
int scene_set_variant(scene *s, int v, char *err, size_t errlen);
/* scene_set_variant for the variant called name; an unknown name is an error listing the scene's. */
int scene_select_variant(scene *s, const char *name, char *err, size_t errlen);
/* Building them (the importer): the names, once; a primitive's mappings as a table of (variant,
 * material) pairs, returning its index; then, after each scene_add_mesh of an instance of it,
 * that the triangles added since first_triangle follow table. Each returns -1 on bad input (an
 * index out of range, over the limits above) or out of memory. */
int scene_add_variants(scene *s, const char *const *names, int n);
int scene_add_variant_table(scene *s, const int *variants, const int *materials, int n);
int scene_map_variants(scene *s, int first_triangle, int table);

/* ---- editing lights (between frames: nothing may be rendering the scene) ------------------ */

/* What a user moves and dims as one light: a punctual light, or every emissive triangle of one
 * material (an area light is many triangles; the user means the lamp). Numbered punctual lights
 * first, in light order, then emissive materials, in material order; moving and dimming never
 * add or remove one, so the numbers hold while the scene lives. */
typedef struct {
    char name[64];
    light_type type; /* LIGHT_POINT, LIGHT_SPOT, LIGHT_DIRECTIONAL, or LIGHT_TRIANGLE (area) */
    int index;       /* punctual: into lights; area: into materials */
    vec3 center;     /* position, or the area-weighted centroid; directional: the origin */
    float gain;      /* intensity multiplier against the scene as loaded */
} light_group;

/* Fills out[0 .. min(count, max) - 1] (out may be NULL when max is 0); returns the count, or -1
 * when out of memory. */
int scene_light_groups(const scene *s, light_group *out, int max);
/* Translates group g by delta, world units: a punctual light's position, or an area light's
 * vertices (then the BVH and the scene's bounds). Returns 0, or -1 with err set (no such group,
 * a directional light, a non-finite delta, out of memory). */
int scene_move_light(scene *s, int g, vec3 delta, char *err, size_t errlen);
/* Sets group g's intensity to gain (1e-6 .. 1e6) times its loaded value. Returns 0 or -1. */
int scene_set_light_gain(scene *s, int g, float gain, char *err, size_t errlen);

/* ---- queries during rendering (thread-safe, read-only) ------------------------------------ */

typedef struct {
    float t;
    int tri; /* triangle index */
    int material;
    vec3 p;         /* position */
    vec3 ng;        /* geometric normal, facing the incoming ray */
    frame3 shading; /* shading frame: n faces the incoming ray's side; t along the tangent for anisotropic
                    * materials, any direction for the rest */
    vec3 coat_n;    /* a clear-coated glTF material's coat normal (world, same side as shading.n): the
                    * interpolated normal, or the clearcoatNormalTexture's; else shading.n */
    vec2 uv0, uv1;
    int backface; /* the ray hit the triangle's back (winding) side */
} surface_hit;

/* Closest hit along o + t d for t in (0, tmax]. Returns 1 on hit and fills h. */
int scene_intersect(const scene *s, vec3 o, vec3 d, float tmax, surface_hit *h);
/* Closest hits of up to SCENE_PACKET rays from one origin o along d[0..n-1] (unbounded), traced
 * together: for camera rays, which go nearly the same way. Bit i of the result is set when ray i
 * hit, and then h[i] is filled as scene_intersect fills it. */
#define SCENE_PACKET 16
unsigned scene_intersect_packet(const scene *s, vec3 o, const vec3 *d, int n, surface_hit *h);
/* The triangles that repeat an earlier one's three corners (any order), or -1 out of memory:
 * scene_finalize counts them into coincident and warns (coincident.c). */
long scene_count_coincident(const scene *s);
/* 1 if anything blocks o + t d for t in (0, tmax): glass too. */
int scene_occluded(const scene *s, vec3 o, vec3 d, float tmax);
/* What reaches o + tmax d from o along d for a shadow ray (docs/design.md, "Transmission and
 * volume"): black when anything but glass that shadow rays pass is in the way (or more than
 * SCENE_MAX_GLASS of it), else the product of that glass's scene_glass_pass and Beer-Lambert in
 * the media between (the ray starts in a medium of absorption sigma). */
#define SCENE_MAX_GLASS 16
vec3 scene_transmittance(const scene *s, vec3 o, vec3 d, float tmax, vec3 sigma);
/* What the surface at hit h lets through of a ray along d by the shadow rays' rule
 * (material_pass_through; black: h stops it), and the medium beyond it in *sigma
 * (material_medium_after). For estimators that follow a ray through such glass as shadow rays do. */
vec3 scene_glass_pass(const scene *s, const surface_hit *h, vec3 d, vec3 *sigma);

/* Ray origin leaving a surface point toward dir without hitting its own triangle: offset along
 * the geometric normal by an epsilon relative to the scene's size and the point's magnitude. */
static inline float scene_offset_eps(const scene *s, vec3 p) {
    float m = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return s->ray_eps + 4e-6f * m;
}
static inline vec3 offset_origin(const scene *s, vec3 p, vec3 ng, vec3 dir) {
    float e = scene_offset_eps(s, p);
    return madd3(p, ng, dot3(dir, ng) >= 0.0f ? e : -e);
}

/* The BSDF at a hit (textures looked up), in the hit's shading frame; *frame may be rotated for
 * anisotropy. */
bsdf material_bsdf(const scene *s, const surface_hit *h, frame3 *frame);
/* The glTF extensions' defaults (no extension: the core material). */
material_ext material_ext_default(void);
/* A glTF material's extensions at a hit, their textures looked up (material_layers.c). */
gltf_layers material_layers(const scene *s, const material *m, const surface_hit *h);
/* KHR_materials_volume: the absorption coefficient inside m, -ln(attenuationColor) /
 * attenuationDistance per channel (finite); 0 without a volume or without absorption. */
vec3 material_absorption(const material *m);
/* The medium a ray is in after scattering at h by `lobe`, having been in one of absorption sigma:
 * a transmission through a volume's front (winding) side enters it, through its back leaves it
 * for air; anything else stays. A ray leaving a volume it never entered (an open mesh) is in air.
 * Nested volumes are not tracked. */
vec3 material_medium_after(const material *m, int backface, int lobe, vec3 sigma);
/* Beer-Lambert over distance t (INFINITY: a ray that escapes): exp(-sigma t), exactly 1 where
 * sigma is 0 (no 0 x infinity). */
static inline vec3 medium_transmittance(vec3 sigma, float t) {
    if (is_black3(sigma)) return v3s(1.0f);
    return v3(sigma.x > 0.0f ? expf(-sigma.x * t) : 1.0f, sigma.y > 0.0f ? expf(-sigma.y * t) : 1.0f,
              sigma.z > 0.0f ? expf(-sigma.z * t) : 1.0f);
}
/* Whether m is a volume (KHR_materials_volume with a thickness): transmission there refracts. */
static inline int material_is_volume(const material *m) {
    return m->model == MATERIAL_GLTF && m->ext.thickness > 0.0f && m->ext.transmission > 0.0f;
}
/* What a shadow ray along -wo (local) takes through the hit's surface, whose BSDF is b: its
 * bsdf_pass_through where the scene lets shadow rays through its material (alpha.c; not without
 * Embree's filter functions), else black. The path tracer asks the same of a transmission it
 * samples, so that its light found through glass and next-event estimation's share weights. */
vec3 material_pass_through(const scene *s, const surface_hit *h, const bsdf *b, vec3 wo);
/* Emitted radiance leaving the hit toward the side the ray came from (0 for the back of a
 * single-sided emitter). */
vec3 material_emission(const scene *s, const surface_hit *h);
/* Texture lookup (bilinear, wrap modes), returns linear RGBA; srgb decodes the colour channels. */
vec4 texture_lookup(const scene *s, texture_slot slot, vec2 uv0, vec2 uv1, int srgb);

/* Environment radiance seen along direction d (world). 0 without a map. */
vec3 env_eval(const scene *s, vec3 d);

#ifdef __cplusplus
}
#endif

#endif
