/* `lamprig compare`: argument parsing, the run and its report around calib/compare.h and
 * calib/view_render.h. Nothing is written unless the whole comparison succeeded; the report
 * and the heatmap are written atomically. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/capture_sim.h"
#include "calib/compare.h"
#include "calib/calfile.h" /* the JSON writer (lr_jw), wherever it lives */
#include "calib/rig.h"
#include "calib/view_render.h"
#include "firmware/commands/commands.h"
#include "render/base/atomic_file.h"
#include "render/scene/scene.h"

#define MAX_CAPTURES 16
#define MAX_SETS 64

static int run_compare(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED, .help = "the scene"},
    {.name = "--calib", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the calibration folder (camera.json and pose.json required;\n"
             "camera_response.json and color.json used when present)"},
    {.name = "--capture", .type = LR_ARG_PATH, .metavar = "IMG",
     .flags = LR_ARG_REQUIRED | LR_ARG_LIST, .repeat = MAX_CAPTURES,
     .help = "the captures (several: an exposure stack, merged to HDR)"},
    {.name = "--report", .type = LR_ARG_PATH, .metavar = "OUT.json", .flags = LR_ARG_REQUIRED,
     .help = "the report, JSON"},
    {.name = "--heatmap", .type = LR_ARG_PATH, .metavar = "OUT.png",
     .help = "the per-pixel CIEDE2000 (scale 0..--heatmap-max)"},
    {.name = "--times", .type = LR_ARG_STRING, .metavar = "T1,T2,...",
     .help = "exposure times of the captures, s (1/30 allowed; default 1 s for one)"},
    {.name = "--gain", .type = LR_ARG_NUMBER, .metavar = "G", .flags = LR_ARG_ABOVE_MIN,
     .max = 1e12,
     .help = "capture units per render unit (default: the scene's render.exposure,\n"
             "as lamprig-capsim assumes)"},
    {.name = "--gamma", .type = LR_ARG_NUMBER, .metavar = "G", .min = 0.1, .max = 10,
     .help = "the camera's response without camera_response.json (default 2.2)"},
    {.name = "--cpu", .help = "render with the CPU twin instead of the GPU renderer"},
    {.name = "--frames", .type = LR_ARG_INT, .min = 1, .max = 1000000,
     .help = "frames to render (default: until converged)"},
    {.name = "--heatmap-max", .type = LR_ARG_NUMBER, .metavar = "DE",
     .flags = LR_ARG_ABOVE_MIN, .max = 1e6,
     .help = "the heatmap's full scale, CIEDE2000 (default 10)"},
    {.name = "--render-out", .type = LR_ARG_PATH, .metavar = "R.pfm",
     .help = "the render, linear PFM"},
    {.name = "--vignette", .type = LR_ARG_STRING, .metavar = "none|cos4|poly:V1,V2,V3",
     .help = "divide the capture by a vignetting model (as lamprig-capsim applies\n"
             "it; cos4 uses the calibrated focal length and principal point)"},
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "key=value", .repeat = MAX_SETS,
     .help = "change a scene parameter first (repeatable), as in lamprig render"},
    LR_CLI_QUIET_OPT,
    {0},
};

