/* Range checks of scene records, shared by the file loader and lr_scene_set so that a value
 * is accepted or refused the same way wherever it comes from. */
#include <math.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/scene/scene_internal.h"

/* Coordinates beyond a kilometre are a typo (mm), and keep float positions meaningful. */
#define MAX_COORD 1e6

static int bad(const char **field, const char *name, lr_err *e, const char *msg)
{
    *field = name;
    return lr_err_set(e, LR_EINVAL, "%s", msg);
}

static bool coord_ok(lr_vec3 v)
{
    return lr_v3_isfinite(v) && fabs(v.x) <= MAX_COORD && fabs(v.y) <= MAX_COORD &&
           fabs(v.z) <= MAX_COORD;
}

/* Normalises a direction; false when it has no length. */
static bool unit(lr_vec3 *d)
{
    double l = lr_v3_len(*d);
    if (!lr_v3_isfinite(*d) || !(l > 0.0) || !isfinite(l))
        return false;
    *d = lr_v3_scale(*d, 1.0 / l);
    return true;
}

void lr_scene_light_defaults(lr_light *l, enum lr_light_type type)
{
    memset(l, 0, sizeof *l);
    l->type = type;
    l->direction = lr_v3(0, 0, -1);
    l->inner_deg = 20.0;
    l->outer_deg = 30.0;
    l->color[0] = l->color[1] = l->color[2] = 1.0;
    l->flicker.frequency_hz = 8.0; /* candle flames flicker at a few Hz to ~10 Hz */
    l->flicker.seed = 1;
}

int lr_scene_check_light(lr_light *l, const char **field, lr_err *e)
{
    if (l->type != LR_LIGHT_DIRECTIONAL && !coord_ok(l->position))
        return bad(field, "position", e, "must be finite and within 1e6 mm of the origin");
    if (l->type != LR_LIGHT_POINT && !unit(&l->direction))
        return bad(field, "direction", e, "must be a non-zero vector");
    const char *strength = l->type == LR_LIGHT_DIRECTIONAL ? "radiance" : "intensity";
    if (!(isfinite(l->intensity) && l->intensity >= 0.0 && l->intensity < 1e12)) {
        *field = strength;
        return lr_err_set(e, LR_EINVAL, "must be >= 0 (%s), got %g",
                          l->type == LR_LIGHT_DIRECTIONAL ? "W/mm^2" : "W/sr", l->intensity);
    }
    for (int b = 0; b < 3; b++)
        if (!(isfinite(l->color[b]) && l->color[b] >= 0.0 && l->color[b] < 1e6)) {
            *field = "color";
            return lr_err_set(e, LR_EINVAL, "each band must be >= 0, got %g", l->color[b]);
        }
    if (l->type == LR_LIGHT_SPOT) {
        if (!(l->outer_deg > 0.0 && l->outer_deg < 90.0)) {
            *field = "outer_deg";
            return lr_err_set(e, LR_EINVAL, "must be in (0, 90) degrees, got %g", l->outer_deg);
        }
        if (!(l->inner_deg > 0.0 && l->inner_deg <= l->outer_deg)) {
            *field = "inner_deg";
            return lr_err_set(e, LR_EINVAL, "must be in (0, outer_deg = %g] degrees, got %g",
                              l->outer_deg, l->inner_deg);
        }
    }
    const lr_flicker *f = &l->flicker;
    if (!(f->amplitude >= 0.0 && f->amplitude <= 1.0)) {
        *field = "flicker.amplitude";
        return lr_err_set(e, LR_EINVAL, "must be in [0, 1], got %g", f->amplitude);
    }
    if (!(f->frequency_hz > 0.0 && f->frequency_hz <= 1000.0)) {
        *field = "flicker.frequency_hz";
        return lr_err_set(e, LR_EINVAL, "must be in (0, 1000] Hz, got %g", f->frequency_hz);
    }
    if (!(f->jitter_mm >= 0.0 && f->jitter_mm <= 1000.0)) {
        *field = "flicker.jitter_mm";
        return lr_err_set(e, LR_EINVAL, "must be in [0, 1000] mm, got %g", f->jitter_mm);
    }
    return LR_OK;
}

