/* Frames in interleaved parts (session_render_part) and the sample sink. A frame in parts is the
 * same frame: after frames rendered whole, in 4, 16, 256 parts or one, from any rotation, or begun in
 * parts and finished by session_render_frame, the films (every component's sums, the rejected counts)
 * and the statistics' counts are equal bit for bit, for pt, vsl and vsl+hl with shared 2x2 blocks and
 * --adapt (its records, probes and judgements), and auto through its probe and judgements. The
 * parts' order, checked against the lattice by brute force: every aligned run of 2^m ranks one cell in each block of the lattice's own shape
 * (ordered dither; Bayer's matrix at 4x4). The sink, as parts go: each part stamps exactly the
 * pixels of its cell's packets, every pixel once a frame (those into the void too), the first
 * quarter and half of a frame's parts cover the image evenly, the statistics count each part, the
 * sink's samples summed are the film's sums and a dropped sample writes nothing. Resetting after every part still walks through
 * all the parts; a frame ordered by need renders the neediest packets first and is the same frame;
 * counts out of range are clamped; a stopped part abandons its frame. Extra samples for a display
 * (session_render_extra) between a frame's parts leave its film as it is without them, bit for
 * bit, whatever records --adapt keeps. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "choice.h"
#include "test_scenes.h"

enum { W = 70, H = 42 }; /* neither a multiple of 4: edge packets and tiles are clipped */
#define PIXELS (W * H)

