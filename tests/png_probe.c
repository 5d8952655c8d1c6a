/* png_probe: numbers about a screenshot for the viewer's shell tests.
 *
 *   png_probe A.png size                      prints "W H"
 *   png_probe A.png ink X0 Y0 X1 Y1           sharp horizontal steps (|luma difference| > 96) per
 *                                             thousand pixels of the box: text is full of them
 *   png_probe A.png inkrows X0 Y0 X1 Y1       rows of the box holding at least one such step: the
 *                                             height of the text in it
 *   png_probe A.png blocky X0 Y0 X1 Y1        per thousand steps between horizontal neighbours
 *                                             in the box: those between two runs of 3 identical
 *                                             pixels (a magnification to nearest neighbours
 *                                             makes nearly all its steps so; a bilinear one ramps)
 *   png_probe A.png diff B.png X0 Y0 X1 Y1    mean absolute difference (0-255) of A and B in the
 *                                             box, B's pixel (x, y) against A's
 *
 * Boxes are [X0, X1) x [Y0, Y1), clipped to the image. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

typedef struct {
    unsigned char *px;
    int w, h;
} img;

static int load(const char *path, img *out) {
    int n;
    out->px = stbi_load(path, &out->w, &out->h, &n, 3);
    if (!out->px) fprintf(stderr, "png_probe: %s: cannot read\n", path);
    return out->px ? 0 : -1;
}

static const unsigned char *at(const img *m, int x, int y) {
    return m->px + 3 * ((size_t)y * (size_t)m->w + (size_t)x);
}

static int luma(const img *m, int x, int y) {
    const unsigned char *p = at(m, x, y);
    return (299 * p[0] + 587 * p[1] + 114 * p[2]) / 1000;
}

/* A sharp horizontal step: the edge of a glyph. */
static int step(const img *m, int x, int y) { return abs(luma(m, x, y) - luma(m, x + 1, y)) > 96; }

static int same(const img *m, int x0, int y0, int x1, int y1) { return memcmp(at(m, x0, y0), at(m, x1, y1), 3) == 0; }

static void clip(const img *m, int *b) {
    if (b[0] < 0) b[0] = 0;
    if (b[1] < 0) b[1] = 0;
    if (b[2] > m->w) b[2] = m->w;
    if (b[3] > m->h) b[3] = m->h;
}

int main(int argc, char **argv) {
    img a, b;
    if (argc < 3 || load(argv[1], &a) != 0) return 2;
    const char *cmd = argv[2];
    if (strcmp(cmd, "size") == 0) {
        printf("%d %d\n", a.w, a.h);
        stbi_image_free(a.px);
        return 0;
    }
    int diff = strcmp(cmd, "diff") == 0, first = diff ? 4 : 3;
    if (argc != first + 4) {
        stbi_image_free(a.px);
        return fprintf(stderr, "png_probe: bad arguments\n"), 2;
    }
    int box[4];
    for (int i = 0; i < 4; i++) box[i] = atoi(argv[first + i]);
    clip(&a, box);
    long count = 0, total = 0;
    if (strcmp(cmd, "ink") == 0) {
        for (int y = box[1]; y < box[3]; y++)
            for (int x = box[0]; x + 1 < box[2]; x++, total++) count += step(&a, x, y);
    } else if (strcmp(cmd, "inkrows") == 0) {
        for (int y = box[1]; y < box[3]; y++) {
            int ink = 0;
            for (int x = box[0]; x + 1 < box[2] && !ink; x++) ink = step(&a, x, y);
            count += ink;
        }
        printf("%ld\n", count);
        stbi_image_free(a.px);
        return 0;
    } else if (strcmp(cmd, "blocky") == 0) {
        for (int y = box[1]; y < box[3]; y++)
            for (int x = box[0] + 2; x + 3 < box[2]; x++) {
                if (same(&a, x, y, x + 1, y)) continue;
                total++;
                count += same(&a, x - 2, y, x, y) && same(&a, x - 1, y, x, y) && same(&a, x + 1, y, x + 2, y) &&
                         same(&a, x + 1, y, x + 3, y);
            }
    } else if (diff) {
        if (load(argv[3], &b) != 0) {
            stbi_image_free(a.px);
            return 2;
        }
        clip(&b, box);
        double sum = 0.0;
        for (int y = box[1]; y < box[3]; y++)
            for (int x = box[0]; x < box[2]; x++, total++)
                for (int k = 0; k < 3; k++) sum += abs(at(&a, x, y)[k] - at(&b, x, y)[k]);
        printf("%.2f\n", total ? sum / (3.0 * (double)total) : 0.0);
        stbi_image_free(b.px);
        stbi_image_free(a.px);
        return 0;
    } else {
        stbi_image_free(a.px);
        return fprintf(stderr, "png_probe: unknown command %s\n", cmd), 2;
    }
    printf("%ld\n", total ? 1000 * count / total : 0);
    stbi_image_free(a.px);
    return 0;
}
