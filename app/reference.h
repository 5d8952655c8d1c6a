/* glint — what makes a reference image trustworthy and reusable: the description glint render
 * stores in the header of its EXR (the string attribute glint.reference, JSON), which glint bench
 * reads to refuse a reference of another scene, camera or size. Older references carried it in a
 * JSON sidecar beside the EXR (OUT.exr.json), which is still read. */
#ifndef GLINT_REFERENCE_H
#define GLINT_REFERENCE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "session.h"

#define REFERENCE_MAX_SHARDS 4096     /* far above a cluster's job array (Slurm's default limit: 1001) */
#define REFERENCE_MAX_LIGHT_EDITS 256 /* lights moved or dimmed in one description */

typedef struct {
    char model[64];      /* BSDF_MODEL_STAMP of the glint that rendered it; "" in older references */
    char scene[1024];    /* as given on the command line, "builtin:NAME" for a built-in scene */
    char scene_hash[64]; /* "fnv1a64:..." of the file's bytes, "builtin:NAME:fnv1a64:..." */
    char env[1024];      /* "" without an environment map */
    char env_hash[64];
    double env_rotation; /* degrees */
    char variant[64];    /* the material variant rendered, "" for the file's default materials */
    int camera_index;    /* -1: the scene's first camera or the framing view; a free camera (the
                          * viewer's, --camera-from's) */
    camera cam;          /* the camera actually rendered from */
    float scene_diag;    /* the scene's diagonal, the scale of camera_same_view; 0 in older ones */
    /* The lights moved or dimmed against the scene as loaded, as reference_lights_text writes
     * them ("" for none, and in older references that have no such field). */
    char lights[4096];
    int width, height;
    char method[16];
    int highlights_layer; /* the EXR has a highlights.* layer */
    long long spp;        /* = frames: one sample per pixel per frame */
    double seconds;
    int max_depth;
    uint64_t seed;
    int threads;
    char params[1024]; /* every other parameter its frames read, "NAME=VALUE ..." in a fixed
                        * order (reference_params_text); "" in older references */
    /* A shard (glint render --shard) or a merge of shards (glint merge): it holds frames i,
     * i + shard_count, i + 2 shard_count, ... of one render for each shard i set in shards[],
     * and its EXR the moments merging needs. shard_count 0: a whole render. */
    int shard_count;
    long long spp_total; /* --spp of the whole render the shards split; 0: each rendered for --time */
    unsigned char shards[REFERENCE_MAX_SHARDS / 8]; /* bit i: shard i is in it */
    /* Noise of the reference itself, from two halves of its frames (reference_noise()), or in a
     * shard or merge from its pixels' variances; has_noise is 0 when it rendered a single frame. */
    int has_noise;
    double mean_variance; /* mean over pixels and channels of the variance of the pixel mean */
    double rel_l2_noise;  /* expected relative L2 error of the reference against the truth */
    /* A capture of what the viewer showed (its script's `capture`): spp is then the view's
     * full-resolution frames, and these say when it was taken and what the image was. */
    int capture;
    double since_change;           /* seconds since the last change the viewer was asked for (a stop) */
    double since_start;            /* seconds since the viewer started */
    double image_age;              /* seconds since the image shown was published */
    int preview;                   /* it was a reduced-resolution preview, magnified to width x height */
    int image_width, image_height; /* its own size */
    int latest;                    /* it showed the last change asked for */
} reference_info;

/* A light's edit: group (as scene_light_groups, glint info and the viewer's panel number them)
 * moved by offset and its intensity gain times the loaded one. */
typedef struct {
    int group;
    vec3 offset;
    float gain;
} light_edit;

/* The canonical text of n edits (distinct groups, any order): "G:DX,DY,DZ*GAIN" for each group
 * moved or dimmed, by group, joined by ';' ("0:0.5,0,-1*1;2:0,0,0*0.5"); "" when none is. Returns
 * 0, or -1 when out is too small. */
int reference_lights_text(const light_edit *edits, int n, char *out, size_t outlen);
/* Parses such a text into at most max edits. Returns their count, or -1 with err = "problem". */
int reference_lights_parse(const char *text, light_edit *out, int max, char *err, size_t errlen);
/* Whether two texts are the same edits, offsets and gains within float noise (a group absent from
 * one is unedited there). A malformed text matches nothing. */
int reference_lights_same(const char *a, const char *b);

/* The content hash of a scene or environment file (FNV-1a 64 of its bytes; for builtin:NAME,
 * of the built-in scene's). Returns 0, or -1 with err = "PATH: problem". */