static render_session *new_session(const scene *s, const camera *cam, const render_params *p) {
    char err[256];
    render_session *rs = session_create(s, cam, p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (!rs) exit(1);
    return rs;
}

/* The next frame of rs in `parts` parts, each call checked. */
static void frame_in_parts(render_session *rs, int parts) {
    long long frames = session_frames(rs);
    int done = 0, calls = 0;
    while (!done && calls <= parts) {
        CHECK(session_render_part(rs, parts, &done) == 0, "part %d of %d: %s", calls, parts, session_error(rs));
        calls++;
        if (!done)
            CHECK(session_frame_parts(rs) == parts && session_frame_parts_done(rs) == calls,
                  "after part %d of %d: a frame of %d parts, %d done", calls, parts, session_frame_parts(rs),
                  session_frame_parts_done(rs));
    }
    CHECK(calls == parts && session_frames(rs) == frames + 1 && session_frame_parts(rs) == 0,
          "a frame of %d parts took %d calls, frames %lld -> %lld", parts, calls, frames, session_frames(rs));
}

/* Whether two sessions' films are the same, bit for bit. */
static int same_film(const render_session *a, const render_session *b) {
    const film *fa = session_film(a), *fb = session_film(b);
    size_t n = (size_t)fa->width * (size_t)fa->height;
    int same = fa->passes == fb->passes && memcmp(fa->rejected, fb->rejected, n * sizeof *fa->rejected) == 0;
    for (int c = 0; c < COMP_COUNT; c++) same &= memcmp(fa->sum[c], fb->sum[c], 3 * n * sizeof(double)) == 0;
    return same;
}

/* Whether two sessions counted the same work (not the times). */
static int same_counts(const render_session *a, const render_session *b) {
    render_stats x = session_stats(a), y = session_stats(b);
    int same = x.rejected_samples == y.rejected_samples && x.pixel_points == y.pixel_points &&
               x.vsl_samples == y.vsl_samples && x.vl_connections == y.vl_connections && x.hl_points == y.hl_points &&
               x.hl_secondary_rays == y.hl_secondary_rays && x.glossy_bounces == y.glossy_bounces &&
               x.auto_pt_paths == y.auto_pt_paths && x.auto_vl_samples == y.auto_vl_samples;
    for (int k = 0; k < RAY_KIND_COUNT; k++) same &= x.rays[k] == y.rays[k];
    return same;
}

/* Four frames of p on showcase (auto: six, through its judgements at 1, 2 and 4): whole (a); in 4,
 * 16, 256 parts and one (b); the same from a rotation advanced by 3 parts of 8 and a reset (c); and begun in f + 1 parts of 16, finished by
 * session_render_frame (d). The third frame begins with --adapt's first judgements
 * (HL_DIM_FRAMES). */
static void check_same_frames(const scene *s, const camera *cam, const render_params *p, const char *name) {
    static const int counts[4] = {4, 16, 256, 1};
    render_session *a = new_session(s, cam, p), *b = new_session(s, cam, p), *c = new_session(s, cam, p),
                   *d = new_session(s, cam, p), *e = new_session(s, cam, p);
    static extra_request extra[PIXELS / 3];
    for (int k = 0; k < 3; k++) CHECK(session_render_part(c, 8, NULL) == 0, "%s: a part of 8", name);
    session_reset(c);
    CHECK(session_frame_parts(c) == 0 && session_frames(c) == 0, "%s: a reset must abandon the frame", name);
    int frames = p->method == METHOD_AUTO ? 6 : 4;
    for (int f = 0; f < frames; f++) {
        CHECK(session_render_frame(a) == 0, "%s: frame %d: %s", name, f, session_error(a));
        frame_in_parts(b, counts[f % 4]);
        frame_in_parts(c, counts[f % 4]);
        for (int k = 0; k <= f; k++) CHECK(session_render_part(d, 16, NULL) == 0, "%s: a part of 16", name);
        CHECK(session_frame_parts(d) == 16 && session_render_frame(d) == 0 && session_frame_parts(d) == 0 &&
                  session_frames(d) == f + 1,
              "%s: session_render_frame must finish frame %d begun in parts (%lld frames)", name, f, session_frames(d));
        for (int k = 0, done = 0; !done; k++) { /* a frame in 4 parts, extra samples of every third pixel between */
            CHECK(session_render_part(e, 4, &done) == 0, "%s: a part of 4", name);
            for (int i = 0; i < PIXELS / 3; i++)
                extra[i] = (extra_request){.pixel = 3 * i + k % 3, .samples = 1 + i % 3, .weight = {1, 1, 1}};
            CHECK(session_render_extra(e, extra, PIXELS / 3) == 0 && extra[1].taken == 2,
                  "%s: extra samples between parts", name);
        }
        CHECK(same_film(a, e), "%s: frame %d with extra samples between its parts: the film differs", name, f);
        CHECK(same_film(a, b), "%s: frame %d in %d parts: the film differs from whole frames'", name, f, counts[f % 4]);
        CHECK(same_film(a, c), "%s: frame %d in %d parts from a rotation of 3: the film differs", name, f,
              counts[f % 4]);
        CHECK(same_film(a, d), "%s: frame %d finished by session_render_frame: the film differs", name, f);
    }
    CHECK(same_counts(a, b) && same_counts(a, c) && same_counts(a, d),
          "%s: the statistics must count the same rays and points whole and in parts", name);
    double sum = 0.0;
    for (int i = 0; i < 3 * PIXELS; i++) sum += session_film(a)->sum[COMP_DIRECT][i];
    CHECK(sum > 0.0 && isfinite(sum), "%s: the scene must be lit (%g)", name, sum);
    if (p->method == METHOD_VSL_HL)
        CHECK(session_plan(a)->highlights && session_stats(a).hl_points > 0 && session_stats(a).hl_secondary_rays > 0,
              "%s: the highlight estimator must run", name);
    if (p->method == METHOD_AUTO)
        CHECK(session_stats(a).auto_pt_paths > 0 && session_stats(a).auto_vl_samples > 0,
              "%s: both estimators must have run", name);
    session_destroy(a);
    session_destroy(b);
    session_destroy(c);
    session_destroy(d);
    session_destroy(e);
}

/* The order against brute force over every lattice: a permutation of the cells, of the lattice's
 * shape, each aligned run of 2^m ranks one cell in each (a >> ceil(m/2)) x (b >> floor(m/2)) block
 * and, on a square lattice, in each of the transposed blocks too; at 2x2 and 4x4 Bayer's matrices. */
static void check_order(void) {
    static const int bayer2[2][2] = {{0, 2}, {3, 1}};
    static const int bayer4[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
    for (int k = 0; (1 << k) <= SESSION_MAX_PARTS; k++) {
        int parts = 1 << k, a = 1 << (k + 1) / 2, b = 1 << k / 2, bad = 0;
        part_cell cells[SESSION_MAX_PARTS];
        int seen[SESSION_MAX_PARTS] = {0};
        for (int r = 0; r < parts; r++) {
            cells[r] = session_part_cell(parts, r);
            part_cell c = cells[r];
            if (c.a != a || c.b != b || c.x < 0 || c.x >= a || c.y < 0 || c.y >= b || seen[c.y * a + c.x]++) bad++;
            if (parts == 4 && bayer2[c.y][c.x] != r) bad++;
            if (parts == 16 && bayer4[c.y][c.x] != r) bad++;
        }
        CHECK(bad == 0, "%d parts: %d ranks off a permutation of a %dx%d lattice (or Bayer's matrix)", parts, bad, a,
              b);
        for (int m = 0; m <= k; m++) {
            for (int t = 0; t < 1 + (a == b && m % 2); t++) { /* t = 1: the transposed blocks */
                int bw = a >> (t ? m / 2 : (m + 1) / 2), bh = b >> (t ? (m + 1) / 2 : m / 2);
                for (int q = 0; q < parts >> m; q++) {
                    int count[SESSION_MAX_PARTS] = {0}, uneven = 0;
                    for (int r = q << m; r < (q + 1) << m; r++) count[cells[r].y / bh * (a / bw) + cells[r].x / bw]++;
                    for (int i = 0; i < 1 << m; i++) uneven += count[i] != 1;
                    CHECK(uneven == 0, "%d parts, ranks %d..%d: %d of the %dx%d blocks not hit once", parts, q << m,
                          ((q + 1) << m) - 1, uneven, bw, bh);
                }
            }
        }
    }
    for (int r = 0; r < 8; r++) {
        part_cell c = session_part_cell(3, r), e = session_part_cell(2, r), f = session_part_cell(1000, r),
                  g = session_part_cell(256, r);
        CHECK(c.a == e.a && c.b == e.b && c.x == e.x && c.y == e.y && f.a == g.a && f.b == g.b && f.x == g.x &&
                  f.y == g.y,
              "counts out of range must be clamped down to a power of two (rank %d)", r);
    }
}

/* A lit floor in the lower part of the view and nothing above it (no environment): the rays there
 * go into the void. */
static scene *half_void_scene(camera *cam) {
    scene *s = ts_new("half void");
    ts_quad(s, v3(-3, 0, 1), v3(3, 0, 1), v3(3, 0, -5), v3(-3, 0, -5), ts_lambert(s, v3s(0.7f), v3s(0), 0));
    ts_point_light(s, v3(0, 2, -1));
    ts_finalize(s);
    *cam = camera_look_at(v3(0, 1, 1.5f), v3(0, 0.6f, -1), v3(0, 1, 0), 1.0f);
    return s;
}

typedef struct {
    float *rgb[COMP_COUNT];
    uint32_t *stamp;
    double *acc[COMP_COUNT]; /* the stamped samples summed, as the film sums them */
    int *seen;               /* stamps a pixel took in this frame */
} sink_store;

static void store_init(sink_store *k, sample_sink *sink) {
    for (int c = 0; c < COMP_COUNT; c++) {
        k->rgb[c] = malloc(3 * PIXELS * sizeof(float));
        for (int i = 0; i < 3 * PIXELS; i++) k->rgb[c][i] = NAN; /* a value never written stays NaN */
        k->acc[c] = calloc(3 * PIXELS, sizeof(double));
        sink->rgb[c] = k->rgb[c];
    }
    k->stamp = malloc(PIXELS * sizeof(uint32_t));
    memset(k->stamp, 0xff, PIXELS * sizeof(uint32_t));
    k->seen = calloc(PIXELS, sizeof(int));
    sink->stamp = k->stamp;
}

static void store_free(sink_store *k) {
    for (int c = 0; c < COMP_COUNT; c++) free(k->rgb[c]), free(k->acc[c]);
    free(k->stamp);
    free(k->seen);
}

/* The pixels stamped with serial: counted and their samples summed. Returns how many. */
static int take_part(sink_store *k, uint32_t serial) {
    int n = 0;
    for (int i = 0; i < PIXELS; i++) {
        if (k->stamp[i] != serial) continue;
        n++, k->seen[i]++;
        for (int c = 0; c < COMP_COUNT; c++)
            for (int j = 0; j < 3; j++) k->acc[c][3 * i + j] += k->rgb[c][3 * i + j];
    }
    return n;
}

/* Whether pixel (x, y) lies in cell c's packets. */
static int in_cell(part_cell c, int x, int y) { return x / 4 % c.a == c.x && y / 4 % c.b == c.y; }

/* How many aligned bw x bh pixel blocks inside the image do not hold exactly `want` pixels stamped
 * below `serial_end`, from serial_begin on. */
static int uneven_blocks(const uint32_t *stamp, uint32_t serial_begin, uint32_t serial_end, int bw, int bh, int want) {
    int uneven = 0;
    for (int by = 0; by + bh <= H; by += bh) {
        for (int bx = 0; bx + bw <= W; bx += bw) {
            int n = 0;
            for (int y = by; y < by + bh; y++)
                for (int x = bx; x < bx + bw; x++)
                    n += stamp[y * W + x] >= serial_begin && stamp[y * W + x] < serial_end;
            uneven += n != want;
        }
    }
    return uneven;
}

/* Two frames of 16 parts with a sink whose serial is the part's count, from a fresh session (so
 * part t has rank t): each part stamps exactly its cell's pixels, each pixel once a frame; after a
 * quarter of the parts every 8x8 block of pixels (2x2 packets) holds one packet of them, after half
 * every 8x4 and 4x8 block; and the stamped samples summed are the film's sums, bit for bit (the film
 * adds each float sample to a double, as the sum here does, in the same order). */
static void check_sink(const scene *s, const camera *cam, render_method method) {
    const char *name = method_name(method);
    render_params p = {.width = W, .height = H, .method = method, .max_depth = 3, .seed = 4, .threads = 2};
    p.vl.count = 32;
    render_session *rs = new_session(s, cam, &p);
    sample_sink sink = {0};
    sink_store k;
    store_init(&k, &sink);
    session_set_sink(rs, &sink);
    int taken = 0;
    for (int f = 0; f < 2; f++) {
        memset(k.seen, 0, PIXELS * sizeof(int));
        for (int t = 0; t < 16; t++) {
            uint32_t serial = (uint32_t)(16 * f + t);
            sink.serial = serial;
            int done = 0;
            CHECK(session_render_part(rs, 16, &done) == 0 && done == (t == 15), "%s: part %d: %s", name, t,
                  session_error(rs));
            taken += take_part(&k, serial);
            /* one camera ray a pixel sampled so far, and those of the pixels' extra points */
            render_stats st = session_stats(rs);
            CHECK(st.rays[RAY_CAMERA] == (uint64_t)taken + st.pixel_points,
                  "%s: part %d: the statistics count %llu camera rays for %d pixels and %llu points", name, t,
                  (unsigned long long)st.rays[RAY_CAMERA], taken, (unsigned long long)st.pixel_points);
            part_cell c = session_part_cell(16, t);
            int wrong = 0;
            for (int i = 0; i < PIXELS; i++) wrong += (k.stamp[i] == serial) != in_cell(c, i % W, i / W);
            CHECK(wrong == 0, "%s: part %d: %d pixels stamped or not against its cell (%d, %d)", name, t, wrong, c.x,
                  c.y);
            if (t == 3)
                CHECK(uneven_blocks(k.stamp, 16 * f, serial + 1, 8, 8, 16) == 0,
                      "%s: the first quarter of the parts must hold one packet in each 8x8 block", name);
            if (t == 7)
                CHECK(uneven_blocks(k.stamp, 16 * f, serial + 1, 8, 4, 16) == 0 &&
                          uneven_blocks(k.stamp, 16 * f, serial + 1, 4, 8, 16) == 0,
                      "%s: the first half of the parts must hold one packet in each 8x4 and 4x8 block", name);
        }
        int once = 0;
        for (int i = 0; i < PIXELS; i++) once += k.seen[i] == 1;
        CHECK(once == PIXELS, "%s: frame %d: %d of %d pixels stamped exactly once", name, f, once, PIXELS);
    }
    const film *fm = session_film(rs);
    int differ = 0, black = 0;
    for (int i = 0; i < PIXELS; i++) {
        int zero = 1;
        for (int c = 0; c < COMP_COUNT; c++) {
            for (int j = 0; j < 3; j++) {
                differ += k.acc[c][3 * i + j] != fm->sum[c][3 * i + j];
                zero &= k.acc[c][3 * i + j] == 0.0;
            }
        }
        black += zero;
    }
    CHECK(differ == 0, "%s: %d values of the sink's samples summed differ from the film's sums", name, differ);
    CHECK(black > PIXELS / 4 && black < PIXELS * 3 / 4, "%s: %d of %d pixels into the void (a third expected)", name,
          black, PIXELS);
    session_destroy(rs);
    store_free(&k);
}

/* A sky near FLT_MAX over a white floor: samples that overflow are dropped (film_reject), and the
 * sink stamps exactly the pixels whose sample the film took. */
static void check_sink_rejects(void) {
    scene *s = ts_new("huge sky");
    ts_quad(s, v3(-50, -1, 50), v3(50, -1, 50), v3(50, -1, -50), v3(-50, -1, -50), ts_lambert(s, v3s(0.9f), v3s(0), 0));
    image_rgb sky = {8, 6, malloc(sizeof(float) * 3 * 8 * 6)};
    for (int i = 0; i < 3 * 8 * 6; i++) sky.rgb[i] = 0.9f * FLT_MAX;
    char err[256];
    CHECK(scene_set_env_image(s, &sky, 0.0f, err, sizeof err) == 0, "env: %s", err);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 0, 0), v3(0, -0.3f, -1), v3(0, 1, 0), 1.0f);
    render_params p = {.width = W, .height = H, .method = METHOD_PT, .max_depth = 3, .seed = 5, .threads = 2};
    render_session *rs = new_session(s, &cam, &p);
    sample_sink sink = {0};
    sink_store k;
    store_init(&k, &sink);
    sink.serial = 7;
    session_set_sink(rs, &sink);
    frame_in_parts(rs, 4);
    int rejected = 0, wrong = 0;
    for (int i = 0; i < PIXELS; i++) {
        rejected += session_film(rs)->rejected[i] > 0;
        wrong += (k.stamp[i] == 7) != (session_film(rs)->rejected[i] == 0);
    }
    CHECK(rejected > 0 && rejected < PIXELS, "huge sky: %d of %d pixels dropped their sample", rejected, PIXELS);
    CHECK(wrong == 0, "huge sky: %d pixels stamped where the film dropped the sample, or not where it took it", wrong);
    session_destroy(rs);
    store_free(&k);
    scene_destroy(s);
}

