/* glint view: the data the UI and the render side hand each other (view_state.h). */
#include "view_state.h"

#include <stdio.h>

#include "reference.h"

void fill_scene_info(scene_info *info, const scene *s) {
    snprintf(info->name, sizeof info->name, "%s", s->path);
    info->num_cameras = s->num_cameras < MAX_VIEW_CAMERAS ? s->num_cameras : MAX_VIEW_CAMERAS;
    for (int i = 0; i < info->num_cameras; i++) info->cameras[i] = s->cameras[i];
    info->bounds = s->bounds;
    info->diag = s->diag;
    int n = scene_light_groups(s, info->lights, MAX_LIGHT_GROUPS); /* -1 (out of memory): none listed */
    info->num_lights = n < 0 ? 0 : n < MAX_LIGHT_GROUPS ? n : MAX_LIGHT_GROUPS;
    info->unlit = s->num_lights - (s->env_light >= 0 ? 1 : 0) == 0;
    info->num_variants = scene_num_variants(s) < MAX_VIEW_VARIANTS ? scene_num_variants(s) : MAX_VIEW_VARIANTS;
    for (int i = 0; i < info->num_variants; i++)
        snprintf(info->variant_names[i], sizeof info->variant_names[i], "%s", scene_variant_name(s, i));
    info->variant = scene_variant(s) < info->num_variants ? scene_variant(s) : -1;
    info->kept_view = 0;
}

void clear_light_edits(light_edits *e) {
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        e->offset[g] = v3(0, 0, 0);
        e->gain[g] = 1.0f;
    }
}

void light_edits_text(const light_edits *e, char *out, size_t n) {
    light_edit list[MAX_LIGHT_GROUPS];
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) list[g] = (light_edit){g, e->offset[g], e->gain[g]};
    if (reference_lights_text(list, MAX_LIGHT_GROUPS, out, n) != 0 && n) out[0] = 0; /* n too small: none said */
}
