/* Reference scene files: analytic shapes, media, receivers, lights, camera and render settings
 * in one JSON document (format in render/reference/README.md, "Scene files"). Errors name
 * file:line:field. */
#include "render/reference/ref_priv.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
#include "render/base/mat4.h"
#include "render/material/material.h"
#include "render/mesh/mesh_io.h"
#include "render/mesh/shapes.h"

#define MAX_MEDIA 64

typedef struct loader {
    const lr_json *j;
    lr_ref_scene *s;
    char names[MAX_MEDIA][LR_REF_NAME_MAX];
    int ids[MAX_MEDIA];
    int n;
} loader;

static int vec(const lr_json *j, lr_jnode o, const char *key, bool req, lr_vec3 *v, lr_err *e)
{
    double a[3] = {v->x, v->y, v->z};
    int rc = lr_json_get_numbers(j, o, key, req, a, 3, e);
    if (!rc)
        *v = lr_v3(a[0], a[1], a[2]);
    return rc;
}

static int load_media(loader *L, lr_jnode arr, lr_err *e)
{
    static const char *const keys[] = {"name", "material", "sigma_a", "sigma_s",
                                       "sigma_s_prime", "g", "eta", NULL};
    const lr_json *j = L->j;
    if (lr_json_type(j, arr) != LR_JSON_ARRAY)
        return lr_json_fail(j, arr, "media", e, LR_EPARSE, "expected an array");
    int n = lr_json_count(j, arr);
    if (n > MAX_MEDIA - 1)
        return lr_json_fail(j, arr, "media", e, LR_EPARSE, "at most %d media", MAX_MEDIA - 1);
    for (int i = 0; i < n; i++) {
        lr_jnode o = lr_json_at(j, arr, i);
        char where[32];
        snprintf(where, sizeof where, "media[%d]", i);
        int rc = lr_json_check_keys(j, o, where, keys, e);
        lr_ref_medium_desc md = {0};
        char *name = L->names[L->n];
        if (!rc)
            rc = lr_json_get_string(j, o, "name", true, name, LR_REF_NAME_MAX, e);
        for (int k = 0; k < L->n && !rc; k++)
            if (!strcmp(L->names[k], name))
                rc = lr_json_fail(j, o, "name", e, LR_EPARSE, "medium '%s' defined twice", name);
        lr_jnode mat = lr_json_get(j, o, "material");
        if (!rc && mat != LR_JNONE) {
            /* A preset of configs/materials (render/material), or coefficients below. */
            char preset[LR_MATERIAL_NAME_MAX];
            lr_material m;
            if (!(rc = lr_json_string(j, mat, "material", preset, sizeof preset, e)) &&
                !(rc = lr_material_find(preset, &m, e)))
                lr_ref_medium_from_optics(&m.medium, &md);
            if (!rc && (lr_json_get(j, o, "sigma_a") != LR_JNONE ||
                        lr_json_get(j, o, "sigma_s") != LR_JNONE ||
                        lr_json_get(j, o, "sigma_s_prime") != LR_JNONE))
                rc = lr_json_fail(j, o, where, e, LR_EPARSE,
                                  "give either 'material' or the coefficients");
        } else {
            if (!rc)
                rc = lr_json_get_numbers(j, o, "sigma_a", true, md.sigma_a, 3, e);
            if (!rc)
                rc = lr_json_get_number(j, o, "g", false, &md.g, e);
            if (!rc)
                rc = lr_json_get_number(j, o, "eta", false, &md.eta, e);
            lr_jnode ss = lr_json_get(j, o, "sigma_s"), sp = lr_json_get(j, o, "sigma_s_prime");
            if (!rc && (ss == LR_JNONE) == (sp == LR_JNONE))
                rc = lr_json_fail(j, o, where, e, LR_EPARSE,
                                  "give exactly one of sigma_s and sigma_s_prime");
            if (!rc && ss != LR_JNONE)
                rc = lr_json_numbers(j, ss, "sigma_s", md.sigma_s, 3, e);
            if (!rc && sp != LR_JNONE) {
                rc = lr_json_numbers(j, sp, "sigma_s_prime", md.sigma_s, 3, e);
                /* sigma_s' = sigma_s (1 - g) (similarity relation; render/optics convention) */
                for (int b = 0; b < 3 && !rc; b++)
                    md.sigma_s[b] /= 1.0 - md.g;
            }
        }
        md.name = name;
        if (!rc && (rc = lr_ref_scene_add_medium(L->s, &md, &L->ids[L->n], e)))
            lr_err_prefix(e, "%s:%d", lr_json_name(j), lr_json_line(j, o));
        if (rc)
            return rc;
        L->n++;
    }
    return LR_OK;
}

