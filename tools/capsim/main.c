/* lamprig-capsim: what the rig's camera would record for a scene and a calibration folder
 * (issue 5 item 6): the calibrated camera's view (calib/camview.h, pose from pose.json,
 * intrinsics from camera.json) rendered by the GPU renderer (or the CPU twin with --cpu),
 * then the sensor model of calib/capture_sim.h (exposure, vignetting, the inverse of the
 * rig's camera response: camera_response.json or, without it, the gamma curve --gamma
 * (default 2.2), lr_rig_camera_response, the rule compare and fit read captures with; the
 * inverse of color.json, shot + read noise, 8/16-bit).
 *
 *   lamprig-capsim --scene FILE --calib DIR --out IMG.png [--exposure S] [--gain G]
 *                  [--noise FULL_WELL,READ | none] [--seed N] [--bits 8|16]
 *                  [--vignette none|cos4|poly:V1,V2,V3] [--gamma G] [--cpu] [--frames N]
 *                  [--hdr RADIANCE.pfm] [--set key=value ...] [--quiet]
 *
 * --gain defaults to the scene's render.exposure (the capture is then about as bright as
 * the renderer's own PNG at --exposure 1); --noise defaults to 10000 e- full well and 4 e-
 * read noise. --seed drives the sensor noise only; the render uses the renderers' default
 * sample seed, as `lamprig compare` does. The render's progress goes to stderr
 * (render/base/progress.h: frames of the GPU render, the CPU twin's stages), --quiet turns it
 * off. Exit status 0, 1 (failure, message on stderr),
 * 2 (bad arguments). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/capture_sim.h"
#include "calib/rig.h"
#include "calib/view_render.h"
#include "render/scene/scene.h"

#define MAX_SETS 64

static int usage(const char *msg, const char *arg)
{
    if (msg) {
        fprintf(stderr, "lamprig-capsim: ");
        fprintf(stderr, msg, arg);
        fprintf(stderr, "\n");
    }
    fprintf(stderr,
            "usage: lamprig-capsim --scene FILE --calib DIR --out IMG.png [--exposure S] "
            "[--gain G] [--noise FULL_WELL,READ|none] [--seed N] [--bits 8|16] "
            "[--vignette none|cos4|poly:V1,V2,V3] [--gamma G] [--cpu] [--frames N] "
            "[--hdr RADIANCE.pfm] [--set key=value ...] [--quiet]\n");
    return 2;
}

static int number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || !*s || *end || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *calib = NULL, *out = NULL, *hdr = NULL;
    const char *sets[MAX_SETS];
    int nsets = 0;
    lr_sensor s = {.full_well_e = 10000, .read_noise_e = 4, .seed = 1};
    bool cpu = false, gain_given = false, quiet = false;
    double frames = 0, seed = 1, gamma = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--cpu")) {
            cpu = true;
            continue;
        }
        if (!strcmp(a, "--quiet")) {
            quiet = true;
            continue;
        }
        if (!strcmp(a, "--help") || !strcmp(a, "-h"))
            return usage(NULL, NULL), 0;
        if (!v)
            return usage("option '%s' needs a value (or is unknown)", a);
        i++;
        if (!strcmp(a, "--scene"))
            scene_path = v;
        else if (!strcmp(a, "--calib"))
            calib = v;
        else if (!strcmp(a, "--out"))
            out = v;
        else if (!strcmp(a, "--hdr"))
            hdr = v;
        else if (!strcmp(a, "--set")) {
            if (nsets >= MAX_SETS)
                return usage("too many --set (at most 64)%s", "");
            sets[nsets++] = v;
        } else if (!strcmp(a, "--exposure")) {
            if (number(v, 1e-9, 1e6, &s.exposure_s))
                return usage("--exposure '%s': expected seconds > 0", v);
        } else if (!strcmp(a, "--gain")) {
            if (number(v, 1e-12, 1e12, &s.gain))
                return usage("--gain '%s': expected a number > 0", v);
            gain_given = true;
        } else if (!strcmp(a, "--gamma")) {
            if (number(v, 0.1, 10, &gamma))
                return usage("--gamma '%s': expected 0.1..10", v);
        } else if (!strcmp(a, "--seed")) {
            if (number(v, 0, 4294967295.0, &seed) || seed != floor(seed))
                return usage("--seed '%s': expected a non-negative integer", v);
        } else if (!strcmp(a, "--frames")) {
            if (number(v, 1, 1e6, &frames) || frames != floor(frames))
                return usage("--frames '%s': expected a count >= 1", v);
        } else if (!strcmp(a, "--bits")) {
            if (strcmp(v, "8") && strcmp(v, "16"))
                return usage("--bits '%s': expected 8 or 16", v);
            s.bits = atoi(v);
        } else if (!strcmp(a, "--noise")) {
            int n = 0;
            if (!strcmp(v, "none")) {
                s.full_well_e = s.read_noise_e = 0;
            } else if (sscanf(v, "%lf,%lf%n", &s.full_well_e, &s.read_noise_e, &n) != 2 ||
                       v[n] || !(s.full_well_e > 0) || !(s.read_noise_e >= 0)) {
                return usage("--noise '%s': expected FULL_WELL,READ (electrons) or none", v);
            }
        } else if (!strcmp(a, "--vignette")) {
            lr_err ve = {0};
            if (lr_sensor_parse_vignette(v, &s, &ve))
                return usage("--vignette %s", ve.msg);
        } else {
            return usage("unknown option '%s'", a);
        }
    }
    if (!scene_path || !calib || !out)
        return usage("--scene, --calib and --out are required%s", "");
    s.seed = (uint64_t)seed;

    lr_err e = {0};
    lr_scene *scene = NULL;
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    lr_camview *view = NULL;
    lr_progress_meter *pm = NULL;
    lr_image rad = {0};
    lr_img cap = {0};
    int status = 1;
    if (!rig) {
        fprintf(stderr, "lamprig-capsim: out of memory\n");
        return 1;
    }
    if (lr_rig_calib_load(calib, rig, &e) || lr_scene_load(scene_path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-capsim"}, &scene, &e))
        goto fail;
    if (!rig->has_camera || !rig->has_pose) {
        lr_err_set(&e, LR_EINVAL, "%s: needs camera.json (intrinsics) and pose.json (lamprig "
                                  "calib pose) for the camera's view", calib);
        goto fail;
    }
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(scene, sets[i], NULL, &e)) {
            lr_err_prefix(&e, "--set %s", sets[i]);
            goto fail;
        }
    if (!gain_given)
        s.gain = lr_scene_render(scene)->exposure;
    if (gamma > 0 && lr_rig_set_gamma(rig, gamma, &e)) {
        lr_err_prefix(&e, "--gamma");
        goto fail;
    }
    /* The rule every reader of captures uses; the simulator writes its inverse. */
    lr_camresp response;
    lr_rig_camera_response(rig, &response);
    s.response = &response;
    if (rig->has_color)
        s.color = &rig->color;
    if (s.vignette == LR_VIGNETTE_COS4) {
        s.focal_px = sqrt(rig->camera.k.fx * rig->camera.k.fy);
        s.cx = rig->camera.k.cx;
        s.cy = rig->camera.k.cy;
    }
    if (lr_sensor_check(&s, &e) ||
        lr_camview_create(&rig->camera.k, &rig->pose.camera, 0, &view, &e))
        goto fail;
    double secs = 0;
    /* The renderers' default sample seed, as `lamprig compare` uses: a capture and a
     * comparison at the same --frames see the same Monte Carlo samples, so what differs is
     * the sensor alone (--seed drives its noise). */
    if (lr_progress_meter_create(&(lr_progress_meter_desc){.prefix = "lamprig-capsim",
                                                            .style = quiet ? LR_PROGRESS_QUIET
                                                                           : LR_PROGRESS_AUTO},
                                 &pm, &e))
        goto fail;
    lr_view_render_desc vd = {.scene = scene, .view = view, .cpu = cpu, .frames = (int)frames,
                              .progress = lr_progress_meter_sink(pm)};
    int rrc = lr_view_render(&vd, &rad, &secs, &e);
    lr_progress_meter_destroy(pm);
    pm = NULL;
    if (rrc || (hdr && lr_image_write_pfm(hdr, &rad, &e)) ||
        lr_sensor_capture(&s, &rad, &cap, &e) || lr_img_write(out, &cap, &e))
        goto fail;
    char rname[256];
    printf("capture %dx%d (%d-bit) of %s through %s: render %.2f s (%s) -> %s\n"
           "written with the response %s\n",
           cap.w, cap.h, cap.depth * 8, scene_path, calib, secs, cpu ? "CPU twin" : "GPU", out,
           lr_rig_response_name(rig, rname, sizeof rname));
    status = 0;
    goto done;
fail:
    fprintf(stderr, "lamprig-capsim: %s\n", e.msg);
done:
    lr_progress_meter_destroy(pm);
    lr_img_free(&cap);
    lr_image_free(&rad);
    lr_camview_destroy(view);
    lr_scene_destroy(scene);
    lr_rig_calib_free(rig);
    free(rig);
    return status;
}
