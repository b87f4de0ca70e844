/* Regions of the camera image from the scene's geometry (eval.h, "regions"): which part of an
 * object or of the receivers each pixel's centre ray hits first, so the bench can say where
 * light is lost (issue 12: shell walls, openings, receiver interreflection). */
#include "render/eval/eval.h"

#include <math.h>
#include <stdlib.h>

#include "render/cpu/frame.h"
#include "render/mesh/bvh.h"

/* An object's axis (through its bounding-sphere centre, along up) and radius about it. */
typedef struct axis {
    lr_vec3 c;
    double r;
} axis;

/* Distance of p from the axis through c along the unit vector up. */
static double axial_distance(lr_vec3 p, lr_vec3 c, lr_vec3 up)
{
    lr_vec3 d = lr_v3_sub(p, c);
    return lr_v3_len(lr_v3_sub(d, lr_v3_scale(up, lr_v3_dot(d, up))));
}

/* The hit facet's plane supports the vertex set: no vertex lies beyond it by more than tol.
 * Such a facet is on the convex hull's surface, seen from outside. */
static bool supporting(const lr_mesh *m, size_t tri, double tol)
{
    lr_vec3 p[3];
    lr_mesh_triangle(m, tri, p);
    lr_vec3 n = lr_mesh_triangle_normal(m, tri);
    double h = lr_v3_dot(n, p[0]);
    size_t nv = lr_mesh_vertex_count(m);
    for (size_t v = 0; v < nv; v++)
        if (lr_v3_dot(n, lr_mesh_vertex(m, v)) > h + tol)
            return false;
    return true;
}

const char *lr_eval_region_name(int region)
{
    static const char *const names[LR_EVAL_REGION_COUNT] = {
        "background", "object outer", "object inner", "pool",
        "table near", "table far",    "wall",         "other",
    };
    return region >= 0 && region < LR_EVAL_REGION_COUNT ? names[region] : "?";
}

int lr_eval_regions_create(const lr_scene *s, int width, int height, lr_eval_regions *out,
                           lr_err *e)
{
    *out = (lr_eval_regions){.width = width, .height = height};
    if (width < 1 || height < 1)
        return lr_err_set(e, LR_EINVAL, "regions: bad size %dx%d", width, height);
    const int nobj = lr_scene_object_count(s), nrec = lr_scene_receiver_count(s);
    const lr_vec3 up = lr_v3(0.0, 0.0, 1.0); /* the scenes' convention (and the reference's) */
    out->label = calloc((size_t)width * (size_t)height, 1);
    axis *ax = calloc((size_t)(nobj > 0 ? nobj : 1), sizeof *ax);
    if (!out->label || !ax) {
        free(ax);
        lr_eval_regions_free(out);
        return lr_err_set(e, LR_ENOMEM, "regions: out of memory");
    }
    for (int k = 0; k < nobj; k++) {
        const lr_scene_object *o = lr_scene_object_at(s, k);
        ax[k].c = o->center;
        for (size_t v = 0; v < lr_mesh_vertex_count(o->mesh); v++)
            ax[k].r = fmax(ax[k].r, axial_distance(lr_mesh_vertex(o->mesh, v), o->center, up));
    }
    bool area = false;
    for (int k = 0; k < lr_scene_light_count(s); k++)
        area |= lr_light_is_area(lr_scene_light_at(s, k));
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            lr_vec3 org, dir;
            lr_cpu_camera_ray(s, width, height, x, y, &org, &dir);
            double best = INFINITY;
            int kind = 0, idx = -1; /* kind 0 none, 1 object, 2 receiver */
            size_t tri = 0;
            lr_hit h;
            for (int k = 0; k < nobj; k++)
                if (lr_bvh_intersect(lr_scene_object_at(s, k)->bvh, org, dir, 0.0, best, &h) &&
                    h.t < best)
                    best = h.t, kind = 1, idx = k, tri = h.triangle;
            for (int k = 0; k < nrec; k++)
                if (lr_bvh_intersect(lr_scene_receiver_at(s, k)->bvh, org, dir, 0.0, best, &h) &&
                    h.t < best)
                    best = h.t, kind = 2, idx = k, tri = h.triangle;
            int region = LR_EVAL_REGION_NONE;
            if (kind && area && lr_eval_emitter_in_pixel(s, width, height, x, y))
                kind = 0; /* an area light in front: no region (masks.c) */
            if (kind == 1) {
                const lr_scene_object *o = lr_scene_object_at(s, idx);
                region = supporting(o->mesh, tri, 1e-3 * (ax[idx].r > 0.0 ? ax[idx].r : o->radius))
                             ? LR_EVAL_REGION_OBJ_OUTER
                             : LR_EVAL_REGION_OBJ_INNER;
            } else if (kind == 2) {
                lr_vec3 p = lr_v3_add(org, lr_v3_scale(dir, best));
                double d = INFINITY; /* in radii of the nearest object */
                for (int k = 0; k < nobj; k++)
                    if (ax[k].r > 0.0)
                        d = fmin(d, axial_distance(p, ax[k].c, up) / ax[k].r);
                double nu = lr_v3_dot(lr_mesh_triangle_normal(lr_scene_receiver_at(s, idx)->mesh,
                                                              tri),
                                      up);
                if (d <= LR_EVAL_POOL_R)
                    region = LR_EVAL_REGION_POOL;
                else if (nu >= 0.7)
                    region = d <= LR_EVAL_NEAR_R ? LR_EVAL_REGION_TABLE_NEAR
                                                 : LR_EVAL_REGION_TABLE_FAR;
                else if (fabs(nu) < 0.3)
                    region = LR_EVAL_REGION_WALL;
                else
                    region = LR_EVAL_REGION_OTHER;
            }
            out->label[(size_t)y * (size_t)width + (size_t)x] = (unsigned char)region;
            out->count[region]++;
        }
    free(ax);
    return LR_OK;
}

void lr_eval_regions_free(lr_eval_regions *r)
{
    free(r->label);
    *r = (lr_eval_regions){0};
}

long lr_eval_regions_mask(const lr_eval_regions *r, int region, unsigned char *mask)
{
    long c = 0;
    size_t n = (size_t)r->width * (size_t)r->height;
    for (size_t i = 0; i < n; i++) {
        mask[i] = r->label[i] == region;
        c += mask[i];
    }
    return c;
}