static int medium_id(const loader *L, lr_jnode o, const char *key, int *id, lr_err *e)
{
    char name[LR_REF_NAME_MAX] = "ambient";
    int rc = lr_json_get_string(L->j, o, key, false, name, sizeof name, e);
    if (rc)
        return rc;
    for (int k = 0; k < L->n; k++)
        if (!strcmp(L->names[k], name)) {
            *id = L->ids[k];
            return LR_OK;
        }
    return lr_json_fail(L->j, lr_json_get(L->j, o, key), key, e, LR_EPARSE,
                        "no medium named '%s'", name);
}

/* Meshes: a file (relative to the scene file) or the procedural candle and shade of
 * render/mesh, moved by an optional "offset". */
static int load_mesh(const lr_json *j, lr_jnode o, const char *kind, lr_ref_shape **shape,
                     lr_err *e)
{
    lr_mesh *m = NULL;
    int rc;
    if (!strcmp(kind, "mesh")) {
        char file[1024], path[2048];
        if ((rc = lr_json_get_string(j, o, "file", true, file, sizeof file, e)))
            return rc;
        const char *scene = lr_json_name(j), *slash = strrchr(scene, '/');
        if (file[0] == '/' || !slash)
            snprintf(path, sizeof path, "%s", file);
        else
            snprintf(path, sizeof path, "%.*s/%s", (int)(slash - scene), scene, file);
        rc = lr_mesh_load(path, NULL, &m, e);
    } else if (!strcmp(kind, "candle")) {
        lr_candle_desc d = {0};
        if (!(rc = lr_json_get_number(j, o, "radius", false, &d.radius, e)) &&
            !(rc = lr_json_get_number(j, o, "height", false, &d.height, e)) &&
            !(rc = lr_json_get_number(j, o, "pool_depth", false, &d.pool_depth, e)) &&
            !(rc = lr_json_get_number(j, o, "pool_radius", false, &d.pool_radius, e)) &&
            !(rc = lr_json_get_bool(j, o, "flat_top", false, &d.flat_top, e)))
            rc = lr_mesh_candle(&d, &m, e);
    } else {
        lr_shade_desc d = {0};
        if (!(rc = lr_json_get_number(j, o, "radius_bottom", false, &d.radius_bottom, e)) &&
            !(rc = lr_json_get_number(j, o, "radius_top", false, &d.radius_top, e)) &&
            !(rc = lr_json_get_number(j, o, "height", false, &d.height, e)) &&
            !(rc = lr_json_get_number(j, o, "thickness", false, &d.thickness, e)))
            rc = lr_mesh_shade(&d, &m, e);
    }
    lr_vec3 off = {0, 0, 0};
    if (!rc)
        rc = vec(j, o, "offset", false, &off, e);
    if (!rc && lr_v3_len(off) > 0.0) {
        double t[16];
        lr_mesh *moved;
        lr_mat4_translate(off, t);
        if (!(rc = lr_mesh_transform(m, t, &moved, e))) {
            lr_mesh_destroy(m);
            m = moved;
        }
    }
    if (rc) {
        lr_mesh_destroy(m);
        return rc;
    }
    return lr_ref_mesh_create(m, true, shape, e);
}