void lr_scene_camera_defaults(lr_camera *c)
{
    memset(c, 0, sizeof *c);
    c->position = lr_v3(0, -600, 300);
    c->target = lr_v3(0, 0, 60);
    c->up = lr_v3(0, 0, 1);
    c->fov_deg = 40.0;
    c->height_mm = 300.0;
    c->near_mm = 10.0;
    c->far_mm = 10000.0;
}

int lr_scene_check_camera(lr_camera *c, const char **field, lr_err *e)
{
    if (!coord_ok(c->position))
        return bad(field, "position", e, "must be finite and within 1e6 mm of the origin");
    if (!coord_ok(c->target))
        return bad(field, "target", e, "must be finite and within 1e6 mm of the origin");
    if (!unit(&c->up))
        return bad(field, "up", e, "must be a non-zero vector");
    lr_vec3 f = lr_v3_sub(c->target, c->position);
    if (!(lr_v3_len(f) > 1e-6))
        return bad(field, "target", e, "must differ from position");
    double m[16];
    if (lr_mat4_look_at(c->position, c->target, c->up, m) != 0)
        return bad(field, "up", e, "must not be parallel to the view direction");
    if (!c->orthographic && !(c->fov_deg > 0.0 && c->fov_deg < 180.0)) {
        *field = "fov_deg";
        return lr_err_set(e, LR_EINVAL, "must be in (0, 180) degrees, got %g", c->fov_deg);
    }
    if (c->orthographic && !(c->height_mm > 0.0 && c->height_mm <= 2 * MAX_COORD)) {
        *field = "height_mm";
        return lr_err_set(e, LR_EINVAL, "must be > 0 mm, got %g", c->height_mm);
    }
    if (!(c->near_mm > 0.0 && c->near_mm < 1e7)) {
        *field = "near";
        return lr_err_set(e, LR_EINVAL, "must be > 0 mm, got %g", c->near_mm);
    }
    if (!(c->far_mm > c->near_mm && c->far_mm <= 1e7)) {
        *field = "far";
        return lr_err_set(e, LR_EINVAL, "must be > near (%g mm) and <= 1e7 mm, got %g",
                          c->near_mm, c->far_mm);
    }
    return LR_OK;
}

int lr_scene_check_receiver(lr_receiver *r, const char **field, lr_err *e)
{
    for (int b = 0; b < 3; b++)
        if (!(r->albedo[b] >= 0.0 && r->albedo[b] <= 1.0)) {
            *field = "albedo";
            return lr_err_set(e, LR_EINVAL,
                              "each band must be in [0, 1] (a diffuse surface reflects at most "
                              "what it receives), got %g",
                              r->albedo[b]);
        }
    if (r->type == LR_RECEIVER_PLANE) {
        lr_quad_desc q = {.center = r->center, .normal = r->normal, .u_dir = r->u_dir,
                          .size_u = r->size[0], .size_v = r->size[1],
                          .subdivisions = r->subdivisions}, res;
        if (!(r->size[0] > 0.0) || !(r->size[1] > 0.0)) {
            *field = "size";
            return lr_err_set(e, LR_EINVAL, "must be > 0 mm, got %g x %g", r->size[0],
                              r->size[1]);
        }
        if (lr_v3_len(r->normal) == 0.0 || !lr_v3_isfinite(r->normal))
            return bad(field, "normal", e, "must be a non-zero vector");
        int rc = lr_quad_check(&q, &res, field, e);
        if (rc)
            return rc;
        r->normal = res.normal;
        r->u_dir = res.u_dir;
        r->subdivisions = res.subdivisions;
        r->size[2] = 0.0;
        return LR_OK;
    }
    lr_box_desc b = {.center = r->center, .size = lr_v3(r->size[0], r->size[1], r->size[2])}, res;
    if (!(r->size[0] > 0.0 && r->size[1] > 0.0 && r->size[2] > 0.0)) {
        *field = "size";
        return lr_err_set(e, LR_EINVAL, "each side must be > 0 mm, got %g, %g, %g", r->size[0],
                          r->size[1], r->size[2]);
    }
    return lr_box_check(&b, &res, field, e);
}

void lr_scene_render_defaults(lr_render_settings *r)
{
    /* Seed 003 renders with 31 maps of 512^2 on a desktop GPU; a Raspberry-Pi-class GPU gets
     * half the maps at a quarter of the texels by default. */
    r->K = 16;
    r->N = 16;
    r->N_vpl = 64;
    r->map_size = 256;
    r->gbuffer_size = 256;
    r->vpl_map_size = 64;
    r->frames = 64;
    r->exposure = 1.0;
}

