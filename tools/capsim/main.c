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
#include "firmware/tool.h"
#include "render/scene/scene.h"

#define PROGRAM "lamprig-capsim"
#define MAX_SETS 64

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the scene file (configs/scenes/)"},
    {.name = "--calib", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the rig's calibration folder: camera.json and pose.json (needed),\n"
             "camera_response.json and color.json (used when present)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "IMG.png", .flags = LR_ARG_REQUIRED,
     .help = "the simulated capture"},
    {.name = "--exposure", .type = LR_ARG_NUMBER, .metavar = "S", .min = 1e-9, .max = 1e6,
     .help = "exposure time in seconds (1e-9..1e6, default 1)"},
    {.name = "--gain", .type = LR_ARG_NUMBER, .metavar = "G", .min = 1e-12, .max = 1e12,
     .help = "radiance to sensor gain (1e-12..1e12; default the scene's\n"
             "render.exposure)"},
    {.name = "--noise", .type = LR_ARG_STRING, .metavar = "FULL_WELL,READ|none",
     .help = "shot and read noise: full well and read noise in electrons (default\n"
             "10000,4), or none"},
    {.name = "--seed", .type = LR_ARG_INT, .metavar = "N", .min = 0, .max = 4294967295.0,
     .help = "seed of the sensor noise (default 1; the render keeps its own)"},
    {.name = "--bits", .type = LR_ARG_CHOICE, .choices = "8|16",
     .help = "bits per channel (default 8)"},
    {.name = "--vignette", .type = LR_ARG_STRING, .metavar = "none|cos4|poly:V1,V2,V3",
     .help = "vignetting model (default none)"},
    {.name = "--gamma", .type = LR_ARG_NUMBER, .metavar = "G", .min = 0.1, .max = 10,
     .help = "the camera's gamma when the rig has no camera_response.json\n"
             "(0.1..10, default 2.2)"},
    {.name = "--cpu", .help = "render with the CPU twin instead of the GPU renderer"},
    {.name = "--frames", .type = LR_ARG_INT, .min = 1, .max = 1e6,
     .help = "progressive frames of the render (1..1000000; default the scene's)"},
    {.name = "--hdr", .type = LR_ARG_PATH, .metavar = "RADIANCE.pfm",
     .help = "also write the rendered radiance before the sensor model"},
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "key=value", .repeat = MAX_SETS,
     .help = "change a scene field before rendering (repeatable)"},
    LR_CLI_QUIET_OPT,
    {0},
};

static const lr_command tool = {
    .name = PROGRAM,
    .about = "What the rig's camera would record for a scene and a calibration folder: the\n"
             "calibrated camera's view rendered by the GPU renderer (or the CPU twin with --cpu),\n"
             "then the sensor model (exposure, vignetting, the inverse of the rig's camera\n"
             "response, the inverse of color.json, shot + read noise, 8/16-bit).",
    .opts = opts,
    .notes = "Exit status 0, 1 (failure, message on stderr), 2 (bad arguments).",
};

/* --noise: "none" or FULL_WELL,READ in electrons, the full well > 0 and the read noise >= 0. */
static int parse_noise(const char *v, lr_sensor *s, lr_err *e)
{
    if (!strcmp(v, "none")) {
        s->full_well_e = s->read_noise_e = 0;
        return LR_OK;
    }
    double x[2];
    int n = 0;
    if (lr_args_numbers("--noise", v, x, 2, 2, &n, e) || !(x[0] > 0) || !(x[1] >= 0))
        return lr_err_set(e, LR_EINVAL, "--noise '%s': expected FULL_WELL,READ (electrons, "
                          "FULL_WELL > 0, READ >= 0) or none", v);
    s->full_well_e = x[0];
    s->read_noise_e = x[1];
    return LR_OK;
}

int main(int argc, char **argv)
{
    lr_sensor s = {.full_well_e = 10000, .read_noise_e = 4, .seed = 1};
    long long seed = 1;
    int frames = 0, bits = 0;
    double gamma = 0;
    lr_args args;
    int st = lr_tool_args(&tool, argc, argv, &args);
    if (st >= 0)
        return st;
    lr_err ae = {0};
    const char *noise = lr_args_get(&args, "--noise"), *vig = lr_args_get(&args, "--vignette");
    /* The first reader that refuses its value stops the chain; ae says which and why. */
    if (lr_args_double(&args, "--exposure", &s.exposure_s, &ae) ||
        lr_args_double(&args, "--gain", &s.gain, &ae) ||
        lr_args_double(&args, "--gamma", &gamma, &ae) ||
        lr_args_int64(&args, "--seed", &seed, &ae) ||
        lr_args_int(&args, "--frames", &frames, &ae) ||
        lr_args_choice(&args, "--bits", &bits, &ae) || (noise && parse_noise(noise, &s, &ae)))
        return lr_tool_usage(PROGRAM, "%s", ae.msg);
    if (vig && lr_sensor_parse_vignette(vig, &s, &ae))
        return lr_tool_usage(PROGRAM, "--vignette %s", ae.msg);
    if (lr_args_has(&args, "--bits"))
        s.bits = bits ? 16 : 8;
    const char *scene_path = lr_args_get(&args, "--scene"), *calib = lr_args_get(&args, "--calib");
    const char *out = lr_args_get(&args, "--out"), *hdr = lr_args_get(&args, "--hdr");
    const char *sets[MAX_SETS];
    int nsets = lr_args_values(&args, "--set", sets, MAX_SETS);
    bool cpu = lr_args_has(&args, "--cpu"), quiet = lr_args_has(&args, "--quiet");
    bool gain_given = lr_args_has(&args, "--gain");
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
