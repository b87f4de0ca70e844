/* lamprig fit — arguments, captures, the fit (calib/fit.h), a GPU confirmation render, the
 * material preset written atomically after the material loader accepted it. */
#include "firmware/cmd_fit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/fit.h"
#include "calib/fit_captures.h"
#include "calib/rig.h"
#include "firmware/args.h"
#include "firmware/cli.h"
#include "render/base/atomic_file.h"
#include "render/base/json.h"
#include "render/gl/gl.h"
#include "render/material/material.h"
#include "render/renderer.h"

const char lr_fit_summary[] = "fit a material (sigma_a, sigma_s' per band, or two scales on a "
                              "preset) to captures of the lit object";

const char lr_fit_usage[] =
    "usage: lamprig fit --scene FILE --captures IMG[,IMG...] --out MATERIAL.json\n"
    "                   [--calib DIR] [--gamma G] [--times T1,T2,...] [--object NAME]\n"
    "                   [--scale-preset NAME] [--start-sigma-a R,G,B --start-sigma-s R,G,B]\n"
    "                   [--size WxH] [--samples N] [--capture-scale S] [--huber H]\n"
    "                   [--max-evals N] [--seed N] [--threads N] [--name NAME] [--no-gpu-check]\n"
    "\n"
    "Fits the object's material so that the CPU reference render of the scene's camera view\n"
    "matches the captures (linearised with the calibration folder's camera response and colour\n"
    "matrix; several exposures are merged to HDR with --times). The scene's camera must be the\n"
    "rig's camera. Nelder-Mead in log sigma per band (or on two scales of the preset NAME with\n"
    "--scale-preset), Huber loss over the object's pixels; the result is confirmed with one GPU\n"
    "render. Prints parameters, residual (relative RMSE), iterations and time; writes the\n"
    "material preset (configs/materials format) atomically.\n"
    "\n"
    "  --captures IMG,...  8-bit photos of the lit object (one, or an exposure stack)\n"
    "  --gamma G           the camera's response when DIR has no camera_response.json (or\n"
    "                      there is no --calib): value v is exposure (v/128)^G; default 2.2\n"
    "                      (an sRGB camera), the rule lamprig compare and lamprig-capsim use;\n"
    "                      refused beside camera_response.json\n"
    "  --times T,...       their exposure times, s (default 1)\n"
    "  --object NAME       the object fitted (default the first)\n"
    "  --size WxH          model resolution (default 64x48; the captures' aspect)\n"
    "  --samples N         reference samples per band per pixel (default 128)\n"
    "  --capture-scale S   camera exposure units per W/(mm^2 sr) (default render.exposure)\n"
    "  --huber H           Huber threshold, fraction of the mean capture (default 0.1)\n"
    "  --max-evals N       model evaluations per band (default 200)\n"
    "\n"
    "Exit status: 0 success, 1 failure (the output is left as it was), 2 bad arguments.";

static int usage_error(const char *msg)
{
    fprintf(stderr, "lamprig fit: %s (see `lamprig help fit`)\n", msg);
    return LR_EXIT_USAGE;
}

static int fail(const lr_err *e)
{
    fprintf(stderr, "lamprig fit: %s\n", e->msg);
    return LR_EXIT_FAIL;
}

static int int_arg(const char *flag, const char *v, int lo, int hi, int *out, lr_err *e)
{
    double d;
    if (lr_args_number(flag, v, &d, e))
        return LR_EINVAL;
    if (d != floor(d) || d < lo || d > hi)
        return lr_err_set(e, LR_EINVAL, "%s %s: a whole number in %d..%d", flag, v, lo, hi);
    *out = (int)d;
    return LR_OK;
}

/* JSON string body with quotes and backslashes escaped (names and paths only). */
static void json_escape(const char *s, char *buf, size_t cap)
{
    size_t k = 0;
    for (; *s && k + 3 < cap; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            buf[k++] = '\\';
        buf[k++] = c < 0x20 ? '?' : (char)c;
    }
    buf[k] = 0;
}

