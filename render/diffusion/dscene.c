/* lamprig — the diffusion_grid objects of a scene, solved per light (dscene.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/paths.h"
#include "render/core/cavity.h"
#include "render/diffusion/bounce.h"
#include "render/diffusion/dscene.h"
#include "render/optics/near_light.h"
#include "render/optics/optics.h"

/* Relative residual of the render solves: B is read to float precision in the maps, and the
 * fair bench's noise floor is far above 1e-5. */
#define LR_DSCENE_TOL 1e-5

typedef struct dobj {
    bool active;
    /* what the grid was built from */
    const lr_mesh *mesh;
    double model[16];
    lr_medium medium;
    double h;
    char volume_path[2048];
    lr_dvolume *volume;
    lr_dsolver *solver;
    float *field[LR_SCENE_MAX_LIGHTS];
    double gain[LR_SCENE_MAX_LIGHTS][3]; /* cavity closure applied to field[l] */
    bool rebuilt;
} dobj;

struct lr_dscene {
    dobj obj[LR_DSCENE_MAX_OBJECTS];
    int iters;
    const lr_cancel *cancel;
};

void lr_dscene_set_cancel(lr_dscene *d, const lr_cancel *cancel) { d->cancel = cancel; }

int lr_dscene_create(lr_dscene **out, lr_err *e)
{
    *out = calloc(1, sizeof **out);
    return *out ? LR_OK : lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory");
}

static void dobj_clear(dobj *o)
{
    lr_dsolver_destroy(o->solver);
    lr_dvolume_destroy(o->volume);
    for (int l = 0; l < LR_SCENE_MAX_LIGHTS; l++)
        free(o->field[l]);
    memset(o, 0, sizeof *o);
}

void lr_dscene_destroy(lr_dscene *d)
{
    if (!d)
        return;
    for (int i = 0; i < LR_DSCENE_MAX_OBJECTS; i++)
        dobj_clear(&d->obj[i]);
    free(d);
}

double lr_dscene_spacing(const lr_scene_object *o)
{
    if (o->dgrid_h_mm > 0.0)
        return o->dgrid_h_mm;
    const double r = fmax(o->radius, 1e-3);
    double h = r / LR_DSCENE_AUTO_CELLS;
    if (o->wall_mm > 0.0)
        h = fmin(h, o->wall_mm / LR_DSCENE_WALL_CELLS);
    return fmax(h, r / LR_DSCENE_MAX_CELLS);
}

typedef struct qctx {
    const lr_scene_object *obj;
    const lr_light *light;
    double cell; /* the finest grid's spacing: the side of the patch a sample stands for */
} qctx;

double lr_dscene_irradiance(const lr_scene_object *obj, const lr_light *light, lr_vec3 b,
                            lr_vec3 n, double cell)
{
    double eta = obj->material.medium.eta;
    double eps = 1e-5 * fmax(obj->radius, 1.0);
    lr_vec3 o = lr_v3_add(b, lr_v3_scale(n, eps));
    if (light->type == LR_LIGHT_DIRECTIONAL) {
        lr_vec3 w = lr_v3_scale(light->direction, -1.0);
        double c = lr_v3_dot(n, w);
        if (!(c > 0.0) || lr_bvh_occluded(obj->bvh, o, w, 0.0, INFINITY))
            return 0.0;
        return lr_fresnel_transmittance(c, eta) * c;
    }
    lr_vec3 d = lr_v3_sub(light->position, b);
    double r2 = lr_v3_dot(d, d), r = sqrt(r2);
    if (!(r > 0.0))
        return 0.0;
    lr_vec3 w = lr_v3_scale(d, 1.0 / r);
    double c = lr_v3_dot(n, w);
    if (!(c > 0.0) || lr_bvh_occluded(obj->bvh, o, w, 0.0, fmax(0.0, r - 2.0 * eps)))
        return 0.0;
    /* The spot's cone and a profile (lr_light_shape); an area light stays the point at its
     * centre here. */
    double shape = lr_light_is_area(light) ? 1.0 : lr_light_shape(light, lr_v3_scale(w, -1.0));
    /* The light over the patch the sample stands for (near_light.h), not at its centre: the
     * point sample cos / r^2 diverges as the light nears the surface (the flame 0.1 mm above
     * the pool's floor gave 1e5 times the object's normal light), the patch's mean is at most
     * 2 pi / cell^2. F_t at the patch's mean cosine (near the light most of the patch is
     * lit at grazing angles from the centre's point of view, but not in solid angle); the
     * spot profile stays the centre's. */
    double mu = 0.0, E = lr_patch_irradiance(light->position, b, n, cell, &mu);
    return lr_fresnel_transmittance(mu, eta) * E * shape;
}

