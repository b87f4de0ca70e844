/* `lamprig calib ar-frame`: one spatial-AR projector frame from a scene and a calibration
 * folder (calib/ar_frame.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calib/albedo.h"
#include "calib/ar_frame.h"
#include "calib/rig.h"
#include "firmware/commands/calib_cli.h"
#include "render/scene/scene.h"

static int run(const lr_cli *c)
{
    const lr_args *args = &c->args;
    const char *scene_path = lr_args_get(args, "--scene"), *cdir = lr_args_get(args, "--calib");
    const char *out = lr_args_get(args, "--out"), *tpath = lr_args_get(args, "--target");
    lr_ar_frame_desc d = {0};
    int sd = 0, rc;
    lr_err pe = {0};
    if ((rc = lr_cli_check(c, lr_args_double(args, "--gain", &d.gain, &pe) ||
                                  lr_args_int(args, "--samples", &d.samples, &pe) ||
                                  lr_args_int(args, "--render-width", &d.render_width, &pe) ||
                                  lr_args_int(args, "--seed", &sd, &pe),
                           &pe)))
        return rc;
    d.seed = (unsigned)sd;
    lr_err e = {0};
    lr_scene *scene = NULL;
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    lr_albedo a = {0};
    lr_image levels = {0}, target = {0};
    lr_img png = {0};
    int status = LR_EXIT_FAIL;
    if (!cal)
        return lr_cli_fail(c->path, "out of memory");
    lr_warn_sink warn = lr_cli_warn_sink(c->path);
    if (lr_scene_load(scene_path, &warn, &scene, &e) || lr_rig_calib_load(cdir, cal, &e)) {
        lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    char apath[4096];
    snprintf(apath, sizeof apath, "%s/%s", cdir, LR_RIG_ALBEDO);
    FILE *f = fopen(apath, "r");
    if (f) {
        fclose(f);
        if (lr_albedo_load(apath, &a, &e)) {
            lr_cli_fail(c->path, "%s", e.msg);
            goto done;
        }
    }
    d.scene = scene;
    d.calib = cal;
    d.response = f ? &a.response : NULL;
    lr_ar_stats st;
    if (lr_ar_frame(&d, &levels, &target, &st, &e) ||
        (tpath && lr_image_write_pfm(tpath, &target, &e)) ||
        lr_img_alloc(&png, levels.width, levels.height, 3, 1, &e)) {
        lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    uint8_t *px = png.px;
    for (size_t k = 0; k < (size_t)levels.width * levels.height * 3; k++)
        px[k] = (uint8_t)lrint(255 * fmin(1.0, fmax(0.0, levels.rgb[k])));
    if (lr_img_write(out, &png, &e)) {
        lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    char msg[128];
    lr_ar_stats_format(&st, msg, sizeof msg);
    printf("%s: %dx%d projector frame, mockup response from %s; gain %.4g; %s (%ld of %ld lit "
           "pixels)\n",
           out, levels.width, levels.height, f ? apath : "the scene's geometry (ideal white)",
           st.gain, msg, st.clipped_pixels, st.lit_pixels);
    status = LR_EXIT_OK;
done:
    lr_img_free(&png);
    lr_image_free(&levels);
    lr_image_free(&target);
    lr_albedo_free(&a);
    lr_rig_calib_free(cal);
    free(cal);
    lr_scene_destroy(scene);
    return status;
}

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED, .help = "the scene"},
    {.name = "--calib", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the calibration folder (pose.json's projector pose; albedo.json when\n"
             "present)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "LEVELS.png", .flags = LR_ARG_REQUIRED,
     .help = "the projector frame written"},
    {.name = "--target", .type = LR_ARG_PATH, .metavar = "OUT.pfm",
     .help = "the target radiance too, linear PFM"},
    {.name = "--gain", .type = LR_ARG_NUMBER, .metavar = "G", .flags = LR_ARG_ABOVE_MIN,
     .max = 1e30,
     .help = "target units -> relative light (default: the brightest target point\n"
             "is full white on a perfect white surface)"},
    {.name = "--samples", .type = LR_ARG_INT, .min = 1, .max = 1 << 20,
     .help = "CPU reference samples per band per pixel (default 64)"},
    {.name = "--render-width", .type = LR_ARG_INT, .min = 2, .max = 16384,
     .help = "render width (default: the projector's)"},
    {.name = "--seed", .type = LR_ARG_INT, .min = 1, .max = 1 << 30,
     .help = "the reference renderer's random seed"},
    {0},
};

const lr_command lr_calib_ar_frame = {
    .name = "ar-frame",
    .summary = "one spatial-AR projector frame: the scene rendered from the projector (pose.json's\n"
               "projector pose), divided by the mockup's response (DIR/albedo.json, else an ideal\n"
               "white mockup of the scene's geometry), clipped, through the inverse projector\n"
               "response; prints how much was clipped",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run,
};