/* A viewer whose camera moves resets after every part: the parts still walk through the frame's
 * order, each pixel once in 16 updates, and no frame counts. A frame of another count begins at the
 * rank after the last one begun, mod its count. */
static void check_rotation(const scene *s, const camera *cam) {
    render_params p = {.width = W, .height = H, .method = METHOD_PT, .max_depth = 2, .seed = 6, .threads = 2};
    render_session *rs = new_session(s, cam, &p);
    sample_sink sink = {0};
    sink_store k;
    store_init(&k, &sink);
    session_set_sink(rs, &sink);
    int repeated = 0;
    for (int u = 0; u < 16; u++) {
        sink.serial = (uint32_t)u;
        int done = 1;
        CHECK(session_render_part(rs, 16, &done) == 0 && !done, "update %d: %s", u, session_error(rs));
        for (int i = 0; i < PIXELS; i++) repeated += k.stamp[i] == (uint32_t)u && k.seen[i] > 0;
        CHECK(take_part(&k, (uint32_t)u) > 0, "update %d stamped nothing", u);
        session_reset(rs);
        CHECK(session_frame_parts(rs) == 0 && session_frames(rs) == 0, "update %d: the reset must abandon the frame",
              u);
    }
    int once = 0;
    for (int i = 0; i < PIXELS; i++) once += k.seen[i] == 1;
    CHECK(repeated == 0 && once == PIXELS,
          "16 updates reset after each part: %d pixels of a part rendered again, %d of %d once", repeated, once,
          PIXELS);
    /* 3 parts of 16 from rank 0, so a frame of 4 parts begins at rank 3 */
    for (int t = 0; t < 3; t++) CHECK(session_render_part(rs, 16, NULL) == 0, "part %d of 16", t);
    session_reset(rs);
    sink.serial = 100;
    CHECK(session_render_part(rs, 4, NULL) == 0 && session_frame_parts(rs) == 4, "a part of 4");
    int wrong = 0;
    for (int i = 0; i < PIXELS; i++) wrong += (k.stamp[i] == 100) != in_cell(session_part_cell(4, 3), i % W, i / W);
    CHECK(wrong == 0, "after ranks 0..2 of 16, a frame of 4 parts must begin at rank 3: %d pixels off", wrong);
    session_destroy(rs);
    store_free(&k);
}

