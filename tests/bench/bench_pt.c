/* Path-tracing throughput on a glTF scene, set up so Embree's own `pathtracer` tutorial can do
 * exactly the same work: every material becomes Lambert with the scene's base colour, emitters
 * are switched off and one point light is placed above the scene's centre. The program writes
 * the triangles as OBJ (+ MTL) for Embree, prints the matching `pathtracer` arguments, then
 * renders with glint's path tracer and reports samples per second.
 *
 * Usage: bench_pt SCENE.gltf OUT_DIR [SIZE_W SIZE_H SPP MAX_DEPTH] */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera.h"
#include "lights.h"
#include "scene.h"
#include "session.h"

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int write_obj(const scene *s, const char *dir) {
    char path[1200];
    snprintf(path, sizeof path, "%s/scene.mtl", dir);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    for (int m = 0; m < s->num_materials; m++) {
        vec3 kd = s->materials[m].kd;
        fprintf(f, "newmtl m%d\nKd %g %g %g\nKs 0 0 0\n\n", m, (double)kd.x, (double)kd.y, (double)kd.z);
    }
    fclose(f);
    snprintf(path, sizeof path, "%s/scene.obj", dir);
    f = fopen(path, "w");
    if (!f) return -1;
    fprintf(f, "mtllib scene.mtl\n");
    for (int i = 0; i < s->num_vertices; i++)
        fprintf(f, "v %.9g %.9g %.9g\n", (double)s->positions[i].x, (double)s->positions[i].y,
                (double)s->positions[i].z);
    for (int i = 0; i < s->num_vertices; i++)
        fprintf(f, "vn %.6g %.6g %.6g\n", (double)s->normals[i].x, (double)s->normals[i].y, (double)s->normals[i].z);
    int current = -2;
    for (int t = 0; t < s->num_triangles; t++) {
        if (s->tri_material[t] != current) fprintf(f, "usemtl m%d\n", current = s->tri_material[t]);
        const uint32_t *v = &s->indices[3 * t];
        fprintf(f, "f %u//%u %u//%u %u//%u\n", v[0] + 1, v[0] + 1, v[1] + 1, v[1] + 1, v[2] + 1, v[2] + 1);
    }
    return fclose(f);
}

int main(int argc, char **argv) {
    if (argc != 3 && argc != 7) {
        fprintf(stderr, "usage: bench_pt SCENE.gltf OUT_DIR [WIDTH HEIGHT SPP MAX_DEPTH]\n");
        return 2;
    }
    int w = argc == 7 ? atoi(argv[3]) : 640, h = argc == 7 ? atoi(argv[4]) : 360;
    int spp = argc == 7 ? atoi(argv[5]) : 32, depth = argc == 7 ? atoi(argv[6]) : 8;
    char err[512];
    scene *s = scene_load(argv[1], NULL, NULL, err, sizeof err);
    if (!s) {
        fprintf(stderr, "bench_pt: %s\n", err);
        return 1;
    }
    for (int m = 0; m < s->num_materials; m++) {
        material *mat = &s->materials[m];
        vec3 kd = mat->model == MATERIAL_GLTF ? mat->base_color : mat->kd;
        *mat = material_default();
        mat->model = MATERIAL_PHONG;
        mat->kd = kd;
        mat->ks = v3s(0.0f);
    }
    vec3 c = bounds_center(s->bounds);
    vec3 lp = v3(c.x, s->bounds.lo.y + 0.9f * (s->bounds.hi.y - s->bounds.lo.y), c.z);
    float intensity = 0.5f * s->diag * s->diag; /* bright enough at the scene's scale */
    s->num_lights = 0;
    light pl = {.type = LIGHT_POINT, .color = v3s(intensity), .position = lp};
    scene_add_light(s, &pl);
    if (scene_build_lights(s, err, sizeof err) != 0 || write_obj(s, argv[2]) != 0) {
        fprintf(stderr, "bench_pt: cannot prepare the scene: %s\n", err);
        return 1;
    }
    float aspect = (float)w / (float)h;
    camera cam = scene_camera(s, -1, aspect);
    vec3 at = add3(cam.position, cam.forward);
    /* Embree's --max-path-length counts primary + shadow as 1, as glint's max_depth does. */
    printf("embree_args: -i %s/scene.obj --size %d %d --spp %d --max-path-length %d --vp %g %g %g --vi %g %g %g "
           "--vu %g %g %g --fov %g --pointlight %g %g %g %g %g %g\n",
           argv[2], w, h, spp, depth, (double)cam.position.x, (double)cam.position.y, (double)cam.position.z,
           (double)at.x, (double)at.y, (double)at.z, (double)cam.up.x, (double)cam.up.y, (double)cam.up.z,
           (double)(cam.yfov * 180.0f / PI_F), (double)lp.x, (double)lp.y, (double)lp.z, (double)intensity,
           (double)intensity, (double)intensity);
    render_params p = {.width = w, .height = h, .max_depth = depth, .seed = 1};
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    if (!rs) {
        fprintf(stderr, "bench_pt: %s\n", err);
        return 1;
    }
    session_render_frame(rs); /* warm-up: thread start, page faults */
    session_reset(rs);
    double t0 = now();
    for (int i = 0; i < spp; i++) session_render_frame(rs);
    double seconds = now() - t0;
    render_stats st = session_stats(rs);
    unsigned long long rays = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) rays += st.rays[k];
    printf("glint_seconds: %.4f\n", seconds);
    printf("glint_samples_per_second: %.0f\n", (double)w * h * spp / seconds);
    printf("glint_rays_per_second: %.0f\n", (double)rays / seconds);
    session_destroy(rs);
    scene_destroy(s);
    return 0;
}
