/* glint tests — a small reader of the SVG that cairo writes: well-formed XML (tags nest, attributes
 * quoted, one <svg> root), the root's size, the paths outside <defs> (colours, widths, opacity,
 * the points of M L C Z data) and where glyphs are placed (<use x y>). */
#ifndef GLINT_TEST_SVG_READ_H
#define GLINT_TEST_SVG_READ_H

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *start, *end; /* the tag from '<' to past '>' */
    char name[32];
    int closing, empty; /* </name>, <name/> */
} tag;

/* The next tag from *p, checking the text before it and its attributes. 1: a tag, 0: the end of
 * the text, -1: malformed (why says how). */
static inline int next_tag(const char **p, tag *t, const char **why) {
    const char *s = *p;
    for (; *s && *s != '<'; s++)
        if (*s == '&' && !(strncmp(s, "&lt;", 4) == 0 || strncmp(s, "&gt;", 4) == 0 || strncmp(s, "&amp;", 5) == 0 ||
                           strncmp(s, "&quot;", 6) == 0 || strncmp(s, "&apos;", 6) == 0 || s[1] == '#'))
            return *why = "a bare & in text", -1;
    if (!*s) return *p = s, 0;
    memset(t, 0, sizeof *t);
    t->start = s;
    if (strncmp(s, "<?", 2) == 0 || strncmp(s, "<!--", 4) == 0) {
        const char *e = strstr(s, s[1] == '?' ? "?>" : "-->");
        if (!e) return *why = "an unterminated declaration or comment", -1;
        t->end = e + (s[1] == '?' ? 2 : 3);
        t->name[0] = '?';
        *p = t->end;
        return 1;
    }
    s++;
    if (*s == '/') t->closing = 1, s++;
    size_t n = 0;
    while (*s && (isalnum((unsigned char)*s) || strchr(":_-.", *s)) && n + 1 < sizeof t->name) t->name[n++] = *s++;
    if (n == 0) return *why = "a tag without a name", -1;
    for (;;) { /* attributes: name="value" */
        while (*s == ' ' || *s == '\n' || *s == '\t' || *s == '\r') s++;
        if (*s == '>') break;
        if (s[0] == '/' && s[1] == '>' && !t->closing) {
            t->empty = 1, s++;
            break;
        }
        if (t->closing) return *why = "attributes in a closing tag", -1;
        const char *a = s;
        while (*s && (isalnum((unsigned char)*s) || strchr(":_-.", *s))) s++;
        if (s == a || *s != '=' || (s[1] != '"' && s[1] != '\''))
            return *why = "an attribute without a quoted value", -1;
        char q = s[1];
        s += 2;
        while (*s && *s != q && *s != '<') s++;
        if (*s != q) return *why = "an unterminated attribute value", -1;
        s++;
    }
    t->end = s + 1;
    *p = t->end;
    return 1;
}

/* NULL when text is one well-formed document whose root is <svg>; else what is wrong. */
static inline const char *xml_problem(const char *text) {
    char stack[64][32];
    int depth = 0, roots = 0;
    const char *p = text, *why = NULL;
    tag t;
    int r;
    while ((r = next_tag(&p, &t, &why)) == 1) {
        if (t.name[0] == '?') continue;
        if (t.closing) {
            if (depth == 0 || strcmp(stack[depth - 1], t.name) != 0) return "a closing tag that closes nothing open";
            depth--;
            continue;
        }
        if (depth == 0 && (roots++ || strcmp(t.name, "svg") != 0)) return "not one <svg> root";
        if (t.empty) continue;
        if (depth == 64) return "nested too deep";
        snprintf(stack[depth++], sizeof stack[0], "%s", t.name);
    }
    if (r < 0) return why;
    return depth ? "elements left open" : roots ? NULL : "no root element";
}