/* The shape of an object or an area light; *shape NULL when kind names no geometry. */
static int load_shape(const lr_json *j, lr_jnode o, const char *kind, lr_ref_shape **shape,
                      lr_err *e)
{
    *shape = NULL;
    lr_vec3 a = {0}, b = {0}, c = {0};
    double r = 0.0, top = 0.0, th = INFINITY;
    int rc;
    if (!strcmp(kind, "mesh") || !strcmp(kind, "candle") || !strcmp(kind, "shade")) {
        rc = load_mesh(j, o, kind, shape, e);
    } else if (!strcmp(kind, "sphere")) {
        if (!(rc = vec(j, o, "center", true, &a, e)) &&
            !(rc = lr_json_get_number(j, o, "radius", true, &r, e)))
            rc = lr_ref_sphere_create(a, r, shape, e);
    } else if (!strcmp(kind, "slab")) {
        if (!(rc = lr_json_get_number(j, o, "top", true, &top, e)) &&
            !(rc = lr_json_get_number(j, o, "thickness", false, &th, e)))
            rc = lr_ref_slab_create(top, th, shape, e);
    } else if (!strcmp(kind, "quad")) {
        if (!(rc = vec(j, o, "corner", true, &a, e)) && !(rc = vec(j, o, "edge1", true, &b, e)) &&
            !(rc = vec(j, o, "edge2", true, &c, e)))
            rc = lr_ref_quad_create(a, b, c, shape, e);
    } else if (!strcmp(kind, "disk")) {
        if (!(rc = vec(j, o, "center", true, &a, e)) && !(rc = vec(j, o, "normal", true, &b, e)) &&
            !(rc = lr_json_get_number(j, o, "radius", true, &r, e)))
            rc = lr_ref_disk_create(a, b, r, shape, e);
    } else {
        return LR_OK;
    }
    if (rc && rc != LR_EPARSE)
        lr_err_prefix(e, "%s:%d", lr_json_name(j), lr_json_line(j, o));
    return rc;
}

static int load_objects(loader *L, lr_jnode arr, lr_err *e)
{
    static const char *const keys[] = {"name", "shape", "center", "radius", "top", "thickness",
                                       "corner", "edge1", "edge2", "normal", "inside",
                                       "outside", "albedo", "file", "offset", "height",
                                       "pool_depth", "pool_radius", "flat_top",
                                       "radius_bottom", "radius_top", NULL};
    const lr_json *j = L->j;
    if (lr_json_type(j, arr) != LR_JSON_ARRAY)
        return lr_json_fail(j, arr, "objects", e, LR_EPARSE, "expected an array");
    for (int i = 0; i < lr_json_count(j, arr); i++) {
        lr_jnode o = lr_json_at(j, arr, i);
        char where[32], kind[16] = "", name[LR_REF_NAME_MAX] = "";
        snprintf(where, sizeof where, "objects[%d]", i);
        int rc = lr_json_check_keys(j, o, where, keys, e);
        if (!rc)
            rc = lr_json_get_string(j, o, "name", false, name, sizeof name, e);
        if (!rc)
            rc = lr_json_get_string(j, o, "shape", true, kind, sizeof kind, e);
        lr_ref_object_desc od = {.name = name};
        if (!rc && !(rc = load_shape(j, o, kind, &od.shape, e)) && !od.shape)
            rc = lr_json_fail(j, lr_json_get(j, o, "shape"), "shape", e, LR_EPARSE,
                              "'%s': expected sphere, slab, quad, disk, mesh, candle or shade",
                              kind);
        if (!rc) {
            bool boundary = lr_json_get(j, o, "inside") != LR_JNONE;
            bool receiver = lr_json_get(j, o, "albedo") != LR_JNONE;
            if (boundary == receiver)
                rc = lr_json_fail(j, o, where, e, LR_EPARSE,
                                  "give 'inside' (a medium boundary) or 'albedo' (a receiver)");
            else if (boundary) {
                od.kind = LR_REF_BOUNDARY;
                if (!(rc = medium_id(L, o, "inside", &od.inside, e)))
                    rc = medium_id(L, o, "outside", &od.outside, e);
            } else {
                od.kind = LR_REF_RECEIVER;
                rc = lr_json_get_numbers(j, o, "albedo", true, od.albedo, 3, e);
            }
        }
        if (rc) {
            lr_ref_shape_destroy(od.shape);
            return rc;
        }
        if ((rc = lr_ref_scene_add_object(L->s, &od, e)))
            return lr_err_prefix(e, "%s:%d", lr_json_name(j), lr_json_line(j, o));
    }
    return LR_OK;
}