static double q_fn(const void *ctx, lr_vec3 b, lr_vec3 n)
{
    const qctx *q = ctx;
    return lr_dscene_irradiance(q->obj, q->light, b, n, q->cell);
}

/* The solver's B is the exitance, (1 - F_dr) J+ (dgrid.h). Composition renders every model's B
 * as L_o = F_t(w_o) B / pi (seed 003 Eq. 5), whose exitance is T_hem B, T_hem the hemispherical
 * transmittance (PIPELINE.md "Energy"; the profiles' B is defined that way). So the pipeline
 * gets exitance / T_hem; without it the grid rendered T_hem (0.91 for wax) of its light. */
static void scale_field(float *field, size_t nodes, const double k[3])
{
    for (size_t j = 0; j < nodes; j++)
        for (int c = 0; c < 3; c++)
            field[4 * j + c] *= (float)k[c];
}

static void to_pipeline_b(float *field, size_t nodes, double eta)
{
    double k = 1.0 / lr_hemi_transmittance(eta);
    scale_field(field, nodes, (const double[3]){k, k, k});
}

/* Light l's solved field of D as a view (the renderer's and the closure's). */
static void view_of(const dobj *D, int l, lr_dfield_view *out)
{
    const lr_dgrid *g = lr_dsolver_grid(D->solver);
    out->data = D->field[l];
    lr_dgrid_dims(g, out->n);
    out->origin = lr_dgrid_origin(g);
    out->h = lr_dgrid_h(g);
}

static void field_b(const void *ctx, lr_vec3 x, lr_vec3 n, double B[3])
{
    (void)n;
    const lr_dfield_view *f = ctx;
    lr_dfield_eval(f->data, f->n, f->origin, f->h, x, B);
}

/* The closure's extra light spread like the first bounce across the cavity (bounce.h): one
 * more solve, in slot LR_SCENE_MAX_LIGHTS + l, with the light field l sends back into the
 * object as its source; the bounce's field is scaled so that the light it adds is the
 * closure's, (gain - 1) times the direct field's, per band (over the surface). Returns LR_OK
 * with *spread false when the bounce carries no light in some band (the caller then scales
 * by the gain). */
