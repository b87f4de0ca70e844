/* From specs to what the passes use: world-space meshes with their BVHs, resolved materials. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
#include "render/base/mat4.h"
#include "render/mesh/mesh_io.h"
#include "render/mesh/refine.h"
#include "render/mesh/wall.h"
#include "render/scene/scene_internal.h"

int lr_scene_resolve_path(const lr_scene *s, const char *rel, char *out, size_t cap)
{
    int n;
    if (rel[0] == '/' || !s->dir[0])
        n = snprintf(out, cap, "%s", rel);
    else
        n = snprintf(out, cap, "%s/%s", s->dir, rel);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}

/* Warnings of a mesh built for a scene carry the scene and the object they belong to. */
typedef struct prefixed {
    const lr_warn_sink *inner;
    const char *prefix;
} prefixed;

static void prefixed_warn(void *user, const char *msg)
{
    const prefixed *p = user;
    lr_warn(p->inner, "%s: %s", p->prefix, msg);
}

/* The renderer's copy of the surface (scene_internal.h, LR_SCENE_MAX_EDGE_MM): `built` itself
 * when no edge is longer, else its midpoint refinement (render/mesh/refine.h), which keeps
 * the surface and the linearly interpolated normal field. `built` was checked and repaired
 * already, so the copy is taken as it is (its winding, open edges, no warnings). */
static int refine_for_renderer(lr_mesh *built, lr_mesh **out, lr_err *e)
{
    *out = built;
    if (lr_mesh_longest_edge(built) <= LR_SCENE_MAX_EDGE_MM)
        return LR_OK;
    lr_refined r;
    int rc = lr_refine(built, LR_SCENE_MAX_EDGE_MM, LR_SCENE_REFINED_MAX_VERTICES, &r, e);
    if (rc)
        return rc;
    double *pos = malloc(r.nv * 3 * sizeof *pos), *nrm = malloc(r.nv * 3 * sizeof *nrm);
    if (!pos || !nrm) {
        rc = lr_err_set(e, LR_ENOMEM, "mesh %s: out of memory", lr_mesh_name(built));
    } else {
        for (size_t i = 0; i < 3 * r.nv; i++) {
            pos[i] = r.pos[i];
            nrm[i] = r.nrm[i];
        }
        lr_mesh_desc d = {.name = lr_mesh_name(built), .vertex_count = r.nv, .positions = pos,
                          .normals = nrm, .triangle_count = r.nt, .indices = r.idx,
                          .checks = {.flags = LR_MESH_OPEN_OK | LR_MESH_KEEP_WINDING}};
        rc = lr_mesh_create(&d, out, e);
        if (rc)
            *out = built;
    }
    free(pos);
    free(nrm);
    lr_refined_free(&r);
    return rc;
}

void lr_scene_object_meshes_destroy(lr_mesh *world, lr_mesh *built)
{
    if (world != built)
        lr_mesh_destroy(world);
    lr_mesh_destroy(built);
}

int lr_scene_build_object(const lr_scene *s, const char *where, const mesh_spec *ms,
                          const xform_spec *xf, lr_mesh **world, lr_mesh **built, lr_bvh **bvh,
                          double model[16], lr_err *e)
{
    *world = *built = NULL;
    *bvh = NULL;
    char prefix[LR_SCENE_PATH_MAX + 80];
    snprintf(prefix, sizeof prefix, "%s: %s", s->path, where);
    prefixed pw = {&s->warn, prefix};
    lr_mesh_checks checks = {.warn = {prefixed_warn, &pw}};
    lr_mesh *local = NULL;
    int rc;
    double pre[16];
    lr_mat4_identity(pre);
    switch (ms->kind) {
    case LR_MESH_CANDLE: {
        lr_candle_desc d = ms->candle;
        d.checks = checks;
        rc = lr_mesh_candle(&d, &local, e);
        break;
    }
    case LR_MESH_SHADE: {
        lr_shade_desc d = ms->shade;
        d.checks = checks;
        rc = lr_mesh_shade(&d, &local, e);
        break;
    }
    case LR_MESH_SPHERE: {
        lr_sphere_desc d = ms->sphere;
        d.checks = checks;
        rc = lr_mesh_sphere(&d, &local, e);
        break;
    }
    case LR_MESH_BOX: {
        lr_box_desc d = ms->box;
        d.checks = checks;
        rc = lr_mesh_box(&d, &local, e);
        break;
    }
    default: {
        char path[LR_SCENE_PATH_MAX];
        if (lr_scene_resolve_path(s, ms->path, path, sizeof path))
            return lr_err_set(e, LR_EINVAL, "%s.mesh.path: too long", where);
        rc = lr_mesh_load(path, &checks, &local, e);
        lr_mat4_scale(lr_v3(ms->file_scale, ms->file_scale, ms->file_scale), pre);
        break;
    }
    }
    if (rc)
        return rc;
    double t[16], r[16], sc[16];
    lr_mat4_translate(xf->translate, t);
    lr_mat4_rotate_xyz_deg(xf->rotate_deg, r);
    lr_mat4_scale(xf->scale, sc);
    lr_mat4_mul(sc, pre, model);
    lr_mat4_mul(r, model, model);
    lr_mat4_mul(t, model, model);
    rc = lr_mesh_transform(local, model, built, e);
    lr_mesh_destroy(local);
    if (rc)
        return rc;
    if ((rc = refine_for_renderer(*built, world, e)) || (rc = lr_bvh_create(*world, bvh, e))) {
        lr_scene_object_meshes_destroy(*world, *built);
        *world = *built = NULL;
    }
    return rc;
}