static int load_lights(loader *L, lr_jnode arr, lr_err *e)
{
    static const char *const keys[] = {"type", "position", "direction", "inner_deg",
                                       "outer_deg", "intensity", "corner", "edge1", "edge2",
                                       "center", "normal", "radius", "radiance", NULL};
    const lr_json *j = L->j;
    if (lr_json_type(j, arr) != LR_JSON_ARRAY)
        return lr_json_fail(j, arr, "lights", e, LR_EPARSE, "expected an array");
    for (int i = 0; i < lr_json_count(j, arr); i++) {
        lr_jnode o = lr_json_at(j, arr, i);
        char where[32], type[16] = "";
        snprintf(where, sizeof where, "lights[%d]", i);
        lr_ref_light_desc ld = {0};
        int rc = lr_json_check_keys(j, o, where, keys, e);
        if (!rc)
            rc = lr_json_get_string(j, o, "type", true, type, sizeof type, e);
        if (rc)
            return rc;
        if (!strcmp(type, "point") || !strcmp(type, "spot")) {
            ld.kind = type[0] == 'p' ? LR_REF_LIGHT_POINT : LR_REF_LIGHT_SPOT;
            if (!(rc = vec(j, o, "position", true, &ld.position, e)) &&
                !(rc = lr_json_get_numbers(j, o, "intensity", true, ld.emission, 3, e)) &&
                ld.kind == LR_REF_LIGHT_SPOT &&
                !(rc = vec(j, o, "direction", true, &ld.direction, e)) &&
                !(rc = lr_json_get_number(j, o, "inner_deg", false, &ld.inner_deg, e)))
                rc = lr_json_get_number(j, o, "outer_deg", false, &ld.outer_deg, e);
        } else if (!strcmp(type, "quad")) {
            ld.kind = LR_REF_LIGHT_QUAD;
            if (!(rc = vec(j, o, "corner", true, &ld.position, e)) &&
                !(rc = vec(j, o, "edge1", true, &ld.edge1, e)) &&
                !(rc = vec(j, o, "edge2", true, &ld.edge2, e)))
                rc = lr_json_get_numbers(j, o, "radiance", true, ld.emission, 3, e);
        } else if (!strcmp(type, "disk")) {
            ld.kind = LR_REF_LIGHT_DISK;
            if (!(rc = vec(j, o, "center", true, &ld.position, e)) &&
                !(rc = vec(j, o, "normal", true, &ld.direction, e)) &&
                !(rc = lr_json_get_number(j, o, "radius", true, &ld.radius, e)))
                rc = lr_json_get_numbers(j, o, "radiance", true, ld.emission, 3, e);
        } else {
            return lr_json_fail(j, lr_json_get(j, o, "type"), "type", e, LR_EPARSE,
                                "'%s': expected point, spot, quad or disk", type);
        }
        if (rc)
            return rc;
        if ((rc = lr_ref_scene_add_light(L->s, &ld, e)))
            return lr_err_prefix(e, "%s:%d", lr_json_name(j), lr_json_line(j, o));
    }
    return LR_OK;
}

