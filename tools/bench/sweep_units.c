/* Units check (issue 6: the GPU's HDR output and the physical reference must agree in units
 * and exposure before errors between them mean anything). The scene's receivers and light
 * alone: every object shrunk to a thousandth and moved far behind the camera, every receiver's
 * albedo 0.05, so what the receivers show is the light's direct illumination (computed exactly
 * by both renderers) plus receiver-to-receiver interreflection, which only the reference has
 * and which the low albedo keeps to about a percent. GPU / reference over the lit receiver
 * pixels should then be 1 within that percent and the reference's noise. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/reference/reference.h"

enum { UW = 32, UH = 24, USPP = 256 };

static int setf(lr_scene *s, const char *key, const char *val, lr_err *e)
{
    return lr_scene_set(s, key, val, NULL, e);
}

int lrb_sweep_units(lr_gl *gl, const char *name, double *ratio, double *se, long *px)
{
    *ratio = *se = NAN;
    *px = 0;
    char path[1024], key[96], val[160];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_err e = {0};
    lr_scene *s = NULL;
    lr_ref_scene *rs = NULL;
    lr_renderer *r = NULL;
    lr_ref_image mean = {0}, var = {0};
    lr_eval_masks m = {0};
    float *gpu = NULL;
    int rc = lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e);
    if (!rc) {
        const lr_camera *c = lr_scene_camera(s);
        lr_vec3 far = lr_v3_sub(c->position, lr_v3_scale(lr_v3_sub(c->target, c->position), 10.0));
        snprintf(val, sizeof val, "%.17g,%.17g,%.17g", far.x, far.y, far.z);
        for (int k = 0; !rc && k < lr_scene_object_count(s); k++) {
            snprintf(key, sizeof key, "objects[%d].transform.scale", k);
            if (!(rc = setf(s, key, "0.001", &e))) {
                snprintf(key, sizeof key, "objects[%d].transform.translate", k);
                rc = setf(s, key, val, &e);
            }
        }
        for (int k = 0; !rc && k < lr_scene_receiver_count(s); k++) {
            snprintf(key, sizeof key, "receivers[%d].albedo", k);
            rc = setf(s, key, "0.05,0.05,0.05", &e);
        }
    }
    lr_ref_camera cam;
    bool hit;
    if (!rc)
        rc = lr_ref_scene_from_scene(s, &rs, &cam, &e);
    if (!rc)
        rc = lr_ref_render_cached(rs, &cam,
                                  &(lr_ref_render_desc){.width = UW, .height = UH, .spp = USPP},
                                  NULL, NULL, NULL,
                                  &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &mean,
                                  &var, &hit, &e);
    if (!rc)
        rc = lr_eval_masks_create(s, UW, UH, &m, &e);
    if (!rc)
        rc = lr_scene_set(s, "render.frames", "1", NULL, &e);
    if (!rc)
        rc = lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = UW,
                                                     .height = UH, .no_vpl = true},
                                &r, &e);
    lr_frame_stats st;
    if (!rc)
        rc = lr_renderer_frame(r, &st, &e);
    if (!rc && !(gpu = malloc((size_t)UW * UH * 3 * sizeof *gpu)))
        rc = lr_err_set(&e, LR_ENOMEM, "out of memory");
    if (!rc)
        rc = lr_renderer_read_hdr(r, gpu, &e);
    if (!rc) {
        double g = 0.0, ref = 0.0, v = 0.0;
        for (int y = 0; y < UH; y++)
            for (int x = 0; x < UW; x++) {
                size_t i = (size_t)y * UW + x, j = (size_t)(UH - 1 - y) * UW + x; /* GL rows */
                if (!m.receivers[i] || !(mean.rgb[3 * i + 1] > 0.0f))
                    continue;
                (*px)++;
                for (int b = 0; b < 3; b++)
                    g += gpu[3 * j + b], ref += mean.rgb[3 * i + b], v += var.rgb[3 * i + b];
            }
        if (ref > 0.0) {
            *ratio = g / ref;
            *se = *ratio * sqrt(v) / ref;
        }
    } else
        fprintf(stderr, "bench sweep: %s units check: %s\n", name, e.msg);
    free(gpu);
    lr_renderer_destroy(r);
    lr_eval_masks_free(&m);
    lr_ref_image_free(&mean);
    lr_ref_image_free(&var);
    lr_ref_scene_destroy(rs);
    lr_scene_destroy(s);
    return rc;
}