static int spread_by_bounce(dobj *D, const lr_scene_object *o, int l, const double gain[3],
                            bool *spread, lr_err *e)
{
    _Static_assert(2 * LR_SCENE_MAX_LIGHTS <= LR_DSOLVER_SLOTS, "a bounce slot per light");
    *spread = false;
    const int slot = LR_SCENE_MAX_LIGHTS + l;
    size_t nodes = lr_dgrid_node_count(lr_dsolver_grid(D->solver));
    lr_dbounce bk = {.obj = o, .rays = LR_DSCENE_BOUNCE_RAYS};
    view_of(D, l, &bk.field);
    float *f1 = malloc(4 * nodes * sizeof *f1);
    if (!f1)
        return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory");
    int rc = lr_dsolver_solve_rgb(D->solver, slot, lr_dbounce_q, &bk, LR_DSCENE_TOL, e);
    if (!rc)
        rc = lr_dsolver_field_rgb(D->solver, slot, lr_dbounce_q, &bk, f1, e);
    if (rc) {
        free(f1);
        return lr_err_prefix(e, "cavity bounce");
    }
    to_pipeline_b(f1, nodes, o->material.medium.eta);
    /* Each field's light over the surface, sum of B at triangle centroids times area (the
     * renderer's refined mesh: no edge over 12 mm). */
    double s0[3] = {0}, s1[3] = {0}, k[3];
    float *f0 = D->field[l];
    const lr_mesh *m = lr_bvh_mesh(o->bvh);
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 p[3], g;
        lr_mesh_triangle(m, t, p);
        g = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        double a = lr_mesh_triangle_area(m, t), b0[3], b1[3];
        lr_dfield_eval(f0, bk.field.n, bk.field.origin, bk.field.h, g, b0);
        lr_dfield_eval(f1, bk.field.n, bk.field.origin, bk.field.h, g, b1);
        for (int c = 0; c < 3; c++)
            s0[c] += a * b0[c], s1[c] += a * b1[c];
    }
    bool ok = true;
    for (int c = 0; c < 3; c++) {
        k[c] = (gain[c] - 1.0) * s0[c] / s1[c];
        ok &= s1[c] > 0.0 && isfinite(k[c]) && k[c] >= 0.0;
    }
    if (ok)
        for (size_t j = 0; j < nodes; j++)
            for (int c = 0; c < 3; c++)
                f0[4 * j + c] += (float)(k[c] * f1[4 * j + c]);
    free(f1);
    *spread = ok;
    return LR_OK;
}

/* Cavity closure (render/core/cavity.h) from the grid's own solved field: q is the light's
 * direct irradiance only, so the light the lit surface sends back into a cavity around the
 * light (Fresnel reflection and what re-emerges there) and that meets the object again is
 * added: as much as the closure's gain says, spread like the first bounce across the cavity
 * (spread_by_bounce; the profile models spread it like the direct light). The grid's cavity
 * side is finite geometry, so its B gives the cavity-side albedo directly. */
static int close_cavity(dobj *D, const lr_scene *s, int i, int l, lr_err *e)
{
    D->gain[l][0] = D->gain[l][1] = D->gain[l][2] = 1.0;
    int k = -1;
    enum lr_enclosure enc = lr_scene_light_enclosure(s, l, &k);
    if (enc != LR_ENCLOSURE_HULL || k != i)
        return LR_OK;
    lr_dfield_view f;
    view_of(D, l, &f);
    lr_cavity_desc cd = {.directions = LR_DSCENE_CAVITY_DIRECTIONS,
                             .points = LR_DSCENE_CAVITY_POINTS, .seed = 1};
    lr_cavity cav;
    const lr_scene_object *o = lr_scene_object_at(s, i);
    int rc = lr_cavity_measure_field(o, lr_scene_light_at(s, l), enc, &cd, field_b, &f,
                                         &cav, e);
    bool spread = false;
    if (!rc)
        rc = spread_by_bounce(D, o, l, cav.gain, &spread, e);
    if (rc)
        return rc;
    if (!spread)
        scale_field(D->field[l], lr_dgrid_node_count(lr_dsolver_grid(D->solver)), cav.gain);
    memcpy(D->gain[l], cav.gain, sizeof D->gain[l]);
    return LR_OK;
}

/* A volume path as written: relative to the scene file's folder, else to the configs
 * folder, else to the working directory. */