void lr_scene_object_attach(lr_scene_object *pub, const lr_mesh *world, const lr_mesh *built,
                            const lr_bvh *bvh)
{
    pub->mesh = world;
    pub->built_mesh = built;
    pub->bvh = bvh;
    lr_mesh_bounding_sphere(world, &pub->center, &pub->radius);
    pub->area = lr_mesh_area(world);
    lr_mesh_report rep;
    lr_mesh_analyze(world, &rep);
    pub->closed = rep.closed;
    pub->wall_mm = rep.closed ? lr_mesh_wall_thickness(bvh) : 0.0;
}

int lr_scene_build_receiver(const lr_scene *s, lr_receiver *r, lr_mesh **mesh, lr_bvh **bvh,
                            lr_err *e)
{
    *mesh = NULL;
    *bvh = NULL;
    (void)s;
    int rc;
    if (r->type == LR_RECEIVER_PLANE) {
        lr_quad_desc q = {.center = r->center, .normal = r->normal, .u_dir = r->u_dir,
                          .size_u = r->size[0], .size_v = r->size[1],
                          .subdivisions = r->subdivisions};
        rc = lr_mesh_quad(&q, mesh, e);
    } else {
        lr_box_desc b = {.center = r->center, .size = lr_v3(r->size[0], r->size[1], r->size[2])};
        rc = lr_mesh_box(&b, mesh, e);
    }
    if (rc)
        return rc;
    rc = lr_bvh_create(*mesh, bvh, e);
    if (rc) {
        lr_mesh_destroy(*mesh);
        *mesh = NULL;
    }
    return rc;
}

/* ---- materials ------------------------------------------------------------------------------ */

typedef struct strbuf {
    char *p;
    size_t n, cap;
    bool overflow;
} strbuf;

static void put(strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(strbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
    va_end(ap);
    if (k < 0 || (size_t)k >= b->cap - b->n)
        b->overflow = true;
    else
        b->n += (size_t)k;
}

static void put_string(strbuf *b, const char *s)
{
    put(b, "\"");
    for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
        if (*c == '"' || *c == '\\')
            put(b, "\\%c", *c);
        else if (*c < 0x20)
            put(b, "\\u%04x", *c);
        else
            put(b, "%c", *c);
    }
    put(b, "\"");
}

static void put_rgb(strbuf *b, const char *key, const double v[3])
{
    /* %.17g round-trips a double exactly. */
    put(b, ", \"%s\": [%.17g, %.17g, %.17g]", key, v[0], v[1], v[2]);
}

int lr_scene_resolve_material(const mat_spec *ms, const char *where, lr_material *out,
                              lr_err *e)
{
    if (ms->is_preset) {
        int rc = lr_material_find(ms->preset, out, e);
        if (rc)
            lr_err_prefix(e, "no usable preset '%s'", ms->preset);
        return rc;
    }
    char text[4096];
    strbuf b = {text, 0, sizeof text, false};
    put(&b, "{\"name\": ");
    put_string(&b, ms->name);
    put(&b, ", \"source\": ");
    put_string(&b, ms->source);
    if (ms->has_base) {
        put(&b, ", \"base\": ");
        put_string(&b, ms->base);
    }
    if (ms->has_scale)
        put_rgb(&b, "scale", ms->scale);
    if (ms->has_sigma_a)
        put_rgb(&b, "sigma_a", ms->sigma_a);
    if (ms->has_sigma_s_prime)
        put_rgb(&b, "sigma_s_prime", ms->sigma_s_prime);
    if (ms->has_eta)
        put(&b, ", \"eta\": %.17g", ms->eta);
    if (ms->has_g)
        put(&b, ", \"g\": %.17g", ms->g);
    put(&b, "}");
    if (b.overflow)
        return lr_err_set(e, LR_EINVAL, "%s: material too long", where);
    lr_json *j = NULL;
    int rc = lr_json_parse(text, b.n, where, &j, e);
    if (rc)
        return rc;
    rc = lr_material_from_json(j, lr_json_root(j), where, out, e);
    lr_json_destroy(j);
    return rc;
}
