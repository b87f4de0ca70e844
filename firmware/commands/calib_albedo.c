/* `lamprig calib albedo`: the mockup's response to each projector pixel from a Gray-code
 * capture of the white mockup, for spatial AR (calib/albedo.h). */
#include <stdio.h>
#include <stdlib.h>

#include "calib/albedo.h"
#include "calib/graycode.h"
#include "calib/rig.h"
#include "firmware/commands/calib_cli.h"

/* Linear camera image of an 8-bit capture (the calibration's response and colour matrix). */
static int read_linear(const char *path, const lr_rig_calib *cal, lr_image *out, lr_err *e)
{
    lr_img img;
    int rc = lr_img_read(path, LR_IMG_RGB8, &img, e);
    if (rc)
        return rc;
    if ((rc = lr_image_alloc(out, img.w, img.h, e))) {
        lr_img_free(&img);
        return rc;
    }
    const uint8_t *p = img.px;
    for (size_t k = 0; k < (size_t)img.w * img.h; k++) {
        double v[3];
        lr_rig_camera_to_linear(cal, p + 3 * k, v);
        for (int c = 0; c < 3; c++)
            out->rgb[3 * k + c] = (float)v[c];
    }
    lr_img_free(&img);
    return LR_OK;
}

static int run(const lr_cli *c)
{
    const lr_args *args = &c->args;
    const char *dir = lr_args_get(args, "--captures"), *out = lr_args_get(args, "--out");
    const char *cdir = lr_args_get(args, "--calib");
    int pw = 0, ph = 0, passes = -1, st;
    lr_gc_params params = {0};
    lr_err pe = {0};
    if ((st = lr_cli_check(c, lr_args_size(args, "--proj", &pw, &ph, &pe) ||
                                  lr_args_int(args, "--contrast", &params.contrast, &pe) ||
                                  lr_args_int(args, "--shadow", &params.shadow, &pe) ||
                                  lr_args_int(args, "--fill", &passes, &pe),
                           &pe)))
        return st;
    lr_err e = {0};
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    if (!cal)
        return lr_cli_fail(c->path, "out of memory");
    if (cdir && lr_rig_calib_load(cdir, cal, &e)) {
        free(cal);
        return lr_cli_fail(c->path, "%s", e.msg);
    }
    lr_progress_meter *pm = lr_cli_progress(c);
    lr_gc_map *m = NULL;
    lr_image white = {0}, black = {0};
    lr_albedo a = {0};
    char path[4096];
    int status = LR_EXIT_OK;
    if (lr_gc_decode_dir(dir, pw, ph, &params, lr_progress_meter_sink(pm), &m, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    snprintf(path, sizeof path, "%s/white.png", dir);
    if (read_linear(path, cal, &white, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    snprintf(path, sizeof path, "%s/black.png", dir);
    if (read_linear(path, cal, &black, &e) ||
        lr_albedo_measure(&white, &black, m, passes, &a, &e) || lr_albedo_save(out, &a, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    lr_gc_map_projector_size(m, &pw, &ph);
    printf("%s: mockup response for a %dx%d projector: %ld pixels measured (%.1f %%), %ld "
           "filled; scale %.4g (camera linear units of full white at M = 1)\n",
           out, pw, ph, a.measured_pixels, 100.0 * a.measured_pixels / ((long)pw * ph),
           a.filled_pixels, a.scale);
done:
    lr_albedo_free(&a);
    lr_image_free(&white);
    lr_image_free(&black);
    lr_gc_map_destroy(m);
    lr_progress_meter_destroy(pm);
    lr_rig_calib_free(cal);
    free(cal);
    return status;
}

static const lr_argspec opts[] = {
    {.name = "--captures", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "a Gray-code capture of the white mockup"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the response written (and FILE.pfm beside it)"},
    {.name = "--calib", .type = LR_ARG_PATH, .metavar = "DIR",
     .help = "the calibration folder: its camera response linearises the captures"},
    LR_CALIB_PROJ_OPT(0, "the projector's resolution (default: the folder's sequence.json)"),
    LR_CALIB_DECODE_OPTS,
    {.name = "--fill", .type = LR_ARG_INT, .min = 0, .max = 64,
     .help = "passes filling unmeasured pixels from their neighbours (default 2)"},
    LR_CLI_QUIET_OPT,
    {0},
};

const lr_command lr_calib_albedo = {
    .name = "albedo",
    .summary = "the mockup's response to each projector pixel (white - black, linearised with the\n"
               "calibration folder's camera response) from a Gray-code capture of the white\n"
               "mockup, for spatial AR; writes FILE.json and FILE.pfm beside it",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run,
};