/* A frame ordered by need (session_set_packet_need), in 8 parts with a sink whose serial is the
 * part's: every pixel once; no packet of a later part needs more than any of an earlier one; the
 * parts as large as an even split makes them; the film the whole frame's, bit for bit. */
static void check_need_order(const scene *s, const camera *cam) {
    enum { PX = (W + SESSION_PACKET - 1) / SESSION_PACKET, PY = (H + SESSION_PACKET - 1) / SESSION_PACKET };
    render_params p = {.width = W, .height = H, .method = METHOD_PT, .max_depth = 2, .seed = 5, .threads = 2};
    render_session *rs = new_session(s, cam, &p), *whole = new_session(s, cam, &p);
    uint8_t need[PX * PY];
    for (int k = 0; k < PX * PY; k++) need[k] = (uint8_t)((k * 7 + k / PX * 3) % SESSION_NEED_LEVELS);
    need[5 * PX + 9] = SESSION_NEED_LEVELS - 1;
    session_set_packet_need(rs, need);
    sample_sink sink = {0};
    sink_store k;
    store_init(&k, &sink);
    session_set_sink(rs, &sink);
    int part_of[PX * PY], size[8] = {0}, done = 0;
    for (int q = 0; q < PX * PY; q++) part_of[q] = -1;
    for (int t = 0; t < 8; t++) {
        sink.serial = (uint32_t)t;
        CHECK(session_render_part(rs, 8, &done) == 0, "ordered part %d: %s", t, session_error(rs));
        take_part(&k, (uint32_t)t);
        for (int i = 0; i < PIXELS; i++) {
            int q = (i / W / SESSION_PACKET) * PX + i % W / SESSION_PACKET;
            if (k.stamp[i] != (uint32_t)t || part_of[q] == t) continue;
            CHECK(part_of[q] < 0, "packet %d rendered in parts %d and %d", q, part_of[q], t);
            part_of[q] = t, size[t]++;
        }
    }
    int once = 0, later_needier = 0, sizes_off = 0;
    for (int i = 0; i < PIXELS; i++) once += k.seen[i] == 1;
    for (int a = 0; a < PX * PY; a++)
        for (int b = 0; b < PX * PY; b++) later_needier += part_of[a] < part_of[b] && need[b] > need[a];
    for (int t = 0; t < 8; t++) sizes_off += size[t] != PX * PY * (t + 1) / 8 - PX * PY * t / 8;
    CHECK(done && once == PIXELS, "an ordered frame must render every pixel once: %d of %d (done %d)", once, PIXELS,
          done);
    CHECK(later_needier == 0 && part_of[5 * PX + 9] == 0,
          "the neediest packets first: %d pairs out of order, the neediest in part %d", later_needier,
          part_of[5 * PX + 9]);
    CHECK(sizes_off == 0, "an ordered frame's parts must split it evenly: %d parts off", sizes_off);
    CHECK(session_render_frame(whole) == 0 && same_film(rs, whole),
          "a frame ordered by need must be the whole frame, bit for bit");
    session_destroy(rs);
    session_destroy(whole);
    store_free(&k);
}