static void resolve_volume(const lr_scene *s, const char *rel, char *out, size_t cap)
{
    int w;
    snprintf(out, cap, "%s", rel);
    if (rel[0] == '/')
        return;
    const char *sp = lr_scene_path(s);
    const char *slash = sp ? strrchr(sp, '/') : NULL;
    if (slash) {
        w = snprintf(out, cap, "%.*s/%s", (int)(slash - sp), sp, rel);
        if (w > 0 && (size_t)w < cap && access(out, R_OK) == 0)
            return;
    }
    w = snprintf(out, cap, "%s/%s", lr_configs_dir(), rel);
    if (w > 0 && (size_t)w < cap && access(out, R_OK) == 0)
        return;
    snprintf(out, cap, "%s", rel);
}

static bool same_grid(const dobj *d, const lr_scene_object *o, double h)
{
    return d->solver && d->mesh == o->mesh && memcmp(d->model, o->model, sizeof d->model) == 0 &&
           d->h == h;
}

static bool same_material(const dobj *d, const lr_scene_object *o, const char *vol)
{
    return memcmp(&d->medium, &o->material.medium, sizeof d->medium) == 0 &&
           strcmp(d->volume_path, vol) == 0;
}

/* A material edit on the same grid: new coefficients, the solutions kept as warm starts. */
static int remat(dobj *d, int i, const lr_scene_object *o, const char *vol, lr_err *e)
{
    lr_dvolume *nv = NULL;
    int rc;
    if (vol[0] && (rc = lr_dvolume_load(vol, &nv, e)))
        return lr_err_prefix(e, "objects[%d].dgrid_volume", i);
    lr_dmaterial m = {{0}, {0}, o->material.medium.eta, nv};
    memcpy(m.sigma_a, o->material.medium.sigma_a, sizeof m.sigma_a);
    memcpy(m.sigma_s_prime, o->material.medium.sigma_s_prime, sizeof m.sigma_s_prime);
    if (m.eta != d->medium.eta) { /* A changes the ghost rows: rebuild */
        lr_dvolume_destroy(nv);
        return -1;
    }
    if ((rc = lr_dsolver_set_material(d->solver, &m, e))) {
        lr_dvolume_destroy(nv);
        return rc;
    }
    lr_dvolume_destroy(d->volume);
    d->volume = nv;
    d->medium = o->material.medium;
    if (snprintf(d->volume_path, sizeof d->volume_path, "%s", vol) >= (int)sizeof d->volume_path)
        return lr_err_set(e, LR_EINVAL, "objects[%d].dgrid_volume: path too long", i);
    return LR_OK;
}

static int build(dobj *d, const lr_scene *s, int i, const lr_scene_object *o, double h,
                 const char *vol, lr_err *e)
{
    dobj_clear(d);
    int rc;
    if (!o->closed)
        return lr_err_set(e, LR_EINVAL,
                          "objects[%d] (%s): model diffusion_grid needs a closed mesh (a solid "
                          "body; this one is open)",
                          i, o->name);
    if (vol[0] && (rc = lr_dvolume_load(vol, &d->volume, e)))
        return lr_err_prefix(e, "objects[%d].dgrid_volume", i);
    lr_dshape shape = lr_dshape_mesh(o->bvh);
    lr_dmaterial m = {{0}, {0}, o->material.medium.eta, d->volume};
    memcpy(m.sigma_a, o->material.medium.sigma_a, sizeof m.sigma_a);
    memcpy(m.sigma_s_prime, o->material.medium.sigma_s_prime, sizeof m.sigma_s_prime);
    if ((rc = lr_dsolver_create(&shape, h, 3, &m, &d->solver, e)))
        return lr_err_prefix(e, "objects[%d] (%s), diffusion_grid at h = %g mm", i, o->name, h);
    d->mesh = o->mesh;
    memcpy(d->model, o->model, sizeof d->model);
    d->medium = o->material.medium;
    d->h = h;
    if (snprintf(d->volume_path, sizeof d->volume_path, "%s", vol) >= (int)sizeof d->volume_path)
        return lr_err_set(e, LR_EINVAL, "objects[%d].dgrid_volume: path too long", i);
    d->rebuilt = true;
    return LR_OK;
}