/* The preset, validated by the material loader before it replaces anything. */
static int write_material(const char *path, const char *name, const char *source,
                          const lr_medium *m, lr_err *e)
{
    char ename[256], esrc[1024], text[4096];
    json_escape(name, ename, sizeof ename);
    json_escape(source, esrc, sizeof esrc);
    int n = snprintf(text, sizeof text,
                     "{\n  \"name\": \"%s\",\n  \"source\": \"%s\",\n"
                     "  \"sigma_a\": [%.6g, %.6g, %.6g],\n"
                     "  \"sigma_s_prime\": [%.6g, %.6g, %.6g],\n"
                     "  \"eta\": %.6g,\n  \"g\": %.6g\n}\n",
                     ename, esrc, m->sigma_a[0], m->sigma_a[1], m->sigma_a[2],
                     m->sigma_s_prime[0], m->sigma_s_prime[1], m->sigma_s_prime[2], m->eta, m->g);
    if (n < 0 || (size_t)n >= sizeof text)
        return lr_err_set(e, LR_EINVAL, "%s: material text too long", path);
    lr_json *j;
    int rc = lr_json_parse(text, (size_t)n, path, &j, e);
    if (rc)
        return rc;
    lr_material check;
    rc = lr_material_from_json(j, lr_json_root(j), "material", &check, e);
    lr_json_destroy(j);
    if (rc)
        return lr_err_prefix(e, "%s: the fitted material does not validate", path);
    return lr_atomic_write(path, text, (size_t)n, e);
}

/* One GPU render of the fitted scene at the fit's size, converged; its relative RMSE against
 * the captures over the object's pixels. */
static int gpu_check(lr_scene *scene, int object, const lr_image *target, double *rel,
                     double *ms, lr_err *e)
{
    lr_gl *gl = NULL;
    lr_renderer *r = NULL;
    lr_image img = {0};
    float *rgb = NULL;
    unsigned char *mask = NULL;
    int w = target->width, h = target->height, rc;
    if ((rc = lr_gl_create(NULL, &gl, e)) ||
        (rc = lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = scene, .width = w,
                                                     .height = h},
                                 &r, e)))
        goto done;
    *ms = 0;
    for (int i = 0; i < 100000 && lr_renderer_needs_frame(r); i++) {
        lr_frame_stats st;
        if ((rc = lr_renderer_frame(r, &st, e)))
            goto done;
        *ms += st.total_ms;
    }
    rgb = malloc(sizeof(float) * 3 * (size_t)w * h);
    mask = malloc((size_t)w * h);
    if (!rgb || !mask) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto done;
    }
    if ((rc = lr_renderer_read_hdr(r, rgb, e)) || (rc = lr_image_alloc(&img, w, h, e)))
        goto done;
    for (int y = 0; y < h; y++) /* GL rows bottom to top */
        memcpy(img.rgb + (size_t)y * w * 3, rgb + (size_t)(h - 1 - y) * w * 3,
               sizeof(float) * 3 * (size_t)w);
    lr_fit_object_mask(scene, object, w, h, mask);
    *rel = lr_fit_rel_rmse(&img, target, mask, NULL);
done:
    lr_image_free(&img);
    free(rgb);
    free(mask);
    lr_renderer_destroy(r);
    lr_gl_destroy(gl);
    return rc;
}