/* Counts out of range are clamped to the nearest allowed value below (1 at least); a part stopped
 * by the abort flag abandons its frame, and after a reset the session renders as a fresh one. */
static void check_clamp_and_abort(const scene *s, const camera *cam) {
    render_params p = {.width = W, .height = H, .method = METHOD_PT, .max_depth = 2, .seed = 8, .threads = 2};
    render_session *rs = new_session(s, cam, &p), *fresh = new_session(s, cam, &p);
    static const int asked[] = {3, 255, 1000, 0, -7, 1}, got[] = {2, 128, 256, 1, 1, 1};
    for (int k = 0; k < 6; k++) {
        int done = 0;
        CHECK(session_render_part(rs, asked[k], &done) == 0, "parts %d: %s", asked[k], session_error(rs));
        CHECK(got[k] == 1 ? done && session_frame_parts(rs) == 0 : !done && session_frame_parts(rs) == got[k],
              "parts %d must be clamped to %d (a frame of %d parts, done %d)", asked[k], got[k],
              session_frame_parts(rs), done);
        /* the count is the frame's: asked another, the frame under way keeps its own */
        if (!done)
            CHECK(session_render_part(rs, 64, &done) == 0 &&
                      (got[k] == 2 ? done : session_frame_parts(rs) == got[k] && session_frame_parts_done(rs) == 2),
                  "a frame of %d parts must keep its count (done %d)", got[k], done);
        session_reset(rs);
    }
    atomic_int stop = 1;
    session_set_abort_flag(rs, &stop);
    CHECK(session_render_part(rs, 16, NULL) == 1, "a part with the abort flag set must report that it stopped");
    CHECK(session_frame_parts(rs) == 0 && session_frames(rs) == 0, "a stopped part must abandon its frame");
    atomic_store(&stop, 0);
    session_reset(rs);
    frame_in_parts(rs, 16);
    CHECK(session_render_frame(fresh) == 0, "a whole frame: %s", session_error(fresh));
    CHECK(same_film(rs, fresh), "after a stopped part and a reset, the film must equal a fresh session's");
    session_destroy(rs);
    session_destroy(fresh);
}