/* The value of attribute name in tag t (copied to out), or "" when absent. */
static inline const char *attr(const tag *t, const char *name, char *out, size_t n) {
    out[0] = 0;
    size_t len = strlen(name);
    for (const char *s = t->start; s && s < t->end; s++) {
        s = strstr(s, name);
        if (!s || s >= t->end) break;
        if ((s[-1] == ' ' || s[-1] == '\n') && s[len] == '=' && s[len + 1] == '"') {
            const char *v = s + len + 2, *e = strchr(v, '"');
            snprintf(out, n, "%.*s", (int)(e - v), v);
            break;
        }
    }
    return out;
}

/* A presentation property of a path: its attribute, or its entry in the style attribute. */
static inline const char *prop(const tag *t, const char *name, char *out, size_t n) {
    if (attr(t, name, out, n)[0]) return out;
    char style[1024];
    attr(t, "style", style, sizeof style);
    size_t len = strlen(name);
    for (const char *s = style; (s = strstr(s, name)) != NULL; s++)
        if ((s == style || s[-1] == ';' || s[-1] == ' ') && s[len] == ':') {
            const char *v = s + len + 1, *e = strchr(v, ';');
            snprintf(out, n, "%.*s", (int)(e ? e - v : (long)strlen(v)), v);
            return out;
        }
    out[0] = 0;
    return out;
}

/* "rgb(12.2%,46.7%,70.6%)" as 0..255; 0 when it is none. */
static inline int svg_colour(const char *v, double c[3]) {
    double a, b, d;
    if (sscanf(v, "rgb(%lf%%,%lf%%,%lf%%)", &a, &b, &d) != 3) return 0;
    c[0] = 2.55 * a, c[1] = 2.55 * b, c[2] = 2.55 * d;
    return 1;
}

enum { MAX_VERTS = 512 };
typedef struct {
    double x[MAX_VERTS], y[MAX_VERTS]; /* every point of the data: ends and control points */
    int sub[MAX_VERTS];                /* its sub-path */
    int n, bad;                        /* bad: a command other than M L C Z, or too many points */
} path_points;

static inline void parse_d(const char *d, path_points *pp) {
    pp->n = pp->bad = 0;
    int sub = -1;
    const char *s = d;
    while (*s) {
        while (*s == ' ' || *s == ',') s++;
        if (!*s) break;
        char cmd = *s++;
        int pairs = cmd == 'M' || cmd == 'L' ? 1 : cmd == 'C' ? 3 : 0;
        if (cmd == 'M') sub++;
        if (cmd != 'Z' && pairs == 0) {
            pp->bad = 1;
            return;
        }
        for (int k = 0; k < pairs; k++) {
            char *e;
            double x = strtod(s, &e), y = strtod(e, &e);
            if (e == s || pp->n == MAX_VERTS) {
                pp->bad = 1;
                return;
            }
            pp->x[pp->n] = x, pp->y[pp->n] = y, pp->sub[pp->n++] = sub;
            s = e;
        }
    }
}

/* Distance from (x, y) to the polyline through the points of sub-path sub. */
static inline double polyline_distance(const path_points *pp, int sub, double x, double y) {
    double best = INFINITY;
    for (int i = 0; i < pp->n; i++) {
        if (pp->sub[i] != sub) continue;
        double ax = pp->x[i], ay = pp->y[i], bx = ax, by = ay;
        if (i + 1 < pp->n && pp->sub[i + 1] == sub) bx = pp->x[i + 1], by = pp->y[i + 1];
        double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
        double t = len2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / len2 : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        best = fmin(best, hypot(ax + t * dx - x, ay + t * dy - y));
    }
    return best;
}

/* The SVG's drawing, outside <defs>: its paths, and its glyphs' positions (<use x y>). */
enum { MAX_PATHS = 1024, MAX_GLYPHS = 4096 };
typedef struct {
    double stroke[3], fill[3];
    int has_stroke, has_fill;
    double stroke_width, fill_opacity;
    path_points pts;
} svg_path;