int lr_cmd_fit(int argc, char **argv)
{
    static const lr_argspec specs[] = {
        {"--scene", 1},   {"--captures", 1},      {"--out", 1},     {"--calib", 1},
        {"--times", 1},   {"--object", 1},        {"--scale-preset", 1},
        {"--start-sigma-a", 1}, {"--start-sigma-s", 1}, {"--size", 1}, {"--samples", 1},
        {"--capture-scale", 1}, {"--huber", 1},   {"--max-evals", 1}, {"--seed", 1},
        {"--threads", 1}, {"--name", 1},          {"--no-gpu-check", 0}, {"--gamma", 1},
        {NULL, 0},
    };
    lr_args a;
    lr_err e = {0};
    if (lr_args_parse(argc - 1, argv + 1, specs, 0, &a, &e))
        return usage_error(e.msg);
    const char *scene_path = lr_args_get(&a, "--scene"), *caps = lr_args_get(&a, "--captures"),
               *out = lr_args_get(&a, "--out");
    if (!scene_path || !caps || !out)
        return usage_error("--scene, --captures and --out are required");
    lr_fit_desc d = {.samples = 128};
    int w = 64, h = 48;
    double times[16], scale = 0, gamma = 0;
    int ntimes = 0;
    const char *v;
    if ((v = lr_args_get(&a, "--size")) && (sscanf(v, "%dx%d", &w, &h) != 2 || w < 2 ||
                                            h < 2 || w > 4096 || h > 4096))
        return usage_error("--size: expected WxH, 2..4096 each");
    if (((v = lr_args_get(&a, "--samples")) && int_arg("--samples", v, 2, 1 << 20, &d.samples, &e)) ||
        ((v = lr_args_get(&a, "--max-evals")) &&
         int_arg("--max-evals", v, 3, 100000, &d.max_evals, &e)) ||
        ((v = lr_args_get(&a, "--threads")) && int_arg("--threads", v, 1, 1024, &d.threads, &e)) ||
        ((v = lr_args_get(&a, "--times")) && lr_args_numbers("--times", v, times, 1, 16, &ntimes, &e)) ||
        ((v = lr_args_get(&a, "--capture-scale")) && lr_args_number("--capture-scale", v, &scale, &e)) ||
        ((v = lr_args_get(&a, "--huber")) && lr_args_number("--huber", v, &d.huber, &e)) ||
        ((v = lr_args_get(&a, "--gamma")) && lr_args_number("--gamma", v, &gamma, &e)) ||
        ((v = lr_args_get(&a, "--start-sigma-a")) && lr_args_triple("--start-sigma-a", v, d.sigma_a_start, &e)) ||
        ((v = lr_args_get(&a, "--start-sigma-s")) && lr_args_triple("--start-sigma-s", v, d.sigma_s_start, &e)))
        return usage_error(e.msg);
    if ((v = lr_args_get(&a, "--seed"))) {
        int s;
        if (int_arg("--seed", v, 1, 1 << 30, &s, &e))
            return usage_error(e.msg);
        d.seed = (unsigned)s;
    }
    if (lr_args_has(&a, "--capture-scale") && !(scale > 0))
        return usage_error("--capture-scale must be > 0");
    if (lr_args_has(&a, "--huber") && !(d.huber > 0))
        return usage_error("--huber must be > 0");
    if (lr_args_has(&a, "--gamma") && !(gamma >= 0.1 && gamma <= 10))
        return usage_error("--gamma: expected 0.1..10");
    if (lr_args_has(&a, "--start-sigma-a") != lr_args_has(&a, "--start-sigma-s"))
        return usage_error("--start-sigma-a and --start-sigma-s go together");
    for (int b = 0; b < 3; b++)
        if (lr_args_has(&a, "--start-sigma-a") &&
            !(d.sigma_a_start[b] > 0 && d.sigma_s_start[b] > 0))
            return usage_error("start sigmas must be > 0");
    /* captures: a comma-separated list */
    char *list = strdup(caps);
    const char *paths[16];
    int n = 0;
    for (char *t = strtok(list, ","); t && n < 16; t = strtok(NULL, ","))
        paths[n++] = t;
    if (ntimes && ntimes != n) {
        free(list);
        return usage_error("--times needs one time per capture");
    }
    if (n > 1 && !ntimes) {
        free(list);
        return usage_error("several captures are an exposure stack: give --times");
    }

    int status = LR_EXIT_FAIL;
    lr_scene *scene = NULL;
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    lr_image target = {0};
    if (!cal) {
        free(list);
        return LR_EXIT_FAIL;
    }
    if (lr_scene_load(scene_path, NULL, &scene, &e)) {
        status = e.code == LR_EIO ? fail(&e) : usage_error(e.msg);
        goto done;
    }
    const char *oname = lr_args_get(&a, "--object");
    d.object = oname ? lr_scene_find_object(scene, oname) : 0;
    if (d.object < 0) {
        char msg[256];
        snprintf(msg, sizeof msg, "--object %s: no such object in %s", oname, scene_path);
        status = usage_error(msg);
        goto done;
    }
    const char *preset = lr_args_get(&a, "--scale-preset");
    if (preset) {
        char key[64];
        snprintf(key, sizeof key, "objects[%d].material", d.object);
        if (lr_scene_set(scene, key, preset, NULL, &e)) {
            status = usage_error(e.msg);
            goto done;
        }
        d.mode = LR_FIT_SCALE;
    }
    const char *cdir = lr_args_get(&a, "--calib");
    if (cdir && lr_rig_calib_load(cdir, cal, &e)) {
        status = fail(&e);
        goto done;
    }
    if (gamma > 0 && lr_rig_set_gamma(cal, gamma, &e)) {
        status = usage_error(e.msg);
        goto done;
    }
    /* Said before the work: an assumed response is the first suspect of a bad fit. */
    char resp[256];
    printf("lamprig fit: captures read with %s\n", lr_rig_response_name(cal, resp, sizeof resp));
    if (!scale)
        scale = lr_scene_render(scene)->exposure;
    if (lr_fit_load_captures(paths, ntimes ? times : NULL, n, cal, w, h, scale, &target, &e)) {
        status = fail(&e);
        goto done;
    }
    unsigned char *om = malloc((size_t)w * h);
    if (!om) {
        lr_err_set(&e, LR_ENOMEM, "out of memory");
        status = fail(&e);
        goto done;
    }
    long inside = lr_fit_object_mask(scene, d.object, w, h, om), clipped = 0;
    for (size_t p = 0; p < (size_t)w * h; p++)
        clipped += om[p] && !isfinite(target.rgb[3 * p]);
    free(om);
    if (clipped) /* said: a mostly clipped object is fitted from what is left */
        printf("lamprig fit: %ld of the object's %ld pixels left out: they touch capture "
               "pixels clipped (some channel >= 250, or black) in every capture\n",
               clipped, inside);
    d.scene = scene;
    d.target = &target;
    lr_fit_result r;
    if (lr_fit_run(&d, &r, &e)) {
        status = fail(&e);
        goto done;
    }
    const lr_scene_object *o = lr_scene_object_at(scene, d.object);
    printf("lamprig fit: %s object '%s', %d x %d, %ld object pixels, %d samples\n",
           lr_scene_name(scene), o->name, w, h, r.mask_pixels, d.samples);
    static const char *band[3] = {"R", "G", "B"};
    if (d.mode == LR_FIT_SCALE)
        printf("  scales on '%s': sigma_a x %.4g (+-%.2g log), sigma_s' x %.4g (+-%.2g log), "
               "%d iterations, %d evaluations\n",
               preset, r.scale[0], r.stderr_log[0][0], r.scale[1], r.stderr_log[0][1],
               r.iterations[0], r.evals[0]);
    for (int b = 0; b < 3; b++) {
        printf("  %s: sigma_a %.5g mm^-1 (+-%.2g log)  sigma_s' %.5g mm^-1 (+-%.2g log)  "
               "rel RMSE %.4f",
               band[b], r.sigma_a[b], r.stderr_log[d.mode == LR_FIT_SCALE ? 0 : b][0],
               r.sigma_s_prime[b], r.stderr_log[d.mode == LR_FIT_SCALE ? 0 : b][1],
               r.rel_rmse[b]);
        if (d.mode == LR_FIT_SIGMA)
            printf("  %d iterations, %d evaluations", r.iterations[b], r.evals[b]);
        printf("\n");
    }
    printf("  residual: relative RMSE %.4f (start %.4f), %d renders, %.2f s\n", r.rel_rmse_all,
           r.start_rel_rmse, r.renders, r.seconds);
    if (!lr_args_has(&a, "--no-gpu-check")) {
        double rel = 0, ms = 0;
        lr_err ge = {0};
        if (gpu_check(scene, d.object, &target, &rel, &ms, &ge))
            printf("  GPU check: not run (%s)\n", ge.msg);
        else
            printf("  GPU check: relative RMSE %.4f against the captures (CPU reference %.4f), "
                   "%.0f ms\n",
                   rel, r.rel_rmse_all, ms);
    }
    char name[LR_MATERIAL_NAME_MAX];
    const char *nm = lr_args_get(&a, "--name");
    if (!nm) {
        const char *base = strrchr(out, '/');
        base = base ? base + 1 : out;
        size_t len = strcspn(base, ".");
        snprintf(name, sizeof name, "%.*s", (int)(len < sizeof name ? len : sizeof name - 1),
                 base);
        nm = name;
    }
    char source[512];
    snprintf(source, sizeof source,
             "lamprig fit: %s, object '%s', %d capture(s) from %s read with %s, %s, relative "
             "RMSE %.4f over %ld pixels at %d x %d",
             scene_path, o->name, n, paths[0], resp,
             d.mode == LR_FIT_SCALE ? "two scales on a preset" : "sigma per band",
             r.rel_rmse_all, r.mask_pixels, w, h);
    if (write_material(out, nm, source, &o->material.medium, &e)) {
        status = fail(&e);
        goto done;
    }
    printf("  wrote %s\n", out);
    status = LR_EXIT_OK;
done:
    lr_image_free(&target);
    lr_rig_calib_free(cal);
    free(cal);
    lr_scene_destroy(scene);
    free(list);
    return status;
}