static int load_view(const lr_json *j, lr_jnode root, lr_ref_camera *cam, lr_ref_render_desc *d,
                     lr_err *e)
{
    static const char *const ckeys[] = {"position", "look_at", "up", "fov_deg", NULL};
    static const char *const rkeys[] = {"width", "height", "spp", "spp_per_pass", "seed", NULL};
    lr_jnode c = lr_json_get(j, root, "camera"), r = lr_json_get(j, root, "render");
    int rc = LR_OK;
    if (c != LR_JNONE) {
        if (!(rc = lr_json_check_keys(j, c, "camera", ckeys, e)) &&
            !(rc = vec(j, c, "position", true, &cam->position, e)) &&
            !(rc = vec(j, c, "look_at", true, &cam->look_at, e)) &&
            !(rc = vec(j, c, "up", false, &cam->up, e)))
            rc = lr_json_get_number(j, c, "fov_deg", false, &cam->fov_y_deg, e);
    }
    if (!rc && r != LR_JNONE) {
        long w = d->width, h = d->height, spp = d->spp, pass = d->spp_per_pass;
        long seed = (long)d->seed;
        if (!(rc = lr_json_check_keys(j, r, "render", rkeys, e)) &&
            !(rc = lr_json_get_int(j, r, "width", false, &w, e)) &&
            !(rc = lr_json_get_int(j, r, "height", false, &h, e)) &&
            !(rc = lr_json_get_int(j, r, "spp", false, &spp, e)) &&
            !(rc = lr_json_get_int(j, r, "spp_per_pass", false, &pass, e)))
            rc = lr_json_get_int(j, r, "seed", false, &seed, e);
        if (!rc && (w < 0 || w > 16384 || h < 0 || h > 16384 || spp < 0 || spp > 1L << 30 ||
                    pass < 0 || pass > 1L << 30 || seed < 0))
            rc = lr_json_fail(j, r, "render", e, LR_EPARSE,
                              "width/height 0..16384, spp and spp_per_pass >= 0, seed >= 0");
        if (!rc) {
            d->width = (int)w;
            d->height = (int)h;
            d->spp = (int)spp;
            d->spp_per_pass = (int)pass;
            d->seed = (uint64_t)seed;
        }
    }
    return rc;
}

int lr_ref_scene_load(const char *path, lr_ref_scene **out, lr_ref_camera *cam,
                      lr_ref_render_desc *d, lr_err *e)
{
    static const char *const keys[] = {"ambient_eta", "media", "objects", "lights", "camera",
                                       "render", NULL};
    *out = NULL;
    lr_json *j;
    int rc = lr_json_load(path, &j, e);
    if (rc)
        return rc;
    lr_jnode root = lr_json_root(j);
    loader *L = calloc(1, sizeof *L);
    lr_ref_scene_desc sd = {0};
    if (!L)
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    if (!rc && lr_json_type(j, root) != LR_JSON_OBJECT)
        rc = lr_json_fail(j, root, "(root)", e, LR_EPARSE, "expected an object");
    if (!rc)
        rc = lr_json_check_keys(j, root, "scene", keys, e);
    if (!rc)
        rc = lr_json_get_number(j, root, "ambient_eta", false, &sd.ambient_eta, e);
    if (!rc)
        rc = lr_ref_scene_create(&sd, &L->s, e);
    if (!rc) {
        L->j = j;
        snprintf(L->names[0], LR_REF_NAME_MAX, "ambient");
        L->ids[0] = 0;
        L->n = 1;
        lr_jnode n;
        if ((n = lr_json_get(j, root, "media")) != LR_JNONE)
            rc = load_media(L, n, e);
        if (!rc && (n = lr_json_get(j, root, "objects")) != LR_JNONE)
            rc = load_objects(L, n, e);
        if (!rc && (n = lr_json_get(j, root, "lights")) != LR_JNONE)
            rc = load_lights(L, n, e);
    }
    if (!rc)
        rc = load_view(j, root, cam, d, e);
    if (!rc && (rc = lr_ref_scene_finish(L->s, e)))
        lr_err_prefix(e, "%s", path);
    if (!rc)
        *out = L->s;
    else if (L)
        lr_ref_scene_destroy(L->s);
    free(L);
    lr_json_destroy(j);
    return rc;
}
