/* Lights that light nothing the renderer draws (issue 33): a scene whose every light is one
 * renders an all-zero image, so the loader warns per light and `lamprig render` refuses such
 * a scene before any pass runs (render/scene/scene.h). Two causes, both exact:
 *  - a light inside a closed object's material (LR_ENCLOSURE_SOLID): every ray from it meets
 *    the surface from behind, which the surface-incidence models count as no light
 *    (render/passes/PIPELINE.md), and the object it is in hides it from everything else;
 *  - zero power: intensity (radiance) x colour is 0 in every band. */
#include <stdio.h>

#include "render/scene/scene.h"

bool lr_scene_light_dark(const lr_scene *s, int light, char *why, size_t cap)
{
    if (why && cap)
        why[0] = '\0';
    const lr_light *l = lr_scene_light_at(s, light);
    if (!l)
        return false;
    int k = -1;
    if (lr_scene_light_enclosure(s, light, &k) == LR_ENCLOSURE_SOLID && k >= 0) {
        const lr_scene_object *o = lr_scene_object_at(s, k);
        if (why && cap)
            snprintf(why, cap,
                     "lights[%d] '%s' at (%g, %g, %g) is inside the material of objects[%d] "
                     "'%s' (%s)",
                     light, l->name, l->position.x, l->position.y, l->position.z, k, o->name,
                     o->material.name);
        return true;
    }
    double rgb[3];
    lr_light_rgb(l, rgb);
    if (!(rgb[0] > 0.0 || rgb[1] > 0.0 || rgb[2] > 0.0)) {
        /* The file's name of the dimmer: `radiance` for directional and area lights. */
        const char *field = l->type == LR_LIGHT_POINT || l->type == LR_LIGHT_SPOT ? "intensity"
                                                                                  : "radiance";
        if (why && cap)
            snprintf(why, cap, "lights[%d] '%s' has zero power (%s %g, color %g, %g, %g)", light,
                     l->name, field, l->intensity, l->color[0], l->color[1], l->color[2]);
        return true;
    }
    return false;
}

bool lr_scene_dark(const lr_scene *s, char *why, size_t cap)
{
    int n = lr_scene_light_count(s);
    size_t used = 0;
    if (why && cap)
        why[0] = '\0';
    for (int i = 0; i < n; i++) {
        char one[LR_ERR_MSG_MAX];
        if (!lr_scene_light_dark(s, i, one, sizeof one))
            return false;
        if (why && used < cap) {
            int w = snprintf(why + used, cap - used, "%s%s", i ? "; " : "", one);
            used += w > 0 ? (size_t)w : 0;
        }
    }
    return n > 0;
}