int lr_dscene_update(lr_dscene *d, const lr_scene *s, lr_err *e)
{
    d->iters = 0;
    int n = lr_scene_object_count(s), L = lr_scene_light_count(s);
    for (int i = 0; i < LR_DSCENE_MAX_OBJECTS; i++) {
        dobj *D = &d->obj[i];
        D->rebuilt = false;
        const lr_scene_object *o = i < n ? lr_scene_object_at(s, i) : NULL;
        if (!o) {
            dobj_clear(D);
            continue;
        }
        if (!lr_sss_model_props_of(o->sss_model)->grid_field) {
            /* Kept, not freed: the rig's preview frame renders the object with a profile
             * model and the refinement right after it comes back to the grid (render/async/);
             * a freed grid was built again at every change (its build is most of a 5 mm
             * solve's cost). Inactive, it gives no field; its memory stays until the object
             * goes or the dscene is destroyed. */
            D->active = false;
            continue;
        }
        double h = lr_dscene_spacing(o);
        char vol[2048] = "";
        if (o->dgrid_volume[0])
            resolve_volume(s, o->dgrid_volume, vol, sizeof vol);
        int rc;
        rc = LR_OK;
        if (same_grid(D, o, h)) {
            if (!same_material(D, o, vol))
                rc = remat(D, i, o, vol, e);
        } else {
            rc = -1;
        }
        if (rc == -1)
            rc = build(D, s, i, o, h, vol, e);
        if (rc) {
            dobj_clear(D);
            return rc;
        }
        D->active = true;
        lr_dsolver_set_cancel(D->solver, d->cancel);
        const lr_dgrid *g = lr_dsolver_grid(D->solver);
        size_t nodes = lr_dgrid_node_count(g);
        for (int l = 0; l < L; l++) {
            /* Every level's source is the finest cell's: the coarse levels only start the
             * finest solve, whose right-hand side and field decide the result. */
            qctx q = {o, lr_scene_light_at(s, l), h};
            if ((rc = lr_dsolver_solve(D->solver, l, q_fn, &q, LR_DSCENE_TOL, e)))
                return rc == LR_ECANCELED ? rc
                                          : lr_err_prefix(e, "objects[%d] (%s), light %d", i,
                                                          o->name, l);
            d->iters += lr_dsolver_last_iters(D->solver);
            if (!D->field[l] && !(D->field[l] = malloc(4 * nodes * sizeof(float))))
                return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory");
            if ((rc = lr_dsolver_field(D->solver, l, q_fn, &q, D->field[l], e)))
                return lr_err_prefix(e, "objects[%d] (%s), light %d", i, o->name, l);
            to_pipeline_b(D->field[l], nodes, o->material.medium.eta);
            if ((rc = close_cavity(D, s, i, l, e)))
                return lr_err_prefix(e, "objects[%d] (%s), light %d", i, o->name, l);
        }
    }
    return LR_OK;
}

bool lr_dscene_field(const lr_dscene *d, int object, int light, lr_dfield_view *out)
{
    if (object < 0 || object >= LR_DSCENE_MAX_OBJECTS || light < 0 || light >= LR_SCENE_MAX_LIGHTS)
        return false;
    const dobj *D = &d->obj[object];
    if (!D->active || !D->field[light])
        return false;
    view_of(D, light, out);
    return true;
}

bool lr_dscene_cavity_gain(const lr_dscene *d, int object, int light, double gain[3])
{
    lr_dfield_view v;
    if (!lr_dscene_field(d, object, light, &v))
        return false;
    memcpy(gain, d->obj[object].gain[light], 3 * sizeof(double));
    return true;
}

bool lr_dscene_rebuilt(const lr_dscene *d, int object)
{
    return object >= 0 && object < LR_DSCENE_MAX_OBJECTS && d->obj[object].rebuilt;
}

int lr_dscene_last_iters(const lr_dscene *d) { return d->iters; }
