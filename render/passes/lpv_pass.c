/* The light-propagation volume's pass (lpv_pass.h). */
#include "render/passes/lpv_pass.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/core/recv_grid.h"
#include "render/lpv/gpu.h"

/* Further bounces off the objects in the volume (scene_lpv.h): a paper shade's cavity
 * returns 0.79 per bounce. The CPU twin uses the same (render/cpu/frame.c). */
#define LPV_BOUNCES 2
#define LPV_OBJ_UNIT 18

void lr_lpv_pass_free(lr_lpv_pass *p)
{
    lr_tex_destroy(p->recv);
    lr_tex_destroy(p->obj);
    memset(p, 0, sizeof *p);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Light l's receiver grids into p->recv (layer: plane index times n_lights plus l, the area
 * pass's layout). */
static int upload_recv(lr_lpv_pass *p, const lr_pass_ctx *c, int l, double *const *out,
                       float *px, lr_err *e)
{
    size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    int planes = 0, rc = LR_OK;
    for (int i = 0; i < c->objs->n_receivers && !rc; i++) {
        if (!out[i])
            continue;
        for (size_t k = 0; k < texels; k++) {
            for (int q = 0; q < 3; q++)
                px[4 * k + q] = (float)out[i][3 * k + q];
            px[4 * k + 3] = 1.0f;
        }
        rc = lr_tex_upload(p->recv, planes++ * c->n_lights + l, px, e);
    }
    return rc;
}

/* Light l's object field into p->obj (layers l (n+1) .. l (n+1) + n). */
static int upload_obj(lr_lpv_pass *p, int l, const lr_lpv_objfield *f, lr_err *e)
{
    const float *t = lr_lpv_objfield_texels(f);
    int n1 = p->n + 1;
    size_t layer = (size_t)n1 * 6 * n1 * 4;
    float *z = NULL; /* a light that lit nothing (directional): zeros */
    if ((!t || lr_lpv_objfield_n(f) != p->n) && !(z = calloc(layer, sizeof *z)))
        return lr_err_set(e, LR_ENOMEM, "lpv pass: out of memory");
    int rc = LR_OK;
    for (int k = 0; k < n1 && !rc; k++)
        rc = lr_tex_upload(p->obj, l * n1 + k, z ? z : t + (size_t)k * layer, e);
    free(z);
    return rc;
}

int lr_lpv_pass_run(lr_lpv_pass *p, const lr_pass_ctx *c, lr_err *e)
{
    double t0 = now_s();
    lr_lpv_pass_free(p);
    int n = c->rs->lpv, nr = c->objs->n_receivers, nl = c->n_lights, planes = 0, rc = LR_OK;
    if (n <= 0 || nl < 1 || lr_scene_object_count(c->scene) == 0) {
        p->valid = true; /* nothing to build: neither texture */
        return LR_OK;
    }
    size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *out[LR_MAX_RECEIVERS] = {NULL};
    for (int i = 0; i < nr; i++) {
        lr_recv_grid_frame f;
        if (!lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, i), &f))
            continue;
        planes++;
        if (!(out[i] = malloc(sizeof *out[i] * texels * 3)))
            rc = lr_err_set(e, LR_ENOMEM, "lpv pass: out of memory");
    }
    float *px = rc ? NULL : malloc(sizeof *px * texels * 4);
    if (!rc && !px)
        rc = lr_err_set(e, LR_ENOMEM, "lpv pass: out of memory");
    if (!rc && planes) {
        lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F,
                          .width = LR_RECV_GRID, .height = LR_RECV_GRID, .layers = planes * nl,
                          .label = "light-propagation volume's receiver grids"};
        rc = lr_tex_create(c->gl, &td, &p->recv, e);
    }
    p->n = n;
    p->n_lights = nl;
    /* The object field: n_lights (n+1) layers of (n+1) x 6 (n+1) RGBA32F texels (0.47 MB per
     * light at n 16, 3.4 MB at 32, 26 MB at 64, 206 MB at 128). */
    if (!rc && (nl * (n + 1) > c->caps->max_array_layers ||
                6 * (n + 1) > c->caps->max_texture_size))
        rc = lr_err_set(e, LR_EUNSUPPORTED,
                        "lpv pass: render.lpv = %d with %d lights needs %d array layers of "
                        "%d x %d texels; the driver takes %d layers of at most %d",
                        n, nl, nl * (n + 1), n + 1, 6 * (n + 1), c->caps->max_array_layers,
                        c->caps->max_texture_size);
    if (!rc) {
        lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = n + 1,
                          .height = 6 * (n + 1), .layers = nl * (n + 1),
                          .label = "light-propagation volume's object field"};
        rc = lr_tex_create(c->gl, &td, &p->obj, e);
    }
    lr_lpv_gpu *g = NULL;
    lr_lpv_objfield *of = NULL;
    if (!rc)
        rc = lr_lpv_gpu_create(c->gl, n, c->shader_dir, &g, e);
    if (!rc)
        rc = lr_lpv_objfield_create(&of, e);
    lr_lpv_scene_desc d = {.n = n, .bounces = LPV_BOUNCES, .propagate = lr_lpv_gpu_run,
                           .ctx = g, .objects = of};
    for (int l = 0; l < nl && !rc; l++) {
        if ((rc = lr_lpv_scene_indirect(c->scene, l, &d, out, &p->stats[l], e)))
            break;
        if (lr_lpv_objfield_n(of) > 0) {
            p->origin = lr_lpv_objfield_origin(of);
            p->h = lr_lpv_objfield_h(of);
        }
        if (p->recv && (rc = upload_recv(p, c, l, out, px, e)))
            break;
        rc = upload_obj(p, l, of, e);
    }
    for (int i = 0; i < nr; i++)
        free(out[i]);
    free(px);
    lr_lpv_objfield_destroy(of);
    lr_lpv_gpu_destroy(g);
    if (rc) {
        lr_lpv_pass_free(p);
        return rc;
    }
    p->valid = true;
    p->build_s = now_s() - t0;
    return LR_OK;
}

void lr_lpv_pass_bind_objects(const lr_lpv_pass *p, const lr_pass_ctx *c, lr_program *prog,
                              int object, const float scale[LR_MAX_LIGHTS])
{
    bool on = p && p->valid && p->obj && p->h > 0.0 && object < lr_scene_object_count(c->scene);
    lr_passes_uniform_i(prog, "u_lpv_obj_on", on);
    lr_passes_bind_tex(prog, "u_lpv_obj", LPV_OBJ_UNIT, on ? p->obj : NULL);
    if (!on)
        return;
    lr_passes_uniform_i(prog, "u_lpv_obj_n", p->n);
    lr_passes_uniform_i(prog, "u_lpv_obj_lights", p->n_lights);
    lr_passes_uniform_v3(prog, "u_lpv_obj_origin", p->origin);
    lr_passes_uniform_f(prog, "u_lpv_obj_h", (float)p->h);
    double kR[3], kT[3];
    lr_lpv_object_factors(lr_scene_object_at(c->scene, object), kR, kT);
    float r[3 * LR_MAX_LIGHTS], t[3 * LR_MAX_LIGHTS];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int b = 0; b < 3; b++) {
            r[3 * l + b] = (float)(kR[b] * scale[l]);
            t[3 * l + b] = (float)(kT[b] * scale[l]);
        }
    lr_passes_uniform_v3_array(prog, "u_lpv_obj_r", r, LR_MAX_LIGHTS);
    lr_passes_uniform_v3_array(prog, "u_lpv_obj_t", t, LR_MAX_LIGHTS);
}
