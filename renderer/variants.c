/* KHR_materials_variants (docs/design.md, "Material variants"): the scene's named variants and,
 * per mesh primitive, which material each variant gives it; per primitive instance, its run of
 * triangles. Switching a variant rewrites those triangles' materials; scene_make.c then builds
 * again what depends on them. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_parts.h"

typedef struct {
    int first, count;  /* triangles */
    int table;         /* its primitive's mappings */
    int base_material; /* the file's default */
} variant_range;

typedef struct {
    int variant, material;
} variant_pair;

struct scene_variants {
    int n, current; /* variants; the one in use, -1 for the default materials */
    char (*names)[64];
    /* table k: pairs [table_start[k], table_start[k + 1]) (table_start: num_tables + 1 entries) */
    variant_pair *pairs;
    int num_pairs, cap_pairs;
    int *table_start, num_tables, cap_starts;
    variant_range *ranges;
    int num_ranges, cap_ranges;
};

static int grow(void **p, int *cap, int need, size_t elem) {
    if (need <= *cap) return 0;
    long long c = *cap ? 2LL * *cap : 16;
    while (c < need) c *= 2;
    void *q = realloc(*p, elem * (size_t)c);
    if (!q) return -1;
    *p = q;
    *cap = (int)c;
    return 0;
}

void scene_variants_free(scene *s) {
    struct scene_variants *v = s->variants;
    if (!v) return;
    free(v->names);
    free(v->pairs);
    free(v->table_start);
    free(v->ranges);
    free(v);
    s->variants = NULL;
}

int scene_add_variants(scene *s, const char *const *names, int n) {
    if (s->variants || n <= 0 || n > SCENE_MAX_VARIANTS) return -1;
    struct scene_variants *v = calloc(1, sizeof *v);
    if (!v) return -1;
    v->names = calloc((size_t)n, sizeof *v->names);
    v->table_start = calloc(1, sizeof(int));
    v->cap_starts = 1;
    if (!v->names || !v->table_start) {
        free(v->names);
        free(v->table_start);
        free(v);
        return -1;
    }
    for (int i = 0; i < n; i++) snprintf(v->names[i], sizeof v->names[i], "%s", names[i]);
    v->n = n;
    v->current = -1;
    s->variants = v;
    return 0;
}

int scene_add_variant_table(scene *s, const int *variants, const int *materials, int n) {
    struct scene_variants *v = s->variants;
    if (!v || n < 0 || (long long)v->num_pairs + n > SCENE_MAX_VARIANT_PAIRS) return -1;
    for (int i = 0; i < n; i++)
        if (variants[i] < 0 || variants[i] >= v->n || materials[i] < 0 || materials[i] >= s->num_materials) return -1;
    if (grow((void **)&v->pairs, &v->cap_pairs, v->num_pairs + n, sizeof(variant_pair)) != 0 ||
        grow((void **)&v->table_start, &v->cap_starts, v->num_tables + 2, sizeof(int)) != 0)
        return -1;
    for (int i = 0; i < n; i++) v->pairs[v->num_pairs++] = (variant_pair){variants[i], materials[i]};
    v->table_start[++v->num_tables] = v->num_pairs;
    return v->num_tables - 1;
}

int scene_map_variants(scene *s, int first_triangle, int table) {
    struct scene_variants *v = s->variants;
    int count = s->num_triangles - first_triangle;
    if (!v || table < 0 || table >= v->num_tables || first_triangle < 0 || count < 0) return -1;
    if (count == 0) return 0;
    if (grow((void **)&v->ranges, &v->cap_ranges, v->num_ranges + 1, sizeof(variant_range)) != 0) return -1;
    v->ranges[v->num_ranges++] = (variant_range){first_triangle, count, table, s->tri_material[first_triangle]};
    return 0;
}

int scene_variants_emit(const scene *s) {
    const struct scene_variants *v = s->variants;
    for (int k = 0; v && k < v->num_pairs; k++)
        if (max_comp3(s->materials[v->pairs[k].material].emission) > 0.0f) return 1;
    return 0;
}

int scene_num_variants(const scene *s) { return s->variants ? s->variants->n : 0; }

const char *scene_variant_name(const scene *s, int i) {
    return s->variants && i >= 0 && i < s->variants->n ? s->variants->names[i] : NULL;
}

int scene_variant(const scene *s) { return s->variants ? s->variants->current : -1; }

int scene_variant_find(const scene *s, const char *name) {
    for (int i = 0; i < scene_num_variants(s); i++)
        if (strcmp(s->variants->names[i], name) == 0) return i;
    return -1;
}

int scene_apply_variant(scene *s, int variant) {
    struct scene_variants *v = s->variants;
    if (variant < -1 || variant >= scene_num_variants(s)) return -1;
    if (!v) return 0;
    /* Each table's material for this variant first (-1: the default): the work is the pairs
     * plus the triangles, however many instances share a table. */
    int *pick = malloc(sizeof(int) * (size_t)(v->num_tables + 1));
    if (!pick) return -1;
    for (int k = 0; k < v->num_tables; k++) {
        pick[k] = -1;
        for (int i = v->table_start[k]; i < v->table_start[k + 1]; i++)
            if (v->pairs[i].variant == variant) pick[k] = v->pairs[i].material;
    }
    for (int r = 0; r < v->num_ranges; r++) {
        const variant_range *g = &v->ranges[r];
        int m = pick[g->table] >= 0 ? pick[g->table] : g->base_material;
        for (int t = g->first; t < g->first + g->count; t++) s->tri_material[t] = m;
    }
    free(pick);
    v->current = variant;
    return 0;
}
