/* Scene accessors, lifetime, and whether a light is surrounded by an object. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

void lr_scene_destroy(lr_scene *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->nobj; i++) {
        lr_bvh_destroy(s->obj[i].bvh);
        lr_scene_object_meshes_destroy(s->obj[i].world, s->obj[i].built);
    }
    for (int i = 0; i < s->nrecv; i++) {
        lr_bvh_destroy(s->recv[i].bvh);
        lr_mesh_destroy(s->recv[i].mesh);
    }
    free(s->obj);
    free(s->light);
    free(s->recv);
    free(s);
}

const char *lr_scene_name(const lr_scene *s) { return s->name; }
const lr_warn_sink *lr_scene_warn_sink(const lr_scene *s) { return &s->warn; }
const char *lr_scene_path(const lr_scene *s) { return s->path; }
int lr_scene_object_count(const lr_scene *s) { return s->nobj; }
int lr_scene_light_count(const lr_scene *s) { return s->nlight; }
int lr_scene_receiver_count(const lr_scene *s) { return s->nrecv; }
const lr_camera *lr_scene_camera(const lr_scene *s) { return &s->camera; }
const lr_render_settings *lr_scene_render(const lr_scene *s) { return &s->render; }
const lr_quality *lr_scene_quality(const lr_scene *s) { return &s->quality; }

static int render_field_index(const char *name)
{
    for (int i = 0; name && i < lr_scene_render_desc.n; i++)
        if (!strcmp(lr_scene_render_desc.fields[i].key, name))
            return i;
    return -1;
}

void lr_scene_render_mark_given(lr_scene *s, const char *name)
{
    int i = render_field_index(name);
    if (i >= 0 && i < 64)
        s->render_given |= 1ull << i;
}

bool lr_scene_render_given(const lr_scene *s, const char *name)
{
    int i = render_field_index(name);
    return i >= 0 && i < 64 && (s->render_given >> i & 1u);
}

const char *lr_scene_object_model_unmet(const lr_scene_object *o, enum lr_sss_model m)
{
    if ((unsigned)m >= LR_SSS_MODEL_COUNT)
        return "unknown model";
    const lr_sss_model_props *p = lr_sss_model_props_of(m);
    if (p->needs_thickness && !(o->thickness_mm > 0.0))
        return p->needs_thickness;
    if (p->needs_closed && !o->closed)
        return p->needs_closed;
    return NULL;
}

const lr_scene_object *lr_scene_object_at(const lr_scene *s, int i)
{
    return i >= 0 && i < s->nobj ? &s->obj[i].pub : NULL;
}

const lr_light *lr_scene_light_at(const lr_scene *s, int i)
{
    return i >= 0 && i < s->nlight ? &s->light[i] : NULL;
}

const lr_receiver *lr_scene_receiver_at(const lr_scene *s, int i)
{
    return i >= 0 && i < s->nrecv ? &s->recv[i].pub : NULL;
}

int lr_scene_find_object(const lr_scene *s, const char *name)
{
    for (int i = 0; i < s->nobj; i++)
        if (strcmp(s->obj[i].pub.name, name) == 0)
            return i;
    return -1;
}

int lr_scene_find_light(const lr_scene *s, const char *name)
{
    for (int i = 0; i < s->nlight; i++)
        if (strcmp(s->light[i].name, name) == 0)
            return i;
    return -1;
}

int lr_scene_find_receiver(const lr_scene *s, const char *name)
{
    for (int i = 0; i < s->nrecv; i++)
        if (strcmp(s->recv[i].pub.name, name) == 0)
            return i;
    return -1;
}

void lr_scene_bounds(const lr_scene *s, lr_vec3 *center, double *radius)
{
    lr_vec3 lo = lr_v3(INFINITY, INFINITY, INFINITY), hi = lr_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < s->nobj; i++) {
        lr_vec3 a, b;
        lr_mesh_bounds(s->obj[i].world, &a, &b);
        lo = lr_v3(fmin(lo.x, a.x), fmin(lo.y, a.y), fmin(lo.z, a.z));
        hi = lr_v3(fmax(hi.x, b.x), fmax(hi.y, b.y), fmax(hi.z, b.z));
    }
    lr_vec3 c = lr_v3_scale(lr_v3_add(lo, hi), 0.5);
    double r = 0.0;
    for (int i = 0; i < s->nobj; i++) {
        const lr_scene_object *o = &s->obj[i].pub;
        r = fmax(r, lr_v3_len(lr_v3_sub(o->center, c)) + o->radius);
    }
    *center = c;
    *radius = r;
}

enum lr_enclosure lr_scene_light_enclosure(const lr_scene *s, int light, int *object)
{
    if (object)
        *object = -1;
    const lr_light *l = lr_scene_light_at(s, light);
    if (!l || l->type == LR_LIGHT_DIRECTIONAL)
        return LR_ENCLOSURE_NONE;
    enum lr_enclosure best = LR_ENCLOSURE_NONE;
    for (int i = 0; i < s->nobj; i++) {
        const lr_scene_object *o = &s->obj[i].pub;
        /* Cheap rejection: outside the bounding sphere is outside the hull. */
        if (lr_v3_len(lr_v3_sub(l->position, o->center)) > o->radius)
            continue;
        enum lr_enclosure k = LR_ENCLOSURE_NONE;
        /* A winding number of 1/2 separates inside from outside robustly, also for a mesh with
         * small holes (the fraction near a hole is the solid angle it subtends). */
        if (o->closed && lr_mesh_winding_number(o->mesh, l->position) >= 0.5)
            k = LR_ENCLOSURE_SOLID;
        else if (lr_mesh_hull_distance(o->mesh, l->position) <= 1e-9 * o->radius)
            k = LR_ENCLOSURE_HULL;
        if (k > best) {
            best = k;
            if (object)
                *object = i;
        }
    }
    return best;
}