int reference_hash_file(const char *path, char out[64], char *err, size_t errlen);

/* Fills what identifies a rendering of scene s (loaded from scene_path, NULL: the default; env_path
 * may be NULL) from camera_index (-1: the default view, recorded as 0 when the scene has cameras)
 * at the size in p: paths, content hashes, camera, size, max depth, seed, threads. The method
 * and the results (spp, seconds, noise) are left to the caller. Returns 0, or -1 with err set
 * (a file unreadable for hashing). */
int reference_describe(reference_info *info, const char *scene_path, const char *env_path, double env_rotation_deg,
                       const struct scene *s, int camera_index, const render_params *p, char *err, size_t errlen);

/* The parameters of p that shape its frames beyond those reference_info has fields for, as
 * text ("plan=auto only=all count=1024 ..."; the many-light ones for those methods only): two
 * renders with the same text draw the same samples. */
void reference_params_text(const render_params *p, char *out, size_t n);

static inline int reference_has_shard(const reference_info *r, int i) { return r->shards[i / 8] >> (i % 8) & 1; }
static inline void reference_add_shard(reference_info *r, int i) { r->shards[i / 8] |= (unsigned char)(1u << (i % 8)); }

/* Writes s as a JSON string (quotes, escapes); shared with glint render's --stats. */
void reference_json_string(FILE *f, const char *s);

/* The EXR header attribute that holds a reference's description: a string, the JSON text that
 * reference_json makes. */
#define REFERENCE_ATTR "glint.reference"

/* info as JSON text (malloc'ed; free it), or NULL when out of memory. */
char *reference_json(const reference_info *info);
/* Parses a description (text: n bytes, then a NUL) into info, checking every field's type and
 * range. label starts every message ("PATH: not a glint reference sidecar"). Returns 0, or -1 with
 * err = "LABEL (problem)". reference_load's parser, exposed for the fuzzer (tests/fuzz). */
int reference_parse(const char *text, size_t n, const char *label, reference_info *info, char *err, size_t errlen);
/* Reads the description of the reference EXR at exr_path: its header attribute REFERENCE_ATTR,
 * or, when the header has none, its sidecar (an older reference). Returns 0, 1 when there is
 * neither, -1 when the file is unreadable or the description malformed (err = "PATH: problem"). */
int reference_load(const char *exr_path, reference_info *info, char *err, size_t errlen);

/* Tracks two halves of a progressive render for the noise estimate: call reference_noise_frame
 * after every frame, reference_noise_finish at the end (which takes the film's moments instead
 * when it keeps them: a shard's). Snapshots of the mean are taken at
 * power-of-two frame counts, so the finish uses a split of the frames between 1/2 and 3/4 (no
 * cost on the hot path: log2(frames) resolves). */
typedef struct {
    float *snap[2]; /* the last two snapshots, at frames snap_frames[k] */
    long long snap_frames[2];
    float *scratch;
    size_t n;
} reference_noise;

int reference_noise_init(reference_noise *rn, int width, int height); /* 0, or -1 out of memory */
void reference_noise_frame(reference_noise *rn, const render_session *rs);
void reference_noise_finish(reference_noise *rn, const render_session *rs, reference_info *info);
void reference_noise_deinit(reference_noise *rn);
/* The noise of an image from its pixels' variances of one sample (a shard's or a merge's
 * moments): channel k of pixel i has mean mean[k][i * stride], variance var[k][i * stride] and
 * count[i] samples. Sets has_noise, mean_variance and rel_l2_noise as reference_noise_finish does. */
void reference_noise_from_variance(const float *const mean[3], const float *const var[3], size_t stride,
                                   const double *count, size_t pixels, reference_info *info);

/* Compares what a bench renders (want) with a reference's description (have), field by field: the
 * material model (a reference of another is stale: re-render it), scene and environment hashes,
 * material variant, light edits, camera index and parameters, size. Returns 0 when they match, else -1
 * with err naming the first difference ("REF.exr: ..."). */
int reference_check(const char *ref_path, const reference_info *have, const reference_info *want, char *err,
                    size_t errlen);

/* Whether have (a shard, at path) is of the same render as want (another shard, at want_path),
 * so their frames may be merged: everything reference_check compares, then the method, max
 * depth, seed, highlights layer, every other parameter (params), the shard count and the whole
 * render's spp. Returns 0, or -1 with err naming the first difference ("PATH: ..."). */
int reference_check_shard(const char *path, const reference_info *have, const char *want_path,
                          const reference_info *want, char *err, size_t errlen);

#endif