typedef struct {
    svg_path path[MAX_PATHS];
    int num_paths;
    double gx[MAX_GLYPHS], gy[MAX_GLYPHS];
    int num_glyphs;
    char width[32], height[32], view_box[64];
} drawing;

static inline void read_drawing(const char *text, drawing *dr) {
    memset(dr, 0, sizeof *dr);
    const char *p = text, *why;
    tag t;
    int defs = 0;
    char v[8192];
    while (next_tag(&p, &t, &why) == 1) {
        if (strcmp(t.name, "svg") == 0 && !t.closing) {
            attr(&t, "width", dr->width, sizeof dr->width);
            attr(&t, "height", dr->height, sizeof dr->height);
            attr(&t, "viewBox", dr->view_box, sizeof dr->view_box);
        }
        if (strcmp(t.name, "defs") == 0) defs += t.closing ? -1 : t.empty ? 0 : 1;
        if (defs) continue;
        if (strcmp(t.name, "use") == 0 && dr->num_glyphs < MAX_GLYPHS) {
            dr->gx[dr->num_glyphs] = atof(attr(&t, "x", v, sizeof v));
            dr->gy[dr->num_glyphs++] = atof(attr(&t, "y", v, sizeof v));
        }
        if (strcmp(t.name, "path") == 0 && !t.closing && dr->num_paths < MAX_PATHS) {
            svg_path *q = &dr->path[dr->num_paths++];
            q->has_stroke = svg_colour(prop(&t, "stroke", v, sizeof v), q->stroke);
            q->has_fill = svg_colour(prop(&t, "fill", v, sizeof v), q->fill);
            q->stroke_width = atof(prop(&t, "stroke-width", v, sizeof v));
            q->fill_opacity = prop(&t, "fill-opacity", v, sizeof v)[0] ? atof(v) : 1.0;
            parse_d(attr(&t, "d", v, sizeof v), &q->pts);
        }
    }
}

static inline int same_colour(const double a[3], const double b[3], double tol) {
    return fabs(a[0] - b[0]) <= tol && fabs(a[1] - b[1]) <= tol && fabs(a[2] - b[2]) <= tol;
}

/* Glyphs placed in [x0, x1) x [y0, y1). */
static inline int glyphs_in(const drawing *dr, double x0, double y0, double x1, double y1) {
    int n = 0;
    for (int i = 0; i < dr->num_glyphs; i++)
        n += dr->gx[i] >= x0 && dr->gx[i] < x1 && dr->gy[i] >= y0 && dr->gy[i] < y1;
    return n;
}

/* Characters other than spaces (UTF-8 code points). */
static inline int visible_chars(const char *s) {
    int n = 0;
    for (; s && *s; s++) n += *s != ' ' && ((unsigned char)*s & 0xC0) != 0x80;
    return n;
}

/* Paths drawn in colour c (within 2 of 255): stroked with the given width (fill_opacity < 0) or
 * filled with that opacity, with every point inside [x0, x1] x [y0, y1]. */
static inline int paths_within(const drawing *dr, const double c[3], double width, double fill_opacity, double x0,
                               double y0, double x1, double y1) {
    int n = 0;
    for (int i = 0; i < dr->num_paths; i++) {
        const svg_path *q = &dr->path[i];
        if (fill_opacity < 0
                ? !q->has_stroke || !same_colour(q->stroke, c, 2.0) || q->stroke_width != width
                : !q->has_fill || !same_colour(q->fill, c, 2.0) || fabs(q->fill_opacity - fill_opacity) > 0.01)
            continue;
        int in = q->pts.n > 0;
        for (int k = 0; k < q->pts.n; k++)
            in &= q->pts.x[k] >= x0 && q->pts.x[k] <= x1 && q->pts.y[k] >= y0 && q->pts.y[k] <= y1;
        n += in;
    }
    return n;
}

#endif
