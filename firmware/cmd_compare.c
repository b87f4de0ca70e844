/* `lamprig compare`: argument parsing, the run and its report around calib/compare.h and
 * calib/view_render.h. Nothing is written unless the whole comparison succeeded; the report
 * and the heatmap are written atomically. */
#include "firmware/cmd_compare.h"

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
#include "firmware/args.h"
#include "firmware/cli.h"
#include "render/base/atomic_file.h"
#include "render/scene/scene.h"

#define MAX_CAPTURES 16
#define MAX_SETS 64

const char lr_compare_summary[] = "compare a render of the calibrated camera's view with captures";
const char lr_compare_usage[] =
    "usage: lamprig compare --scene FILE --calib DIR --capture IMG [IMG...] --report OUT.json\n"
    "                       [--heatmap OUT.png] [--times T1,T2,...] [--gain G] [--gamma G]\n"
    "                       [--cpu] [--frames N] [--heatmap-max DE] [--render-out R.pfm]\n"
    "                       [--vignette none|cos4|poly:V1,V2,V3] [--set key=value ...]\n"
    "\n"
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
    "focal length and principal point).\n"
    "\n"
    "Exit status: 0 success, 1 failure (nothing written), 2 bad arguments.";

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "lamprig compare: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see `lamprig help compare`)\n");
    return LR_EXIT_USAGE;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int parse_number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || !*s || *end || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
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

int lr_cmd_compare(int argc, char **argv)
{
    const char *scene_path = NULL, *calib = NULL, *report_path = NULL, *heatmap = NULL;
    const char *times_s = NULL, *render_out = NULL, *vignette = NULL;
    const char *captures[MAX_CAPTURES], *sets[MAX_SETS];
    int ncap = 0, nsets = 0;
    double gain = 0, gamma = 0, frames = 0, hmax = 10;
    bool cpu = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--cpu")) {
            cpu = true;
            continue;
        }
        if (!strcmp(a, "--capture")) {
            while (i + 1 < argc && strncmp(argv[i + 1], "--", 2) != 0) {
                if (ncap >= MAX_CAPTURES)
                    return usage_error("%s", "too many captures (at most 16)");
                captures[ncap++] = argv[++i];
            }
            continue;
        }
        if (strncmp(a, "--", 2) != 0)
            return usage_error("unexpected argument '%s'", a);
        if (i + 1 >= argc)
            return usage_error("option '%s' needs a value (or is unknown)", a);
        const char *v = argv[++i];
        if (!strcmp(a, "--scene"))
            scene_path = v;
        else if (!strcmp(a, "--calib"))
            calib = v;
        else if (!strcmp(a, "--report"))
            report_path = v;
        else if (!strcmp(a, "--heatmap"))
            heatmap = v;
        else if (!strcmp(a, "--times"))
            times_s = v;
        else if (!strcmp(a, "--render-out"))
            render_out = v;
        else if (!strcmp(a, "--vignette"))
            vignette = v;
        else if (!strcmp(a, "--set")) {
            if (nsets >= MAX_SETS)
                return usage_error("%s", "too many --set (at most 64)");
            sets[nsets++] = v;
        } else if (!strcmp(a, "--gain")) {
            if (parse_number(v, 1e-12, 1e12, &gain))
                return usage_error("--gain '%s': expected a number > 0", v);
        } else if (!strcmp(a, "--gamma")) {
            if (parse_number(v, 0.1, 10, &gamma))
                return usage_error("--gamma '%s': expected 0.1..10", v);
        } else if (!strcmp(a, "--frames")) {
            if (parse_number(v, 1, 1e6, &frames) || frames != floor(frames))
                return usage_error("--frames '%s': expected a count >= 1", v);
        } else if (!strcmp(a, "--heatmap-max")) {
            if (parse_number(v, 1e-6, 1e6, &hmax))
                return usage_error("--heatmap-max '%s': expected a number > 0", v);
        } else {
            return usage_error("unknown option '%s'", a);
        }
    }
    if (!scene_path)
        return usage_error("%s", "missing --scene");
    if (!calib)
        return usage_error("%s", "missing --calib");
    if (!report_path)
        return usage_error("%s", "missing --report");
    if (ncap == 0)
        return usage_error("%s", "missing --capture IMG [IMG...]");
    double times[MAX_CAPTURES];
    if (times_s) {
        int nt = lr_args_times(times_s, times, MAX_CAPTURES);
        if (nt != ncap)
            return usage_error("--times '%s': expected one exposure time (s) per capture", times_s);
    } else if (ncap > 1) {
        return usage_error("%s", "an exposure stack of several captures needs --times");
    } else {
        times[0] = 1.0;
    }

    lr_sensor vig = {0};
    if (vignette) {
        lr_err ve = {0};
        if (lr_sensor_parse_vignette(vignette, &vig, &ve))
            return usage_error("--vignette %s", ve.msg);
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
        status = usage_error("--gamma: %s", e.msg);
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
    if (lr_scene_load(scene_path, NULL, &scene, &e))
        goto fail;
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(scene, sets[i], NULL, &e)) {
            status = usage_error("--set: %s", e.msg);
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
                for (int c = 0; c < 3; c++) { /* V = 0 (a polynomial's far corner): excluded */
                    float *p = cap.rgb + 3 * ((size_t)y * k->width + x) + c;
                    *p = V > 1e-6 ? (float)(*p / V) : NAN;
                }
            }
    }
    if (lr_camview_create(k, &rig->pose.camera, 0, &view, &e) ||
        lr_camview_labels(view, scene, labels, &e))
        goto fail;
    double render_s = 0;
    lr_view_render_desc vd = {.scene = scene, .view = view, .cpu = cpu, .frames = (int)frames};
    if (lr_view_render(&vd, &ren, &render_s, &e))
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
    fprintf(stderr, "lamprig compare: %s\n", e.msg);
    status = LR_EXIT_FAIL;
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