static int range_int(const char **field, const char *name, int v, int lo, int hi, lr_err *e)
{
    if (v >= lo && v <= hi)
        return LR_OK;
    *field = name;
    return lr_err_set(e, LR_EINVAL, "must be between %d and %d, got %d", lo, hi, v);
}

int lr_scene_check_render(lr_render_settings *r, const char **field, lr_err *e)
{
    int rc;
    /* 256: GL_MAX_ARRAY_TEXTURE_LAYERS is at least 256 on GLES 3.x; 8192: the largest
     * texture an SBC GPU offers. */
    if ((rc = range_int(field, "K", r->K, 1, 256, e)) ||
        (rc = range_int(field, "N", r->N, 1, 65536, e)) ||
        (rc = range_int(field, "N_vpl", r->N_vpl, 1, 65536, e)) ||
        (rc = range_int(field, "map_size", r->map_size, 8, 8192, e)) ||
        (rc = range_int(field, "gbuffer_size", r->gbuffer_size, 8, 8192, e)) ||
        (rc = range_int(field, "vpl_map_size", r->vpl_map_size, 4, 4096, e)) ||
        (rc = range_int(field, "frames", r->frames, 1, 10000000, e)))
        return rc;
    if (!(r->exposure > 0.0 && isfinite(r->exposure) && r->exposure < 1e30)) {
        *field = "exposure";
        return lr_err_set(e, LR_EINVAL, "must be > 0, got %g", r->exposure);
    }
    return LR_OK;
}

int lr_scene_check_quality(const lr_quality *q, const char **field, lr_err *e)
{
    if (!(q->max_error >= 0.0 && q->max_error < 1e6)) {
        *field = "max_error";
        return lr_err_set(e, LR_EINVAL, "must be >= 0 (0: no budget), got %g", q->max_error);
    }
    if (!(q->frame_ms >= 0.0 && q->frame_ms < 1e9)) {
        *field = "frame_ms";
        return lr_err_set(e, LR_EINVAL, "must be >= 0 ms (0: no budget), got %g", q->frame_ms);
    }
    return LR_OK;
}

int lr_scene_check_transform(const xform_spec *x, const char **field, lr_err *e)
{
    if (!coord_ok(x->translate))
        return bad(field, "transform.translate", e,
                   "must be finite and within 1e6 mm of the origin");
    if (!coord_ok(x->rotate_deg))
        return bad(field, "transform.rotate_deg", e, "must be finite");
    const double s[3] = {x->scale.x, x->scale.y, x->scale.z};
    for (int i = 0; i < 3; i++)
        if (!(s[i] > 0.0 && s[i] < 1e6)) {
            *field = "transform.scale";
            return lr_err_set(e, LR_EINVAL, "must be > 0 (no mirroring) and < 1e6, got %g",
                              s[i]);
        }
    return LR_OK;
}

int lr_scene_check_mesh(const mesh_spec *m, const char **field, lr_err *e)
{
    const char *f = NULL;
    int rc = LR_OK;
    switch (m->kind) {
    case LR_MESH_CANDLE: {
        lr_candle_desc r;
        rc = lr_candle_check(&m->candle, &r, &f, e);
        break;
    }
    case LR_MESH_SHADE: {
        lr_shade_desc r;
        rc = lr_shade_check(&m->shade, &r, &f, e);
        break;
    }
    case LR_MESH_SPHERE: {
        lr_sphere_desc r;
        rc = lr_sphere_check(&m->sphere, &r, &f, e);
        break;
    }
    case LR_MESH_BOX: {
        lr_box_desc r;
        rc = lr_box_check(&m->box, &r, &f, e);
        break;
    }
    case LR_MESH_FILE:
        if (!m->path[0]) {
            f = "path";
            rc = lr_err_set(e, LR_EINVAL, "must not be empty");
        } else if (!(m->file_scale > 0.0 && m->file_scale < 1e6)) {
            f = "scale";
            rc = lr_err_set(e, LR_EINVAL, "must be > 0, got %g", m->file_scale);
        }
        break;
    }
    /* The generators' field names are the file's ("pool_depth" in "mesh"). */
    *field = f;
    return rc;
}