const lr_command lr_compare_command = {
    .name = "compare",
    .summary = "compare a render of the calibrated camera's view with captures",
    .about =
        "Renders the camera's view of the scene with the calibrated intrinsics and pose (DIR:\n"
        "camera.json and pose.json required; camera_response.json and color.json used when\n"
        "present; without camera_response.json captures are read as gamma --gamma, default 2.2,\n"
        "the rule lamprig fit and lamprig-capsim use), linearises the captures (several\n"
        "captures are an exposure stack with --times in seconds, merged to HDR; one capture has\n"
        "time 1 s unless --times says otherwise), divides by --gain (default: the scene's\n"
        "render.exposure, as lamprig-capsim assumes) and reports per region (object, receivers,\n"
        "all; boundary, saturated and shadow pixels excluded): relative RMSE in linear light,\n"
        "SSIM on luminance, mean and 95th-percentile CIEDE2000, and the render time.\n"
        "--heatmap writes the per-pixel CIEDE2000 (scale 0..--heatmap-max, default 10).\n"
        "--cpu renders with the CPU twin instead of the GPU renderer. --vignette divides the\n"
        "capture by a vignetting model (as lamprig-capsim applies it; cos4 uses the calibrated\n"
        "focal length and principal point). Progress (render frames) goes to stderr; --quiet\n"
        "turns it off.",
    .opts = opts,
    .notes = "Exit status: 0 success, 1 failure (nothing written), 2 bad arguments.",
    .run = run_compare,
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

typedef struct report {
    const char *scene, *calib, *response;
    const char *const *captures;
    const double *times;
    int ncaptures, width, height, render_w, render_h;
    bool cpu;
    double render_s, total_s;
    const lr_compare_result *res;
} report;

static int write_report(const char *path, const report *r, lr_err *e)
{
    lr_atomic_file *f = NULL;
    int rc = lr_atomic_file_open(path, &f, e);
    if (rc)
        return rc;
    lr_jw *w = lr_jw_create(lr_atomic_file_stream(f));
    if (!w) {
        lr_atomic_file_abort(f);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    lr_jw_object(w, NULL);
    lr_jw_int(w, "version", 1);
    lr_jw_string(w, "kind", "comparison");
    lr_jw_string(w, "scene", r->scene);
    lr_jw_string(w, "calib", r->calib);
    lr_jw_array(w, "captures");
    for (int i = 0; i < r->ncaptures; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "path", r->captures[i]);
        lr_jw_number(w, "time_s", r->times[i]);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    /* How the captures were linearised (lr_rig_response_name). */
    lr_jw_string(w, "response", r->response);
    lr_jw_string(w, "renderer", r->cpu ? "cpu" : "gpu");
    lr_jw_numbers(w, "image_size", (const double[]){r->width, r->height}, 2);
    /* The undistorted pinhole render behind the camera's view (calib/camview.h). */
    lr_jw_numbers(w, "render_size", (const double[]){r->render_w, r->render_h}, 2);
    lr_jw_number(w, "render_s", r->render_s);
    lr_jw_number(w, "total_s", r->total_s);
    lr_jw_number(w, "scale", r->res->scale);
    lr_jw_int(w, "excluded_pixels", r->res->excluded);
    lr_jw_int(w, "edge_pixels", r->res->edge);
    lr_jw_object(w, "regions");
    for (int g = 0; g < LR_REGION_COUNT; g++) {
        const lr_compare_stats *s = &r->res->region[g];
        lr_jw_object(w, lr_compare_region_name(g));
        lr_jw_int(w, "pixels", s->pixels);
        if (s->pixels > 0) { /* no metric for an empty region (JSON has no NaN) */
            lr_jw_number(w, "rmse", s->rmse);
            lr_jw_number(w, "rel_rmse", s->rel_rmse);
            lr_jw_number(w, "ssim", s->ssim);
            lr_jw_number(w, "delta_e", s->delta_e);
            lr_jw_number(w, "delta_e_p95", s->delta_e_p95);
        }
        lr_jw_object_end(w);
    }
    lr_jw_object_end(w);
    lr_jw_object_end(w);
    if ((rc = lr_jw_finish(w, e))) {
        lr_atomic_file_abort(f);
        return lr_err_prefix(e, "%s", path);
    }
    fputc('\n', lr_atomic_file_stream(f));
    return lr_atomic_file_commit(f, e);
}

static int run_compare(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *scene_path = lr_args_get(a, "--scene"), *calib = lr_args_get(a, "--calib");
    const char *report_path = lr_args_get(a, "--report"), *heatmap = lr_args_get(a, "--heatmap");
    const char *times_s = lr_args_get(a, "--times"), *render_out = lr_args_get(a, "--render-out");
    const char *vignette = lr_args_get(a, "--vignette");
    const char *captures[MAX_CAPTURES], *sets[MAX_SETS];
    int ncap = lr_args_values(a, "--capture", captures, MAX_CAPTURES);
    int nsets = lr_args_values(a, "--set", sets, MAX_SETS);
    double gain = 0, gamma = 0, hmax = 10;
    int frames = 0;
    bool cpu = lr_args_has(a, "--cpu");
    lr_err pe = {0};
    int st = lr_cli_check(c, lr_args_double(a, "--gain", &gain, &pe) ||
                                 lr_args_double(a, "--gamma", &gamma, &pe) ||
                                 lr_args_int(a, "--frames", &frames, &pe) ||
                                 lr_args_double(a, "--heatmap-max", &hmax, &pe),
                          &pe);
    if (st)
        return st;
    double times[MAX_CAPTURES];
    if (times_s) {
        int nt = lr_args_times(times_s, times, MAX_CAPTURES);
        if (nt != ncap)
            return lr_cli_usage(c->path, "--times '%s': expected one exposure time (s) per capture",
                                times_s);
    } else if (ncap > 1) {
        return lr_cli_usage(c->path, "%s", "an exposure stack of several captures needs --times");
    } else {
        times[0] = 1.0;
    }

    lr_sensor vig = {0};
    if (vignette) {
        lr_err ve = {0};
        if (lr_sensor_parse_vignette(vignette, &vig, &ve))
            return lr_cli_usage(c->path, "--vignette %s", ve.msg);
    }

    double t0 = now_s();
    lr_err e = {0};
    int status = LR_EXIT_FAIL;
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    lr_scene *scene = NULL;
    lr_camview *view = NULL;
    lr_img imgs[MAX_CAPTURES];
    int nimg = 0;
    lr_image cap = {0}, ren = {0};
    uint8_t *labels = NULL, *exclude = NULL;
    float *demap = NULL;
    if (!rig) {
        lr_err_set(&e, LR_ENOMEM, "out of memory");
        goto fail;
    }
    if (lr_rig_calib_load(calib, rig, &e))
        goto fail;
    if (gamma > 0 && lr_rig_set_gamma(rig, gamma, &e)) {
        status = lr_cli_usage(c->path, "--gamma: %s", e.msg);
        goto done;
    }
    if (!rig->has_camera || !rig->has_pose) {
        lr_err_set(&e, LR_EINVAL,
                   "%s: a comparison needs camera.json (lamprig calib camera) and pose.json "
                   "(lamprig calib pose)%s%s",
                   calib, rig->has_camera ? "" : "; camera.json is missing",
                   rig->has_pose ? "" : "; pose.json is missing");
        goto fail;
    }
    lr_warn_sink warn = lr_cli_warn_sink(c->path);
    if (lr_scene_load(scene_path, &warn, &scene, &e))
        goto fail;
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(scene, sets[i], NULL, &e)) {
            status = lr_cli_usage(c->path, "--set: %s", e.msg);
            goto done;
        }
    for (; nimg < ncap; nimg++)
        if (lr_img_read(captures[nimg], LR_IMG_AS_IS, &imgs[nimg], &e))
            goto fail;
    const lr_intrinsics *k = &rig->camera.k;
    for (int i = 0; i < ncap; i++)
        if (imgs[i].w != k->width || imgs[i].h != k->height) {
            lr_err_set(&e, LR_EINVAL, "%s is %dx%d but the camera (%s/camera.json) is %dx%d",
                       captures[i], imgs[i].w, imgs[i].h, calib, k->width, k->height);
            goto fail;
        }
    if (gain <= 0)
        gain = lr_scene_render(scene)->exposure;
    size_t np = (size_t)k->width * k->height;
    if (!(labels = malloc(np)) || !(exclude = malloc(np)) ||
        !(demap = malloc(np * sizeof *demap))) {
        lr_err_set(&e, LR_ENOMEM, "out of memory");
        goto fail;
    }
    if (lr_compare_linearise(rig, imgs, times, ncap, gain, &cap, &e) ||
        lr_compare_capture_mask(imgs, ncap, 0, 0, exclude, &e))
        goto fail;
    if (vig.vignette != LR_VIGNETTE_NONE) {
        vig.focal_px = sqrt(k->fx * k->fy);
        vig.cx = k->cx;
        vig.cy = k->cy;
        if (lr_sensor_check(&vig, &e))
            goto fail;
        for (int y = 0; y < k->height; y++)
            for (int x = 0; x < k->width; x++) {
                double V = lr_sensor_vignette(&vig, k->width, k->height, x, y);
                for (int ch = 0; ch < 3; ch++) { /* V = 0 (a polynomial's far corner): excluded */
                    float *p = cap.rgb + 3 * ((size_t)y * k->width + x) + ch;
                    *p = V > 1e-6 ? (float)(*p / V) : NAN;
                }
            }
    }
    if (lr_camview_create(k, &rig->pose.camera, 0, &view, &e) ||
        lr_camview_labels(view, scene, labels, &e))
        goto fail;
    double render_s = 0;
    lr_progress_meter *pm = lr_cli_progress(c);
    lr_view_render_desc vd = {.scene = scene, .view = view, .cpu = cpu, .frames = frames,
                              .progress = lr_progress_meter_sink(pm)};
    int rrc = lr_view_render(&vd, &ren, &render_s, &e);
    lr_progress_meter_destroy(pm);
    if (rrc)
        goto fail;
    lr_compare_result res;
    lr_compare_desc cd = {.render = &ren, .capture = &cap, .labels = labels, .exclude = exclude};
    if (lr_compare_run(&cd, &res, demap, &e))
        goto fail;
    int rw, rh;
    lr_camview_render_size(view, &rw, &rh);
    char resp[256];
    report r = {scene_path, calib, lr_rig_response_name(rig, resp, sizeof resp), captures,
                times, ncap, k->width, k->height, rw, rh, cpu, render_s, now_s() - t0, &res};
    if ((render_out && lr_image_write_pfm(render_out, &ren, &e)) ||
        (heatmap && lr_heatmap_png(heatmap, demap, k->width, k->height, hmax,
                                   "CIEDE2000, render vs capture (grey: not compared)", &e)) ||
        write_report(report_path, &r, &e))
        goto fail;
    for (int g = 0; g < LR_REGION_COUNT; g++) {
        const lr_compare_stats *s = &res.region[g];
        if (s->pixels == 0)
            printf("%-9s      0 px\n", lr_compare_region_name(g));
        else
            printf("%-9s %7ld px  rel RMSE %.4f  SSIM %.4f  dE00 mean %.3f p95 %.3f\n",
                   lr_compare_region_name(g), s->pixels, s->rel_rmse, s->ssim, s->delta_e,
                   s->delta_e_p95);
    }
    printf("captures read with %s\n", resp);
    printf("render %.2f s (%s, %dx%d undistorted), total %.2f s -> %s\n", render_s,
           cpu ? "CPU twin" : "GPU", rw, rh, r.total_s, report_path);
    status = LR_EXIT_OK;
    goto done;
fail:
    status = lr_cli_fail(c->path, "%s", e.msg);
done:
    for (int i = 0; i < nimg; i++)
        lr_img_free(&imgs[i]);
    lr_image_free(&cap);
    lr_image_free(&ren);
    free(labels);
    free(exclude);
    free(demap);
    lr_camview_destroy(view);
    lr_scene_destroy(scene);
    lr_rig_calib_free(rig);
    free(rig);
    return status;
}