int main(void) {
    check_order();
    char err[256];
    scene *showcase = scene_load("builtin:showcase", NULL, NULL, err, sizeof err);
    CHECK(showcase != NULL, "showcase: %s", err);
    if (!showcase) return check_exit("test_parts");
    camera cam = scene_camera(showcase, 0, (float)W / (float)H);
    render_params p = {.width = W, .height = H, .max_depth = 4, .seed = 9, .threads = 2};
    p.vl.count = 64;
    p.method = METHOD_PT;
    check_same_frames(showcase, &cam, &p, "pt");
    p.method = METHOD_VSL;
    check_same_frames(showcase, &cam, &p, "vsl");
    p.method = METHOD_VSL_HL;
    p.vl.share = HL_SHARE_ON;
    check_same_frames(showcase, &cam, &p, "vsl+hl");
    p.method = METHOD_AUTO;
    p.vl.share = HL_SHARE_DEFAULT;
    check_same_frames(showcase, &cam, &p, "auto");
    scene_destroy(showcase);

    scene *s = half_void_scene(&cam);
    check_sink(s, &cam, METHOD_PT);
    check_sink(s, &cam, METHOD_VSL);
    check_sink(s, &cam, METHOD_AUTO);
    check_rotation(s, &cam);
    check_need_order(s, &cam);
    check_clamp_and_abort(s, &cam);
    scene_destroy(s);
    check_sink_rejects();
    return check_exit("test_parts");
}
